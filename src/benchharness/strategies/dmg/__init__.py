"""Dexterous Manipulation Graph (DMG) planner for a parallel gripper (Level III).

After Cruciani, Smith, Kragic, Hang, "Dexterous Manipulation Graphs", IROS
2018, as evaluated in the in-hand benchmark's Table III. The object surface
is cut into ~1 cm patches; a state is a patch and a gripper angle about its
normal at which the opposite finger meets the object within the opening, in
an antipodal pair, and the gripper clears the object; in-hand motions are
rotations about the contact normal and translations between adjacent
patches, planned as a shortest path. See ``docs/dmg.md``.

Modules: :mod:`.config` (parameters), :mod:`.patches` (surface
discretisation), :mod:`.graph` (construction, "DMG time"), :mod:`.planner`
(queries, "Plan time"), :mod:`.placement` (published data on our meshes),
:mod:`.strategy` (the strategy object, results files), :mod:`.execution`
(executing plans on a simulator with the ``pr2-gripper``: the strategy's
``run_trial``). The Level II task set and the contact-region errors of
stored trials are scoring, in :mod:`benchharness.runner.contact_regions`.
Importing this package is cheap:
trimesh/networkx load inside the factory's products.
"""

from __future__ import annotations

from benchharness.plugin import Registration

__all__ = ["REGISTRATIONS", "make_planner"]


def make_planner(**kwargs):
    """Strategy factory: a :class:`~.strategy.DMGPlanner` (keyword arguments pass through)."""
    from .strategy import DMGPlanner

    return DMGPlanner(**kwargs)


def _options():
    """``--strategy-option`` defaults: the object model (:class:`.config.DMGSurface`; the YCB
    scans), e.g. ``--strategy-option model=generated`` to plan, simulate and score on the shapes
    generated from the published dimensions; and the execution
    (:class:`.execution.DMGExecConfig`), e.g. ``execution.support=table``."""
    from .config import DMGSurface
    from .execution import DMGExecConfig

    return {"surface": DMGSurface(), "execution": DMGExecConfig()}


REGISTRATIONS = [
    Registration(
        "dmg",
        make_planner,
        "Dexterous Manipulation Graph planner (parallel gripper, Levels II/III); runs on pr2-gripper",
        {
            "levels": [2, 3],
            "hand": "parallel gripper (YuMi smart gripper model; executed by pr2-gripper)",
            "benchmarks": ["inhand"],
            "robots": ["pr2-gripper"],
        },
        options=_options,
    )
]
