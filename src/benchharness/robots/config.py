"""Typed configurations of robots and their parts (arms, grippers/hands).

A robot is described by data, not by subclassing: a :class:`RobotConfig`
names the URDF, the arms (serial chains ending in a tool frame), the
grippers or hands (actuated joint sets with a coupling), extra joint groups
and a home configuration. The shipped robots (``pr2``, ``herb``, ``allegro``)
are functions returning such configs; a user's own robot is another one.

All names (joints, links) are those of the URDF in use. :meth:`RobotConfig.remapped`
renames them when a user points a robot at a full-fidelity URDF whose names
differ from ours.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Literal

import numpy as np

from ..geometry import Pose

__all__ = [
    "ArmConfig",
    "FingertipLinkage",
    "GripperConfig",
    "JointMimic",
    "RobotConfig",
    "gains_from_effort",
    "robot_meta",
]


@dataclass(frozen=True)
class ArmConfig:
    """A serial chain from ``base_link`` to a tool frame ``tcp_link``: an arm, or one finger."""

    name: str  #: group name, e.g. ``"left_arm"``, ``"index"``
    joints: tuple[str, ...]  #: movable joints from base to tip (the chain's order)
    base_link: (
        str  #: IK targets are expressed in this link's frame (converted from world by the robot)
    )
    tcp_link: str  #: tool-centre-point frame (a URDF link)
    stiffness: tuple[float, ...]  #: PD stiffness per joint (N m/rad or N/m)
    damping: tuple[float, ...]  #: PD damping per joint (N m s/rad or N s/m)
    position_only: bool = False  #: IK on position only (fingers with < 6 DOF)
    velocity_scale: float = (
        0.5  #: trajectories use this fraction of each joint's URDF velocity limit
    )
    gravity_carried: bool = (
        False  #: gravity torque is carried by a counterbalance, not by the motors (PR2)
    )


@dataclass(frozen=True)
class JointMimic:
    """A joint that the hand's mechanism ties to another: ``q_follower = multiplier * q_leader``.

    The URDF's ``<mimic>``, made a constraint of the engine
    (:meth:`~benchharness.backends.interface.Backend.couple_joints`), not a
    controller target: a load that pushes one finger out pulls the other in
    through the mechanism, whatever the drives do. Why: a gripper whose two
    fingers one transmission moves (the PR2's, pr2_description
    ``gripper_v0/gripper.urdf.xacro``: ``*_r_finger_joint`` mimics
    ``*_l_finger_joint`` with multiplier 1) keeps its fingers symmetric about
    the tool frame. Two independent force-capped drives do not: under a light
    squeeze they are a neutral pair, and what they hold can drift or lean
    towards either finger at no cost (an object standing on a table topples
    sideways; docs/pivoting.md, "Symmetric fingers").
    """

    follower: str
    leader: str
    multiplier: float = 1.0


@dataclass(frozen=True)
class FingertipLinkage:
    """A fingertip joint that a parallelogram linkage ties to its finger's lateral joint.

    Why: a four-bar finger (the PR2's) moves its pad on a circular arc, so the
    pad slides along the approach as the gripper opens — a nonlinear mimic
    relation that no engine's joint drives express (PhysX has no mimic joints
    at all). The model gives each fingertip a prismatic ``follower`` joint along
    the approach, re-aimed every control tick at the arc position of the
    measured ``leader`` (lateral) joint: with the leader at ``q`` the real
    fingertip frame sits ``radius * sin(angle) = q + lateral_offset`` out, and
    the follower's value is ``radius * cos(angle)`` minus its value closed
    (``q + lateral_offset = closed_offset``).
    """

    follower: str  #: the fingertip's prismatic joint along the approach
    leader: str  #: the finger's lateral joint (a joint of the gripper)
    radius: float  #: m, distance of the fingertip frame from the real finger's pivot
    lateral_offset: float  #: m, added to the leader's value to give the lateral arm of the arc
    closed_offset: float  #: m, that lateral arm where the follower reads 0
    #: PD gains of the follower (N/m, N s/m): stiff, a stand-in for the rigid linkage (a 5 N load along
    #: the approach moves the pad 0.25 mm); its force cap is the joint's URDF effort
    stiffness: float = 2.0e4
    damping: float = 200.0

    def target(self, q_leader: float) -> float:
        r = self.radius
        s = min(r, max(-r, q_leader + self.lateral_offset))
        # math.sqrt: correctly rounded like np.sqrt, without NumPy's per-call cost (per physics step)
        return math.sqrt(r * r - s * s) - math.sqrt(r * r - self.closed_offset**2)

    def rate(self, q_leader: float) -> float:
        """d target / d q_leader: the follower's velocity per unit leader velocity."""
        r = self.radius
        s = min(0.999 * r, max(-0.999 * r, q_leader + self.lateral_offset))
        return -s / math.sqrt(r * r - s * s)


