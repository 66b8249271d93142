"""From measured layer angles to moves: snapping and the layer → move table.

Pure functions, no physics, so they are tested against the cube core alone.

Sign convention: a layer angle is the rotation of an outer slab **relative to
the middle slab**, right-handed about the **+axis** of the body frame, i.e.
exactly the reading of the joints ``layer_0`` and ``layer_2``. A quarter-turn
count ``k`` means ``k × 90°`` in that sense.

A clockwise face turn (seen from outside) is a rotation by -90° about the
face's outward normal, so the face on the +axis side (R, B, U) turns -90°
about +axis and the face on the -axis side (L, F, D) +90°. The slices turn
like their -axis face (M like L, S like F, E like D): the middle slab turns
+90° about +axis, which relative to the middle slab is both outer slabs
turning -90°.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..cube.moves import Move, parse_move
from .model import AXES, AXIS_FACES, AXIS_SLICES

__all__ = [
    "IntendedTwist",
    "SnappedAngle",
    "intended_twist",
    "layer_moves",
    "snap_angle",
]


@dataclass(frozen=True)
class SnappedAngle:
    """One measured angle against the nearest multiple of 90°."""

    angle_deg: float
    quarter_turns: int  #: nearest multiple of 90°, signed (not reduced mod 4)
    residual_deg: float  #: angle - 90·quarter_turns, in [-45, 45]
    within: bool  #: |residual| <= tolerance

    @property
    def snapped_deg(self) -> float:
        return 90.0 * self.quarter_turns


def snap_angle(angle_deg: float, tolerance_deg: float) -> SnappedAngle:
    if not math.isfinite(angle_deg):
        raise ValueError(f"cannot snap a non-finite angle {angle_deg!r}")
    k = int(round(angle_deg / 90.0))
    r = angle_deg - 90.0 * k
    return SnappedAngle(float(angle_deg), k, float(r), abs(r) <= tolerance_deg)


def _face_token(face: str, clockwise_quarters: int) -> str:
    n = clockwise_quarters % 4
    return "" if n == 0 else str(Move(face, n))


def layer_moves(axis: str, quarter_turns_0: int, quarter_turns_2: int) -> str:
    """The face moves that turn slab 0 and slab 2 by the given quarter turns relative to the middle.

    Because the body frame follows the middle slab (see :mod:`.model`), this
    is the whole logical effect of a twist about ``axis``: a slice turn or a
    wide turn appears here as the equivalent outer-face moves (``E`` as
    ``U D'``), which differ from the core's spatial slice move only by the
    whole-cube rotation the body's pose already carries.
    """
    neg, pos = AXIS_FACES[axis]
    tokens = [_face_token(neg, quarter_turns_0), _face_token(pos, -quarter_turns_2)]
    return " ".join(t for t in tokens if t)


@dataclass(frozen=True)
class IntendedTwist:
    """What a single intended move asks of the three slabs."""

    move: str
    axis: str
    quarter_turns: tuple[int, int]  #: expected (slab 0, slab 2) relative to the middle, mod 4
    turning: int  #: the slab meant to turn: 0, 1 (a slice) or 2
    reference: int  #: the outer slab meant to stay still (held)
    angle_deg: float  #: intended rotation of ``turning`` relative to ``reference`` (-90, 90 or 180)


def intended_twist(move: str | Move) -> IntendedTwist:
    """Decode one face or slice move (core notation) into slab terms.

    Whole-cube rotations (``x y z``) are not twists: they change the pose only.
    """
    m = move if isinstance(move, Move) else parse_move(move.strip())
    for axis in AXES:
        neg, pos = AXIS_FACES[axis]
        if m.kind == pos:
            q2 = (-m.turns) % 4
            return IntendedTwist(str(m), axis, (0, q2), 2, 0, _signed(q2))
        if m.kind == neg:
            q0 = m.turns % 4
            return IntendedTwist(str(m), axis, (q0, 0), 0, 2, _signed(q0))
        if m.kind == AXIS_SLICES[axis]:
            q = (-m.turns) % 4
            # the middle turns +turns quarters relative to slab 0
            return IntendedTwist(str(m), axis, (q, q), 1, 0, _signed(m.turns % 4))
    raise ValueError(f"{m} is a whole-cube rotation, not a twist: it changes only the cube's pose")


def _signed(quarters: int) -> float:
    """Quarter turns mod 4 as the signed angle a twist would take: 1 → 90, 2 → 180, 3 → -90."""
    return {0: 0.0, 1: 90.0, 2: 180.0, 3: -90.0}[quarters % 4]
