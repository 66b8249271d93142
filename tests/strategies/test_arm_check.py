"""The machine's arm check (``arm_check``, the PR2's ``arm_margin``) against the engines' own contacts.

The case is recorded from a trial, before the check existed: the giver's retreat after a hand-over take
(SAPIEN Rubiks-5-20 sensor-aided seed 0 trial 2, 448.7 s), whose nearest IK solution folded the left
elbow onto the right one (an ``arm_contact`` of 20.3 N in that trial). Both arms are put where they were
and the retreat's target is solved. The nearest solution brings the elbows to touching; where the trial's
arm ended (that solution plus the trial's injected arm errors, a few mrad) they press on each other in
both engines. The solution the machine takes instead reaches the same pose with the arms apart, and
stays apart with the same joint error added.

The other cases are detours (``DETOURS``, two trials): a giver in front of the cube backing out along its
approach on its way to a stand-off at the cube's side put its elbow on the holding arm's (50-67 N in
the trials, as much here). No elbow posture keeps that way out clear; the machine goes out another way
(sideways, or sideways and up), and the engines find no contact. The last case is a detour's way out
for an open hand still round the cube (``SLIDE``): it slides along its pads' faces.
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


def _scene(make_ctx, backend, strategy="sensor-aided"):
    """A PR2 scene with the strategy's hands set up and no action taken: (ctx, backend, strategy, the two
    arms' links for :func:`arm_contact_forces`)."""
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig
    from benchharness.strategies.pr2_rubiks.strategy import (
        DeadReckoningStrategy,
        SensorAidedStrategy,
    )

    cls = SensorAidedStrategy if strategy == "sensor-aided" else DeadReckoningStrategy
    ctx, b = make_ctx(backend, "R")
    st = cls(replace(PR2RubiksConfig().zero_error(), max_actions=0))
    assert st.run_trial(ctx).failure is None
    robot = ctx.robot
    links = tuple(robot.links_below(robot.arm(f"{s}_arm").joints[0]) for s in ("left", "right"))
    return ctx, b, st, links


def _place(b, robot, arm, q):
    b.set_joint_positions(robot.body, q, joints=arm.joints)
    arm.move_to_joints(q, duration=0.05, settle=0.3)  # the drives hold it there


@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_a_retreat_that_folds_the_elbow_onto_the_other_arm_is_solved_on_another_elbow_posture(
    make_ctx, backend
):
    ctx, b, st, links = _scene(make_ctx, backend)
    robot = ctx.robot
    left, right = st.hands["left"], st.hands["right"]
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


#: a hand-over's giver in front of the cube on its way to a re-grip stand-off at the cube's side, recorded
#: where the trial's detour backed out along the approach into the holding arm's elbow: the free arm's
#: side, its joints, the holding arm's, the free tool's commanded pose, the stand-off, the believed cube
#: (the free arm's base frame, x, y, z, qx, qy, qz, qw), the grip's planned joints, and the way out the
#: machine takes instead. "side": SAPIEN Rubiks-5-20 sensor-aided seed 1 trial 3 at 277.67 s (66.5 N in
#: that trial, at 3b6e43c); "side-up": SAPIEN Rubiks-1-50 seed 0 at 1385.6 s (50.3 N), where the turns
#: from straight up and straight sideways would sweep the cube.
DETOURS = {
    "side": (
        "left",
        [-0.4106, -0.0306, 3.0418, -1.982, 2.7217, -1.9477, 6.1717],
        [0.1447, 0.031, -3.4974, -1.0858, 1.8658, -1.7788, -1.0655],
        [0.516573, 0.003589, -0.288849, -0.020656, 0.009211, -0.013272, 0.999656],
        [0.650051, 0.179229, -0.294863, -0.494756, 0.516371, 0.488256, -0.500184],
        [0.648241, -0.000492, -0.288851, -0.494756, 0.516371, 0.488256, -0.500184],
        [-0.208, 0.1237, 3.7388, -1.0331, 4.1685, -2.0, 7.2848],
    ),
    "side-up": (
        "right",
        [0.4451, -0.0134, -3.0723, -1.9644, -2.6792, -1.9394, 7.9505],
        [-0.1226, 0.0416, 3.4516, -1.0585, 10.7539, -1.7702, -22.5014],
        [0.51528, -0.002399, -0.290634, -0.70269, -0.010427, -0.008613, -0.711367],
        [0.649346, -0.161682, -0.294616, -0.499343, -0.502798, 0.492766, 0.505007],
        [0.650776, 0.001623, -0.292049, -0.004651, -0.712626, 0.701527, 0.001563],
        [-0.3771, 0.7689, -1.038, -1.02, -0.8587, -1.1151, 6.2123],
    ),
}
LABEL = "hand-over re-grip stand-off"


