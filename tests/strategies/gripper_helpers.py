"""Shared helpers of the parallel-gripper strategy tests (pivoting, DMG execution): in-process trial contexts."""

from __future__ import annotations

import numpy as np

from benchharness.backends.interface import PhysicsConfig
from benchharness.plugin import get_manager
from benchharness.runner.contract import InhandItem, TimeBudget, TrialContext
from benchharness.runner.recorder import TrialRecorder

BACKENDS = ("pybullet", "sapien")


def make_context(backend: str, item: InhandItem, seed: int = 0):
    """A fresh (ctx, backend) for ``item`` on the ``pr2-gripper``, as the runner builds one; close the backend after."""
    m = get_manager()
    phys = PhysicsConfig(seed=seed)
    b = m.create("backend", backend, config=phys)
    rec = TrialRecorder(clock=lambda: float(b.time))
    ctx = TrialContext(
        item=item,
        trial_index=1,
        robot=m.create("robot", "pr2-gripper"),
        backend=b,
        sensors={},
        rng=np.random.default_rng(seed),
        budget=TimeBudget(),
        recorder=rec,
        physics=phys,
    )
    return ctx, b


def task_item(task_set: str, row: int) -> InhandItem:
    """Row ``row`` (0-based) of a registered in-hand task set as the runner's :class:`InhandItem`."""
    from benchharness.runner.tasks import plan_task

    ts = get_manager().create("task", task_set)
    plan = plan_task(task_set, ts, seed=0)
    return plan.items[row + 1]
