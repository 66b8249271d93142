"""PR2 on each backend: FK oracle, tracked arm motion, a 5.7 cm cube grasped and lifted."""

from __future__ import annotations

import numpy as np
import pytest
from simhelpers import check_fk_against_backend, check_motion, offset_pose

from benchharness.backends.interface import Box
from benchharness.geometry import Pose

BACKENDS = ("pybullet", "sapien")
CUBE_HALF = 0.0285  # m, 5.7 cm Rubik's cube
CUBE_MASS = 0.094  # kg


@pytest.mark.parametrize("backend", BACKENDS)
def test_backend_link_poses_match_fk(make_backend, make_robot, backend):
    be = make_backend(backend)
    robot = make_robot("pr2")
    robot.spawn(be, Pose([0.3, -0.2, 0.0], [0, 0, np.sin(0.2), np.cos(0.2)]))
    check_fk_against_backend(robot, be)


@pytest.mark.parametrize("backend", BACKENDS)
def test_arm_tracks_trajectory_to_pose(make_backend, make_robot, backend):
    be = make_backend(backend)
    be.add_ground()
    robot = make_robot("pr2")
    robot.spawn(be)
    other = robot.arm("right_arm").tcp_pose()
    arm = robot.arm("left_arm")
    goal = offset_pose(arm.tcp_pose(), [-0.05, 0.04, 0.08], [0.0, 0.0, 0.25])
    res = arm.move_to_pose(goal, seed=1)
    check_motion(res)
    # the other arm held still meanwhile
    assert np.linalg.norm(robot.arm("right_arm").tcp_pose().p - other.p) < 2e-3


@pytest.mark.parametrize("backend", BACKENDS)
def test_gripper_grasps_and_lifts_cube(make_backend, make_robot, backend):
    be = make_backend(backend)
    be.add_ground()
    robot = make_robot("pr2")
    robot.spawn(be)
    arm, grip = robot.arm("left_arm"), robot.gripper("left_gripper")
    tcp = arm.tcp_pose()
    top = tcp.p[2] - CUBE_HALF
    be.add_body(
        [Box((0.02, 0.02, top / 2))],
        Pose([tcp.p[0], tcp.p[1], top / 2]),
        1.0,
        fixed=True,
        name="pedestal",
    )
    cube = be.add_body(
        [Box((CUBE_HALF,) * 3)],
        Pose([tcp.p[0], tcp.p[1], top + CUBE_HALF + 5e-4]),
        CUBE_MASS,
        friction=1.0,
        name="cube",
    )
    robot.settle(0.1)
    g = grip.close(obj=cube)
    assert g.contact and not g.closed
    assert np.mean(g.joint_positions) == pytest.approx(
        CUBE_HALF - 0.001, abs=2e-3
    )  # pads on the faces
    c0 = be.get_pose(cube).p.copy()
    res = arm.move_to_pose(Pose(tcp.p + [0, 0, 0.10], tcp.q))
    assert res.ik_success
    robot.settle(1.0)
    c1 = be.get_pose(cube).p
    assert c1[2] - c0[2] == pytest.approx(0.10, abs=0.01), "cube did not follow the lift"
    assert grip.touching(cube)
    assert np.linalg.norm(arm.tcp_pose().p - c1) < 0.01  # still centred between the pads
