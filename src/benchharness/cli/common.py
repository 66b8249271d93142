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


def _json_requested() -> bool:
    """Whether the running command was given ``--json`` (its parsed ``as_json``)."""
    ctx = click.get_current_context(silent=True)
    while ctx is not None:
        if ctx.params.get("as_json"):
            return True
        ctx = ctx.parent
    return False


def error_line(message: str, code: int, as_json: bool) -> str:
    """One line: ``error: ...`` as text, or one JSON object under ``--json``."""
    if as_json:
        return json.dumps({"error": message, "exit_code": code})
    return f"error: {message}"


def fail(message: str, code: int = EXIT_BAD_INPUT) -> NoReturn:
    """Print an error to stderr as one line and exit (2 = bad input by default).

    Under ``--json`` the line is one JSON object, ``{"error": message,
    "exit_code": code}``, still on stderr (stdout carries results only) and
    with the same exit code.
    """
    click.echo(error_line(" ".join(message.split()), code, _json_requested()), err=True)
    sys.exit(code)


json_option = click.option(
    "--json", "as_json", is_flag=True, help="Print machine-readable JSON instead of text."
)


#: Width of plain text lines when output is not a terminal: lines are not
#: re-wrapped for a pipe (tables get their own natural width, below).
PIPE_WIDTH = 220


def console(stderr: bool = False) -> Any:
    """A rich console: the terminal's width in a terminal, :data:`PIPE_WIDTH` in a pipe."""
    from rich.console import Console

    con = Console(stderr=stderr)
    if not con.is_terminal:  # piped or captured: do not wrap at 80 columns
        con = Console(width=PIPE_WIDTH, stderr=stderr)
    return con


def print_table(table: Any, con: Any = None, stderr: bool = False) -> None:
    """Print a rich table without ever truncating a cell.

    Names one must type (plugins, joints, tasks) and failure messages are
    never cut: every column folds (``overflow="fold"``, wrapping allowed)
    instead of ending in an ellipsis, so in a narrow terminal a long cell
    continues on the next line. In a pipe (not a terminal) the table is
    printed at its natural width, whatever ``COLUMNS`` says, so each row
    stays one greppable line.
    """
    from rich.console import Console

    for col in table.columns:
        col.overflow = "fold"
        col.no_wrap = False
    con = con if con is not None else console(stderr)
    if not con.is_terminal:
        natural = Console(width=100_000).measure(table).maximum
        if natural > con.width:
            con = Console(width=natural, stderr=stderr, file=con.file)
    con.print(table)
