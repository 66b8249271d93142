"""Allegro hand on each backend: FK oracle, fingertip motion, holding a ball palm-down."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from simhelpers import check_fk_against_backend

from benchharness.backends.interface import Sphere
from benchharness.geometry import Pose

BACKENDS = ("pybullet", "sapien")
PALM_DOWN = Pose([0.0, 0.0, 0.5], Rotation.from_euler("y", 90, degrees=True).as_quat())


@pytest.mark.parametrize("backend", BACKENDS)
def test_backend_link_poses_match_fk(make_backend, make_robot, backend):
    be = make_backend(backend)
    robot = make_robot(
        "allegro",
        base_pose=Pose([0.1, 0.2, 0.4], Rotation.from_euler("xyz", [0.3, -0.5, 1.0]).as_quat()),
    )
    robot.spawn(be)
    check_fk_against_backend(robot, be, n=6)


@pytest.mark.parametrize("backend", BACKENDS)
def test_fingertip_moves_to_position(make_backend, make_robot, backend):
    be = make_backend(backend)
    robot = make_robot("allegro")
    robot.spawn(be)
    finger = robot.arm("index")
    start = finger.tcp_pose()
    goal = Pose(start.p + [0.02, 0.0, -0.015], start.q)
    res = finger.move_to_pose(goal, seed=3)
    assert res.ik_success and res.peak_velocity_ratio <= 0.3 + 1e-9
    assert res.max_tracking_error < 0.1
    assert res.pos_error < 0.004  # soft 3 N m/rad finger drives under gravity


@pytest.mark.parametrize("backend", BACKENDS)
def test_hand_holds_ball_palm_down(make_backend, make_robot, backend):
    """A 7 cm, 50 g ball is held at the palm while the hand closes, then released to the fingers."""
    be = make_backend(backend)
    robot = make_robot("allegro", base_pose=PALM_DOWN)
    robot.spawn(be)
    hand = robot.hand("hand")
    hand.open()
    local = Pose([0.055, 0.0, 0.02])  # in front of the palm, between thumb and fingers
    ball = be.add_body([Sphere(0.035)], PALM_DOWN * local, 0.05, friction=1.0, name="ball")
    hold = be.attach(robot.body, "palm_link", ball, None, local)
    g = hand.close(obj=ball, timeout=1.0)
    assert g.contact and not g.closed
    be.detach(hold)
    p0 = be.get_pose(ball).p.copy()
    robot.settle(3.0)
    p1 = be.get_pose(ball).p
    assert p1[2] > p0[2] - 0.01, "the ball dropped"
    assert np.linalg.norm(p1 - p0) < 0.03
    assert hand.touching(ball)


@pytest.mark.parametrize("backend", BACKENDS)
def test_hand_mounted_on_an_arm_follows_it(make_backend, make_robot, backend):
    """The hand as a free body attached to the PR2's wrist (0.30 m out, clear of the gripper) moves with the arm."""
    be = make_backend(backend)
    be.add_ground()
    pr2 = make_robot("pr2")
    pr2.spawn(be)
    offset = Pose([0.30, 0.0, 0.0], Rotation.from_euler("y", 90, degrees=True).as_quat())
    flange = be.get_link_pose(pr2.body, "l_gripper_palm_link")
    hand = make_robot("allegro", base_pose=flange * offset, fixed_base=False)
    hand.spawn(be)
    be.attach(pr2.body, "l_gripper_palm_link", hand.body, None, offset)
    pr2.settle(0.3)
    z0 = be.get_link_pose(hand.body, None).p[2]
    arm = pr2.arm("left_arm")
    tcp = arm.tcp_pose()
    res = arm.move_to_pose(Pose(tcp.p + [0.0, 0.0, 0.05], tcp.q))
    assert (
        res.ik_success and res.pos_error < 0.005
    )  # the 1 kg hand is not in the arm's gravity model
    want = be.get_link_pose(pr2.body, "l_gripper_palm_link") * offset
    assert np.linalg.norm(be.get_link_pose(hand.body, None).p - want.p) < 1e-3
    assert be.get_link_pose(hand.body, None).p[2] - z0 > 0.04
