"""The arm-contact record of the bimanual machine (``arm_contact_event``) against the engines' own
contacts: two PR2 grippers driven into the same point press on each other, two arms apart do not."""

from __future__ import annotations

import numpy as np
import pytest

from benchharness.geometry import Pose
from benchharness.strategies.bimanual.machine import arm_contact_forces

pytestmark = pytest.mark.sim


def _arms(robot):
    return tuple(robot.links_below(robot.arm(f"{s}_arm").joints[0]) for s in ("left", "right"))


def test_each_arm_holds_its_own_links_and_its_hands_only(make_robot):
    """From the URDF tree: the PR2's arms from the shoulder pan down, hands included, no shared link."""
    robot = make_robot("pr2")
    left, right = _arms(robot)
    assert not left & right
    assert {"l_shoulder_pan_link", "l_elbow_flex_link", "l_gripper_l_finger_tip_link"} <= left
    assert all(n.startswith("l_") for n in left) and all(n.startswith("r_") for n in right)
    assert "torso_lift_link" not in left | right


@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_grippers_driven_into_each_other_are_found_pressing(make_backend, make_robot, backend):
    be = make_backend(backend)
    robot = make_robot("pr2")
    robot.spawn(be)
    left, right = _arms(robot)
    robot.settle(0.2)
    assert arm_contact_forces(be, robot.body, left, right) == {}  # home: the arms apart
    # both tool frames commanded 2 cm past each other at one point in front of the robot: the
    # grippers meet on the way and the arms' drives push them together
    la, ra = robot.arm("left_arm"), robot.arm("right_arm")
    z = 0.5 * (la.tcp_pose().p[2] + ra.tcp_pose().p[2])
    meet = np.array([0.6, 0.0, z])
    for arm, side in ((la, -1.0), (ra, 1.0)):
        arm.move_to_pose(Pose(meet + [0.0, 0.02 * side, 0.0], arm.tcp_pose().q), settle=0.0)
    robot.settle(0.5)
    forces = arm_contact_forces(be, robot.body, left, right)
    engine = sum(
        c.normal_force
        for c in be.contacts(robot.body, robot.body)
        if {c.link_a, c.link_b} & left and {c.link_a, c.link_b} & right
    )
    assert forces and all(a in left and b in right for a, b in forces)
    assert sum(forces.values()) == pytest.approx(engine) and engine > 5.0
