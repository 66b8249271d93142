"""From the prescribed notation to the face twists a pair of grippers can make.

The cube core applies moves *spatially*: after ``x`` or ``M`` the letter ``U``
names whatever layer is now on top, which carries another centre. A robot,
however, can only turn an outer slab against the other two (two grippers
cannot hold both outer slabs apart from the middle), and a face is best named
by its centre colour, which no twist moves. So every input move is rewritten
as twists of **centre-named faces** (the frame of the exchange format,
:func:`benchharness.cube.reorient`):

* a face turn ``U`` turns the face whose centre sits at the spatial ``U``
  position now;
* a slice is two opposite face turns plus a change of frame, by the core's own
  identities ``M = R L' x'``, ``E = U D' y'``, ``S = F' B z`` (checked against
  :func:`benchharness.cube.apply` in the tests); the two face turns commute, so
  both orders are offered and the search picks the cheaper;
* a whole-cube rotation ``x y z`` needs no twist: it only changes which centre
  later letters name. The robot does not have to turn the cube for it, because
  the protocol reads the final state with the centres in place.

Which centre sits where is tracked by applying the frame moves to the solved
cube with the core and reading the centres, so this module holds no move
tables of its own beyond the three slice identities.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from ...cube import SOLVED, Move, apply, parse_move, parse_sequence
from ...cube.facelets import CENTRE_INDICES, FACE_INDEX, FACES

__all__ = ["FaceTwist", "MoveTwists", "logical_twists"]

#: Slice kind → (face, sign), (face, sign), (rotation, sign): ``K^k = F1^(s1 k) F2^(s2 k) r^(s3 k)``.
_SLICE_IDENTITIES: dict[str, tuple[tuple[str, int], tuple[str, int], tuple[str, int]]] = {
    "M": (("R", 1), ("L", -1), ("x", -1)),
    "E": (("U", 1), ("D", -1), ("y", -1)),
    "S": (("F", -1), ("B", 1), ("z", 1)),
}


@dataclass(frozen=True)
class FaceTwist:
    """One clockwise-quarter-turn count of a centre-named outer face, and the input move it serves."""

    face: str  #: U R F D L B, named by centre colour
    turns: int  #: clockwise quarter turns seen from outside the face, 1..3
    source: int  #: 0-based index of the input move

    @property
    def move(self) -> Move:
        return Move(self.face, self.turns)

    @property
    def axis_faces(self) -> frozenset[str]:
        """The face and its opposite: twists on the same axis share a work axis."""
        return frozenset((self.face, _OPPOSITE[self.face]))


_OPPOSITE = {"U": "D", "D": "U", "R": "L", "L": "R", "F": "B", "B": "F"}


@dataclass(frozen=True)
class MoveTwists:
    """The twists that realise one input move; ``alternatives`` are equivalent orders."""

    token: str
    source: int
    alternatives: tuple[tuple[FaceTwist, ...], ...]  #: one empty tuple for a rotation


def _centre_at(frame_state, spatial_face: str) -> str:
    return FACES[int(frame_state[CENTRE_INDICES[FACE_INDEX[spatial_face]]])]


def logical_twists(moves: str | Iterable[Move | str]) -> tuple[MoveTwists, ...]:
    """Rewrite a move sequence (any core notation) as centre-named face twists."""
    seq = (
        parse_sequence(moves)
        if isinstance(moves, str)
        else tuple(
            m if isinstance(m, Move) else parse_move(m, i) for i, m in enumerate(moves, start=1)
        )
    )
    frame = (
        SOLVED  # the solved cube carried through every frame change: its centres say who is where
    )
    out: list[MoveTwists] = []
    for i, m in enumerate(seq):
        if m.kind in "URFDLB":
            twist = FaceTwist(_centre_at(frame, m.kind), m.turns, i)
            out.append(MoveTwists(str(m), i, ((twist,),)))
        elif m.kind in _SLICE_IDENTITIES:
            (f1, s1), (f2, s2), (rot, s3) = _SLICE_IDENTITIES[m.kind]
            a = FaceTwist(_centre_at(frame, f1), (s1 * m.turns) % 4, i)
            b = FaceTwist(_centre_at(frame, f2), (s2 * m.turns) % 4, i)
            out.append(MoveTwists(str(m), i, ((a, b), (b, a))))
            frame = apply(frame, [Move(rot, (s3 * m.turns) % 4)])
        else:
            out.append(MoveTwists(str(m), i, ((),)))
            frame = apply(frame, [m])
    return tuple(out)