@pytest.mark.parametrize("way", sorted(DETOURS))
@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_a_detour_out_along_the_approach_into_the_other_arm_goes_out_another_way(
    make_ctx, backend, way
):
    ctx, b, st, links = _scene(make_ctx, backend)
    robot = ctx.robot
    side, free_q, hold_q, cmd, standoff, cube, plan_q = DETOURS[way]
    free, hold = st.hands[side], st.other(st.hands[side])
    base = free.arm.base_pose()
    q0, seed = np.array(free_q), np.array(plan_q)
    target = base * Pose.from_array(standoff)

    def start() -> None:
        _place(b, robot, hold.arm, np.array(hold_q))
        _place(b, robot, free.arm, q0)
        free.cmd = base * Pose.from_array(cmd)
        st.est = base * Pose.from_array(cube)
        assert arm_contact_forces(b, robot.body, *links) == {}

    def contacts() -> list[dict]:
        return [e for e in ctx.recorder.events if e["kind"] == "arm_contact"]

    # the detour the trial took: out along the approach to 25 cm. Clear of the cube, not of the other
    # arm: the model's margin goes below zero and the engine finds the elbows pressing
    start()
    old = st._plan_detour(
        free, target, None, 0.25, q0, seed, st._hand_points(free), LABEL, notes=[]
    )
    assert old is not None
    outs = [q0, *(q for _, q in old.leg_out)]
    ins = [old.qb, *(q for _, q in old.leg_in)]
    steps = [*zip(outs[:-1], outs[1:]), (old.qa, old.qb), *zip(ins[:-1], ins[1:])]
    margin = min(
        float(
            st.grasp.arm_margin(st, free, a[None] + np.linspace(0, 1, 21)[:, None] * (b_ - a)).min()
        )
        for a, b_ in steps
    )
    assert margin < -0.02
    st._make_detour(free, old, LABEL, 0.05, clear=0.0)
    pressed = contacts()
    assert pressed and max(e["force_n"] for e in pressed) > 5.0, pressed
    assert {tuple(e["links"]) for e in pressed} == {("l_elbow_flex_link", "r_elbow_flex_link")}, (
        pressed
    )

    # the machine's choice from the same start: out another way, towards the stand-off's side of the
    # cube; no contact on the way, and the hand at the stand-off
    start()
    n = len(contacts())
    st.transit(free, target, label=LABEL, seed_q=seed)
    detour = [e for e in ctx.recorder.events if e["kind"] == "detour"][-1]
    assert detour["way_out"] == way and detour["label"] == LABEL
    assert len(contacts()) == n
    assert arm_contact_forces(b, robot.body, *links) == {}
    reached = base * Pose.from_matrix(free.arm.fk(free.arm.positions()[None])[0])
    assert np.linalg.norm(reached.p - target.p) < 5e-3


#: a giver above the cube whose retreat was cut to 2 cm (the way up left the arm's branch), bound for a
#: re-grip stand-off at the cube's -y side, recorded at 2506.65 s of SAPIEN Rubiks-1-100 sensor-aided
#: seed 0 at 0361275 (the layout of ``DETOURS``): no way out but sliding along the pads' faces cleared
#: the cube, and that trial ended ``unreachable``
SLIDE = (
    "right",
    [0.042293, -0.331408, -2.55587, -1.227067, -0.727882, -0.894567, 54.16156],
    [0.297207, 0.143106, 2.43198, -1.042332, -0.885782, -1.119938, -25.792177],
    [0.650515, 0.002787, -0.252557, -0.0044, 0.710218, -0.002635, 0.703963],
    [0.656226, -0.171834, -0.290346, 0.702667, 0.711518, -0.000376, 0.000841],
    [0.653975, 0.007982, -0.290656, -0.707701, -0.004658, 0.004193, 0.706484],
    [-0.408418, 0.343384, -1.961886, -0.98987, 0.26329, -1.001675, 54.365301],
)


