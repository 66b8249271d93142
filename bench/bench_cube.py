"""Benchmark: applying moves with benchharness.cube vs magiccube (the test oracle).

A script, not a test. Run from the repository root:

    .venv/bin/python bench/bench_cube.py            # defaults: 10,000 sequences × 20 moves
    .venv/bin/python bench/bench_cube.py --sequences 2000 --repeat 3

Cases (each timed ``--repeat`` times, best time reported; inputs prepared
outside the timed region, outputs checked equal between the two libraries):

1. sequences: N random 20-move sequences (face turns), each from solved,
   parsed from text, ending with the 54-letter string. Ours: parse, compose
   into one permutation, apply, format. magiccube: new Cube, rotate(text),
   get_kociemba_facelet_positions().
2. single moves: one move at a time applied to a running state (no
   composition), per-move throughput. Ours: ``state = state[perm]``;
   magiccube: ``cube.rotate([CubeMove])``.
3. batched: the same N sequences as an (N, 20) index array through
   ``apply_batch`` (ours only; magiccube has no batch form, its figure is
   case 1's).
"""

from __future__ import annotations

import argparse
import platform
import random
import time

import numpy as np

from benchharness.cube import (
    ALL_MOVES,
    FACE_MOVES,
    MOVE_PERMUTATIONS,
    SOLVED,
    apply,
    apply_batch,
    to_string,
    to_strings,
)
from benchharness.cube.moves import permutation


def best_of(fn, repeat: int) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--sequences", type=int, default=10_000)
    ap.add_argument("--length", type=int, default=20)
    ap.add_argument("--single-moves", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    import magiccube
    from magiccube.cube_move import CubeMove

    rng = random.Random(args.seed)
    idx = np.array(
        [
            [rng.randrange(len(FACE_MOVES)) for _ in range(args.length)]
            for _ in range(args.sequences)
        ]
    )
    face_index = np.array([m.index for m in FACE_MOVES])
    idx = face_index[idx]
    texts = [" ".join(str(ALL_MOVES[j]) for j in row) for row in idx]

    def ours_sequences():
        return [to_string(apply(SOLVED, t)) for t in texts]

    def magic_sequences():
        out = []
        for t in texts:
            c = magiccube.Cube(3, hist=False)
            c.rotate(t)
            out.append(c.get_kociemba_facelet_positions())
        return out

    t_ours, a = best_of(ours_sequences, args.repeat)
    t_magic, b = best_of(magic_sequences, args.repeat)
    assert a == b, "ours and magiccube disagree"

    t_batch, c = best_of(lambda: to_strings(apply_batch(SOLVED, idx)), args.repeat)
    assert c == a

    n_single = args.single_moves
    singles = [ALL_MOVES[j] for j in idx.reshape(-1)[:n_single]]
    perms = [MOVE_PERMUTATIONS[m.index] for m in singles]
    magic_moves = [CubeMove.create(str(m)) for m in singles]
    n_single = len(singles)

    def ours_single():
        s = SOLVED.copy()
        for p in perms:
            s = s[p]
        return to_string(s)

    def magic_single():
        cube = magiccube.Cube(3, hist=False)
        for m in magic_moves:
            cube.rotate([m])
        return cube.get_kociemba_facelet_positions()

    t_s_ours, x = best_of(ours_single, args.repeat)
    t_s_magic, y = best_of(magic_single, args.repeat)
    assert x == y

    # the composition alone (no state), for reference
    t_compose, _ = best_of(lambda: [permutation(t) for t in texts], args.repeat)

    n, L = args.sequences, args.length
    rows = [
        (f"{n:,} × {L}-move sequences (parse+apply+format)", t_ours, t_magic),
        (f"{n:,} × {L}-move sequences, batched (N, {L}) array", t_batch, t_magic),
        (f"{n_single:,} single moves, one at a time", t_s_ours, t_s_magic),
    ]
    print(
        f"python {platform.python_version()}, numpy {np.__version__}, magiccube 1.2, "
        f"{platform.machine()}, best of {args.repeat}"
    )
    print(f"{'case':<48}{'ours':>12}{'magiccube':>12}{'speed-up':>10}")
    for name, ours, magic in rows:
        print(f"{name:<48}{ours:>11.3f}s{magic:>11.3f}s{magic / ours:>9.0f}×")
    print(f"{'':<48}{'per item':>12}")
    print(
        f"{'sequence (ours, one at a time)':<48}{t_ours / n * 1e6:>10.1f}µs{t_magic / n * 1e6:>10.0f}µs"
    )
    print(f"{'sequence (ours, batched)':<48}{t_batch / n * 1e6:>10.2f}µs")
    print(
        f"{'single move':<48}{t_s_ours / n_single * 1e6:>10.2f}µs{t_s_magic / n_single * 1e6:>10.1f}µs"
    )
    print(f"{'compose only (parse + 20 index ops)':<48}{t_compose / n * 1e6:>10.1f}µs")


if __name__ == "__main__":
    main()
