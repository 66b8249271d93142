"""An example third-party benchharness plugin.

Everything here uses benchharness' public API only: a robot is a
``RobotConfig`` (data) around our own URDF, and a task is a ``RubiksTier``.
The ``benchharness`` entry point in ``pyproject.toml`` names this module.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchharness.cube.tiers import RubiksTier
from benchharness.geometry import Pose
from benchharness.plugin import Registration, hookimpl

URDF = Path(__file__).with_name("gantry_gripper.urdf")


def gantry_gripper_config():
    from benchharness.robots.config import ArmConfig, GripperConfig, RobotConfig

    gantry = ArmConfig(
        name="gantry",
        joints=("gantry_x", "gantry_y", "gantry_z"),
        base_link="world_link",
        tcp_link="tcp",
        stiffness=(4000.0,) * 3,
        damping=(400.0,) * 3,
        position_only=True,  # three translations cannot orient the tool
    )
    gripper = GripperConfig(
        name="gripper",
        joints=("finger_left_joint", "finger_right_joint"),
        actuators=("grip",),
        coupling=((1.0,), (1.0,)),  # both fingers follow one command (no mimic joints in PhysX)
        open=(0.04,),
        closed=(0.0,),
        grasp_actuators=("grip",),
        stiffness=(2000.0, 2000.0),  # spring-like pads (docs/benchmarks/cube_spike.md)
        damping=(20.0, 20.0),
        force_limit=(20.0, 20.0),
        finger_links=("finger_left", "finger_right"),
        tcp_link="tcp",
    )
    return RobotConfig(
        name="example-gantry-gripper",
        urdf=URDF,
        arms=(gantry,),
        grippers=(gripper,),
        home={"gantry_z": 0.3, "finger_left_joint": 0.04, "finger_right_joint": 0.04},
        base_pose=Pose(np.array([0.0, 0.0, 0.1])),
        summary="Example: parallel gripper on a 3-axis gantry (third-party plugin)",
    )


def make_gantry_gripper(**_: object):
    from benchharness.robots.robot import Robot

    return Robot(gantry_gripper_config())


def _robot_meta() -> dict[str, object]:
    """DOF, groups and URDF as ``benchharness robots`` lists them, read off the config."""
    from benchharness.robots.config import robot_meta

    return robot_meta(gantry_gripper_config())


@hookimpl
def benchharness_robots() -> list[Registration]:
    return [
        Registration(
            "example-gantry-gripper",
            make_gantry_gripper,
            "Example: parallel gripper on a 3-axis gantry (third-party plugin)",
            meta=_robot_meta,
        )
    ]


@hookimpl
def benchharness_tasks() -> list[Registration]:
    tier = RubiksTier(name="Example-Rubiks-2-3", trials=2, moves=3)
    return [Registration(tier.name, lambda **_: tier, tier.summary, meta={"benchmark": "rubiks"})]
