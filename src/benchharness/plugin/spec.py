"""Hook specifications: the contract between benchharness and its plugins.

A plugin is any module named by an entry point in the ``benchharness`` group.
It implements one or more of the hooks below, each returning a list of
:class:`Registration`. The built-in backends, robots, sensors, strategies and
tasks are registered by modules in ``plugins/benchharness_builtins`` through
this same entry-point group, so a third-party distribution has exactly the
powers the built-ins have.

Example (a third-party ``my_robot_plugin.py``)::

    from benchharness.plugin import Registration, hookimpl

    @hookimpl
    def benchharness_robots():
        return [Registration("my-arm", make_my_arm, "My 6-DOF arm")]

and in that distribution's ``pyproject.toml``::

    [project.entry-points.benchharness]
    my_robot = "my_robot_plugin"

The manager calls each hook through pluggy's hook relay, so a hook must carry
``@hookimpl``; a ``benchharness_*`` attribute that is not one of the hooks
below, or is one left unmarked, makes the plugin a load error (see
``docs/plugins.md``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import pluggy

PROJECT = "benchharness"
ENTRY_POINT_GROUP = "benchharness"
#: Every hook's name starts with this; any other attribute of a plugin that does is a typo.
HOOK_PREFIX = "benchharness_"
#: Comma-separated entry-point names that the manager does not load (as tox's
#: ``TOX_DISABLED_EXTERNAL_PLUGINS``).
DISABLED_ENV = "BENCHHARNESS_DISABLED_PLUGINS"

hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)

#: The kinds of item a plugin can register, mapped to the hook that registers them.
KIND_HOOKS: Mapping[str, str] = {
    "backend": "benchharness_backends",
    "robot": "benchharness_robots",
    "sensor": "benchharness_sensors",
    "strategy": "benchharness_strategies",
    "task": "benchharness_tasks",
}


@dataclass(frozen=True)
class Registration:
    """One named item a plugin provides.

    ``factory`` builds the item (a backend, robot, sensor or strategy instance,
    or a task definition); its keyword arguments are the item's own business.
    ``summary`` is the one line shown by ``benchharness plugins``. ``meta``
    holds any extra, JSON-serialisable facts the item wants listed (e.g. a
    backend's capability flags or a robot's DOF), or a function returning
    them, called the first time they are read: a robot's DOF and groups come
    from its config, and building configs need not slow every command down.
    ``options`` (strategies) returns the factory's configuration keywords
    with their default dataclass instances, e.g. ``{"config": MyConfig()}``:
    what ``--strategy-option KEY=VALUE`` may set (see
    :mod:`benchharness.runner.options`); the factory is then called with
    those keywords. Called only when options are given or listed.
    """

    name: str
    factory: Callable[..., Any]
    summary: str = ""
    meta: Mapping[str, Any] | Callable[[], Mapping[str, Any]] = field(default_factory=dict)
    options: Callable[[], Mapping[str, Any]] | None = None


class BenchharnessSpec:
    """The hooks. Each returns the items of one kind that a plugin provides.

    The bodies never run: pluggy reads the names and signatures only.
    """

    @hookspec
    def benchharness_backends(self) -> list[Registration]:
        """Physics backends (engines behind :class:`benchharness.backends.Backend`)."""
        raise NotImplementedError  # a specification: pluggy calls the implementations

    @hookspec
    def benchharness_robots(self) -> list[Registration]:
        """Robots: description, kinematics and motion primitives."""
        raise NotImplementedError  # a specification: pluggy calls the implementations

    @hookspec
    def benchharness_sensors(self) -> list[Registration]:
        """Sensors and pose estimators."""
        raise NotImplementedError  # a specification: pluggy calls the implementations

    @hookspec
    def benchharness_strategies(self) -> list[Registration]:
        """Manipulation strategies (baselines and users' own methods)."""
        raise NotImplementedError  # a specification: pluggy calls the implementations

    @hookspec
    def benchharness_tasks(self) -> list[Registration]:
        """Benchmark tasks: Rubik's tiers, in-hand task sets."""
        raise NotImplementedError  # a specification: pluggy calls the implementations
