"""Move notation, move permutations derived from geometry, and fast application.

Notation (Singmaster/WCA):

* face turns ``U D L R F B``: a clockwise quarter turn of that outer layer as
  seen looking at the face from outside;
* slice moves ``M`` (the layer between L and R, turning like ``L``), ``E``
  (between U and D, turning like ``D``) and ``S`` (between F and B, turning like
  ``F``);
* whole-cube rotations ``x`` (like ``R``), ``y`` (like ``U``), ``z`` (like ``F``).

Suffixes: none (quarter turn), ``'`` (counter-clockwise quarter turn), ``2``
(half turn). Parsing is lenient where the meaning is unambiguous: tokens are
separated by any whitespace; the typographic apostrophe ``’``, the prime
``′`` and the acute accent ``´`` read as ``'``; ``2'`` and ``'2`` read as ``2``
(a half turn is its own inverse, and some solvers print it so); ``X Y Z`` read
as ``x y z``. Anything else is rejected, naming the token and its 1-based
position — in particular ``3`` suffixes (write ``'``), wide moves (``Rw``,
lowercase ``r``) and unspaced runs such as ``RUR'U'``, because guessing what
those meant could silently change the prescribed sequence.

Permutation convention: a move is a ``numpy.intp`` array ``p`` of shape (54,)
such that ``new = old[..., p]``; ``p[j]`` is the position the facelet now at
``j`` came from. Applying ``a`` then ``b`` is the single permutation
``a[b]``, so a whole sequence is composed into one permutation before it
touches any state; a batch of states is permuted with one fancy index, and
many sequences at once go through :func:`apply_batch`, two moves per pass.

Moves act *spatially*: slice moves and rotations carry the centres with them,
exactly like turning a physical cube in a fixed frame. :func:`reorient`
brings a state back to the held orientation of the exchange format (the
U-coloured centre up, the F-coloured centre in front) — see its docstring.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .facelets import CENTRE_INDICES, FACE_NORMALS, FACELET_CUBIES, FACELET_POSITIONS

#: The move letters: 6 face turns, 3 slices, 3 whole-cube rotations.
KINDS = "URFDLBMESxyz"
FACE_KINDS = "URFDLB"

# Which face each kind turns like, and which layer (cubie · normal) it moves;
# ``None`` means every layer (a whole-cube rotation).
_TURNS_LIKE = {"M": "L", "E": "D", "S": "F", "x": "R", "y": "U", "z": "F"}
_LAYER: dict[str, int | None] = {
    **{f: 1 for f in FACE_KINDS},
    "M": 0,
    "E": 0,
    "S": 0,
    "x": None,
    "y": None,
    "z": None,
}

_SUFFIX = {1: "", 2: "2", 3: "'"}
_KIND_POSITION = {k: i for i, k in enumerate(KINDS)}
EXPECTED_TOKENS = "U D L R F B M E S x y z with optional ' or 2"


class MoveError(ValueError):
    """An unknown token in a move sequence; says which and where (1-based)."""

    def __init__(self, token: str, position: int) -> None:
        self.token = token
        self.position = position
        super().__init__(
            f'unknown move "{token}" at position {position} (expected {EXPECTED_TOKENS})'
        )


@dataclass(frozen=True, order=True)
class Move:
    """One move: a kind from :data:`KINDS` and 1, 2 or 3 clockwise quarter turns."""

    kind: str
    turns: int

    def __post_init__(self) -> None:
        if self.kind not in KINDS or self.turns not in (1, 2, 3):
            raise ValueError(f"no move {self.kind!r} × {self.turns}")

    @property
    def index(self) -> int:
        """Row of :data:`MOVE_PERMUTATIONS` (kind-major, then 1, 2, 3 turns)."""
        return 3 * _KIND_POSITION[self.kind] + self.turns - 1

    def inverse(self) -> Move:
        return Move(self.kind, 4 - self.turns)

    def __str__(self) -> str:
        return self.kind + _SUFFIX[self.turns]


#: All 36 moves, in :attr:`Move.index` order.
ALL_MOVES: tuple[Move, ...] = tuple(Move(k, t) for k in KINDS for t in (1, 2, 3))
#: The 18 face turns (the moves the sequence generator draws from), in URFDLB order.
FACE_MOVES: tuple[Move, ...] = tuple(m for m in ALL_MOVES if m.kind in FACE_KINDS)

_CANONICAL_TOKENS = {str(m): m for m in ALL_MOVES}
_APOSTROPHES = str.maketrans({"\u2019": "'", "\u2032": "'", "\u00b4": "'"})
_TOKEN_RE = re.compile(r"^([URFDLBMESxyzXYZ])(|'|2|2'|'2)$")


def _quarter_turn_matrix(normal: tuple[int, int, int]) -> np.ndarray:
    """Rotation by -90° about ``normal``: clockwise seen from the tip of the normal."""
    n = np.array(normal, dtype=np.int64)
    cross = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    return -cross + np.outer(n, n)  # cos(-90°) = 0, sin(-90°) = -1


def _quarter_turn_permutation(kind: str) -> np.ndarray:
    face = _TURNS_LIKE.get(kind, kind)
    normal = FACE_NORMALS[face]
    rot = _quarter_turn_matrix(normal)
    layer = _LAYER[kind]
    depth = FACELET_CUBIES @ np.array(normal)
    moving = np.ones(54, dtype=bool) if layer is None else depth == layer
    lookup = {tuple(p): i for i, p in enumerate(FACELET_POSITIONS.tolist())}
    perm = np.arange(54, dtype=np.intp)
    # The sticker at p goes to rot @ p, so the one now at q came from rot.T @ q.
    for j in np.flatnonzero(moving):
        perm[j] = lookup[tuple((rot.T @ FACELET_POSITIONS[j]).tolist())]
    return perm


def _build_permutations() -> np.ndarray:
    out = np.empty((len(ALL_MOVES), 54), dtype=np.intp)
    for k, kind in enumerate(KINDS):
        q = _quarter_turn_permutation(kind)
        p = np.arange(54, dtype=np.intp)
        for t in range(3):
            p = p[q]
            out[3 * k + t] = p
    out.setflags(write=False)
    return out


#: Shape (36, 54): the permutation of every move, indexed by :attr:`Move.index`.
MOVE_PERMUTATIONS: np.ndarray = _build_permutations()
IDENTITY = np.arange(54, dtype=np.intp)
IDENTITY.setflags(write=False)
_ROWS = tuple(MOVE_PERMUTATIONS)  # row views: cheaper to fetch than 2-D indexing


def parse_move(token: str, position: int = 1) -> Move:
    """Parse one token (see the module docstring for what is accepted)."""
    move = _CANONICAL_TOKENS.get(token)
    if move is not None:
        return move
    m = _TOKEN_RE.match(token.translate(_APOSTROPHES))
    if m is None:
        raise MoveError(token, position)
    letter, suffix = m.groups()
    kind = letter.lower() if letter in "XYZ" else letter
    turns = 1 if suffix == "" else 3 if suffix == "'" else 2
    return Move(kind, turns)


def parse_sequence(text: str | Iterable[str]) -> tuple[Move, ...]:
    """Parse a whitespace-separated sequence (or an iterable of tokens)."""
    tokens = text.split() if isinstance(text, str) else list(text)
    return tuple(parse_move(tok, i) for i, tok in enumerate(tokens, start=1))


def format_sequence(moves: Iterable[Move]) -> str:
    return " ".join(str(m) for m in moves)


def _as_moves(moves: str | Iterable[Move | str]) -> tuple[Move, ...]:
    if isinstance(moves, str):
        return parse_sequence(moves)
    out = []
    for i, m in enumerate(moves, start=1):
        out.append(m if isinstance(m, Move) else parse_move(m, i))
    return tuple(out)


def invert(moves: str | Iterable[Move | str]) -> tuple[Move, ...]:
    """The sequence that undoes ``moves``: reversed, each move inverted."""
    return tuple(m.inverse() for m in reversed(_as_moves(moves)))


def permutation(moves: str | Iterable[Move | str]) -> np.ndarray:
    """Compose a whole sequence into one (54,) permutation."""
    perm = IDENTITY
    for m in _as_moves(moves):
        perm = perm.take(_ROWS[m.index])  # ndarray.take: less overhead than p[q] on 54 items
    return perm


def apply(state: np.ndarray, moves: str | Iterable[Move | str]) -> np.ndarray:
    """Apply a sequence to one state (54,) or a batch (n, 54); returns a new array."""
    return np.asarray(state)[..., permutation(moves)]


@lru_cache(maxsize=1)
def _pair_table() -> np.ndarray:
    """Every ordered pair of moves composed, (36·36, 54): halves the batched steps."""
    n = len(ALL_MOVES)
    # pair[a, b, j] = P[a][P[b]][j] = P[a, P[b, j]]: move a, then move b
    pairs = MOVE_PERMUTATIONS[np.arange(n)[:, None, None], MOVE_PERMUTATIONS[None, :, :]]
    return pairs.reshape(n * n, 54)


_CHUNK = 16384  # rows per pass: bounds the (rows, 54) index temporaries to a few MB


def _permute_rows(data: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Row ``i`` of ``data`` through the moves in row ``i`` of ``idx``, two moves per pass.

    Each pass is one flat gather: the per-row permutations plus row offsets
    index the flattened data. Doing it on the (small-dtype) data itself and two
    moves at a time is what makes the batch several times faster per sequence
    than the one-at-a-time path.
    """
    n, length = idx.shape
    if n > _CHUNK:
        return np.concatenate(
            [_permute_rows(data[i : i + _CHUNK], idx[i : i + _CHUNK]) for i in range(0, n, _CHUNK)]
        )
    data = np.ascontiguousarray(data)
    off = (54 * np.arange(n, dtype=np.intp))[:, None]
    pairs = _pair_table()
    k = 0
    while k + 1 < length:
        gather = pairs[idx[:, k] * len(ALL_MOVES) + idx[:, k + 1]]
        gather += off
        data = data.ravel()[gather]
        k += 2
    if k < length:
        gather = MOVE_PERMUTATIONS[idx[:, k]]
        gather += off
        data = data.ravel()[gather]
    return data


