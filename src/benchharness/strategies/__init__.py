"""Manipulation strategies (baselines and planners).

Each strategy package defines ``REGISTRATIONS: list[Registration]`` (with
the ``benchmarks`` and ``robots`` it declares) and is named in
``benchharness_builtins.strategies.PACKAGES``; a package must import heavy
dependencies (torch, simulators) lazily inside its factories so that listing
plugins stays fast.
"""