@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_an_open_hand_round_the_cube_with_no_way_up_slides_out_along_its_pads(make_ctx, backend):
    from benchharness.strategies.bimanual.machine import WAYS_OUT

    ctx, b, st, _ = _scene(make_ctx, backend)
    side, free_q, hold_q, cmd, standoff, cube, plan_q = SLIDE
    free, hold = st.hands[side], st.other(st.hands[side])
    _place(b, ctx.robot, hold.arm, np.array(hold_q))
    _place(b, ctx.robot, free.arm, np.array(free_q))
    base = free.arm.base_pose()
    free.cmd = base * Pose.from_array(cmd)
    st.est = base * Pose.from_array(cube)
    target = base * Pose.from_array(standoff)
    q0, seed, points = free.arm.positions(), np.array(plan_q), st._hand_points(free)

    # the hand points down at the cube's top, 38 mm above its centre, pads on its +-y faces: straight up
    # (its approach) takes another arm branch, every world-frame way out drags a pad through the cube
    assert free.cmd.rotation.apply([1.0, 0.0, 0.0])[2] < -0.99
    for way in (None, "up", "side", "side-up"):
        assert st._first_detour(free, target, (way,), q0, seed, points, LABEL) is None, way
    assert WAYS_OUT[-2:] == ("slide+", "slide-")

    st.transit(free, target, label=LABEL, seed_q=seed)
    detour = [e for e in ctx.recorder.events if e["kind"] == "detour"][-1]
    assert detour["way_out"] == "slide-" and detour["label"] == LABEL
    reached = base * Pose.from_matrix(free.arm.fk(free.arm.positions()[None])[0])
    assert np.linalg.norm(reached.p - target.p) < 5e-3


#: a giver's 12 cm retreat after a hand-over, recorded at 535.94 s of SAPIEN Rubiks-1-20 sensor-aided
#: seed 0 at f8d49ca (35.5 N in that trial): the left arm's joints, the right (holding) arm's, the left
#: tool's last grip and the believed cube (the left arm's base frame, x, y, z, qx, qy, qz, qw), and the
#: retreat's joints the check on the arm's least margin chose there (the nearest solution's elbow
#: swung: an ``arm_avoid`` event)
RETREAT = (
    [-0.447654, -0.063778, 3.219257, -1.647454, 2.67796, -1.54581, -9.51978],
    [0.161442, 0.063671, -3.546879, -1.042551, -4.380783, -1.824377, 11.570182],
    [0.637731, -0.00037, -0.292028, -0.999885, -0.013871, -0.001582, -0.005914],
    [0.648621, 0.000908, -0.291782, 0.715545, 0.016253, 0.698357, 0.00536],
    [-0.447511, -0.017339, 3.037463, -1.938622, 2.632132, -1.931101, -9.5125],
)


@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_a_retreat_is_judged_per_pair_of_arm_parts_and_keeps_the_elbows_apart(make_ctx, backend):
    ctx, b, st, links = _scene(make_ctx, backend)
    robot = ctx.robot
    left, right = st.hands["left"], st.hands["right"]
    left_q, right_q, grip, cube, chosen = RETREAT
    q0 = np.array(left_q)

    def start() -> None:
        _place(b, robot, right.arm, np.array(right_q))
        _place(b, robot, left.arm, q0)
        base = left.arm.base_pose()
        left.holding, left.cmd = True, base * Pose.from_array(grip)
        left.last_grip = left.cmd
        st.est = base * Pose.from_array(cube)
        # the elbows start within a hair of each other (the joints rounded to 1e-6 rad): touching, not pressing
        assert sum(arm_contact_forces(b, robot.body, *links).values()) < 1.0

    # the straight 12 cm retreat on the elbow posture the trial's check chose: the arm's least margin
    # never falls below where it starts (another pair of parts is inside the clearance there, -15 mm),
    # so a check on the least margin passed it; the elbows' own pair goes from about -6 to -14 mm, and
    # the engine finds them pressing where the arm ends
    start()
    back = left.arm.base_pose().inv() * st.back_off(left.cmd, 0.12)
    q1 = np.array(chosen)
    assert np.linalg.norm(left.arm.fk(q1[None])[0][:3, 3] - back.p) < 1e-3
    path = q0[None] + np.linspace(0.0, 1.0, 11)[:, None] * (q1 - q0)[None]
    pairs = st.grasp.arm_margin(st, left, path)
    least = pairs.min(axis=1)
    assert least[0] < -0.01 and least[1:].min() >= least[0]
    worse = (pairs[1:] < np.minimum(0.0, pairs[0]) - 1e-9).any(axis=0)
    assert worse.any()
    assert not st._arm_clears(left, q0, q1)
    left.arm.move_to_joints(q1, settle=0.3)
    pressed = arm_contact_forces(b, robot.body, *links)
    assert sum(pressed.values()) > 5.0, pressed
    assert set(pressed) == {("l_elbow_flex_link", "r_elbow_flex_link")}, pressed

    # the machine's retreat from the same start: the full 12 cm (in steps on other elbow postures), no
    # contact on the way or at the end
    start()
    st.release_hand(left, 0.12)
    assert not [e for e in ctx.recorder.events if e["kind"] == "arm_contact"]
    assert arm_contact_forces(b, robot.body, *links) == {}
    approach = left.last_grip.rotation.apply([1.0, 0.0, 0.0])
    backed = float(np.dot(left.last_grip.p - left.arm.tcp_pose().p, approach))
    assert backed > 0.115


