"""Is a 54-letter string a cube that could be in someone's hands?

Checks run in layers, and a layer runs only when the one before it passed,
because e.g. cubie identification means nothing with the wrong colour counts:

1. form: exactly 54 characters, all from ``URFDLB``;
2. colours: each letter exactly 9 times; the six centres read ``URFDLB``
   (the exchange format describes the cube held in the reference orientation);
3. cubies: every corner and edge position shows the colours of a real cubie
   (a corner's colours in the right cyclic order, since a mirrored corner
   does not exist), and no cubie appears twice;
4. invariants of the legal group: corner twists sum to 0 mod 3, edge flips to
   0 mod 2, and the corner and edge permutations have the same parity.

A string passing all four is reachable from solved by face turns. Corner and
edge facelet tables follow Kociemba's definition (reference facelet first —
the U or D sticker — then clockwise); a test checks them against the geometry
in :mod:`benchharness.cube.facelets`.
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from .facelets import FACELET_INDEX, FACELET_NAMES, FACES

#: Corner positions and their facelets: U/D sticker first, then clockwise.
CORNERS: dict[str, tuple[str, str, str]] = {
    "URF": ("U9", "R1", "F3"),
    "UFL": ("U7", "F1", "L3"),
    "ULB": ("U1", "L1", "B3"),
    "UBR": ("U3", "B1", "R3"),
    "DFR": ("D3", "F9", "R7"),
    "DLF": ("D1", "L9", "F7"),
    "DBL": ("D7", "B9", "L7"),
    "DRB": ("D9", "R9", "B7"),
}
#: Edge positions and their facelets: U/D (or F/B for middle-layer edges) first.
EDGES: dict[str, tuple[str, str]] = {
    "UR": ("U6", "R2"),
    "UF": ("U8", "F2"),
    "UL": ("U4", "L2"),
    "UB": ("U2", "B2"),
    "DR": ("D6", "R8"),
    "DF": ("D2", "F8"),
    "DL": ("D4", "L8"),
    "DB": ("D8", "B8"),
    "FR": ("F6", "R4"),
    "FL": ("F4", "L6"),
    "BL": ("B6", "L4"),
    "BR": ("B4", "R6"),
}

_CORNER_NAMES = tuple(CORNERS)
_EDGE_NAMES = tuple(EDGES)
_CORNER_IDX = [tuple(FACELET_INDEX[f] for f in fs) for fs in CORNERS.values()]
_EDGE_IDX = [tuple(FACELET_INDEX[f] for f in fs) for fs in EDGES.values()]


class FaceletError(ValueError):
    """A facelet string that is not a legal cube; ``reasons`` lists every problem found."""

    def __init__(self, reasons: list[str], label: str = "facelets") -> None:
        self.reasons = reasons
        super().__init__(f"invalid {label}: " + "; ".join(reasons))


def _parity(perm: list[int]) -> int:
    seen = [False] * len(perm)
    swaps = 0
    for i in range(len(perm)):
        j, length = i, 0
        while not seen[j]:
            seen[j] = True
            j = perm[j]
            length += 1
        swaps += max(length - 1, 0)
    return swaps % 2


def _form_reasons(s: str) -> list[str]:
    if len(s) != 54:
        return [f"expected 54 facelets, got {len(s)}"]
    bad = [(i, ch) for i, ch in enumerate(s) if ch not in FACES]
    if bad:
        shown = ", ".join(f"{ch!r} at {FACELET_NAMES[i]}" for i, ch in bad[:5])
        more = f" and {len(bad) - 5} more" if len(bad) > 5 else ""
        return [
            f"invalid character{'s' if len(bad) > 1 else ''} {shown}{more}; facelets must be letters from URFDLB"
        ]
    return []


def _colour_reasons(s: str) -> list[str]:
    reasons = []
    counts = Counter(s)
    wrong = [f"{f} appears {counts.get(f, 0)} times" for f in FACES if counts.get(f, 0) != 9]
    if wrong:
        reasons.append("each colour must appear exactly 9 times, but " + ", ".join(wrong))
    centres = "".join(s[9 * k + 4] for k in range(6))
    if centres != FACES:
        reasons.append(
            f"centres (U5 R5 F5 D5 L5 B5) read {centres}, expected URFDLB: each face's centre "
            "carries that face's letter (hold the cube with the U centre up and the F centre in front)"
        )
    return reasons


def _cubie_reasons(s: str) -> list[str]:
    reasons: list[str] = []
    corner_colours = ["".join(f[0] for f in fs) for fs in CORNERS.values()]  # "URF", ...
    edge_colours = ["".join(f[0] for f in fs) for fs in EDGES.values()]
    c_perm, c_twist, e_perm, e_flip = [], [], [], []
    where_c: dict[int, str] = {}
    where_e: dict[int, str] = {}
    for pos, idx in zip(_CORNER_NAMES, _CORNER_IDX):
        cols = "".join(s[i] for i in idx)
        ud = [k for k, c in enumerate(cols) if c in "UD"]
        cubie = -1
        if len(ud) == 1:
            t = ud[0]
            rotated = cols[t:] + cols[:t]  # reference sticker first, clockwise
            cubie = corner_colours.index(rotated) if rotated in corner_colours else -1
        if cubie < 0:
            reasons.append(
                f"corner {pos} ({'/'.join(CORNERS[pos])}) shows {'-'.join(cols)}, which is no corner of the cube"
            )
            continue
        if cubie in where_c:
            reasons.append(
                f"corner cubie {_CORNER_NAMES[cubie]} appears twice, at {where_c[cubie]} and {pos}"
            )
            continue
        where_c[cubie] = pos
        c_perm.append(cubie)
        c_twist.append(t)
    for pos, idx in zip(_EDGE_NAMES, _EDGE_IDX):
        cols = "".join(s[i] for i in idx)
        if cols in edge_colours:
            cubie, flip = edge_colours.index(cols), 0
        elif cols[::-1] in edge_colours:
            cubie, flip = edge_colours.index(cols[::-1]), 1
        else:
            reasons.append(
                f"edge {pos} ({'/'.join(EDGES[pos])}) shows {'-'.join(cols)}, which is no edge of the cube"
            )
            continue
        if cubie in where_e:
            reasons.append(
                f"edge cubie {_EDGE_NAMES[cubie]} appears twice, at {where_e[cubie]} and {pos}"
            )
            continue
        where_e[cubie] = pos
        e_perm.append(cubie)
        e_flip.append(flip)
    if reasons:
        return reasons
    twist = sum(c_twist) % 3
    if twist:
        reasons.append(
            f"corner twist: the corner orientations sum to {twist} mod 3, must be 0 "
            "(a corner is twisted in place)"
        )
    flip = sum(e_flip) % 2
    if flip:
        reasons.append(
            "edge flip: the edge orientations sum to 1 mod 2, must be 0 (an edge is flipped in place)"
        )
    pc, pe = _parity(c_perm), _parity(e_perm)
    if pc != pe:
        word = {0: "even", 1: "odd"}
        reasons.append(
            f"permutation parity: the corner permutation is {word[pc]} but the edge permutation is {word[pe]}; "
            "they must match (two edges or two corners are swapped)"
        )
    return reasons


def format_problems(facelets: str) -> list[str]:
    """Problems of form and colour only (layers 1-2): what a transcription error looks like.

    A string passing these is a well-formed reading of *some* physical object;
    whether it is a legal cube is :func:`facelet_problems`'s question.
    """
    for layer in (_form_reasons, _colour_reasons):
        reasons = layer(facelets)
        if reasons:
            return reasons
    return []


def facelet_problems(facelets: str) -> list[str]:
    """Every reason ``facelets`` is not a legal cube; empty when it is."""
    for layer in (_form_reasons, _colour_reasons, _cubie_reasons):
        reasons = layer(facelets)
        if reasons:
            return reasons
    return []


def is_valid(facelets: str) -> bool:
    return not facelet_problems(facelets)


def check_facelets(facelets: str, label: str = "facelets") -> np.ndarray:
    """Validate and decode; raises :class:`FaceletError` with the reasons."""
    from .facelets import to_array

    reasons = facelet_problems(facelets)
    if reasons:
        raise FaceletError(reasons, label)
    return to_array(facelets)
