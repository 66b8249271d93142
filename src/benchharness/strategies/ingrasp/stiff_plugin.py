"""Opt-in plugin: relaxed-rigidity with 100x stiffer rigidity weights (``relaxed-rigidity-stiff``).

Why it exists: with the default weights (goal 1e6 against rigidity 1e3)
the relaxed-rigidity plans reach the published goals by stretching the
fingertip triangle by 2-4 cm, which no rigid object survives in simulation
(``docs/benchmarks/inhand_sim.md``). With ``w_rigid_pos = 1e5`` and
``w_rigid_rot = 1e3`` the triangle changes by a few millimetres and the plan
still ends within a few millimetres of the goal. Not registered by default
(so the built-in plugin list and the planning benchmark are unchanged); use

    benchharness run ... --strategy relaxed-rigidity-stiff --plugin benchharness.strategies.ingrasp.stiff_plugin
"""

from __future__ import annotations

from benchharness.plugin import Registration, hookimpl

STIFF = {"w_rigid_pos": 1.0e5, "w_rigid_rot": 1.0e3}


def make_stiff(**kwargs):
    """Strategy factory: relaxed-rigidity planner/executor with the stiff rigidity weights."""
    from .strategy import InGraspPlanner

    p = InGraspPlanner("relaxed-rigidity", **{**STIFF, **kwargs})
    p.name = "relaxed-rigidity-stiff"
    return p


@hookimpl
def benchharness_strategies() -> list[Registration]:
    return [
        Registration(
            "relaxed-rigidity-stiff",
            make_stiff,
            "relaxed-rigidity with 100x rigidity weights (fingertip triangle kept; Allegro, Level I)",
            {"levels": [1], "hand": "allegro", "variant": "relaxed-rigidity"},
        )
    ]
