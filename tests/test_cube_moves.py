"""Cube core: moves against an independent oracle (magiccube) and group identities."""

from __future__ import annotations

import random

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from benchharness.cube import (
    ALL_MOVES,
    FACE_MOVES,
    SOLVED,
    SOLVED_STRING,
    MoveError,
    apply,
    apply_batch,
    format_sequence,
    invert,
    order,
    parse_move,
    parse_sequence,
    permutation,
    reorient,
    to_array,
    to_string,
    to_strings,
)
from benchharness.cube.facelets import FACELET_CUBIES, FACELET_NAMES, FACELET_POSITIONS
from benchharness.cube.moves import IDENTITY, MOVE_PERMUTATIONS, Move, indices

magiccube = pytest.importorskip("magiccube")

ALL_TOKENS = [str(m) for m in ALL_MOVES]
FACE_TOKENS = [str(m) for m in FACE_MOVES]


def oracle(sequence: str) -> str:
    """magiccube's state after ``sequence`` from solved, as a URFDLB facelet string.

    magiccube 1.2 uses the same notation (M E S x y z included, ``'`` and ``2``)
    and its ``get_kociemba_facelet_positions`` maps its colour scheme (W R G Y O B)
    to U R F D L B in Kociemba's facelet order.
    """
    cube = magiccube.Cube(3, hist=False)
    if sequence:
        cube.rotate(sequence)
    return cube.get_kociemba_facelet_positions()


def random_sequence(rng: random.Random, tokens: list[str], n: int) -> str:
    return " ".join(rng.choice(tokens) for _ in range(n))


# -- geometry and layout ------------------------------------------------------------


def test_sticker_positions_are_unique_and_on_the_surface():
    assert len({tuple(p) for p in FACELET_POSITIONS.tolist()}) == 54
    assert (np.abs(FACELET_POSITIONS).max(axis=1) == 3).all()


def test_net_neighbours_share_a_cubie():
    # Facts about the net, read off a picture of it: U9 touches R1 and F3; U1 touches
    # L1 and B3; D1 touches F7 and L9; D9 touches R9 and B7; F6 and R4 form one edge.
    idx = {n: i for i, n in enumerate(FACELET_NAMES)}
    groups = [
        ("U9", "R1", "F3"),
        ("U1", "L1", "B3"),
        ("D1", "F7", "L9"),
        ("D9", "R9", "B7"),
        ("F6", "R4"),
    ]
    for group in groups:
        cubies = {tuple(FACELET_CUBIES[idx[n]]) for n in group}
        assert len(cubies) == 1, group


def test_string_round_trip():
    assert to_string(SOLVED) == SOLVED_STRING
    s = "UBULURUFURURFRBRDRFUFLFRFDFDFDLDRDBDLULBLFLDLBUBRBLBDB"
    assert to_string(to_array(s)) == s
    assert to_strings(np.stack([to_array(s), SOLVED])) == [s, SOLVED_STRING]
    with pytest.raises(ValueError, match="54"):
        to_array("U" * 53)
    with pytest.raises(ValueError, match="U3"):
        to_array("UUx" + "U" * 51)


# -- against the oracle ------------------------------------------------------------


def test_known_single_turns():
    # Hand-checked: R carries F's right column to U, U's to B (upside down), etc.
    assert to_string(apply(SOLVED, "R")) == "UUFUUFUUFRRRRRRRRRFFDFFDFFDDDBDDBDDBLLLLLLLLLUBBUBBUBB"
    assert to_string(apply(SOLVED, "U")) == "UUUUUUUUUBBBRRRRRRRRRFFFFFFDDDDDDDDDFFFLLLLLLLLLBBBBBB"
    assert to_string(apply(SOLVED, "F")) == "UUUUUULLLURRURRURRFFFFFFFFFRRRDDDDDDLLDLLDLLDBBBBBBBBB"


@pytest.mark.parametrize("token", ALL_TOKENS)
def test_every_move_matches_oracle(token):
    assert to_string(apply(SOLVED, token)) == oracle(token)


def test_1000_random_face_turn_sequences_match_oracle():
    rng = random.Random(20260101)
    for _ in range(1000):
        seq = random_sequence(rng, FACE_TOKENS, rng.randint(1, 25))
        assert to_string(apply(SOLVED, seq)) == oracle(seq), seq


def test_300_random_sequences_with_slices_and_rotations_match_oracle():
    rng = random.Random(7)
    for _ in range(300):
        seq = random_sequence(rng, ALL_TOKENS, 20)
        assert to_string(apply(SOLVED, seq)) == oracle(seq), seq


def test_batched_application_matches_one_by_one():
    rng = np.random.default_rng(3)
    idx = rng.integers(0, len(ALL_MOVES), size=(200, 15))
    starts = np.stack(
        [apply(SOLVED, random_sequence(random.Random(i), FACE_TOKENS, 10)) for i in range(200)]
    )
    got = apply_batch(starts, idx)
    for i in range(200):
        seq = [ALL_MOVES[j] for j in idx[i]]
        assert np.array_equal(got[i], apply(starts[i], seq))
    # one start broadcast over many sequences
    got_solved = apply_batch(SOLVED, idx)
    assert to_string(got_solved[5]) == oracle(format_sequence(ALL_MOVES[j] for j in idx[5]))
    # a batch of states through one sequence
    assert np.array_equal(apply(starts, "R U")[7], apply(starts[7], "R U"))


