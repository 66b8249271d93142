"""Plugin system: typed hook specifications and an entry-point based manager."""

from .manager import (
    DisabledPlugin,
    Item,
    PluginLoadError,
    PluginManager,
    PluginNotFoundError,
    disabled_names,
    get_manager,
)
from .spec import DISABLED_ENV, ENTRY_POINT_GROUP, KIND_HOOKS, Registration, hookimpl, hookspec

__all__ = [
    "DISABLED_ENV",
    "ENTRY_POINT_GROUP",
    "KIND_HOOKS",
    "DisabledPlugin",
    "Item",
    "PluginLoadError",
    "PluginManager",
    "PluginNotFoundError",
    "Registration",
    "disabled_names",
    "get_manager",
    "hookimpl",
    "hookspec",
]
