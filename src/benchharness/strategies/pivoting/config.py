"""Parameters of the parallel-gripper execution (pivoting, DMG plans): every number named, with its default.

One config serves both baselines because they share the physical
primitives (:mod:`.rig`): the object rests on the table, the grasp is
loosened to a light squeeze, the gripper turns about its grasp axis or
slides along the object, and the grasp is tightened again. Defaults are the
values the tests and ``docs/benchmarks/parallel_gripper_sim.md`` use.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

__all__ = [
    "GripConfig",
    "SetupConfig",
    "HoldConfig",
    "MotionConfig",
    "ExecutionConfig",
    "PivotConfig",
]


@dataclass(frozen=True)
class GripConfig:
    """Grip forces and friction.

    ``hold_force`` (N per finger) is the firm grasp (the PR2 gripper
    default, 20 N). ``loose_force_ratio`` sets the light squeeze during a
    pivot or a slide as a fraction of the object's weight, per finger: the
    two pads then drag the object with at most ``2 * mu * ratio * m g``,
    which must stay below the table's friction ``mu_table * m g`` for the
    object to stay put while the fingers move over it, and, applied at the
    grasp height ``h``, below the tipping resistance ``m g b`` (``b``: half
    the base along the push) so that a tall box is not knocked over:
    ``ratio < b / (2 mu h)``. 0.1 (with both coefficients 1.0) leaves a
    factor 5 on sliding and ~3 for the gelatin box gripped 7 cm up on its
    28 x 85 mm face; 0.2 toppled it in one of five DMG trials on PyBullet. ``min_loose_force`` keeps the pads
    in contact on very light objects. Frictions are the static = dynamic
    coefficients given to the object and the table; the finger links use
    the backend's ``default_friction`` (1.0). PyBullet multiplies the two
    bodies' coefficients, PhysX averages them: equal at 1.0.
    """

    hold_force: float = 20.0
    loose_force_ratio: float = 0.1
    min_loose_force: float = 0.05
    object_friction: float = 1.0
    table_friction: float = 1.0
    regrip_time: float = 0.25  #: s the fingers are given to settle after a force change

    def loose_force(self, mass: float, g: float = 9.81) -> float:
        return max(self.min_loose_force, self.loose_force_ratio * mass * g)


@dataclass(frozen=True)
class SetupConfig:
    """How the object is put into the initial grasp.

    The robot grasps the object where it rests on the table; the commanded
    grasp is off the task's by Gaussian set-up noise (``ctx.rng``):
    ``position_std`` (m, each axis of the hand frame; along the closing axis
    it puts the tool frame off the object's mid-plane, and since the fingers
    are symmetric they close onto the mid-plane anyway: an object standing on
    the table tilts, docs/pivoting.md "Symmetric fingers"), ``angle_std`` (deg, about
    the grasp axis). The set-up hand pose is then *measured*, and the runner
    discards the trial if it is more than 10 % off (paper II-B).
    ``approach_clearance`` (m): the pre-grasp stand-off along the approach.
    """

    position_std: float = 0.002
    angle_std: float = 2.0
    approach_clearance: float = 0.03
    settle_time: float = 0.3


@dataclass(frozen=True)
class HoldConfig:
    """The final stability check (paper II-B: constant hand pose for 5 s, no external support).

    After execution the firm grasp lifts the object ``lift_height`` (m) off
    the table and holds it ``hold_time`` (s). The grasp counts as stable if
    the hand pose in the object frame changed by less than
    ``stable_position`` (m) and ``stable_angle`` (deg) over the hold. The
    object counts as **dropped** if a finger lost contact with it, it touched
    the table during the hold, or it moved more than ``drop_distance`` (m)
    from the hand.
    """

    lift_height: float = 0.05
    hold_time: float = 5.0
    stable_position: float = 0.002
    stable_angle: float = 2.0
    drop_distance: float = 0.02


@dataclass(frozen=True)
class MotionConfig:
    """Speeds of the stage and where it may go.

    ``rotation_speed`` (rad/s) and ``translation_speed`` (m/s) are the peak
    speeds of the quintic-timed hand paths; ``min_clearance`` (m) is how far
    every gripper box must stay above the table for a hand pose to be used;
    ``table_height`` (m) is the top of the table (the ground plane).
    ``max_object_turn`` (deg): if the object turns more than this on the
    table while the grasp changes, it has toppled -- counted as a drop.
    ``tracker_position_std`` (m) / ``tracker_angle_std`` (deg): Gaussian noise
    of the object tracker that closes the loop (0: a perfect tracker, as a
    motion-capture system would nearly be).
    """

    rotation_speed: float = 0.5
    translation_speed: float = 0.03
    min_clearance: float = 0.003
    table_height: float = 0.0
    max_object_turn: float = 10.0
    tracker_position_std: float = 0.0
    tracker_angle_std: float = 0.0


@dataclass(frozen=True)
class ExecutionConfig:
    """Everything the table-supported execution needs (shared by pivoting and DMG)."""

    grip: GripConfig = field(default_factory=GripConfig)
    setup: SetupConfig = field(default_factory=SetupConfig)
    hold: HoldConfig = field(default_factory=HoldConfig)
    motion: MotionConfig = field(default_factory=MotionConfig)
    #: object surface resolution (m) for the contact-region geometry (``load_object``)
    resolution: float = 0.003


@dataclass(frozen=True)
class PivotConfig:
    """The pivoting baseline: closed-loop pivots about the grasp axis.

    Each pivot turns the loosened gripper by the remaining error, measured
    on the tracked object; up to ``max_pivots`` pivots are made until the
    error is below ``tolerance`` (deg).
    """

    execution: ExecutionConfig = field(default_factory=ExecutionConfig)
    tolerance: float = 1.0
    max_pivots: int = 3

    @property
    def tolerance_rad(self) -> float:
        return math.radians(self.tolerance)
