"""Built-in robots: PR2, HERB, the Allegro hand and the stand-alone PR2 gripper.

Each registration names the module holding the robot's config function and
factory; both are imported only when used. The listed facts (DOF, joint
groups, URDF) are read off the config by
:func:`benchharness.robots.config.robot_meta` the first time they are asked
for, so they cannot drift from the robot, and listing plugins imports no
robot code.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any

from benchharness.plugin import Registration, hookimpl

#: name -> (module under benchharness.robots, config function, factory, summary)
ROBOTS = {
    "pr2": (
        "pr2",
        "pr2_config",
        "make_pr2",
        "Willow Garage PR2: torso, two 7-DOF arms, parallel grippers",
    ),
    "herb": (
        "herb",
        "herb_config",
        "make_herb",
        "CMU HERB: two Barrett WAM arms with BarrettHand BH8-280",
    ),
    "allegro": (
        "allegro",
        "allegro_config",
        "make_allegro",
        "Allegro hand v4 (right), 16 joints",
    ),
    "pr2-gripper": (
        "pr2_gripper",
        "pr2_gripper_config",
        "make_pr2_gripper",
        "PR2 parallel gripper on a 6-DOF stage (in-hand pivoting / DMG execution)",
    ),
}


def _attr(module: str, name: str) -> Any:
    return getattr(importlib.import_module(f"benchharness.robots.{module}"), name)


def _factory(module: str, name: str) -> Callable[..., Any]:
    def factory(**kwargs: Any) -> Any:
        return _attr(module, name)(**kwargs)

    factory.__doc__ = f"Plugin factory: benchharness.robots.{module}.{name}(**kwargs)."
    return factory


def _meta(module: str, config: str) -> Callable[[], Mapping[str, Any]]:
    def meta() -> Mapping[str, Any]:
        from benchharness.robots.config import robot_meta

        return robot_meta(_attr(module, config)())

    return meta


@hookimpl
def benchharness_robots() -> list[Registration]:
    return [
        Registration(name, _factory(module, make), summary, _meta(module, config))
        for name, (module, config, make, summary) in ROBOTS.items()
    ]
