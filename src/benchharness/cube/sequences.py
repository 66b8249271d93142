"""The fixed-seed sequence generator (protocol step 2: "acquire the sequence").

Algorithm ``benchharness-rubiks-v1``, stated fully so it can be re-implemented:

1. Per-trial stream. For seed ``s`` (a non-negative integer), tier name ``T``
   (e.g. ``Rubiks-5-20``) and trial number ``k`` (1-based), form the ASCII key
   ``"benchharness-rubiks-v1:{s}:{T}:{k}"`` (``s`` and ``k`` in decimal), hash it
   with FNV-1a-64 and seed a :class:`~benchharness.cube.prng.SplitMix64` with
   the hash. Each trial has its own stream, so trial 3 does not depend on how
   many draws trials 1 and 2 took, and changing the tier changes every trial.
2. Move set: the 18 face turns, in this order:
   ``U U2 U' R R2 R' F F2 F' D D2 D' L L2 L' B B2 B'``. Slice moves and rotations
   are never generated (a robot may use them, but the prescribed sequence is
   face turns).
3. Rules. A candidate move is *allowed* unless (a) it turns the same face as
   the previous move, or (b) the previous two moves turned the two opposite
   faces of one axis (e.g. ``U D`` or ``D U``) and the candidate turns a face
   of that axis too. (a) removes ``U U`` (= ``U2``); (b) removes ``U D U``
   (= ``U2 D``, since opposite faces commute). Both orders ``U D`` and ``D U``
   stay possible: the robot executes the sequence literally, so they are
   different tasks even though they reach the same state.
4. Each move: list the allowed moves in the order of step 2 (15 of them, or 12
   after rule (b) applies) and pick index ``below(len(allowed))`` — one uniform
   draw by rejection sampling, see :mod:`benchharness.cube.prng`.
5. Distinct trials. If trial ``k``'s sequence equals the sequence of an earlier
   trial of the same tier and seed, draw a fresh N-move sequence from the same
   stream (rules restart) until it differs.
"""

from __future__ import annotations

from .moves import FACE_MOVES, Move
from .prng import SplitMix64, fnv1a_64

ALGORITHM = "benchharness-rubiks-v1"

#: The generator's move set, in the order of step 2 of the module docstring.
GENERATED_MOVES: tuple[Move, ...] = FACE_MOVES
_AXIS = {"U": 0, "D": 0, "R": 1, "L": 1, "F": 2, "B": 2}


def trial_key(seed: int, tier: str, trial: int) -> str:
    return f"{ALGORITHM}:{seed}:{tier}:{trial}"


def _allowed(prev1: Move | None, prev2: Move | None) -> list[Move]:
    out = []
    for m in GENERATED_MOVES:
        if prev1 is not None and m.kind == prev1.kind:
            continue
        if (
            prev1 is not None
            and prev2 is not None
            and _AXIS[prev1.kind] == _AXIS[prev2.kind]
            and _AXIS[m.kind] == _AXIS[prev1.kind]
        ):
            continue
        out.append(m)
    return out


def _draw(rng: SplitMix64, n_moves: int) -> tuple[Move, ...]:
    seq: list[Move] = []
    for _ in range(n_moves):
        prev1 = seq[-1] if seq else None
        prev2 = seq[-2] if len(seq) > 1 else None
        allowed = _allowed(prev1, prev2)
        seq.append(allowed[rng.below(len(allowed))])
    return tuple(seq)


def _check(seed: int, n_moves: int) -> None:
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    if n_moves < 1:
        raise ValueError(f"a sequence needs at least one move, got {n_moves}")


def count_sequences(n_moves: int) -> int:
    """How many distinct sequences of ``n_moves`` the rules allow (18, 270, 3888, 56376, ...)."""
    # state: (last face, were the last two moves on one axis?) -> number of sequences
    counts = {(m.kind, False): 0 for m in GENERATED_MOVES}
    for m in GENERATED_MOVES:
        counts[(m.kind, False)] += 1
    for _ in range(n_moves - 1):
        nxt: dict[tuple[str, bool], int] = {}
        for (face, same_axis), c in counts.items():
            for g in "URFDLB":
                if g == face or (same_axis and _AXIS[g] == _AXIS[face]):
                    continue
                key = (g, _AXIS[g] == _AXIS[face])
                nxt[key] = nxt.get(key, 0) + 3 * c
        counts = nxt
    return sum(counts.values())


def generate_sequences(seed: int, tier: str, trials: int, n_moves: int) -> list[tuple[Move, ...]]:
    """All ``trials`` sequences of a tier, pairwise distinct (trial 1 first)."""
    _check(seed, n_moves)
    if n_moves < 8 and trials > count_sequences(n_moves):  # from 8 moves on there are > 10^9
        raise ValueError(f"only {count_sequences(n_moves)} distinct {n_moves}-move sequences exist")
    out: list[tuple[Move, ...]] = []
    for k in range(1, trials + 1):
        rng = SplitMix64(fnv1a_64(trial_key(seed, tier, k)))
        seq = _draw(rng, n_moves)
        while seq in out:
            seq = _draw(rng, n_moves)
        out.append(seq)
    return out


def generate_sequence(seed: int, tier: str, trial: int, n_moves: int) -> tuple[Move, ...]:
    """The sequence of one trial (1-based), identical to that trial's row of :func:`generate_sequences`."""
    if trial < 1:
        raise ValueError(f"trials are numbered from 1, got {trial}")
    return generate_sequences(seed, tier, trial, n_moves)[-1]