@pytest.mark.parametrize("length", [0, 1, 2, 7])
def test_batched_application_in_chunks(monkeypatch, length):
    import benchharness.cube.moves as moves_module

    monkeypatch.setattr(moves_module, "_CHUNK", 16)
    idx = np.random.default_rng(length).integers(0, len(ALL_MOVES), size=(50, length))
    got = apply_batch(SOLVED, idx)
    perms = moves_module.permutations_batch(idx)
    for i in range(50):
        expected = permutation([ALL_MOVES[j] for j in idx[i]])
        assert np.array_equal(perms[i], expected) and np.array_equal(got[i], SOLVED[expected])


def test_batched_input_errors():
    with pytest.raises(ValueError, match="shape"):
        apply_batch(np.stack([SOLVED] * 3), np.zeros((2, 4), dtype=int))
    with pytest.raises(ValueError, match="0..35"):
        apply_batch(SOLVED, np.full((2, 4), 36))


# -- slices and rotations by identities (independent of the oracle) -------------------


@pytest.mark.parametrize(
    "lhs, rhs",
    [
        ("M", "R L' x'"),
        ("E", "U D' y'"),
        ("S", "F' B z"),
        ("x", "R M' L'"),
        ("y", "U E' D'"),
        ("z", "F S B'"),
        ("M2", "R2 L2 x2"),
    ],
)
def test_slice_and_rotation_identities(lhs, rhs):
    assert np.array_equal(permutation(lhs), permutation(rhs))


def test_rotations_do_not_change_the_held_state():
    state = apply(SOLVED, "R U F' D2 L B")
    for rot in ("x", "y'", "z2", "x y z"):
        assert to_string(reorient(apply(state, rot))) == to_string(state)
    # M is R L' seen by a person holding the cube the reference way
    assert to_string(reorient(apply(state, "M"))) == to_string(apply(state, "R L'"))


# -- group identities (hypothesis) ---------------------------------------------------

moves_st = st.lists(st.sampled_from(ALL_MOVES), max_size=40)


@settings(max_examples=200, deadline=None)
@given(moves_st)
def test_sequence_then_inverse_is_identity(moves):
    state = apply(SOLVED, moves)
    assert np.array_equal(apply(state, invert(moves)), SOLVED)
    assert np.array_equal(permutation(list(moves) + list(invert(moves))), IDENTITY)


@settings(max_examples=100, deadline=None)
@given(moves_st, moves_st)
def test_composition_is_concatenation(a, b):
    assert np.array_equal(apply(apply(SOLVED, a), b), apply(SOLVED, list(a) + list(b)))


@pytest.mark.parametrize("move", ALL_MOVES, ids=str)
def test_move_orders(move):
    assert order([move]) == (2 if move.turns == 2 else 4)
    assert np.array_equal(permutation([move] * 4), IDENTITY)


def test_known_orders():
    assert order("R U R' U'") == 6
    assert order("R U") == 105
    assert order("R U2 D' B D'") == 1260  # the largest order of any Rubik's cube element


@pytest.mark.parametrize(
    "a, b", [("U", "D"), ("R", "L"), ("F", "B"), ("U2", "D'"), ("M", "R"), ("E", "U")]
)
def test_opposite_layers_commute(a, b):
    assert np.array_equal(permutation(f"{a} {b}"), permutation(f"{b} {a}"))


def test_adjacent_faces_do_not_commute():
    assert not np.array_equal(permutation("R U"), permutation("U R"))


def test_superflip_flips_every_edge_and_nothing_else():
    superflip = "U R2 F B R B2 R U2 L B2 R U' D' R2 F R' L B2 U2 F2"
    assert (
        to_string(apply(SOLVED, superflip))
        == "UBULURUFURURFRBRDRFUFLFRFDFDFDLDRDBDLULBLFLDLBUBRBLBDB"
    )


def test_permutation_table_is_consistent():
    for m in ALL_MOVES:
        assert sorted(MOVE_PERMUTATIONS[m.index].tolist()) == list(range(54))
        assert np.array_equal(
            MOVE_PERMUTATIONS[m.index][MOVE_PERMUTATIONS[m.inverse().index]], IDENTITY
        )
    assert indices(parse_sequence("U R2 x'")).tolist() == [0, 4, 29]


# -- parsing ------------------------------------------------------------------------


def test_parse_and_format_round_trip():
    text = "R U R' U' M2 E S' x y2 z'"
    assert format_sequence(parse_sequence(text)) == text
    assert format_sequence(invert(text)) == "z y2 x' S E' M2 U R U' R'"


def test_lenient_spellings():
    assert parse_sequence("R\u2019  U\tF\u2032\nB\u00b4") == parse_sequence("R' U F' B'")
    assert parse_move("R2'") == parse_move("R'2") == Move("R", 2)
    assert parse_move("X") == Move("x", 1)
    assert parse_sequence("") == ()


@pytest.mark.parametrize(
    "text, token, position",
    [
        ("R U Q U'", "Q", 3),
        ("R3", "R3", 1),
        ("R U Rw", "Rw", 3),
        ("r", "r", 1),
        ("RUR'U'", "RUR'U'", 1),
        ("U u", "u", 2),
        ("R''", "R''", 1),
        ("F,", "F,", 1),
    ],
)
def test_unknown_moves_name_token_and_position(text, token, position):
    with pytest.raises(MoveError) as info:
        parse_sequence(text)
    assert info.value.token == token and info.value.position == position
    assert str(info.value) == (
        f'unknown move "{token}" at position {position} '
        "(expected U D L R F B M E S x y z with optional ' or 2)"
    )
