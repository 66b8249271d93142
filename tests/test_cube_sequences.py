"""The fixed-seed generator: known answers, the documented rules, determinism."""

from __future__ import annotations

import pytest

from benchharness.cube import (
    format_sequence,
    generate_sequence,
    generate_sequences,
    get_tier,
    load_tiers,
)
from benchharness.cube.prng import SplitMix64, fnv1a_64
from benchharness.cube.sequences import GENERATED_MOVES, trial_key

AXIS = {"U": 0, "D": 0, "R": 1, "L": 1, "F": 2, "B": 2}


# -- primitives against published reference values ------------------------------------


def test_splitmix64_reference_outputs():
    # Reference output of Vigna's splitmix64.c for seed 1234567.
    g = SplitMix64(1234567)
    assert [g.next_u64() for _ in range(5)] == [
        6457827717110365317,
        3203168211198807973,
        9817491932198370423,
        4593380528125082431,
        16408922859458223821,
    ]


def test_fnv1a_64_reference_values():
    # From the FNV reference test vectors (Fowler/Noll/Vo).
    assert fnv1a_64("") == 0xCBF29CE484222325
    assert fnv1a_64("a") == 0xAF63DC4C8601EC8C
    assert fnv1a_64("foobar") == 0x85944171F73967E8


def test_below_is_in_range_and_rejects_the_biased_tail():
    g = SplitMix64(1)
    assert all(0 <= g.below(15) < 15 for _ in range(1000))
    assert g.below(1) == 0

    class Fixed(SplitMix64):
        """Feeds chosen words: the first lies in the biased tail for n = 3."""

        def __init__(self, words):
            super().__init__(0)
            self.words = list(words)

        def next_u64(self):
            return self.words.pop(0)

    top = (1 << 64) - 1  # 2**64 - 1 >= 2**64 - (2**64 % 3) -> rejected
    assert Fixed([top, 10]).below(3) == 1
    with pytest.raises(ValueError):
        SplitMix64(-1)


# -- an independent implementation, written from docs/rubiks.md --------------------------


def reference_generator(seed: int, tier: str, trials: int, n: int) -> list[list[str]]:
    faces = "URFDLB"
    moves = [f + s for f in faces for s in ("", "2", "'")]
    mask = (1 << 64) - 1

    def stream(key: str):
        h = 0xCBF29CE484222325
        for b in key.encode():
            h = ((h ^ b) * 0x100000001B3) & mask
        state = h
        while True:
            state = (state + 0x9E3779B97F4A7C15) & mask
            z = state
            z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & mask
            z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & mask
            yield z ^ (z >> 31)

    def uniform(words, k):
        limit = (1 << 64) - (1 << 64) % k
        for w in words:
            if w < limit:
                return w % k

    def one(words):
        seq: list[str] = []
        for _ in range(n):
            ok = []
            for m in moves:
                if seq and m[0] == seq[-1][0]:
                    continue
                if len(seq) > 1 and AXIS[seq[-1][0]] == AXIS[seq[-2][0]] == AXIS[m[0]]:
                    continue
                ok.append(m)
            seq.append(ok[uniform(words, len(ok))])
        return seq

    out: list[list[str]] = []
    for k in range(1, trials + 1):
        words = stream(f"benchharness-rubiks-v1:{seed}:{tier}:{k}")
        seq = one(words)
        while seq in out:
            seq = one(words)
        out.append(seq)
    return out


@pytest.mark.parametrize("seed", [0, 1, 7, 2**63 + 5])
@pytest.mark.parametrize("tier", ["Rubiks-1-5", "Rubiks-5-20", "Rubiks-5-200"])
def test_matches_the_documented_algorithm(seed, tier):
    t = get_tier(tier)
    got = [[str(m) for m in s] for s in t.sequences(seed)]
    assert got == reference_generator(seed, tier, t.trials, t.moves)


# -- known answers (pinned: a change here changes every published sequence) ---------------


