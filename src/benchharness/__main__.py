"""``python -m benchharness``: the same command line as the ``benchharness`` script (no PATH needed)."""

from benchharness.cli.main import cli

cli(prog_name="benchharness")
