"""The PR2 robot: config factory and the name map for a full ``pr2_description`` URDF."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from ..geometry import Pose
from ..paths import robots_dir
from .config import (
    ArmConfig,
    FingertipLinkage,
    GripperConfig,
    JointMimic,
    RobotConfig,
    gains_from_effort,
)
from .descriptions.pr2 import (
    FINGER_RADIUS,
    FINGER_TRAVEL,
    FINGER_Y,
    GRIPPER_CLOSE_SPEED,
    PAD_FACE_Y,
    PAD_GAP,
)

if TYPE_CHECKING:  # the robot loads with the robot, not with its config (robot_meta reads configs)
    from .robot import Robot

__all__ = [
    "PR2_FULL_URDF_LINK_MAP",
    "PR2_FULL_URDF_JOINT_MAP",
    "pr2_config",
    "pr2_gripper_part",
    "make_pr2",
]

ARM_JOINTS = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "upper_arm_roll_joint",
    "elbow_flex_joint",
    "forearm_roll_joint",
    "wrist_flex_joint",
    "wrist_roll_joint",
)
ARM_EFFORT = (30, 30, 30, 30, 30, 10, 10)  # N m, pr2_description

#: Home (left arm; the right mirrors it): torso 0.1 m up, elbows out, each gripper horizontal and pointing
#: forward, 0.65 m in front of the base centre, 0.12 m either side of the midline, 0.79 m above the floor
#: (an IK solution, rounded).
HOME_ARM = {
    "shoulder_pan_joint": 0.5,
    "shoulder_lift_joint": 0.13,
    "upper_arm_roll_joint": 1.75,
    "elbow_flex_joint": -1.78,
    "forearm_roll_joint": -2.93,
    "wrist_flex_joint": -1.31,
    "wrist_roll_joint": 1.41,
}

#: Our names -> names in the Willow Garage ``pr2_description`` URDF. The real gripper is one
#: ``l_gripper_joint`` with mimic fingers, which our two-prismatic-finger gripper part cannot drive,
#: so the grippers are dropped ("") there; arms, torso and TCP frames work unchanged.
PR2_FULL_URDF_JOINT_MAP: Mapping[str, str] = {
    f"{s}_gripper_{f}_finger{part}_joint": "" for s in "lr" for f in "lr" for part in ("", "_tip")
}
PR2_FULL_URDF_LINK_MAP: Mapping[str, str] = {
    "l_gripper_tcp": "l_gripper_tool_frame",
    "r_gripper_tcp": "r_gripper_tool_frame",
}


def pr2_gripper_part(
    s: str, name: str, grip_force: float = 20.0, *, symmetric: bool = True
) -> GripperConfig:
    """The PR2 gripper on side ``s`` (``"l"``/``"r"``): one half-opening actuator, force in N per finger.

    The two lateral finger joints take the command; each fingertip follows its
    finger on the four-bar's arc (:class:`FingertipLinkage`, figures in
    :mod:`.descriptions.pr2`), so the pads slide back along the approach as the
    gripper opens, as the real ones do. ``symmetric``: the right finger
    mimics the left one (:class:`JointMimic`, multiplier 1, as
    pr2_description's ``*_r_finger_joint`` does), so the fingers stay
    symmetric about the tool frame under any load; False: two independent
    finger drives (the model before 2026-12-05; a diagnostic now).
    """
    lateral = PAD_GAP + PAD_FACE_Y - FINGER_Y  # leader value 0 -> the real tip's lateral arm
    linkages = tuple(
        FingertipLinkage(
            follower=f"{s}_gripper_{f}_finger_tip_joint",
            leader=f"{s}_gripper_{f}_finger_joint",
            radius=FINGER_RADIUS,
            lateral_offset=lateral,
            closed_offset=PAD_FACE_Y - FINGER_Y,
        )
        for f in "lr"
    )
    return GripperConfig(
        name=name,
        joints=(f"{s}_gripper_l_finger_joint", f"{s}_gripper_r_finger_joint"),
        actuators=("half_opening",),
        coupling=((1.0,), (1.0,)),
        open=(FINGER_TRAVEL,),
        closed=(0.0,),
        grasp_actuators=("half_opening",),
        stiffness=(2000.0, 2000.0),
        damping=(40.0, 40.0),
        force_limit=(grip_force, grip_force),
        # the pads (one link per finger, left first): where the gripper touches what it holds
        finger_links=(f"{s}_gripper_l_finger_tip_link", f"{s}_gripper_r_finger_tip_link"),
        tcp_link=f"{s}_gripper_tcp",
        kind="parallel",
        linkages=linkages,
        mimic=(
            (JointMimic(f"{s}_gripper_r_finger_joint", f"{s}_gripper_l_finger_joint"),)
            if symmetric
            else ()
        ),
        # one motor drives both fingers through the screw and the mimic linkage: the finger weights cancel
        gravity_compensated=True,
        # l_gripper_joint (the gap) velocity="0.2" m/s (pr2_description gripper_v0/gripper.urdf.xacro): 0.1 per finger
        close_speed=GRIPPER_CLOSE_SPEED,
    )


def pr2_config(
    urdf: str | Path | None = None,
    joint_map: Mapping[str, str] | None = None,
    link_map: Mapping[str, str] | None = None,
    base_pose: Pose | None = None,
) -> RobotConfig:
    arms, grippers, home = [], [], {"torso_lift_joint": 0.1}
    for s, side in (("l", "left"), ("r", "right")):
        k, d = gains_from_effort(ARM_EFFORT, 100.0, 10.0)
        arms.append(
            ArmConfig(
                name=f"{side}_arm",
                joints=tuple(f"{s}_{j}" for j in ARM_JOINTS),
                base_link="torso_lift_link",
                tcp_link=f"{s}_gripper_tcp",
                stiffness=k,
                damping=d,
                gravity_carried=True,
            )
        )
        grippers.append(pr2_gripper_part(s, f"{side}_gripper"))
        sign = 1.0 if s == "l" else -1.0
        for j, v in HOME_ARM.items():
            mirrored = j in (
                "shoulder_pan_joint",
                "upper_arm_roll_joint",
                "forearm_roll_joint",
                "wrist_roll_joint",
            )
            home[f"{s}_{j}"] = sign * v if mirrored else v
    cfg = RobotConfig(
        name="pr2",
        urdf=robots_dir() / "pr2" / "pr2.urdf",
        arms=tuple(arms),
        grippers=tuple(grippers),
        extra_groups={"torso": ("torso_lift_joint",)},
        extra_gains={"torso_lift_joint": (1.0e6, 1.0e5)},
        home=home,
        base_pose=base_pose or Pose(),
        summary="Willow Garage PR2: torso lift, two 7-DOF arms, two parallel grippers (base fixed)",
        sources=("PR2/pr2_common pr2_description xacros",),
        # IK and the primitives stay inside the safety controller's soft limits, which the URDF carries
        # (descriptions.pr2.SAFETY); a full pr2_description URDF carries the same elements.
        soft_limits=True,
    )
    if urdf is not None:
        cfg = cfg.remapped(urdf, joint_map, link_map)
    return cfg


def make_pr2(
    urdf: str | Path | None = None,
    joint_map: Mapping[str, str] | None = None,
    link_map: Mapping[str, str] | None = None,
    base_pose: Pose | None = None,
) -> Robot:
    """Plugin factory: our PR2, or the PR2 parts on ``urdf`` with names mapped (see module maps)."""
    from .robot import Robot

    return Robot(pr2_config(urdf, joint_map, link_map, base_pose))
