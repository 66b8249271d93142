"""Typed parameters of the physical Rubik's cube, each with its default and why.

The figures come from the spike recorded in docs/benchmarks/cube_spike.md:
they made a 90° twist held by 20 N-per-finger grippers with pad friction 1.0
come out right on PyBullet and SAPIEN at 1/240 s. Everything a twist's outcome
depends on is here so a sweep can vary it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class CubeConfig:
    """Geometry, mass and mechanism of the axis-articulated cube.

    Torques are N·m, angles degrees unless a name says otherwise.
    """

    #: Edge length (m). A standard 3×3 cube is 57 mm; a cubie (and a slab) is a third.
    edge: float = 0.057
    #: Total mass (kg), split equally over the three slabs while articulated.
    mass: float = 0.094
    #: Coulomb friction coefficient of the cube's outer surface. 1.0 is what the
    #: spike used for pads; backends combine it with the pad's own coefficient.
    surface_friction: float = 1.0
    #: Friction torque of each layer joint. 0.02 N·m is the spike's figure: small
    #: next to what two 20 N pads transmit (~0.5 N·m), large enough that a free
    #: layer is carried along by its neighbour's motion rather than floating.
    joint_friction: float = 0.02
    #: Tie-break for the under-constrained grasp (see docs/cube_physics.md). When
    #: the caller names the intended face turn, the joint next to the turning
    #: layer gets ``joint_friction * (1 + drag_bias)`` and the far joint
    #: ``joint_friction * (1 - drag_bias)``, so a free middle slab follows the
    #: turning layer (the paper's Fig. 2 middle row). 0 keeps both equal.
    drag_bias: float = 0.5
    #: Extra holding torque of the detent at a multiple of 90°. It is added to the
    #: friction cap of the joint drive; 0.01 N·m keeps the total resistance a turn
    #: must beat (≤ 0.04 N·m) two orders of magnitude below the 3 N·m wrist limit
    #: and an order below what the pads transmit, so it never decides a grasped turn.
    detent_torque: float = 0.01
    #: Angle (deg) over which the detent spring rises to its full pull
    #: (``joint friction + detent_torque``); beyond it the pull is constant.
    #: Stiffness = cap / this angle (≈ 0.2 N·m/rad for the defaults).
    detent_ramp_deg: float = 8.0
    #: Relative joint speed (rad/s) above which the joint's friction is fully
    #: developed. The engines' drives are spring-dampers, so Coulomb friction is
    #: a damper saturated at its cap; 0.5 rad/s (29°/s) is well below a twist's
    #: ~90°/s yet gives a loose layer ~0.3 s to settle into its detent.
    friction_saturation_speed: float = 0.5
    #: A layer within this many degrees of a multiple of 90° snaps when the twist
    #: ends. 15° is within the corner-cutting range of a real cube (a layer this
    #: far off still re-aligns under the next twist); beyond it the cube stays
    #: misaligned and blocks twists about other axes.
    snap_tolerance_deg: float = 15.0
    #: An intended layer that turned less than this (deg) counts as jammed.
    jam_threshold_deg: float = 45.0

    def __post_init__(self) -> None:
        positive = {
            "edge": self.edge,
            "mass": self.mass,
            "detent_ramp_deg": self.detent_ramp_deg,
            "friction_saturation_speed": self.friction_saturation_speed,
            "snap_tolerance_deg": self.snap_tolerance_deg,
            "jam_threshold_deg": self.jam_threshold_deg,
        }
        for name, value in positive.items():
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"CubeConfig.{name} must be positive and finite, got {value!r}")
        for name in ("surface_friction", "joint_friction", "detent_torque"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"CubeConfig.{name} must be >= 0, got {value!r}")
        if not 0.0 <= self.drag_bias < 1.0:
            raise ValueError(f"CubeConfig.drag_bias must be in [0, 1), got {self.drag_bias!r}")
        if self.snap_tolerance_deg >= 45.0:
            raise ValueError(
                "CubeConfig.snap_tolerance_deg must be below 45° or snapping is ambiguous"
            )

    @property
    def slab_thickness(self) -> float:
        """Thickness of one layer along its twist axis (m)."""
        return self.edge / 3.0

    @property
    def slab_mass(self) -> float:
        return self.mass / 3.0

    def joint_frictions(self, turning_slab: int | None) -> tuple[float, float]:
        """Friction torques of the joints to slab 0 and slab 2 (N·m).

        ``turning_slab`` is the outer slab (0 or 2) the caller means to turn,
        or ``None`` (no intention, or a slice move): both joints equal.
        """
        f = self.joint_friction
        if turning_slab is None or self.drag_bias == 0.0:
            return (f, f)
        hi, lo = f * (1.0 + self.drag_bias), f * (1.0 - self.drag_bias)
        return (hi, lo) if turning_slab == 0 else (lo, hi)

    def drive_cap(self, friction: float) -> float:
        """Cap of a joint's drive: its friction plus the detent's holding torque."""
        return friction + self.detent_torque

    def drive_gains(self, friction: float) -> tuple[float, float]:
        """(stiffness N·m/rad, damping N·m·s/rad) of a joint's detent-friction drive."""
        cap = self.drive_cap(friction)
        return cap / math.radians(self.detent_ramp_deg), cap / self.friction_saturation_speed
