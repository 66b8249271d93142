"""Helpers for the in-grasp strategy tests: the runner's context for one Level I trial."""

from __future__ import annotations

import numpy as np

from benchharness.plugin import get_manager


def trial_context(task, be):
    """The runner's context for one trial of ``task`` on the Allegro in backend ``be`` (seed 0)."""
    from benchharness.runner.contract import InhandItem, TimeBudget, TrialContext
    from benchharness.runner.recorder import TrialRecorder

    return TrialContext(
        item=InhandItem("inhand-level1", task.task_id, task.object, 1, task.initial, task.desired),
        trial_index=1,
        robot=get_manager().create("robot", "allegro"),
        backend=be,
        sensors={},
        rng=np.random.default_rng(0),
        budget=TimeBudget(),
        recorder=TrialRecorder(lambda: be.time),
        physics=be.config,
    )
