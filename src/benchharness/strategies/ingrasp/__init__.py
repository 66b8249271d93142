"""In-grasp manipulation on the Allegro hand (benchmark Level I), five planners.

After Sundaralingam & Hermans, "Relaxed-rigidity constraints" (RSS 2017;
Autonomous Robots 2019), as compared in the in-hand benchmark's section IV-A:
relaxed-rigidity, relaxed-position, relaxed-position-orientation, IK-rigid and
point-contact, all as one kinematic trajectory optimiser (torch autograd, L-BFGS)
with different costs. See ``docs/ingrasp.md``.

Modules: :mod:`.config` (settings, variant names), :mod:`.hand` (fingertip
FK), :mod:`.rotations`, :mod:`.tasks` (published Level I tasks),
:mod:`.problem` (a task in our hand's frames), :mod:`.planner` (the
optimiser), :mod:`.strategy` (the plugin object: ``plan_task`` and the
runner's ``run_trial``), :mod:`.placement` (where our object model sits in
the initial grasp), :mod:`.execution` (a simulated trial: set-up, execution,
5 s stability check, drops), :mod:`.results` (results files). Importing this package is cheap: torch
loads in the factories.
"""

from __future__ import annotations

from benchharness.plugin import Registration

__all__ = ["REGISTRATIONS", "make_planner"]

_SUMMARIES = {
    "relaxed-rigidity": "in-grasp trajectory optimisation, relaxed rigid fingertip-object attachment (Allegro, Level I)",
    "relaxed-position": "in-grasp trajectory optimisation, fingertip positions on the object relaxed (Allegro, Level I)",
    "relaxed-position-orientation": "in-grasp trajectory optimisation, fingertip positions and orientations relaxed (Allegro, Level I)",
    "ik-rigid": "in-grasp IK along the object path with rigid fingertip contacts (Allegro, Level I)",
    "point-contact": "in-grasp IK along the object path with point contacts, orientation free (Allegro, Level I)",
}


def make_planner(variant: str = "relaxed-rigidity", **kwargs):
    """Strategy factory: an :class:`~.strategy.InGraspPlanner` (keyword arguments pass through)."""
    from .strategy import InGraspPlanner

    return InGraspPlanner(variant, **kwargs)


def _factory(variant: str):
    def factory(**kwargs):
        return make_planner(variant, **kwargs)

    factory.__doc__ = f"Strategy factory for the {variant} in-grasp planner."
    return factory


def _options():
    """``--strategy-option`` defaults: the planner's :class:`.config.IngraspConfig` (every variant
    reads the same one) and the execution's :class:`.execution.ExecConfig` as ``exec_config``."""
    from .config import IngraspConfig
    from .execution import ExecConfig

    return {"config": IngraspConfig(), "exec_config": ExecConfig()}


REGISTRATIONS = [
    Registration(
        name,
        _factory(name),
        summary,
        {"levels": [1], "robots": ["allegro"], "variant": name},
        options=_options,
    )
    for name, summary in _SUMMARIES.items()
]