@dataclass(frozen=True)
class GripperConfig:
    """An actuated grasping joint set (parallel gripper, BarrettHand, Allegro hand).

    The physical joints follow a few actuator commands through a linear
    coupling, ``q_joint = coupling @ u`` — this is how fingers that a real
    hand couples mechanically (mimic joints) are driven, since PhysX has no
    mimic joints. Each joint is an independent PD drive towards its coupled
    target, capped at ``force_limit``: a blocked proximal link does not stop
    its distal link, much like the BarrettHand's breakaway clutch. Joints that
    the mechanism itself ties together (a parallel gripper's two fingers)
    are listed in ``mimic`` as well: that makes an engine constraint of it.
    """

    name: str  #: group name, e.g. ``"left_gripper"``
    joints: tuple[str, ...]  #: physical joints
    actuators: tuple[
        str, ...
    ]  #: command names, e.g. ``("grip",)``, ``("spread", "f1", "f2", "f3")``
    coupling: tuple[tuple[float, ...], ...]  #: (len(joints), len(actuators)) matrix
    open: tuple[float, ...]  #: actuator values of the open hand
    closed: tuple[float, ...]  #: actuator values of the fully closed hand (no object)
    grasp_actuators: tuple[
        str, ...
    ]  #: actuators that close() moves (others keep their value, e.g. spread)
    stiffness: tuple[float, ...]  #: per joint
    damping: tuple[float, ...]  #: per joint
    force_limit: tuple[float, ...]  #: default per-joint force/torque cap for closing (N or N m)
    finger_links: tuple[str, ...]  #: links whose contacts count as the hand touching an object
    tcp_link: str | None = None  #: grasp-centre frame, if the hand has one
    kind: Literal["parallel", "multifinger"] = "parallel"
    #: (follower joint, leader joint, ratio): the follower tracks ``ratio * measured leader`` while the
    #: leader moves, and its own coupled target once the leader stalls (the BarrettHand's breakaway).
    follow: tuple[tuple[str, str, float], ...] = ()
    #: fingertip joints that follow their finger's lateral joint on a linkage's arc (not in ``joints``:
    #: the actuators, forces and openings stay those of ``joints``)
    linkages: tuple[FingertipLinkage, ...] = ()
    #: joints of ``joints`` that the mechanism ties together (:class:`JointMimic`), as engine
    #: constraints made when the robot spawns; each joint keeps its own drive and force cap
    mimic: tuple[JointMimic, ...] = ()
    #: each joint's drive also carries the weight its links put on it (gravity feed-forward, refreshed
    #: every control tick), so that ``force_limit`` is the force the finger presses with in any
    #: orientation. Why: a hand whose fingers one transmission couples (the PR2's: one motor, mimic
    #: fingers) has their weights cancel in the transmission; independent finger drives standing in for it
    #: would otherwise press one pad harder than the other by twice a finger's weight whenever the
    #: fingers close vertically (PR2: 2 x 2.1 N), a net push on what they hold (docs/strategies.md,
    #: "One-hand holds"). Applied to ``close()`` and its squeeze, whose targets are unsaturated springs
    #: (``set_command(..., feed_forward=True)`` elsewhere): the engines' force caps are symmetric, so a
    #: saturated drive cannot be compensated. Needs a backend with ``capabilities.gravity_torques``;
    #: False: the drive's force cap is all it has (hands whose motors carry their own fingers).
    gravity_compensated: bool = False
    #: joint speed (m/s or rad/s) at which ``close()`` moves each joint's target towards closed, stopping
    #: each finger where its link first touches (then pressing with ``force_limit`` as a spring): the
    #: fingers close together at a bounded speed, as a position-controlled gripper's do. Needs one
    #: finger link per joint. None: a step target, the force cap alone limiting the motion.
    close_speed: float | None = None

    def joint_targets(self, u: Sequence[float]) -> np.ndarray:
        return np.asarray(self.coupling, dtype=float) @ np.asarray(u, dtype=float)

    @property
    def driven_joints(self) -> tuple[str, ...]:
        """Every joint this hand drives: ``joints`` and the linkages' fingertip joints."""
        return self.joints + tuple(k.follower for k in self.linkages)


