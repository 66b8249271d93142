"""Protocol step 6: the expected final state, and how an observed one differs.

Both strings are in the exchange format, i.e. the cube as a person holds it to
read it (U-coloured centre up, F-coloured centre in front). The expected state
is therefore the spatial result of the moves, re-oriented
(:func:`~benchharness.cube.moves.reorient`): a robot that ends holding the cube
upside down, or that executes ``M`` as ``R L' x'``, has still produced the
same cube.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from .facelets import FACELET_NAMES, SOLVED_STRING, to_string
from .moves import Move, apply, reorient
from .validation import check_facelets


@dataclass(frozen=True)
class FaceletDifference:
    name: str
    expected: str
    observed: str

    def __str__(self) -> str:
        return f"{self.name}: expected {self.expected}, got {self.observed}"


def expected_final(sequence: str | Iterable[Move | str], initial: str = SOLVED_STRING) -> str:
    """The state after ``sequence`` from ``initial``, as the 54-letter string.

    Raises :class:`~benchharness.cube.validation.FaceletError` for an invalid
    initial string and :class:`~benchharness.cube.moves.MoveError` for an
    unknown move.
    """
    state = check_facelets(initial, "initial state")
    return to_string(reorient(apply(state, sequence)))


def differences(expected: str, observed: str) -> list[FaceletDifference]:
    """Facelets where two 54-letter strings disagree, in string order."""
    if len(expected) != 54 or len(observed) != 54:
        raise ValueError("both states must have 54 facelets")
    return [
        FaceletDifference(FACELET_NAMES[i], e, o)
        for i, (e, o) in enumerate(zip(expected, observed))
        if e != o
    ]
