"""The benchmark's tiers, read from ``tasks/rubiks/tiers.toml``.

The tiers and the paper's baseline figures are data, not code, so that the
table can be checked against the paper line by line and so that a packaged
install reads the same file (through :func:`benchharness.paths.tasks_dir`).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10 (requires-python >= 3.10): the same parser, as the tomli package
    import tomli as tomllib

from ..paths import tasks_dir
from .moves import Move
from .sequences import generate_sequences


@dataclass(frozen=True)
class BaselineScore:
    """One published baseline on one tier (Table I of the paper)."""

    key: str
    label: str
    completed: bool
    mean_s: float | None = None
    std_s: float | None = None

    def describe(self) -> str:
        if not self.completed:
            return "not completed"
        std = "—" if self.std_s is None else f"{self.std_s:.2f}"
        return f"{self.mean_s:.2f} / {std} s"


@dataclass(frozen=True)
class RubiksTier:
    """Tier ``Rubiks-M-N``: ``trials`` (M) consecutive trials of ``moves`` (N) turns."""

    name: str
    trials: int
    moves: int
    baselines: tuple[BaselineScore, ...] = ()

    @property
    def summary(self) -> str:
        return f"Rubik's cube: {self.trials} trial{'s' if self.trials != 1 else ''} × {self.moves} moves"

    def sequences(self, seed: int = 0) -> list[tuple[Move, ...]]:
        """The tier's M sequences for ``seed`` (see :mod:`benchharness.cube.sequences`)."""
        return generate_sequences(seed, self.name, self.trials, self.moves)

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "trials": self.trials,
            "moves": self.moves,
            "baselines": {
                b.key: {
                    "label": b.label,
                    "completed": b.completed,
                    "mean_s": b.mean_s,
                    "std_s": b.std_s,
                }
                for b in self.baselines
            },
        }


def tiers_file() -> Path:
    return tasks_dir() / "rubiks" / "tiers.toml"


def _parse(data: dict) -> dict[str, RubiksTier]:
    labels = {k: v.get("label", k) for k, v in data.get("baselines", {}).items()}
    out: dict[str, RubiksTier] = {}
    for row in data["tiers"]:
        baselines = []
        for key, label in labels.items():
            b = row.get(key)
            if b is None:
                continue
            baselines.append(
                BaselineScore(key, label, bool(b["completed"]), b.get("mean_s"), b.get("std_s"))
            )
        tier = RubiksTier(row["name"], int(row["trials"]), int(row["moves"]), tuple(baselines))
        if tier.name != f"Rubiks-{tier.trials}-{tier.moves}":
            raise ValueError(
                f"tier {tier.name!r} does not match its trials/moves ({tier.trials}, {tier.moves})"
            )
        out[tier.name] = tier
    return out


@lru_cache(maxsize=4)
def _load(path: str) -> dict[str, RubiksTier]:
    with open(path, "rb") as fh:
        return _parse(tomllib.load(fh))


def load_tiers(path: Path | None = None) -> dict[str, RubiksTier]:
    """All tiers by name, in the paper's order."""
    return dict(_load(str(path or tiers_file())))


class UnknownTierError(LookupError):
    """No tier of that name; the message lists the valid ones."""


def get_tier(name: str) -> RubiksTier:
    """Look a tier up by name (case-insensitive); :class:`UnknownTierError` lists the valid names.

    The paper's twelve tiers come from ``tasks/rubiks/tiers.toml``; a tier
    that a third-party plugin registers as a task (a factory returning a
    :class:`RubiksTier`) is found through the plugin manager, so the protocol
    CLI serves plugin tiers too.
    """
    tiers = load_tiers()
    wanted = name.strip().lower()
    for tier_name, tier in tiers.items():
        if tier_name.lower() == wanted:
            return tier
    from ..plugin import get_manager  # deferred: the built-in tier plugin imports this module

    plugin_tiers = []
    for item in get_manager().items("task"):
        if item.name in tiers:
            continue
        if item.name.lower() == wanted:
            obj = item.create()
            if isinstance(obj, RubiksTier):
                return obj
        elif item.meta.get("benchmark") == "rubiks":
            plugin_tiers.append(item.name)
    known = ", ".join(list(tiers) + plugin_tiers)
    raise UnknownTierError(f"unknown tier {name!r}; tiers are {known}")
