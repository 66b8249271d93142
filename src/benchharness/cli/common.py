"""Helpers shared by the subcommands: JSON output and error exits.

Exit codes follow one rule across the CLI: 0 success, 1 a negative answer
(e.g. ``rubiks validate`` found a different state), 2 bad input.
"""

from __future__ import annotations

import json
import sys
from typing import Any, NoReturn

import click
import numpy as np

EXIT_OK = 0
EXIT_NEGATIVE = 1
EXIT_BAD_INPUT = 2


def _default(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if hasattr(o, "__dataclass_fields__"):
        from dataclasses import asdict

        return asdict(o)
    raise TypeError(f"cannot serialise {type(o).__name__}")


def emit_json(data: Any) -> None:
    click.echo(json.dumps(data, indent=2, default=_default, allow_nan=True))


def fail(message: str, code: int = EXIT_BAD_INPUT) -> NoReturn:
    """Print an error to stderr and exit (2 = bad input by default)."""
    click.echo(f"error: {message}", err=True)
    sys.exit(code)


json_option = click.option(
    "--json", "as_json", is_flag=True, help="Print machine-readable JSON instead of text."
)
