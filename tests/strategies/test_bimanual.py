"""The bimanual Rubik's state machine: every two-armed robot's Rubik's strategy is it, with its own grasp module.

No physics: registration and class contracts. Whole trials of the machine
driving each robot are in test_pr2_rubiks_sim.py (the PR2, Rubiks-1-5 on
both engines) and test_herb_push_grasp.py (HERB, a one-move trial).
"""

from __future__ import annotations

import dataclasses
import inspect

import numpy as np
import pytest

from benchharness.strategies.bimanual.config import BimanualConfig
from benchharness.strategies.bimanual.frames import along
from benchharness.strategies.bimanual.machine import BimanualRubiksMachine, GraspModule

STRATEGIES = {
    "dead-reckoning": "pr2",
    "dead-reckoning-exact": "pr2",
    "sensor-aided": "pr2",
    "push-grasp": "herb",
    "push-grasp-exact": "herb",
}


@pytest.mark.parametrize("name", sorted(STRATEGIES))
def test_every_rubiks_strategy_is_the_machine_with_a_grasp_module(name):
    from benchharness.plugin import get_manager

    s = get_manager().create("strategy", name)
    assert isinstance(s, BimanualRubiksMachine)
    # a robot's strategy class adds a name and builds its grasp module, nothing else: the state machine
    # (pick, twist, regrasp, hand-over, swing, turn travel, retreat) is never overridden
    own = {n for n in vars(type(s)) if not n.startswith("__") or n == "__init__"}
    assert own <= {"name", "__init__"}, own
    assert isinstance(s.config, BimanualConfig)
    assert s.config is s.grasp.config
    for member in ("config", "approach_axis", "finger_axis", "gripper_name", "robot_name"):
        assert hasattr(s.grasp, member), member
    for method in (
        "hand_model",
        "hand_state",
        "take_relation",
        "choose",
        "ready",
        "close_in",
        "open",
        "regrip_before_twist",
        "twist_diagnostics",
    ):
        ours = inspect.signature(getattr(s.grasp, method))
        theirs = inspect.signature(getattr(GraspModule, method))
        assert list(ours.parameters) == list(theirs.parameters)[1:], method  # bound: no self
    assert s.grasp.robot_name in (None, STRATEGIES[name])


def test_the_two_robots_share_the_machine_and_differ_in_their_grasp_modules():
    from benchharness.plugin import get_manager

    m = get_manager()
    pr2, herb = m.create("strategy", "dead-reckoning"), m.create("strategy", "push-grasp")
    assert type(pr2).__mro__[1] is BimanualRubiksMachine is type(herb).__mro__[1]
    assert type(pr2.grasp) is not type(herb.grasp)
    # the tool frames differ (PR2: x = approach, y = fingers; HERB: z = approach, fingers across x)
    assert (pr2.grasp.approach_axis, pr2.grasp.finger_axis) == (0, 1)
    assert (herb.grasp.approach_axis, herb.grasp.finger_axis) == (2, 0)
    # the planner's hand models are each robot's (HERB's wrist is limited, the PR2's continuous)
    assert pr2.grasp.hand_model().wrist_roll_limit is None
    assert herb.grasp.hand_model().wrist_roll_limit is not None


def test_configs_share_the_common_fields():
    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig

    common = {f.name for f in dataclasses.fields(BimanualConfig)}
    for cls in (PR2RubiksConfig, HerbPushGraspConfig):
        assert issubclass(cls, BimanualConfig)
        cfg = cls()
        assert {f.name for f in dataclasses.fields(cfg)} >= common
        z = cfg.zero_error()
        assert type(z) is cls and z.errors.is_zero and not cfg.errors.is_zero
    with pytest.raises(TypeError):  # the scene is a robot's to give
        BimanualConfig()  # type: ignore[call-arg]
    # tuning knobs are config fields, not class attributes of the strategies
    assert PR2RubiksConfig().handover_retreat == HerbPushGraspConfig().handover_retreat == 0.12
    assert PR2RubiksConfig().giver_seeds == 6 and PR2RubiksConfig().finger_preference == "parallel"


def test_along_builds_the_exact_tool_vector():
    """Moves along the approach are ``[d, 0, 0]`` to the bit, as the PR2 code always wrote them."""
    d = 0.07
    assert along(0, d).tolist() == [d, 0.0, 0.0]
    assert along(2, -d).tolist() == [0.0, 0.0, -d]
    assert np.signbit(along(0, -d)[1]) == np.False_
