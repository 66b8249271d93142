"""The ``pr2-gripper`` robot: description sanity and the stage's direct tool-pose control on both backends."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.backends.interface import PhysicsConfig
from benchharness.geometry import Pose
from benchharness.paths import robots_dir
from benchharness.plugin import get_manager
from benchharness.robots.pr2_gripper import stage_joints_for


def test_description_is_physical_and_cited():
    root = ET.parse(robots_dir() / "pr2_gripper" / "pr2_gripper.urdf").getroot()
    movable = [j for j in root.findall("joint") if j.get("type") != "fixed"]
    assert len(movable) == 10  # 3 prismatic + 3 wrist + 2 fingers + 2 four-bar fingertips
    for link in root.findall("link"):
        i = link.find("inertial/inertia")
        d = np.array([float(i.get(k)) for k in ("ixx", "iyy", "izz")])
        assert np.all(d > 0)
    text = (robots_dir() / "pr2_gripper" / "pr2_gripper.urdf").read_text().splitlines()
    for k, line in enumerate(text):
        if line.startswith("  <link ") or line.startswith("  <joint "):
            assert text[k - 1].strip().startswith("<!--"), line


def test_fingers_mimic_as_published():
    """pr2_description gripper_v0/gripper.urdf.xacro (PR2/pr2_common c36a5c9, line 80): ``*_r_finger_joint``
    carries ``<mimic joint="${prefix}_l_finger_joint" multiplier="1" offset="0"/>``: one DOF."""
    from benchharness.robots.config import JointMimic
    from benchharness.robots.pr2 import pr2_config
    from benchharness.robots.pr2_gripper import pr2_gripper_config

    (grip,) = pr2_gripper_config().grippers
    assert grip.mimic == (JointMimic("r_gripper_r_finger_joint", "r_gripper_l_finger_joint", 1.0),)
    assert [g.mimic for g in pr2_config().grippers] == [
        (JointMimic(f"{s}_gripper_r_finger_joint", f"{s}_gripper_l_finger_joint", 1.0),)
        for s in "lr"
    ]


def test_spawn_refuses_a_backend_that_cannot_couple_joints():
    """The coupling is part of the robot: a backend without it gets a clear error, not a silent stand-in."""
    from dataclasses import replace

    from benchharness.backends.interface import CapabilityError

    m = get_manager()
    b = m.create("backend", "pybullet", config=PhysicsConfig())
    try:
        b.capabilities = replace(b.capabilities, joint_coupling=False)
        with pytest.raises(
            CapabilityError, match="r_gripper_r_finger_joint mimics r_gripper_l_finger_joint"
        ):
            m.create("robot", "pr2-gripper").spawn(b)
    finally:
        b.close()


@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
def test_stage_puts_the_tool_where_commanded(backend):
    """Teleport the stage to joint values from ``stage_joints_for`` and read the tool frame back from the engine."""
    m = get_manager()
    b = m.create("backend", backend, config=PhysicsConfig())
    try:
        robot = m.create("robot", "pr2-gripper")
        robot.spawn(b)
        rng = np.random.default_rng(0)
        names = robot.joint_names
        arm = robot.arm("stage")
        for _ in range(5):
            rot = Rotation.from_rotvec(rng.normal(0, 0.6, 3)) * Rotation.from_euler(
                "y", 90, degrees=True
            )
            target = Pose.from_rotation(rng.uniform(-0.2, 0.2, 3) + [0, 0, 0.4], rot)
            q = robot.home()
            for n, v in zip(arm.joints, stage_joints_for(target)):
                q[names.index(n)] = v
            b.set_joint_positions(robot.body, q)
            got = arm.tcp_pose()
            assert np.linalg.norm(got.p - target.p) < 1e-5
            assert (got.rotation * target.rotation.inv()).magnitude() < 1e-5
    finally:
        b.close()


@pytest.mark.parametrize("force", [3.0, 20.0])
@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
def test_vertical_fingers_press_equally_on_what_they_hold(backend, force):
    """Fingers closing vertically on a fixed block press it with the force asked for, both alike.

    The real gripper's fingers share one motor through the mimic linkage, so their weights (2.1 N
    each) cancel; independent finger drives (``symmetric=False``, the model before the coupling)
    carry their own weight (``gravity_compensated``) and close together at the published gap speed
    (``close_speed``). Without that, the upper pad pressed twice a finger's weight harder than the
    lower one: a net push on a cube held by the other hand.
    """
    from dataclasses import replace

    from benchharness.backends.interface import Box
    from benchharness.robots.descriptions.pr2 import pad_setback
    from benchharness.robots.pr2 import pr2_gripper_part
    from benchharness.robots.pr2_gripper import pr2_gripper_config
    from benchharness.robots.robot import Robot

    m = get_manager()
    b = m.create("backend", backend, config=PhysicsConfig())
    try:
        # independent fingers: on a *fixed* block a coupled pair's two pad forces are
        # set by how far the stage sags off the block's centre (tens of micrometres), not by the drives
        cfg = pr2_gripper_config()
        robot = Robot(replace(cfg, grippers=(pr2_gripper_part("r", "gripper", symmetric=False),)))
        robot.spawn(b)
        arm, grip = robot.arm("stage"), robot.gripper("gripper")
        # approach along world x, the fingers closing along world z
        tool = Pose.from_rotation([0.0, 0.0, 0.4], Rotation.from_euler("x", 90, degrees=True))
        arm.move_to_joints(stage_joints_for(tool), settle=0.3)
        grip.open(wait=0.5)
        centre = arm.tcp_pose().p - [pad_setback(0.057), 0.0, 0.0]
        block = b.add_body(
            [Box((0.01, 0.02, 0.0285))], Pose(np.asarray(centre)), 0.1, fixed=True, name="block"
        )
        res = grip.close(force_limit=force, obj=block)
        assert res.contact and not res.closed
        robot.settle(0.3)
        pads: dict[str, float] = {}
        for c in b.contacts(robot.body, block):
            pads[c.link_a] = pads.get(c.link_a, 0.0) + c.normal_force
        assert set(pads) == set(grip.config.finger_links), pads
        f = np.array(list(pads.values()))
        assert np.all(np.abs(f - force) < 0.1 * force + 0.3), pads
        assert abs(f[0] - f[1]) < 0.1 * force + 0.3, pads
    finally:
        b.close()
