"""Manipulation strategies (baselines and planners).

A module here that defines ``REGISTRATIONS: list[Registration]`` is picked up
by the built-in ``strategies`` plugin; a module must import heavy
dependencies (torch, simulators) lazily inside its factories so that listing
plugins stays fast.
"""
