"""Validation of facelet strings: every rejection has a precise reason."""

from __future__ import annotations

import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from benchharness.cube import (
    FACE_MOVES,
    SOLVED,
    SOLVED_STRING,
    FaceletError,
    apply,
    check_facelets,
    facelet_problems,
    format_problems,
    is_valid,
    to_string,
)
from benchharness.cube.facelets import FACELET_CUBIES, FACELET_INDEX, FACELET_POSITIONS
from benchharness.cube.validation import CORNERS, EDGES

SCRAMBLE = "R U F' D2 L B' U2 R' F D"
SCRAMBLED = to_string(apply(SOLVED, SCRAMBLE))


def edit(s: str, **changes: str) -> str:
    out = list(s)
    for name, letter in changes.items():
        out[FACELET_INDEX[name]] = letter
    return "".join(out)


def swap(s: str, *pairs: tuple[str, str]) -> str:
    out = list(s)
    for a, b in pairs:
        i, j = FACELET_INDEX[a], FACELET_INDEX[b]
        out[i], out[j] = out[j], out[i]
    return "".join(out)


def test_cubie_tables_match_geometry():
    # Each corner/edge lists the facelets of one cubie; corners are listed
    # clockwise seen from outside (the triple product of the normals is > 0).
    import numpy as np

    for pos, names in {**CORNERS, **EDGES}.items():
        idx = [FACELET_INDEX[n] for n in names]
        assert len({tuple(FACELET_CUBIES[i]) for i in idx}) == 1, pos
        assert names[0][0] in "UD" or pos in ("FR", "FL", "BL", "BR")
    for pos, names in CORNERS.items():
        idx = [FACELET_INDEX[n] for n in names]
        normals = [FACELET_POSITIONS[i] - 2 * FACELET_CUBIES[i] for i in idx]
        assert np.dot(np.cross(normals[0], normals[1]), normals[2]) < 0, (
            pos
        )  # clockwise from outside


def test_solved_and_scrambled_are_valid():
    assert is_valid(SOLVED_STRING)
    assert is_valid(SCRAMBLED)
    assert check_facelets(SCRAMBLED).shape == (54,)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.sampled_from(FACE_MOVES), max_size=60))
def test_every_reachable_state_is_valid(moves):
    assert facelet_problems(to_string(apply(SOLVED, moves))) == []


def test_superflip_is_valid():
    assert is_valid("UBULURUFURURFRBRDRFUFLFRFDFDFDLDRDBDLULBLFLDLBUBRBLBDB")


def test_wrong_length():
    assert facelet_problems(SOLVED_STRING[:-1]) == ["expected 54 facelets, got 53"]
    assert facelet_problems(SOLVED_STRING + "U") == ["expected 54 facelets, got 55"]


def test_wrong_characters():
    (reason,) = facelet_problems(edit(SOLVED_STRING, U3="W", F1="g"))
    assert reason == "invalid characters 'W' at U3, 'g' at F1; facelets must be letters from URFDLB"


def test_wrong_counts():
    (reason,) = facelet_problems(edit(SOLVED_STRING, U1="R"))
    assert (
        reason
        == "each colour must appear exactly 9 times, but U appears 8 times, R appears 10 times"
    )


def test_centres_out_of_order():
    s = swap(SOLVED_STRING, ("U5", "F5"))
    assert facelet_problems(s) == [
        "centres (U5 R5 F5 D5 L5 B5) read FRUDLB, expected URFDLB: each face's centre carries that "
        "face's letter (hold the cube with the U centre up and the F centre in front)"
    ]


def test_single_twisted_corner():
    # Rotate the URF corner's three stickers in place (U9 R1 F3).
    s = SCRAMBLED
    u9, r1, f3 = (s[FACELET_INDEX[n]] for n in ("U9", "R1", "F3"))
    twisted = edit(s, U9=f3, R1=u9, F3=r1)
    assert facelet_problems(twisted) == [
        "corner twist: the corner orientations sum to 1 mod 3, must be 0 (a corner is twisted in place)"
    ]
    twisted_back = edit(s, U9=r1, R1=f3, F3=u9)
    assert "sum to 2 mod 3" in facelet_problems(twisted_back)[0]


def test_single_flipped_edge():
    s = swap(SCRAMBLED, ("U6", "R2"))
    assert facelet_problems(s) == [
        "edge flip: the edge orientations sum to 1 mod 2, must be 0 (an edge is flipped in place)"
    ]


def test_swapped_pair_of_edges():
    s = swap(SCRAMBLED, ("U6", "U8"), ("R2", "F2"))  # exchange the UR and UF edges
    assert facelet_problems(s) == [
        "permutation parity: the corner permutation is even but the edge permutation is odd; "
        "they must match (two edges or two corners are swapped)"
    ]


def test_swapped_pair_of_corners():
    s = swap(
        SOLVED_STRING, ("U9", "U7"), ("R1", "F1"), ("F3", "L3")
    )  # URF <-> UFL, orientation kept
    assert (
        "permutation parity: the corner permutation is odd but the edge permutation is even"
        in (facelet_problems(s)[0])
    )


def test_three_cycle_of_edges_is_fine():
    s = swap(SOLVED_STRING, ("U6", "U8"), ("R2", "F2"), ("U8", "U4"), ("F2", "L2"))
    assert is_valid(s)


def test_impossible_corner_colours():
    # U and D on one corner: no such cubie. Counts stay right by swapping two stickers.
    s = swap(SOLVED_STRING, ("R1", "D3"))
    reasons = facelet_problems(s)
    assert "corner URF (U9/R1/F3) shows U-D-F, which is no corner of the cube" in reasons
    assert "corner DFR (D3/F9/R7) shows R-F-R, which is no corner of the cube" in reasons


def test_mirrored_corner_is_no_corner():
    s = swap(SOLVED_STRING, ("R1", "F3"))  # U-F-R order: a mirror image of the URF cubie
    assert (
        facelet_problems(s)[0]
        == "corner URF (U9/R1/F3) shows U-F-R, which is no corner of the cube"
    )


def test_duplicated_cubie():
    # The UR position shows the UF edge's colours and the DF position the DR edge's;
    # colour counts are unchanged (one F became R, one R became F).
    s = edit(SOLVED_STRING, R2="F", F8="R")
    assert facelet_problems(s) == [
        "edge cubie UF appears twice, at UR and UF",
        "edge cubie DR appears twice, at DR and DF",
    ]


def test_check_facelets_raises_with_reasons():
    with pytest.raises(FaceletError) as info:
        check_facelets("U" * 54, "initial state")
    assert str(info.value).startswith(
        "invalid initial state: each colour must appear exactly 9 times"
    )
    assert len(info.value.reasons) == 2


def test_format_problems_ignore_legality():
    twisted = swap(SOLVED_STRING, ("U6", "R2"))
    assert format_problems(twisted) == [] and facelet_problems(twisted) != []


def test_random_single_sticker_swaps_are_rejected():
    rng = random.Random(5)
    for _ in range(200):
        a, b = rng.sample(range(54), 2)
        if SCRAMBLED[a] == SCRAMBLED[b]:
            continue
        s = list(SCRAMBLED)
        s[a], s[b] = s[b], s[a]
        assert not is_valid("".join(s))  # a single transposition of stickers is never a legal cube
