"""The machine's arm check (``arm_check``, the PR2's ``arm_margin``) against the engines' own contacts.

The case is recorded from a trial, before the check existed: the giver's retreat after a hand-over take
(SAPIEN Rubiks-5-20 sensor-aided seed 0 trial 2, 448.7 s), whose nearest IK solution folded the left
elbow onto the right one (an ``arm_contact`` of 20.3 N in that trial). Both arms are put where they were
and the retreat's target is solved. The nearest solution brings the elbows to touching; where the trial's
arm ended (that solution plus the trial's injected arm errors, a few mrad) they press on each other in
both engines. The solution the machine takes instead reaches the same pose with the arms apart, and
stays apart with the same joint error added.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from benchharness.geometry import Pose
from benchharness.strategies.bimanual.machine import arm_contact_forces

pytestmark = pytest.mark.sim

#: the retreating (left) arm's joints, the holding (right) arm's, and the retreat's target in the left
#: arm's base frame (x, y, z, qx, qy, qz, qw), recorded at 448.7 s of the trial above
LEFT_Q = [-0.4316, -0.0939, 3.2192, -1.6944, -9.8085, -1.5443, -9.5009]
RIGHT_Q = [0.1335, 0.0532, -3.4792, -1.0632, 1.8688, -1.8367, 24.0871]
TARGET = [0.515054, 0.008892, -0.284503, 0.99953, -0.026336, -0.015696, 0.00017]
#: where the left arm ended that retreat in the trial (the 20.3 N contact)
LEFT_END = [-0.4954, -0.0423, 3.1542, -2.0058, -9.9117, -1.8931, -9.6108]


def _place(b, robot, arm, q):
    b.set_joint_positions(robot.body, q, joints=arm.joints)
    arm.move_to_joints(q, duration=0.05, settle=0.3)  # the drives hold it there


@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_a_retreat_that_folds_the_elbow_onto_the_other_arm_is_solved_on_another_elbow_posture(
    make_ctx, backend
):
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig
    from benchharness.strategies.pr2_rubiks.strategy import SensorAidedStrategy

    ctx, b = make_ctx(backend, "R")
    st = SensorAidedStrategy(replace(PR2RubiksConfig().zero_error(), max_actions=0))
    assert st.run_trial(ctx).failure is None  # the scene and the hands, no action
    robot = ctx.robot
    left, right = st.hands["left"], st.hands["right"]
    links = tuple(robot.links_below(robot.arm(f"{s}_arm").joints[0]) for s in ("left", "right"))
    q0 = np.array(LEFT_Q)
    _place(b, robot, right.arm, np.array(RIGHT_Q))
    _place(b, robot, left.arm, q0)
    assert arm_contact_forces(b, robot.body, *links) == {}  # where the retreat starts: apart
    target = left.arm.base_pose() * Pose.from_array(TARGET)
    rows = (left.arm.base_pose().inv() * target).as_matrix()[None]

    # the nearest solution: the model says its path brings the arms nearer than allowed; the engine
    # finds the elbows pressing where the trial's arm went for it (with its injected errors)
    nearest = np.asarray(left.arm.ik(rows, seed_q=q0).q[0], dtype=float)
    path = q0[None] + np.linspace(0.0, 1.0, 101)[:, None] * (nearest - q0)[None]
    assert st.grasp.arm_margin(st, left, path).min() < 0.0
    error = np.array(LEFT_END) - nearest
    assert float(np.max(np.abs(error))) < 0.04  # the trial's arm went for this solution
    left.arm.move_to_joints(nearest + error, settle=0.3)
    pressed = arm_contact_forces(b, robot.body, *links)
    assert sum(pressed.values()) > 5.0, pressed
    assert set(pressed) == {("l_elbow_flex_link", "r_elbow_flex_link")}, pressed

    # the machine's choice from the same start: the same tool pose, the path clear in the model at a
    # finer sampling than the machine's own, and no contact in the engine, with the error or without
    _place(b, robot, left.arm, q0)
    chosen = st.smooth_q(left, target, label="retreat")
    assert chosen is not None
    assert float(np.max(np.abs(chosen - q0))) <= st.config.max_waypoint_jump
    reached = left.arm.fk(chosen[None])[0]
    assert np.linalg.norm(reached[:3, 3] - rows[0][:3, 3]) < 1e-3
    path = q0[None] + np.linspace(0.0, 1.0, 101)[:, None] * (chosen - q0)[None]
    assert st.grasp.arm_margin(st, left, path).min() >= -1e-3
    for q in (chosen, chosen + error):
        left.arm.move_to_joints(q, settle=0.3)
        assert arm_contact_forces(b, robot.body, *links) == {}
    avoid = [e for e in ctx.recorder.events if e["kind"] == "arm_avoid"]
    assert avoid and avoid[-1]["label"] == "retreat" and "joint_change" in avoid[-1]
