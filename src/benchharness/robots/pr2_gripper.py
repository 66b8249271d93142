"""The stand-alone PR2 gripper on a 6-DOF positioning stage (``pr2-gripper`` robot plugin).

Used by the parallel-gripper in-hand baselines (pivoting, DMG execution).
See :mod:`benchharness.robots.descriptions.pr2_gripper` for the description
and ``robots/pr2_gripper/README.md`` for its figures. Hand poses are set as
joint targets directly: :func:`stage_joints_for` turns a world tool pose into
the six stage joint values (the wrist's axes meet at the tool centre point).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial.transform import Rotation

from ..geometry import Pose
from ..paths import robots_dir
from .config import ArmConfig, RobotConfig
from .descriptions.pr2_gripper import MOUNT_RPY, SIDE, STAGE_EFFORT, WRIST_EFFORT
from .pr2 import pr2_gripper_part

if TYPE_CHECKING:  # the robot loads with the robot, not with its config (robot_meta reads configs)
    from .robot import Robot

__all__ = ["STAGE_JOINTS", "pr2_gripper_config", "make_pr2_gripper", "stage_joints_for", "MOUNT"]

STAGE_JOINTS = (
    "stage_x_joint",
    "stage_y_joint",
    "stage_z_joint",
    "wrist_yaw_joint",
    "wrist_pitch_joint",
    "wrist_roll_joint",
)
#: Tool frame at zero wrist angles, relative to the wrist frame.
MOUNT = Rotation.from_euler("xyz", MOUNT_RPY)


def stage_joints_for(tcp: Pose, previous: np.ndarray | None = None) -> np.ndarray:
    """The six stage joint values that put the tool frame at ``tcp`` (world).

    Position: the stage's prismatic joints directly (the wrist centre is the
    tool centre point). Orientation: ``R = Rz(yaw) Ry(pitch) Rx(roll) MOUNT``,
    read as intrinsic Z-Y-X Euler angles of ``R MOUNT^-1``; yaw and roll are
    moved by multiples of 2 pi to the branch nearest ``previous`` so that a
    sequence of poses gives a continuous joint path.
    """
    r = tcp.rotation * MOUNT.inv()
    yaw, pitch, roll = r.as_euler("ZYX")
    q = np.array([*np.asarray(tcp.p, float), yaw, pitch, roll])
    if previous is not None:
        for i in (3, 5):
            q[i] += 2 * np.pi * np.round((previous[i] - q[i]) / (2 * np.pi))
    return q


def pr2_gripper_config(base_pose: Pose | None = None, grip_force: float = 20.0) -> RobotConfig:
    """Config: one ``stage`` arm (6 joints, tool = ``r_gripper_tcp``) and the PR2 ``gripper``.

    ``grip_force`` is the default per-finger force cap (N) of ``close()``.
    Stage gains follow the PR2 convention (stiffness 100 x effort, damping
    10 x effort); the finger drives are the PR2's (2000 N/m, 40 N s/m).
    """
    s = SIDE
    k_lin, k_rot = 100.0 * STAGE_EFFORT, 100.0 * WRIST_EFFORT
    stage = ArmConfig(
        name="stage",
        joints=STAGE_JOINTS,
        base_link="stage_base",
        tcp_link=f"{s}_gripper_tcp",
        stiffness=(k_lin,) * 3 + (k_rot,) * 3,
        damping=(0.1 * k_lin,) * 3 + (0.1 * k_rot,) * 3,
        velocity_scale=0.5,
    )
    grip = pr2_gripper_part(s, "gripper", grip_force)
    return RobotConfig(
        name="pr2-gripper",
        urdf=robots_dir() / "pr2_gripper" / "pr2_gripper.urdf",
        arms=(stage,),
        grippers=(grip,),
        home={"stage_z_joint": 0.3},
        base_pose=base_pose or Pose(),
        summary="PR2 parallel gripper (0-90 mm) on an ideal XYZ stage + spherical wrist centred on the tool point",
        sources=("PR2/pr2_common pr2_description gripper_v0 (gripper); stage figures assumed",),
    )


def make_pr2_gripper(
    base_pose: Pose | None = None, grip_force: float = 20.0, urdf: str | Path | None = None
) -> Robot:
    """Plugin factory for ``pr2-gripper``; ``urdf`` may point at another file with the same names."""
    from .robot import Robot

    cfg = pr2_gripper_config(base_pose, grip_force)
    if urdf is not None:
        from dataclasses import replace

        cfg = replace(cfg, urdf=Path(urdf))
    return Robot(cfg)
