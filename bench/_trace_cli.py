"""The command line every ``bench/trace_*.py`` diagnostic shares (not a test, not a benchmark).

A trace script installs its wrappers round the state machine and then runs
``benchharness`` in this same process (so give the command ``--workers 0``);
its own options come first, as ``--name value`` pairs, before the
``benchharness`` command and its arguments::

    python bench/trace_twist.py --moves 2 run --task Rubiks-1-20 --robot herb ... --workers 0
"""

from __future__ import annotations

import sys
from collections.abc import Callable


def run_traced(
    install: Callable[[], None], options: dict[str, Callable[[str], None]] | None = None
) -> None:
    """Take the leading ``--name value`` pairs in ``options`` (each handed its value), install, run the CLI."""
    args = sys.argv[1:]
    options = options or {}
    while args[:1] and args[0] in options:
        if len(args) < 2:
            raise SystemExit(f"{args[0]} needs a value")
        options[args[0]](args[1])
        args = args[2:]
    install()
    from benchharness.cli.main import main as cli

    sys.argv = ["benchharness", *args]
    cli()
