"""The Allegro hand (right, v4): four finger chains and one 16-joint hand."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..geometry import Pose
from ..paths import robots_dir
from .config import ArmConfig, GripperConfig, RobotConfig

if TYPE_CHECKING:  # the robot loads with the robot, not with its config (robot_meta reads configs)
    from .robot import Robot

__all__ = ["allegro_config", "make_allegro", "FINGERS"]

FINGERS = {"index": 0, "middle": 1, "ring": 2, "thumb": 3}
#: Open: fingers straight, thumb rotated under the palm (joint_12 lower limit region).
OPEN = (0.0, 0.0, 0.0, 0.0) * 3 + (0.4, 0.0, 0.0, 0.0)
#: Closed (no object): fingers curled, thumb opposed and curled.
CLOSED = (0.0, 1.4, 1.4, 1.2) * 3 + (1.3, 1.0, 1.2, 1.4)
#: Home: a relaxed precision-grasp preshape.
HOME = (0.0, 0.3, 0.3, 0.3) * 3 + (0.9, 0.3, 0.3, 0.3)
#: Palm 0.5 m above the world origin, fingers up: clear of a ground plane at z = 0.
DEFAULT_BASE_POSE = Pose(np.array([0.0, 0.0, 0.5]))
#: Allegro joint PD gains (N m/rad, N m s/rad), soft as on the real hand's default controller.
KP, KD, TORQUE = 3.0, 0.1, 0.7


def allegro_config(
    urdf: str | Path | None = None,
    joint_map: Mapping[str, str] | None = None,
    link_map: Mapping[str, str] | None = None,
    base_pose: Pose | None = None,
    fixed_base: bool = True,
) -> RobotConfig:
    """``base_pose``: the palm frame in the world (fixed in space); to mount the hand on an arm,
    spawn it with ``fixed_base=False`` and ``backend.attach`` its palm to the arm's flange."""
    joints = tuple(f"joint_{i}" for i in range(16))
    arms = []
    for name, f in FINGERS.items():
        fj = joints[4 * f : 4 * f + 4]
        arms.append(
            ArmConfig(
                name=name,
                joints=fj,
                base_link="palm_link",
                tcp_link=f"link_{4 * f + 3}_tip",
                stiffness=(KP,) * 4,
                damping=(KD,) * 4,
                position_only=True,
                velocity_scale=0.3,
            )
        )
    hand = GripperConfig(
        name="hand",
        joints=joints,
        actuators=joints,
        coupling=tuple(tuple(np.eye(16)[i]) for i in range(16)),
        open=OPEN,
        closed=CLOSED,
        grasp_actuators=joints,
        stiffness=(KP,) * 16,
        damping=(KD,) * 16,
        force_limit=(TORQUE,) * 16,
        finger_links=tuple(f"link_{i}" for i in range(16))
        + tuple(f"link_{i}_tip" for i in (3, 7, 11, 15)),
        tcp_link="palm_tcp",
        kind="multifinger",
    )
    cfg = RobotConfig(
        name="allegro",
        urdf=robots_dir() / "allegro" / "allegro.urdf",
        arms=tuple(arms),
        grippers=(hand,),
        home=dict(zip(joints, HOME)),
        base_pose=base_pose or DEFAULT_BASE_POSE,
        fixed_base=fixed_base,
        summary="Wonik Allegro hand v4 (right): 16 joints, index/middle/ring/thumb",
        sources=("simlabrobotics/allegro_hand_ros_v4 allegro_hand_description_right.xacro",),
    )
    if urdf is not None:
        cfg = cfg.remapped(urdf, joint_map, link_map)
    return cfg


def make_allegro(
    urdf: str | Path | None = None,
    joint_map: Mapping[str, str] | None = None,
    link_map: Mapping[str, str] | None = None,
    base_pose: Pose | None = None,
    fixed_base: bool = True,
) -> Robot:
    from .robot import Robot

    return Robot(allegro_config(urdf, joint_map, link_map, base_pose, fixed_base))
