"""``python -m benchharness``: the same command line as the ``benchharness`` script (no PATH needed)."""

from benchharness.cli.main import main

main(prog_name="benchharness")
