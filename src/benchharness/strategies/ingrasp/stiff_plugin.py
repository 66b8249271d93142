"""Opt-in plugin: relaxed-rigidity with 100x stiffer rigidity weights (``relaxed-rigidity-stiff``).

Why it exists: with the weights before 2026-12-02 (goal 1e6 against a pose-coupled
rigidity 1e3) the relaxed-rigidity plans stretched the fingertip triangle by 2-4 cm
and dropped objects. Its weights now apply to the position-only rigidity term
(docs/ingrasp.md), where they have not been re-measured. Kept (2026-12-02): with the
converging solver the default relaxed-rigidity executes like point-contact, but it
still drops one trial point-contact holds and only ties its err_pos (BENCHMARKS.md,
2026-12-02), so the default does not yet hold on its own. Not registered by default
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
