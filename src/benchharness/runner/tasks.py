"""Turning a task plugin into the list of trials a run executes.

A Rubik's tier ``Rubiks-M-N`` is M trials, trial k with the protocol
generator's sequence for (seed, tier, k). An in-hand task set of n task rows
run ``repeats`` = R times is n R trials, numbered repeat-major: trial
``t + (r - 1) n`` is the r-th repeat of the t-th task row (file order), so
trials 1..n are one pass over the set whatever R is, trial k always means
task ``(k - 1) % n + 1``, repeat ``(k - 1) // n + 1``, and ``--trials``
selects among these numbers (docs/runner.md). Trial indices are 1-based
and stable, so a stored row always means the same trial.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any, Protocol, cast

import numpy as np

from ..cube.sequences import generate_sequence
from ..cube.tiers import RubiksTier
from .contract import InhandItem, RubiksItem, TrialItem

__all__ = ["TaskPlan", "parse_trial_indices", "parse_trial_selection", "plan_task", "trial_task"]


@dataclass(frozen=True)
class TaskPlan:
    """A task, resolved: its canonical name, benchmark and trials (index -> item)."""

    name: str
    benchmark: str
    items: dict[int, TrialItem]

    @property
    def total(self) -> int:
        return len(self.items)


class _TaskSetLike(Protocol):
    """What the runner reads of an in-hand task set (``benchharness.inhand.records.TaskSet``)."""

    task_id: Any
    object: Any
    level: Any
    initial: Any
    desired: Any


def plan_task(name: str, task: object, seed: int, repeats: int = 1) -> TaskPlan:
    if isinstance(task, RubiksTier):
        items: dict[int, TrialItem] = {
            k: RubiksItem(
                task.name,
                k,
                task.trials,
                generate_sequence(seed, task.name, k, task.moves),
                int(seed),
            )
            for k in range(1, task.trials + 1)
        }
        return TaskPlan(task.name, "rubiks", items)
    # In-hand task sets: duck-typed on benchharness.inhand.records.TaskSet.
    if all(hasattr(task, a) for a in ("task_id", "initial", "desired", "object", "level")):
        ts = cast(_TaskSetLike, task)
        if repeats < 1:
            raise ValueError("repeats must be at least 1")
        items = {}
        n = len(ts.task_id)
        for row in range(n):
            contacts = {
                stage: np.asarray(c[row], float)
                for stage, c in (getattr(task, "contacts", None) or {}).items()
            }
            contacts = {s: c[np.all(np.isfinite(c), axis=1)] for s, c in contacts.items()}
            extra = {
                k: (v[row].item() if hasattr(v[row], "item") else v[row])
                for k, v in (getattr(task, "extra", None) or {}).items()
            }
            for r in range(1, repeats + 1):
                items[row + 1 + (r - 1) * n] = InhandItem(
                    task_set=name,
                    task_id=str(ts.task_id[row]),
                    object=str(ts.object[row]),
                    level=int(ts.level[row]),
                    initial=np.asarray(ts.initial[row], float),
                    desired=np.asarray(ts.desired[row], float),
                    repeat=r,
                    contacts=contacts,
                    extra=extra,
                )
        return TaskPlan(name, "inhand", dict(sorted(items.items())))
    raise TypeError(
        f"task {name!r} is a {type(task).__name__}; the runner runs Rubik's tiers (RubiksTier) "
        "and in-hand task sets (TaskSet)"
    )


def parse_trial_indices(text: str) -> list[int]:
    """The indices ``"1,3-5"`` names, sorted, before any task is known.

    A reversed range (``5-3``) or a selection naming nothing is an error, not
    an empty run that exits 0.
    """
    chosen: list[int] = []
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if "-" in part:
                a, b = (int(x) for x in part.split("-", 1))
            else:
                a = b = int(part)
        except ValueError:
            raise ValueError(f"--trials: cannot read {part!r} (use e.g. 1,3-5)") from None
        if a > b:
            raise ValueError(f"--trials: {part!r} is a reversed range (write {b}-{a})")
        chosen.extend(range(a, b + 1))
    if not chosen:
        raise ValueError(f"--trials: {text!r} names no trial (use e.g. 1,3-5)")
    return sorted(set(chosen))


def parse_trial_selection(text: str | None, available: list[int]) -> list[int]:
    """``"1,3-5"`` → [1, 3, 4, 5]; ``None`` → all. Unknown indices are an error."""
    if not text:
        return list(available)
    chosen = parse_trial_indices(text)
    bad = sorted(set(chosen) - set(available))
    if bad:
        raise ValueError(
            f"--trials: no trial {', '.join(map(str, bad))}; this task has trials 1..{max(available)}"
        )
    return sorted(set(chosen))


def trial_task(task: str, index: int, outcome: dict | None = None) -> tuple[str, str, int] | None:
    """(task id, object, repeat) of in-hand trial ``index`` of task set ``task``; ``None`` otherwise.

    Read from the stored ``outcome`` where the trial was scored, else from
    the task set itself (a trial that failed before scoring stores no
    outcome): with the repeat-major numbering, index ``k`` is row
    ``(k - 1) % n`` whatever the number of repeats. Rubik's tiers, unknown
    task names and out-of-range indices give ``None``.
    """
    o = outcome or {}
    if o.get("task_id"):
        return str(o["task_id"]), str(o.get("object", "")), int(o.get("repeat", 1))
    rows = _inhand_rows(task)
    if not rows or index < 1:
        return None
    tid, obj = rows[(index - 1) % len(rows)]
    return tid, obj, (index - 1) // len(rows) + 1


@functools.lru_cache(maxsize=32)
def _inhand_rows(task: str) -> tuple[tuple[str, str], ...] | None:
    if task.startswith("Rubiks-"):
        return None
    try:
        from ..plugin import get_manager

        ts = get_manager().create("task", task)
    except Exception:  # noqa: BLE001 - a label is best effort: an unloadable task just has none
        return None
    if not all(hasattr(ts, a) for a in ("task_id", "object")):
        return None
    return tuple((str(t), str(o)) for t, o in zip(ts.task_id, ts.object))
