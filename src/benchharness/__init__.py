"""benchharness: run and score the Rubik's cube and in-hand manipulation benchmarks.

See README.md for the command-line tour and docs/ for formats and conventions.
"""

__version__ = "0.1.0"
