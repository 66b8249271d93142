"""The strategy example in docs/runner.md runs as printed, against the real interfaces.

Its ``...`` (the robot's actions) does nothing, so no layer turns: every twist
the example opens must still end aligned (the cube's own step callback holds
the detents while the robot settles), the cube must end rigid and solved, and
none of the cube's step callbacks may outlive the twists.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from benchharness.cube import SOLVED_STRING
from benchharness.plugin import get_manager
from benchharness.runner.contract import RubiksItem, SensorSlot, TimeBudget, TrialContext
from benchharness.runner.recorder import TrialRecorder

DOC = Path(__file__).resolve().parents[2] / "docs" / "runner.md"


def _example_source() -> str:
    text = DOC.read_text(encoding="utf-8")
    section = text[text.index("## The strategy contract") :]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_runner_doc_strategy_example_runs():
    namespace: dict = {}
    exec(compile(_example_source(), str(DOC), "exec"), namespace)
    m = get_manager()
    be = m.create("backend", "pybullet")
    camera = m.get("sensor", "head-camera")
    try:
        item = RubiksItem("Rubiks-1-5", 1, 1, ("U", "R'"), 0)
        ctx = TrialContext(
            item=item,
            trial_index=1,
            robot=m.create("robot", "pr2"),
            backend=be,
            sensors={
                "head-camera": SensorSlot("head-camera", np.random.default_rng(1), camera.factory)
            },
            rng=np.random.default_rng(0),
            budget=TimeBudget(),
            recorder=TrialRecorder(lambda: be.time),
            physics=be.config,
        )
        out = namespace["MyStrategy"]().run_trial(ctx)
        assert out.final_state == SOLVED_STRING
        moves = [e for e in ctx.recorder.events if e["kind"] == "move"]
        assert [(e["move"], e["moves"]) for e in moves] == [("U", ""), ("R'", "")]
        assert len(ctx.recorder.estimates) == 2
        # the cube went rigid: its callback is gone (the robot's grippers keep theirs while a finger
        # still moves faster than 1e-4 rad/s, which settling may or may not have reached by now)
        owners = {
            type(getattr(cb, "__self__", None)).__module__ for cb in be._step_callbacks.values()
        }
        assert not {o for o in owners if o.startswith("benchharness.cube_physics")}, owners
    finally:
        be.close()