@dataclass(frozen=True)
class RobotConfig:
    """A whole robot: description, parts, groups and home configuration."""

    name: str
    urdf: Path
    arms: tuple[ArmConfig, ...] = ()
    grippers: tuple[GripperConfig, ...] = ()
    extra_groups: Mapping[str, tuple[str, ...]] = field(
        default_factory=dict
    )  #: e.g. ``{"torso": ("torso_lift_joint",)}``
    extra_gains: Mapping[str, tuple[float, float]] = field(
        default_factory=dict
    )  #: joint -> (stiffness, damping) for joints outside arms/grippers
    home: Mapping[str, float] = field(
        default_factory=dict
    )  #: joint -> position; unnamed joints home at 0 (clamped to limits)
    base_pose: Pose = field(default_factory=Pose)  #: world pose of the URDF root link
    fixed_base: bool = True
    summary: str = ""
    sources: tuple[str, ...] = ()  #: where the figures come from (README has the detail)
    #: IK and every motion primitive keep joints inside the URDF's ``<safety_controller>`` soft limits
    #: (the PR2's: a few tenths of a radian inside the hard limits). Joints without one keep their hard
    #: limits, so a robot with none (HERB, Allegro) is unaffected; False: hard limits everywhere.
    soft_limits: bool = True

    def groups(self) -> dict[str, tuple[str, ...]]:
        g: dict[str, tuple[str, ...]] = {a.name: a.joints for a in self.arms}
        g.update({h.name: h.joints for h in self.grippers})
        g.update(dict(self.extra_groups))
        return g

    def remapped(
        self,
        urdf: str | Path,
        joint_map: Mapping[str, str] | None = None,
        link_map: Mapping[str, str] | None = None,
    ) -> RobotConfig:
        """The same robot on another URDF whose joint/link names differ by the given maps.

        Maps go from our names to the names in ``urdf``; names not in a map
        are kept. Parts whose joints the maps name ``""`` are dropped — e.g.
        a full PR2 URDF has one gripper joint with mimic fingers, which our
        two-finger gripper part cannot drive.
        """
        jm = dict(joint_map or {})
        lm = dict(link_map or {})

        def j(n: str) -> str:
            return jm.get(n, n)

        def lk(n: str | None) -> str | None:
            return None if n is None else lm.get(n, n)

        arms = tuple(
            replace(
                a,
                joints=tuple(j(n) for n in a.joints),
                base_link=lk(a.base_link),
                tcp_link=lk(a.tcp_link),
            )
            for a in self.arms
            if all(j(n) for n in a.joints)
        )
        grippers = tuple(
            replace(
                h,
                joints=tuple(j(n) for n in h.joints),
                finger_links=tuple(lk(n) for n in h.finger_links),
                tcp_link=lk(h.tcp_link),
                linkages=tuple(
                    replace(k, follower=j(k.follower), leader=j(k.leader)) for k in h.linkages
                ),
            )
            for h in self.grippers
            if all(j(n) for n in h.driven_joints)
        )
        extra = {k: tuple(j(n) for n in v if j(n)) for k, v in self.extra_groups.items()}
        gains = {j(k): v for k, v in self.extra_gains.items() if j(k)}
        home = {j(k): v for k, v in self.home.items() if j(k)}
        return replace(
            self,
            urdf=Path(urdf),
            arms=arms,
            grippers=grippers,
            extra_groups=extra,
            extra_gains=gains,
            home=home,
        )


def gains_from_effort(
    efforts: Sequence[float], kp_per_effort: float, kd_per_effort: float
) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """PD gains proportional to each joint's effort limit.

    Why: stiff joints where the motor is strong and soft where it is weak
    keep the drive saturating at about the same position error on every
    joint, instead of the wrist saturating long before the shoulder.
    """
    e = np.asarray(efforts, dtype=float)
    return tuple((kp_per_effort * e).tolist()), tuple((kd_per_effort * e).tolist())


def robot_meta(config: RobotConfig) -> dict[str, object]:
    """What ``benchharness robots`` lists about a robot, read off its config.

    ``dof``: the distinct joints of its groups (arms, grippers/hands, extra
    groups), i.e. every joint the robot drives; ``groups``: the group names in
    the config's order; ``urdf``: the description, relative to the data root
    when it lies under it. Plugins register this instead of typing the
    figures, so they cannot drift from the robot they describe.
    """
    from ..paths import data_root

    groups = config.groups()
    joints = {j for names in groups.values() for j in names}
    urdf = Path(config.urdf)
    try:
        shown = urdf.resolve().relative_to(data_root().resolve()).as_posix()
    except ValueError:
        shown = str(urdf)
    return {"dof": len(joints), "groups": list(groups), "urdf": shown}
