"""The plugin manager a run uses, with any ``--plugin`` modules registered.

Extra plugin modules (a user's strategy under development, the tests'
throw-away strategies) are named by import path rather than registered on the
process-wide manager, because sweep workers are fresh *spawned* processes:
they rebuild the manager from entry points and must register the same
modules to see the same items. A separate cached manager per module list
keeps those items out of the process-wide registry.
"""

from __future__ import annotations

import importlib
from functools import lru_cache
from typing import Any

from ..plugin import Item, PluginManager, PluginNotFoundError, get_manager
from .contract import check_drives

__all__ = ["manager_for", "lookup", "create_item", "create_strategy", "check_strategy_robot"]


@lru_cache(maxsize=8)
def _manager_with(plugins: tuple[str, ...]) -> PluginManager:
    m = PluginManager()
    m.load_entry_points()
    for name in plugins:
        try:
            module = importlib.import_module(name)
        except ImportError as exc:
            raise PluginNotFoundError(f"--plugin {name!r}: cannot import it: {exc}") from exc
        m.register_module(module, entry_point=f"--plugin {name}", distribution="(--plugin)")
    return m


def manager_for(plugins: tuple[str, ...] = ()) -> PluginManager:
    return _manager_with(tuple(plugins)) if plugins else get_manager()


def lookup(kind: str, name: str, plugins: tuple[str, ...] = ()) -> Item:
    """The item, matching case-insensitively when there is no exact match (tier names)."""
    m = manager_for(plugins)
    try:
        return m.get(kind, name)
    except PluginNotFoundError:
        folded = [n for n in m.names(kind) if n.lower() == name.strip().lower()]
        if len(folded) == 1:
            return m.get(kind, folded[0])
        raise


def create_item(kind: str, name: str, plugins: tuple[str, ...] = (), **kwargs: Any) -> Any:
    return lookup(kind, name, plugins).create(**kwargs)


def create_strategy(spec: Any) -> Any:
    """The run's strategy, its factory given the run's ``--strategy-option`` settings.

    ``spec`` is a :class:`~.spec.RunSpec`. Without options the factory is
    called bare, exactly as before options existed.
    """
    item = lookup("strategy", spec.strategy, spec.plugins)
    if not spec.strategy_options:
        return item.create()
    from .options import apply_options

    if item.options is None:
        raise ValueError(f"strategy {spec.strategy!r} declares no options")
    kwargs, _ = apply_options(item.options(), spec.strategy_options)
    return item.create(**kwargs)


def check_strategy_robot(strategy: str, robot: str, plugins: tuple[str, ...] = ()) -> None:
    """Refuse a robot the strategy does not drive (:func:`.contract.check_drives`), before any trial.

    Unknown names are left to the lookups that report them (:func:`lookup`
    of the strategy and the robot); only a known strategy's declaration is
    checked here, from its registration, so the strategy is not built.
    """
    try:
        item = lookup("strategy", strategy, plugins)
    except PluginNotFoundError:
        return
    check_drives(item.name, item.meta, robot)
