"""Turning a task plugin into the list of trials a run executes.

A Rubik's tier ``Rubiks-M-N`` is M trials, trial k with the protocol
generator's sequence for (seed, tier, k). An in-hand task set is one trial
per task row (times ``repeats``), in file order. Trial indices are 1-based
and stable, so a stored row always means the same trial.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..cube.sequences import generate_sequence
from ..cube.tiers import RubiksTier
from .contract import InhandItem, RubiksItem, TrialItem

__all__ = ["TaskPlan", "plan_task", "parse_trial_indices", "parse_trial_selection"]


@dataclass(frozen=True)
class TaskPlan:
    """A task, resolved: its canonical name, benchmark and trials (index -> item)."""

    name: str
    benchmark: str
    items: dict[int, TrialItem]

    @property
    def total(self) -> int:
        return len(self.items)


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
        if repeats < 1:
            raise ValueError("repeats must be at least 1")
        items = {}
        idx = 1
        for row in range(len(task.task_id)):
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
                items[idx] = InhandItem(
                    task_set=name,
                    task_id=str(task.task_id[row]),
                    object=str(task.object[row]),
                    level=int(task.level[row]),
                    initial=np.asarray(task.initial[row], float),
                    desired=np.asarray(task.desired[row], float),
                    repeat=r,
                    contacts=contacts,
                    extra=extra,
                )
                idx += 1
        return TaskPlan(name, "inhand", items)
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
