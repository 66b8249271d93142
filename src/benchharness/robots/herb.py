"""HERB: two WAM arms with BarrettHands on a fixed torso."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from ..geometry import Pose
from ..paths import robots_dir
from .config import ArmConfig, GripperConfig, RobotConfig, gains_from_effort
from .descriptions.herb import BH_COUPLING, BH_PROX, WAM_EFFORT

if TYPE_CHECKING:  # the robot loads with the robot, not with its config (robot_meta reads configs)
    from .robot import Robot

__all__ = ["herb_config", "make_herb", "BARRETT_HAND_COUPLING"]

#: Physical joints of one hand (after the side prefix) and the coupling from the actuators
#: (spread, f1, f2, f3): spread drives both F1 and F2 knuckles; each distal joint follows its
#: proximal joint at the BH8-280 ratio.
HAND_JOINTS = (
    "bh_j11_joint",
    "bh_j21_joint",
    "bh_j12_joint",
    "bh_j13_joint",
    "bh_j22_joint",
    "bh_j23_joint",
    "bh_j32_joint",
    "bh_j33_joint",
)
BARRETT_HAND_COUPLING = (
    (1.0, 0.0, 0.0, 0.0),
    (1.0, 0.0, 0.0, 0.0),
    (0.0, 1.0, 0.0, 0.0),
    (0.0, BH_COUPLING, 0.0, 0.0),
    (0.0, 0.0, 1.0, 0.0),
    (0.0, 0.0, BH_COUPLING, 0.0),
    (0.0, 0.0, 0.0, 1.0),
    (0.0, 0.0, 0.0, BH_COUPLING),
)
#: Arm home (left; the right arm mirrors it, negating j1, j3, j5, j7 — the WAM's zero pose lies in
#: the mirror plane): elbow folded, tool frame at (0.85, 0.22, 0.95) m pointing forward and 45 deg
#: down (found by IK on the published mount; both WAMs are mounted alike, j1 along the base's +x).
HOME_ARM = (0.318, -1.058, 0.241, 2.579, 0.629, -0.845, -0.614)


def herb_config(
    urdf: str | Path | None = None,
    joint_map: Mapping[str, str] | None = None,
    link_map: Mapping[str, str] | None = None,
    base_pose: Pose | None = None,
) -> RobotConfig:
    arms, hands, home = [], [], {}
    for s, side in (("l", "left"), ("r", "right")):
        k, d = gains_from_effort(WAM_EFFORT, 100.0, 10.0)
        joints = tuple(f"{s}_wam_j{i}" for i in range(1, 8))
        arms.append(
            ArmConfig(
                name=f"{side}_arm",
                joints=joints,
                base_link=f"{s}_wam_base_link",
                tcp_link=f"{s}_bh_tcp",
                stiffness=k,
                damping=d,
            )
        )
        hj = tuple(f"{s}_{j}" for j in HAND_JOINTS)
        finger_links = tuple(f"{s}_bh_finger_{f}{n}_link" for f in "123" for n in "23")
        hands.append(
            GripperConfig(
                name=f"{side}_hand",
                joints=hj,
                actuators=("spread", "f1", "f2", "f3"),
                coupling=BARRETT_HAND_COUPLING,
                open=(0.0, 0.0, 0.0, 0.0),
                closed=(0.0, BH_PROX[1], BH_PROX[1], BH_PROX[1]),
                grasp_actuators=("f1", "f2", "f3"),
                # the spread's worm drive is not backdrivable: a stiff, strong drive stands in for it
                stiffness=(100.0, 100.0) + (10.0, 10.0) * 3,
                damping=(2.0, 2.0) + (0.2, 0.2) * 3,
                force_limit=(10.0, 10.0) + (2.0, 2.0) * 3,
                finger_links=finger_links,
                tcp_link=f"{s}_bh_tcp",
                kind="multifinger",
                follow=tuple(
                    (f"{s}_bh_j{f}3_joint", f"{s}_bh_j{f}2_joint", BH_COUPLING) for f in "123"
                ),
            )
        )
        sign = 1.0 if s == "l" else -1.0
        for i, v in enumerate(HOME_ARM):
            home[joints[i]] = sign * v if i in (0, 2, 4, 6) else v
    cfg = RobotConfig(
        name="herb",
        urdf=robots_dir() / "herb" / "herb.urdf",
        arms=tuple(arms),
        grippers=tuple(hands),
        home=home,
        base_pose=base_pose or Pose(),
        summary="CMU HERB: two Barrett WAM 7-DOF arms with BarrettHand BH8-280 (base fixed)",
        sources=(
            "Barrett WAM manual DH parameters",
            "personalrobotics/herb_description@2604b90 (mounts, F/T plate, limits)",
            "jhu-lcsr/barrett_model@b58cf4c (BarrettHand kinematics)",
        ),
    )
    if urdf is not None:
        cfg = cfg.remapped(urdf, joint_map, link_map)
    return cfg


def make_herb(
    urdf: str | Path | None = None,
    joint_map: Mapping[str, str] | None = None,
    link_map: Mapping[str, str] | None = None,
    base_pose: Pose | None = None,
) -> Robot:
    from .robot import Robot

    return Robot(herb_config(urdf, joint_map, link_map, base_pose))
