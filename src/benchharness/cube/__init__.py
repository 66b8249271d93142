"""Rubik's cube core: 54-facelet states, moves, validation, sequences, tiers.

Pure Python + NumPy; nothing here imports a simulator. The pieces, each in a
module named for what it holds:

* :mod:`.facelets` — layout, names (``U1`` … ``B9``), geometry, string format;
* :mod:`.moves` — notation, permutations derived from geometry, application;
* :mod:`.validation` — is a string a legal cube, and if not, why;
* :mod:`.protocol` — expected final state and facelet differences;
* :mod:`.prng`, :mod:`.sequences` — the pinned fixed-seed generator;
* :mod:`.tiers` — the twelve tiers and the paper's baselines.
"""

from .facelets import FACELET_NAMES, FACES, SOLVED, SOLVED_STRING, to_array, to_string, to_strings
from .moves import (
    ALL_MOVES,
    FACE_MOVES,
    MOVE_PERMUTATIONS,
    Move,
    MoveError,
    apply,
    apply_batch,
    format_sequence,
    invert,
    order,
    parse_move,
    parse_sequence,
    permutation,
    permutations_batch,
    reorient,
)
from .protocol import FaceletDifference, differences, expected_final
from .sequences import ALGORITHM, generate_sequence, generate_sequences
from .tiers import BaselineScore, RubiksTier, UnknownTierError, get_tier, load_tiers
from .validation import FaceletError, check_facelets, facelet_problems, format_problems, is_valid

__all__ = [
    "ALGORITHM",
    "ALL_MOVES",
    "BaselineScore",
    "FACELET_NAMES",
    "FACES",
    "FACE_MOVES",
    "FaceletDifference",
    "FaceletError",
    "MOVE_PERMUTATIONS",
    "Move",
    "MoveError",
    "RubiksTier",
    "SOLVED",
    "SOLVED_STRING",
    "UnknownTierError",
    "apply",
    "apply_batch",
    "check_facelets",
    "differences",
    "expected_final",
    "facelet_problems",
    "format_problems",
    "format_sequence",
    "generate_sequence",
    "generate_sequences",
    "get_tier",
    "invert",
    "is_valid",
    "load_tiers",
    "order",
    "parse_move",
    "parse_sequence",
    "permutation",
    "permutations_batch",
    "reorient",
    "to_array",
    "to_string",
    "to_strings",
]