def test_known_answers():
    assert trial_key(7, "Rubiks-5-20", 3) == "benchharness-rubiks-v1:7:Rubiks-5-20:3"
    assert [format_sequence(s) for s in get_tier("Rubiks-5-20").sequences(7)] == [
        "R B' F L' D2 B F' U D2 F2 L D2 R2 F B2 D2 F R2 F2 B2",
        "D' R2 U D2 B' L D' R2 D2 B' U2 R2 B2 U F2 L2 U' L U2 R",
        "U' D' F2 R2 B R F U B2 F2 D2 F D U2 R' F D' R' D' R'",
        "U D F2 U D' R D' R F B R U B' F L D2 U' B U D'",
        "D B' F2 U L' F' U F' L D2 F B2 L2 B2 F2 R B L2 F L2",
    ]
    assert [format_sequence(s) for s in get_tier("Rubiks-1-5").sequences(0)] == ["D' U F D2 L"]
    assert [format_sequence(s) for s in get_tier("Rubiks-5-5").sequences(0)] == [
        "D L2 R2 D' U2",
        "R B R L B",
        "F' B' R2 D F2",
        "F' B2 R D' F2",
        "B' F D' L D2",
    ]


# -- rules and properties ---------------------------------------------------------------


def test_move_set_is_the_18_face_turns():
    assert [str(m) for m in GENERATED_MOVES] == [f + s for f in "URFDLB" for s in ("", "2", "'")]


@pytest.mark.parametrize("seed", range(30))
def test_rules_hold(seed):
    for tier in ("Rubiks-5-50", "Rubiks-1-200"):
        for seq in get_tier(tier).sequences(seed):
            faces = [m.kind for m in seq]
            assert all(m.kind in "URFDLB" for m in seq)
            for i in range(1, len(faces)):
                assert faces[i] != faces[i - 1]
            for i in range(2, len(faces)):
                assert not (AXIS[faces[i]] == AXIS[faces[i - 1]] == AXIS[faces[i - 2]])


def test_all_tiers_have_m_distinct_sequences_of_n_moves():
    for tier in load_tiers().values():
        seqs = tier.sequences(11)
        assert len(seqs) == tier.trials and len(set(seqs)) == tier.trials
        assert all(len(s) == tier.moves for s in seqs)


def test_duplicates_are_redrawn():
    # Short sequences collide often: with 1-move "tiers" of 18 trials, the rule
    # must still give 18 distinct moves (every face turn exactly once).
    seqs = generate_sequences(3, "custom", 18, 1)
    assert sorted(str(s[0]) for s in seqs) == sorted(str(m) for m in GENERATED_MOVES)


def test_count_sequences_by_brute_force():
    from itertools import product

    from benchharness.cube.sequences import count_sequences

    def ok(seq):
        return all(seq[i][0] != seq[i - 1][0] for i in range(1, len(seq))) and not any(
            AXIS[seq[i][0]] == AXIS[seq[i - 1][0]] == AXIS[seq[i - 2][0]]
            for i in range(2, len(seq))
        )

    tokens = [str(m) for m in GENERATED_MOVES]
    for n in (1, 2, 3):
        assert count_sequences(n) == sum(ok(s) for s in product(tokens, repeat=n))
    with pytest.raises(ValueError, match="only 18 distinct"):
        generate_sequences(0, "custom", 19, 1)


def test_all_allowed_moves_occur():
    counts: dict[str, int] = {}
    for seed in range(40):
        for seq in get_tier("Rubiks-1-200").sequences(seed):
            for m in seq:
                counts[str(m)] = counts.get(str(m), 0) + 1
    assert set(counts) == {str(m) for m in GENERATED_MOVES}
    assert min(counts.values()) > 0.8 * max(counts.values())  # roughly uniform over 8000 draws


def test_determinism_and_independence():
    t = get_tier("Rubiks-5-10")
    assert t.sequences(5) == t.sequences(5)
    assert t.sequences(5) != t.sequences(6)
    # a trial's stream depends only on (seed, tier, trial)
    assert generate_sequence(5, "Rubiks-5-10", 4, 10) == t.sequences(5)[3]
    # the tier name is part of the key
    assert get_tier("Rubiks-1-10").sequences(5)[0] != t.sequences(5)[0]


def test_bad_seed():
    with pytest.raises(ValueError):
        generate_sequences(-1, "Rubiks-1-5", 1, 5)
    with pytest.raises(ValueError):
        generate_sequence(0, "Rubiks-1-5", 0, 5)