#: a giver's release after a hand-over, recorded at 525.575 s of SAPIEN Rubiks-5-100 dead-reckoning seed 0
#: trial 1 (91e88f9): the right (giving) arm's joints, the left (holding) arm's, both grippers' joints, the
#: right tool's grip, the left's, the believed cube and the true one (the right arm's base frame, x, y, z,
#: qx, qy, qz, qw). The right hand points down at the cube's top, pads on its +-y faces; the left
#: pinches its +-x faces from +y. The straight way up leaves the arm's branch (the shoulder lift on its
#: soft limit); the trial slid the right hand 6 cm along +x into the left's finger (28-103 N).
HANDOVER_RELEASE = (
    [0.078291, -0.327517, -2.676612, -1.258537, -0.658929, -0.781773, -8.693778],
    [-0.148509, 0.065556, 3.519427, -1.034519, -1.898754, -1.835188, 15.186838],
    [0.027483, 0.027517],
    [0.026645, 0.02882],
    [0.65, -0.0, -0.27731, -0.0, -0.707107, -0.0, -0.707107],
    [0.65, 0.013331, -0.290641, 0.707107, -0.707107, -0.0, 0.0],
    [0.65, -0.0, -0.290641, -0.0, 0.0, -1.0, -0.0],
    [0.652786, -0.000889, -0.295519, 0.007897, -0.003611, -0.99996, 0.001923],
)


@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_a_sideways_retreat_into_the_other_hands_fingers_is_refused_and_the_arm_changes_posture(
    make_ctx, backend
):
    ctx, b, st, links = _scene(make_ctx, backend, "dead-reckoning")
    robot = ctx.robot
    giver, taker = st.hands["right"], st.hands["left"]
    q, taker_q, grip_q, taker_grip_q, grip, taker_grip, est, cube = HANDOVER_RELEASE

    def start() -> Pose:
        _place(b, robot, taker.arm, np.array(taker_q))
        _place(b, robot, giver.arm, np.array(q))
        base = giver.arm.base_pose()
        b.set_joint_positions(robot.body, taker_grip_q, joints=taker.gripper.joints)
        b.set_joint_positions(robot.body, grip_q, joints=giver.gripper.joints)
        b.set_pose(st.cube.body, base * Pose.from_array(cube))
        taker.gripper.close(obj=st.cube.body)
        giver.gripper.close(obj=st.cube.body)
        giver.holding, giver.cmd = True, base * Pose.from_array(grip)
        giver.last_grip = giver.cmd
        taker.holding, taker.cmd = True, base * Pose.from_array(taker_grip)
        st.est = base * Pose.from_array(est)
        assert arm_contact_forces(b, robot.body, *links) == {}
        return st.cube.pose()

    # the trial's slide: 6 cm along +x (the left's finger axis) in 2 cm steps; the believed boxes say
    # the right fingertips run into the left's finger, and the engine finds them pressing
    held = start()
    giver.gripper.open()
    points = st._hand_points(giver)
    q0 = giver.arm.positions()
    slid = Pose(giver.cmd.p + np.array([0.06, 0.0, 0.0]), giver.cmd.q)
    q1 = giver.arm.ik((giver.arm.base_pose().inv() * slid).as_matrix()[None], seed_q=q0).q[0]
    assert st.hand_gap(giver, q0, q0, points) > 0.0 == st.hand_gap(giver, q0, q1, points)  # inside
    pressed = 0.0
    for i in (1, 2, 3):
        giver.arm.move_to_pose(Pose(giver.cmd.p + np.array([0.02 * i, 0.0, 0.0]), giver.cmd.q))
        pressed = max(pressed, sum(arm_contact_forces(b, robot.body, *links).values()))
    assert pressed > 3.0  # SAPIEN 74 N (the cube knocked out of the left hand), PyBullet 4.9 N

    # the machine's release from the same start: +x is refused at its first step, -x does not clear the
    # cube, the straight steps up do not either, so the arm turns its forearm in place, the tool held,
    # and backs straight up the full 12 cm
    held = start()
    st.release_hand(giver, 0.12)
    kinds = [e["kind"] for e in ctx.recorder.events]
    avoid = [e for e in ctx.recorder.events if e["kind"] == "hand_avoid"]
    assert avoid and avoid[0]["direction"] == [1.0, 0.0, 0.0] and avoid[0]["side_cm"] == 2
    assert "retreat_posture" in kinds and "retreat_side" not in kinds and "arm_contact" not in kinds
    assert arm_contact_forces(b, robot.body, *links) == {}
    approach = giver.last_grip.rotation.apply([1.0, 0.0, 0.0])
    assert float(np.dot(giver.last_grip.p - giver.arm.tcp_pose().p, approach)) > 0.115
    assert np.linalg.norm(st.cube.pose().p - held.p) < 0.01  # still in the left hand
