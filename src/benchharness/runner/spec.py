"""What identifies a run: the run key, and the configuration it is hashed from.

A run is task × robot × strategy × sensors × backend × seed × physics ×
options × code version. Every trial row in the store carries its run key, so
re-running the same arguments finds the trials already finished (resume),
and changing anything that could change a result (physics settings, time
budgets, the code) starts a separate run instead of mixing results.
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

from .. import __version__
from ..backends.interface import PhysicsConfig
from .contract import TimeBudget

__all__ = [
    "RunSpec",
    "code_version",
    "parse_physics",
    "physics_hash",
    "stable_hash",
]


def stable_hash(data: Any, length: int = 16) -> str:
    """A short SHA-256 of canonical JSON: the same on every machine and Python."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:length]


def _physics_dict(config: PhysicsConfig) -> dict[str, Any]:
    d = asdict(config)
    # The backend's own seed is derived per trial from the run seed, so it is
    # not a setting of the run.
    d.pop("seed", None)
    d["gravity"] = list(d["gravity"])
    return d


def physics_hash(config: PhysicsConfig) -> str:
    return stable_hash(_physics_dict(config), 12)


def parse_physics(pairs: Mapping[str, str] | list[str]) -> PhysicsConfig:
    """A :class:`PhysicsConfig` from ``key=value`` strings (``gravity=0,0,-9.81``)."""
    items = (
        pairs.items()
        if isinstance(pairs, Mapping)
        else [p.split("=", 1) if "=" in p else (p, None) for p in pairs]
    )
    known = {f.name: f for f in fields(PhysicsConfig)}
    base = PhysicsConfig()
    values: dict[str, Any] = {}
    for key, raw in items:
        key = key.strip().replace("-", "_")
        if raw is None:
            raise ValueError(f"physics setting {key!r} needs a value (key=value)")
        if key not in known or key == "seed":
            names = ", ".join(n for n in known if n != "seed")
            raise ValueError(f"unknown physics setting {key!r}; settings are {names}")
        current = getattr(base, key)
        try:
            if key == "gravity":
                parts = [float(v) for v in raw.split(",")]
                if len(parts) != 3:
                    raise ValueError("three numbers")
                values[key] = tuple(parts)
            elif key == "solver_iterations":
                values[key] = None if raw.strip().lower() in ("", "none", "default") else int(raw)
            elif key == "timestep" and "/" in raw:
                num, den = raw.split("/", 1)
                values[key] = float(num) / float(den)
            elif isinstance(current, int) and not isinstance(current, bool):
                values[key] = int(raw)
            else:
                values[key] = float(raw)
        except (ValueError, ZeroDivisionError):
            raise ValueError(f"physics setting {key}: cannot read {raw!r}") from None
    # PhysicsConfig refuses values no engine can simulate (zero or negative
    # timestep, NaN, negative friction ...), naming the field.
    return replace(base, **values)


@lru_cache(maxsize=1)
def code_version() -> str:
    """The package version, plus the git commit when running from a checkout.

    ``BENCHHARNESS_CODE_VERSION`` overrides it (e.g. to resume across a
    commit known not to change results). Uncommitted edits are not detected:
    commit before a sweep whose results you mean to keep.
    """
    env = os.environ.get("BENCHHARNESS_CODE_VERSION")
    if env:
        return env
    root = Path(__file__).resolve().parents[3]
    if (root / ".git").exists():
        try:
            out = subprocess.run(
                ["git", "-C", str(root), "rev-parse", "--short=12", "HEAD"],
                capture_output=True,
                text=True,
                timeout=10,
                check=False,
            )
            if out.returncode == 0 and out.stdout.strip():
                return f"{__version__}+g{out.stdout.strip()}"
        except (OSError, subprocess.SubprocessError):
            pass
    return __version__


@dataclass(frozen=True)
class RunSpec:
    """One run's arguments. Hashable and picklable (it travels to the workers).

    ``repeats`` applies to in-hand task sets (trials per task row; Rubik's
    tiers have their own M). ``plugins`` names extra plugin modules to
    register in every process (see ``--plugin``); they are not part of the
    key, the item names they provide are. ``strategy_options`` are the
    ``--strategy-option`` settings in canonical form (sorted ``(key, value)``
    pairs, :func:`benchharness.runner.options.normalise_options`); they are
    part of the options hash, which is unchanged when there are none.
    """

    task: str
    robot: str
    strategy: str
    backend: str
    seed: int = 0
    sensors: tuple[str, ...] = ()
    physics: PhysicsConfig = field(default_factory=PhysicsConfig)
    budget: TimeBudget = field(default_factory=TimeBudget)
    repeats: int = 1
    plugins: tuple[str, ...] = ()
    code: str = field(default_factory=code_version)
    strategy_options: tuple[tuple[str, str], ...] = ()

    @property
    def sensors_label(self) -> str:
        return ",".join(self.sensors)

    @property
    def physics_hash(self) -> str:
        return physics_hash(self.physics)

    @property
    def options_hash(self) -> str:
        data: dict[str, Any] = {"budget": asdict(self.budget), "repeats": self.repeats}
        if self.strategy_options:
            data["strategy_options"] = [list(p) for p in self.strategy_options]
        return stable_hash(data, 12)

    def key_fields(self) -> dict[str, Any]:
        return {
            "task": self.task,
            "robot": self.robot,
            "strategy": self.strategy,
            "sensors": self.sensors_label,
            "backend": self.backend,
            "seed": int(self.seed),
            "physics_hash": self.physics_hash,
            "options_hash": self.options_hash,
            "code_version": self.code,
        }

    @property
    def run_key(self) -> str:
        return stable_hash(self.key_fields(), 20)

    def with_backend(self, backend: str) -> RunSpec:
        return replace(self, backend=backend)

    def to_json(self) -> dict[str, Any]:
        d = self.key_fields()
        d.update(
            physics=_physics_dict(self.physics),
            budget=asdict(self.budget),
            repeats=self.repeats,
            plugins=list(self.plugins),
            strategy_options=dict(self.strategy_options),
            run_key=self.run_key,
        )
        return d
