"""Pivoting with a parallel gripper (Level I) and the table-supported primitives it shares with DMG execution.

The PR2 gripper (robot ``pr2-gripper``) holds an object resting on the
table, loosens its grip to a light squeeze, turns about its grasp axis and
tightens again; the change of grasp comes from the contact physics (pad
friction against table friction and the object's weight). See
``docs/pivoting.md``.

Modules: :mod:`.config` (parameters), :mod:`.rig` (scene and physical
primitives: set-up, grip force, hand paths, lift-and-hold, drops),
:mod:`.strategy` (the ``pivoting`` strategy), :mod:`.tasks` (the pivoting
task set derived from the published Level I tasks). Importing this package
is cheap: engines and meshes load inside the strategy.
"""

from __future__ import annotations

from benchharness.plugin import Registration

__all__ = ["REGISTRATIONS", "make_pivoting"]


def make_pivoting(**kwargs):
    """Strategy factory: a :class:`~.strategy.PivotingStrategy` (``config=PivotConfig(...)``)."""
    from .strategy import PivotingStrategy

    return PivotingStrategy(**kwargs)


def _options():
    """``--strategy-option`` defaults: :class:`.config.PivotConfig` (grip, set-up, hold, motion ...)."""
    from .config import PivotConfig

    return {"config": PivotConfig()}


REGISTRATIONS = [
    Registration(
        "pivoting",
        make_pivoting,
        "Pivoting about the grasp axis by grip-force control, against the table (parallel gripper, Level I)",
        {
            "levels": [1],
            "hand": "parallel gripper (pr2-gripper)",
            "benchmarks": ["inhand"],
            "robots": ["pr2-gripper"],
        },
        options=_options,
    )
]
