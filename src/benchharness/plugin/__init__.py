"""Plugin system: typed hook specifications and an entry-point based manager."""

from .manager import Item, PluginLoadError, PluginManager, PluginNotFoundError, get_manager
from .spec import ENTRY_POINT_GROUP, KIND_HOOKS, Registration, hookimpl, hookspec

__all__ = [
    "ENTRY_POINT_GROUP",
    "KIND_HOOKS",
    "Item",
    "PluginLoadError",
    "PluginManager",
    "PluginNotFoundError",
    "Registration",
    "get_manager",
    "hookimpl",
    "hookspec",
]
