"""Plans as a benchmark results file (``docs/inhand.md`` format).

A planned trajectory is scored as a trial whose reached pose is the pose the
plan implies (Fig. 6 of the paper: "error in planning"); nothing is
executed, so ``exec_time_s`` is left empty and no trial is dropped.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .config import IngraspConfig
from .planner import PlanResult
from .tasks import InGraspTask

__all__ = ["results_for_plans", "write_plan_results"]


def results_for_plans(
    tasks: Sequence[InGraspTask], plans: Sequence[PlanResult], config: IngraspConfig | None = None
):
    """One results row per (task, plan); ``initial``/``desired`` are the published poses."""
    from benchharness.inhand.records import ResultSet

    if len(tasks) != len(plans):
        raise ValueError("one plan per task")
    n = len(plans)
    cols = ResultSet.empty_like_columns(n)
    cols["reached"] = np.array([p.reached for p in plans]).reshape(n, 7)
    cols["plan_time_s"] = np.array([p.plan_time_s for p in plans], float)
    extra = {
        "robot": np.array(["allegro"] * n, dtype=object),
        "fingers": np.array([";".join(p.fingers) for p in plans], dtype=object),
        "converged": np.array([str(int(p.converged)) for p in plans], dtype=object),
        "iterations": np.array([str(p.iterations) for p in plans], dtype=object),
    }
    if config is not None:
        extra["object_frame"] = np.array([config.object_frame] * n, dtype=object)
        extra["waypoints"] = np.array([str(config.waypoints)] * n, dtype=object)
    return ResultSet(
        method=np.array([p.variant for p in plans], dtype=object),
        object=np.array([t.object for t in tasks], dtype=object),
        task_id=np.array([t.task_id for t in tasks], dtype=object),
        trial=np.ones(n, dtype=int),
        level=np.ones(n, dtype=int),
        dropped=np.zeros(n, dtype=bool),
        initial=np.array([t.initial for t in tasks], float).reshape(n, 7),
        desired=np.array([t.desired for t in tasks], float).reshape(n, 7),
        extra=extra,
        **cols,
    )


def write_plan_results(
    path: str | Path,
    tasks: Sequence[InGraspTask],
    plans: Sequence[PlanResult],
    config: IngraspConfig | None = None,
) -> Path:
    """Write the plans as a results CSV that ``benchharness inhand score`` reads."""
    from benchharness.inhand.fileformat import write_results

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_results(results_for_plans(tasks, plans, config), path)
    return path