def _check_indices(move_indices: np.ndarray) -> np.ndarray:
    idx = np.asarray(move_indices, dtype=np.intp)
    if idx.ndim != 2:
        raise ValueError("move_indices must have shape (n, L)")
    if idx.size and (idx.min() < 0 or idx.max() >= len(ALL_MOVES)):
        raise ValueError(f"move indices must be in 0..{len(ALL_MOVES) - 1}")
    return idx


def permutations_batch(move_indices: np.ndarray) -> np.ndarray:
    """Compose many equal-length sequences at once.

    ``move_indices`` is an integer array (n, L) of :attr:`Move.index` values;
    the result is (n, 54), one composed permutation per row, vectorised over
    rows (about L/2 array operations, not n·L).
    """
    idx = _check_indices(move_indices)
    return _permute_rows(np.broadcast_to(IDENTITY, (idx.shape[0], 54)), idx)


def apply_batch(states: np.ndarray, move_indices: np.ndarray) -> np.ndarray:
    """Apply sequence ``i`` (row ``i`` of ``move_indices``) to state ``i``.

    ``states`` is (n, 54), or one (54,) state used for every row.
    """
    idx = _check_indices(move_indices)
    states = np.asarray(states)
    if states.ndim == 1:
        states = np.broadcast_to(states, (idx.shape[0], 54))
    if states.shape != (idx.shape[0], 54):
        raise ValueError(f"states has shape {states.shape}, expected ({idx.shape[0]}, 54)")
    return _permute_rows(states, idx)


