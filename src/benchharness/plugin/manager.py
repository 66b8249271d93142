"""Discovers plugins through entry points and keeps the registry of items.

Loading is per entry point and fault-isolated: a plugin that fails to import,
whose hook raises, or that registers a name already taken is recorded as a
:class:`PluginLoadError` naming the entry point and its distribution, and
every other plugin still loads. Lookups of a missing item say which group was
searched, what exists, and which plugins failed, so "robot not found" is never
a dead end.

Order is deterministic: the ``benchharness`` distribution's own entry points
first (built-ins win name clashes), then the others sorted by distribution
and entry-point name.
"""

from __future__ import annotations

import importlib
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from importlib import metadata
from types import ModuleType
from typing import Any

import pluggy

from .spec import ENTRY_POINT_GROUP, KIND_HOOKS, PROJECT, BenchharnessSpec, Registration

__all__ = [
    "Item",
    "PluginLoadError",
    "PluginNotFoundError",
    "PluginManager",
    "get_manager",
]

BUILTIN_DISTRIBUTION = "benchharness"


@dataclass(frozen=True)
class Item:
    """A registered item and where it came from."""

    kind: str
    name: str
    factory: Callable[..., Any]
    summary: str
    distribution: str
    entry_point: str
    meta: dict

    def create(self, **kwargs: Any) -> Any:
        return self.factory(**kwargs)

    def describe(self) -> dict:
        return {
            "kind": self.kind,
            "name": self.name,
            "summary": self.summary,
            "distribution": self.distribution,
            "entry_point": self.entry_point,
            "meta": dict(self.meta),
        }


@dataclass(frozen=True)
class PluginLoadError:
    """Why one entry point (or one of its registrations) was not taken."""

    entry_point: str
    distribution: str
    reason: str

    def __str__(self) -> str:
        return (
            f"entry point {self.entry_point!r} of distribution {self.distribution!r} "
            f"(group {ENTRY_POINT_GROUP!r}): {self.reason}"
        )


class PluginNotFoundError(LookupError):
    """No item of that kind and name is registered."""


def _entry_point_label(ep: metadata.EntryPoint) -> str:
    return f"{ep.name} = {ep.value}"


def _distribution_name(ep: metadata.EntryPoint) -> str:
    dist = getattr(ep, "dist", None)
    return dist.metadata["Name"] if dist is not None else "(unknown distribution)"


class PluginManager:
    """The registry of backends, robots, sensors, strategies and tasks."""

    def __init__(self) -> None:
        self._pm = pluggy.PluginManager(PROJECT)
        self._pm.add_hookspecs(BenchharnessSpec)
        self._items: dict[tuple[str, str], Item] = {}
        self.errors: list[PluginLoadError] = []

    # -- loading -----------------------------------------------------------
    def load_entry_points(self, group: str = ENTRY_POINT_GROUP) -> None:
        eps = list(metadata.entry_points(group=group))
        eps.sort(
            key=lambda ep: (
                _distribution_name(ep) != BUILTIN_DISTRIBUTION,
                _distribution_name(ep).lower(),
                ep.name,
            )
        )
        seen: set[tuple[str, str]] = set()
        for ep in eps:
            dist = _distribution_name(ep)
            if (dist, ep.name) in seen:  # the same distribution seen twice on sys.path
                continue
            seen.add((dist, ep.name))
            label = _entry_point_label(ep)
            try:
                module = ep.load()
            except Exception as exc:  # noqa: BLE001 - any import failure is the plugin's
                self.errors.append(
                    PluginLoadError(label, dist, f"failed to import: {type(exc).__name__}: {exc}")
                )
                continue
            self.register_module(module, entry_point=label, distribution=dist)

    def register_module(
        self,
        module: ModuleType | object,
        *,
        entry_point: str | None = None,
        distribution: str = "(registered in process)",
    ) -> None:
        """Register a plugin object directly (tests, notebooks, embedding)."""
        label = entry_point or getattr(module, "__name__", repr(module))
        try:
            self._pm.register(module, name=label)
        except Exception as exc:  # noqa: BLE001 - pluggy validation errors
            self.errors.append(PluginLoadError(label, distribution, f"invalid plugin: {exc}"))
            return
        for kind, hook_name in KIND_HOOKS.items():
            impl = getattr(module, hook_name, None)
            if impl is None:
                continue
            try:
                regs = impl()
            except Exception as exc:  # noqa: BLE001 - a plugin's hook raising is isolated
                self.errors.append(
                    PluginLoadError(
                        label, distribution, f"hook {hook_name} raised {type(exc).__name__}: {exc}"
                    )
                )
                continue
            for reg in regs or []:
                self._add(kind, reg, label, distribution)

    def _add(self, kind: str, reg: Registration, label: str, dist: str) -> None:
        if not isinstance(reg, Registration):
            self.errors.append(
                PluginLoadError(
                    label, dist, f"{kind} hook returned {type(reg).__name__}, not Registration"
                )
            )
            return
        key = (kind, reg.name)
        if key in self._items:
            first = self._items[key]
            self.errors.append(
                PluginLoadError(
                    label,
                    dist,
                    f"duplicate {kind} name {reg.name!r}: already registered by entry point "
                    f"{first.entry_point!r} of distribution {first.distribution!r}; this one is ignored",
                )
            )
            return
        self._items[key] = Item(
            kind, reg.name, reg.factory, reg.summary, dist, label, dict(reg.meta)
        )

    # -- queries -----------------------------------------------------------
    def items(self, kind: str | None = None) -> list[Item]:
        if kind is not None and kind not in KIND_HOOKS:
            raise ValueError(f"unknown kind {kind!r}; kinds are {', '.join(KIND_HOOKS)}")
        return [it for (k, _), it in self._items.items() if kind is None or k == kind]

    def names(self, kind: str) -> list[str]:
        return [it.name for it in self.items(kind)]

    def get(self, kind: str, name: str) -> Item:
        try:
            return self._items[(kind, name)]
        except KeyError:
            pass
        available = ", ".join(sorted(self.names(kind))) or "(none)"
        msg = [
            f"no {kind} named {name!r} is registered. Available {kind}s: {available}.",
            f"Items are discovered through the {ENTRY_POINT_GROUP!r} entry-point group; "
            f"a distribution providing {name!r} must be installed and declare it under "
            f"[project.entry-points.{ENTRY_POINT_GROUP}].",
        ]
        if self.errors:
            msg.append("Plugins that failed to load:")
            msg.extend(f"  - {e}" for e in self.errors)
        raise PluginNotFoundError("\n".join(msg))

    def create(self, kind: str, name: str, **kwargs: Any) -> Any:
        return self.get(kind, name).create(**kwargs)


_manager: PluginManager | None = None
_lock = threading.Lock()


def get_manager(reload: bool = False) -> PluginManager:
    """The process-wide manager, loaded from entry points on first use."""
    global _manager
    with _lock:
        if _manager is None or reload:
            m = PluginManager()
            m.load_entry_points()
            _manager = m
        return _manager


def iter_kinds() -> Iterable[str]:
    return KIND_HOOKS.keys()


def import_optional(module: str, extra: str) -> ModuleType:
    """Import an optional dependency, naming the extra that installs it."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise ImportError(
            f"{module!r} is not installed; install it with: pip install 'benchharness[{extra}]'"
        ) from exc
