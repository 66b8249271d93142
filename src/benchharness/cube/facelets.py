"""The 54-facelet layout: names, 3-D geometry, and the string exchange format.

The exchange format is Kociemba's: 54 letters in URFDLB face order, each face
read row by row as printed on the usual net (U and D seen from above/below with
F towards the bottom/top of the net, the four side faces seen from outside with
U at the top). A letter names the face whose *centre* has that colour, so the
solved cube is ``UUUUUUUUURRRRRRRRRFFFFFFFFFDDDDDDDDDLLLLLLLLLBBBBBBBBB``.

Internally a state is a ``numpy.uint8`` array of shape ``(54,)`` (or ``(n, 54)``
for a batch) holding colour codes 0..5 in URFDLB order. Index ``i`` of the array
is the facelet *position* ``FACELET_NAMES[i]``.

Every facelet also has a 3-D position so that move permutations can be derived
by rotating coordinates (see :mod:`benchharness.cube.moves`) instead of being
typed in by hand. Axes: +x points to R, +y to U, +z to F; a sticker's
coordinates are ``2 * cubie + normal`` with cubie coordinates in {-1, 0, 1},
so every sticker has integer coordinates and a unique position.
"""

from __future__ import annotations

import numpy as np

#: Face letters in Kociemba order; also the colour codes 0..5.
FACES = "URFDLB"
FACE_INDEX = {f: i for i, f in enumerate(FACES)}

#: Outward normal of each face (x → R, y → U, z → F).
FACE_NORMALS: dict[str, tuple[int, int, int]] = {
    "U": (0, 1, 0),
    "R": (1, 0, 0),
    "F": (0, 0, 1),
    "D": (0, -1, 0),
    "L": (-1, 0, 0),
    "B": (0, 0, -1),
}

#: ``U1`` … ``B9``: the name of each of the 54 positions, in string order.
FACELET_NAMES: tuple[str, ...] = tuple(f"{f}{k}" for f in FACES for k in range(1, 10))
FACELET_INDEX = {name: i for i, name in enumerate(FACELET_NAMES)}

#: Indices of the six centres (U5, R5, F5, D5, L5, B5).
CENTRE_INDICES = np.array([9 * f + 4 for f in range(6)], dtype=np.intp)

SOLVED_STRING = "".join(f * 9 for f in FACES)

_LETTERS = np.frombuffer(FACES.encode("ascii"), dtype=np.uint8)
# ASCII byte -> colour code; 255 marks "not a face letter".
_DECODE = np.full(256, 255, dtype=np.uint8)
for _i, _f in enumerate(FACES):
    _DECODE[ord(_f)] = _i


def _cubie_of(face: str, row: int, col: int) -> tuple[int, int, int]:
    """Cubie coordinates of the facelet at (row, col) of ``face`` on the net."""
    a, b = col - 1, row - 1  # -1..1 across, -1..1 down
    if face == "U":
        return (a, 1, b)  # row 0 is the back edge
    if face == "D":
        return (a, -1, -b)  # row 0 is the front edge
    if face == "F":
        return (a, -b, 1)
    if face == "B":
        return (-a, -b, -1)  # seen from behind, left is +x
    if face == "R":
        return (1, -b, -a)  # seen from the right, left is +z
    if face == "L":
        return (-1, -b, a)  # seen from the left, left is -z
    raise ValueError(face)


def _positions() -> np.ndarray:
    out = np.empty((54, 3), dtype=np.int64)
    for i, name in enumerate(FACELET_NAMES):
        face, k = name[0], int(name[1]) - 1
        cubie = np.array(_cubie_of(face, k // 3, k % 3))
        out[i] = 2 * cubie + np.array(FACE_NORMALS[face])
    return out


#: Sticker coordinates, shape (54, 3), integers in -3..3 (see module docstring).
FACELET_POSITIONS: np.ndarray = _positions()
#: Cubie coordinates of each facelet, shape (54, 3), integers in -1..1.
FACELET_CUBIES: np.ndarray = np.sign(FACELET_POSITIONS) * (np.abs(FACELET_POSITIONS) >= 2)

SOLVED: np.ndarray = np.repeat(np.arange(6, dtype=np.uint8), 9)
SOLVED.setflags(write=False)


def to_array(facelets: str) -> np.ndarray:
    """Decode a 54-letter string into a colour-code array, without validation.

    Raises ``ValueError`` only for a wrong length or a non-URFDLB character;
    whether the string is a reachable cube is :func:`~benchharness.cube.validation.check_facelets`'s
    business.
    """
    raw = np.frombuffer(facelets.encode("ascii", errors="replace"), dtype=np.uint8)
    if raw.size != 54:
        raise ValueError(f"expected 54 facelets, got {len(facelets)}")
    codes = _DECODE[raw]
    if (codes == 255).any():
        i = int(np.argmax(codes == 255))
        raise ValueError(f"invalid character {facelets[i]!r} at {FACELET_NAMES[i]}")
    return codes


def to_string(state: np.ndarray) -> str:
    """Encode one state (54,) as its 54-letter string."""
    return _LETTERS[np.asarray(state, dtype=np.intp)].tobytes().decode("ascii")


def to_strings(states: np.ndarray) -> list[str]:
    """Encode a batch (n, 54) of states as strings."""
    blob = _LETTERS[np.asarray(states, dtype=np.intp)].tobytes().decode("ascii")
    return [blob[i : i + 54] for i in range(0, len(blob), 54)]