def indices(moves: Sequence[Move]) -> np.ndarray:
    return np.fromiter((m.index for m in moves), dtype=np.intp, count=len(moves))


def order(moves: str | Iterable[Move | str]) -> int:
    """How many times the sequence must be repeated to return to the start."""
    p = permutation(moves)
    q, n = p, 1
    while not np.array_equal(q, IDENTITY):
        q, n = q[p], n + 1
    return n


def _build_rotations() -> dict[tuple[int, ...], np.ndarray]:
    """The 24 whole-cube rotations, keyed by where they take the centres from."""
    gens = [MOVE_PERMUTATIONS[Move(k, 1).index] for k in "xyz"]
    found = {tuple(IDENTITY.tolist()): IDENTITY}
    frontier = [IDENTITY]
    while frontier:
        nxt = []
        for p in frontier:
            for g in gens:
                q = p[g]
                key = tuple(q.tolist())
                if key not in found:
                    found[key] = q
                    nxt.append(q)
        frontier = nxt
    assert len(found) == 24, len(found)
    return {tuple(p[CENTRE_INDICES].tolist()): p for p in found.values()}


_ROTATIONS = _build_rotations()


def reorient(state: np.ndarray) -> np.ndarray:
    """Turn the whole cube so its centres read URFDLB again.

    A person reading a cube into the exchange format holds it with the
    U-coloured centre up and the F-coloured centre in front; the robot's grasp
    at termination is not part of the protocol. After slice moves or rotations
    the spatial state has its centres elsewhere, so this applies the one
    whole-cube rotation (of 24) that restores them: the result is the string a
    person would read. Only centres are looked at; a state whose centres are
    not a rotation of the solved centres raises ``ValueError``.
    """
    state = np.asarray(state)
    if state.ndim == 2:
        return np.stack([reorient(s) for s in state]) if len(state) else state.copy()
    centres = state[CENTRE_INDICES]
    # The rotation r with state[r][centres] == 0..5 takes from the positions
    # where each colour's centre now sits.
    where = np.empty(6, dtype=np.intp)
    where[centres] = CENTRE_INDICES
    if sorted(centres.tolist()) != list(range(6)):
        raise ValueError("centres are not six distinct colours")
    rot = _ROTATIONS.get(tuple(where.tolist()))
    if rot is None:
        raise ValueError("centres are not in a rotation of the standard arrangement")
    return state[rot]
