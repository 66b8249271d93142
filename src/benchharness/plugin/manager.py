"""Discovers plugins through entry points and keeps the registry of items.

Every hook is called through pluggy's hook relay (``pm.hook.benchharness_*``),
one entry point at a time (:meth:`pluggy.PluginManager.subset_hook_caller`
leaves the others out), so that:

* **fault isolation**: a plugin that fails to import, names a hook that does
  not exist (``benchharness_robot``), leaves a hook unmarked (no
  ``@hookimpl``: pluggy would never call it), whose hook raises, or that
  registers a name already taken is recorded as a :class:`PluginLoadError`
  naming the entry point and its distribution, and every other plugin still
  loads;
* **provenance**: each item knows the entry point and distribution that
  provided it (``benchharness plugins`` lists them).

A plugin with a hook-name error is refused whole: loading the hooks it spelled
right would hide the one it did not.

Entry points named in ``BENCHHARNESS_DISABLED_PLUGINS`` (comma-separated) are
not imported at all, as tox's ``TOX_DISABLED_EXTERNAL_PLUGINS``: a broken or
unwanted plugin is switched off without uninstalling it.

Lookups of a missing item say which group was searched, what exists, which
plugins failed and which were disabled, so "robot not found" is never a dead
end. Order is deterministic: the ``benchharness`` distribution's own entry
points first (built-ins win name clashes), then the others sorted by
distribution and entry-point name.
"""

from __future__ import annotations

import importlib
import os
import threading
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from importlib import metadata
from types import ModuleType
from typing import Any

import pluggy

from .spec import (
    DISABLED_ENV,
    ENTRY_POINT_GROUP,
    HOOK_PREFIX,
    KIND_HOOKS,
    PROJECT,
    BenchharnessSpec,
    Registration,
)

__all__ = [
    "DisabledPlugin",
    "Item",
    "PluginLoadError",
    "PluginNotFoundError",
    "PluginManager",
    "disabled_names",
    "get_manager",
]

BUILTIN_DISTRIBUTION = "benchharness"


@dataclass(frozen=True)
class Item:
    """A registered item and where it came from.

    ``meta`` is resolved on first use when the registration gave a callable
    (a robot's DOF and groups come from its config, which only listing needs).
    """

    kind: str
    name: str
    factory: Callable[..., Any]
    summary: str
    distribution: str
    entry_point: str
    meta_source: Mapping[str, Any] | Callable[[], Mapping[str, Any]] = field(
        default_factory=dict, repr=False
    )
    #: the registration's ``options`` (strategies): factory keyword -> default config dataclass
    options: Callable[[], Mapping[str, Any]] | None = field(default=None, repr=False)

    @cached_property
    def meta(self) -> dict[str, Any]:
        src = self.meta_source
        return dict(src() if callable(src) else src)

    def create(self, **kwargs: Any) -> Any:
        return self.factory(**kwargs)

    def describe(self) -> dict[str, Any]:
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


@dataclass(frozen=True)
class DisabledPlugin:
    """An entry point named in ``BENCHHARNESS_DISABLED_PLUGINS`` and therefore not loaded."""

    entry_point: str
    distribution: str

    def __str__(self) -> str:
        return (
            f"entry point {self.entry_point!r} of distribution {self.distribution!r} "
            f"(disabled by {DISABLED_ENV})"
        )


class PluginNotFoundError(LookupError):
    """No item of that kind and name is registered."""


def _plural(kind: str) -> str:
    """The plural of an item kind for messages ("strategy" -> "strategies")."""
    return kind[:-1] + "ies" if kind.endswith("y") else kind + "s"


def _entry_point_label(ep: metadata.EntryPoint) -> str:
    return f"{ep.name} = {ep.value}"


def _distribution_name(ep: metadata.EntryPoint) -> str:
    dist = getattr(ep, "dist", None)
    return str(dist.metadata["Name"]) if dist is not None else "(unknown distribution)"


def disabled_names(environ: Mapping[str, str] | None = None) -> frozenset[str]:
    """Entry-point names listed in ``BENCHHARNESS_DISABLED_PLUGINS`` (comma-separated)."""
    raw = (os.environ if environ is None else environ).get(DISABLED_ENV, "")
    return frozenset(n.strip() for n in raw.split(",") if n.strip())


def hook_name_problems(plugin: object, impls: Iterable[str]) -> list[str]:
    """What is wrong with a plugin's ``benchharness_*`` attributes, one line each.

    ``impls`` are the names pluggy registered as hook implementations (marked
    with ``@hookimpl``). A prefixed name that is no hook (a typo; pluggy keeps
    it as a pending hook that nothing calls) or a hook left unmarked (pluggy
    skips it) would otherwise register nothing without a word.
    """
    marked = set(impls)
    hooks = set(KIND_HOOKS.values())
    problems = []
    for attr in sorted(dir(plugin)):
        if not attr.startswith(HOOK_PREFIX) or not callable(getattr(plugin, attr, None)):
            continue
        if attr not in hooks:
            problems.append(f"unknown hook {attr!r}; the hooks are {', '.join(sorted(hooks))}")
        elif attr not in marked:
            problems.append(f"{attr} is not marked with @hookimpl, so it would never be called")
    return problems


class PluginManager:
    """The registry of backends, robots, sensors, strategies and tasks."""

    def __init__(self) -> None:
        self._pm = pluggy.PluginManager(PROJECT)
        self._pm.add_hookspecs(BenchharnessSpec)
        self._items: dict[tuple[str, str], Item] = {}
        self.errors: list[PluginLoadError] = []
        self.disabled: list[DisabledPlugin] = []
        #: names in ``BENCHHARNESS_DISABLED_PLUGINS`` that match no entry point (a typo there)
        self.disabled_unmatched: list[str] = []

    @property
    def pluggy_manager(self) -> pluggy.PluginManager:
        """The underlying pluggy manager (every plugin registered, named by its entry point)."""
        return self._pm

    # -- loading -----------------------------------------------------------
    def load_entry_points(
        self, group: str = ENTRY_POINT_GROUP, disabled: Iterable[str] | None = None
    ) -> None:
        """Load every entry point of ``group`` except those named in ``disabled``.

        ``disabled`` defaults to :func:`disabled_names` (the environment).
        """
        blocked = disabled_names() if disabled is None else frozenset(disabled)
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
            if ep.name in blocked:
                self.disabled.append(DisabledPlugin(label, dist))
                continue
            try:
                module = ep.load()
            except Exception as exc:  # noqa: BLE001 - any import failure is the plugin's
                self.errors.append(
                    PluginLoadError(label, dist, f"failed to import: {type(exc).__name__}: {exc}")
                )
                continue
            self.register_module(module, entry_point=label, distribution=dist)
        names = {ep.name for ep in eps}
        self.disabled_unmatched = sorted(blocked - names)

    def register_module(
        self,
        module: ModuleType | object,
        *,
        entry_point: str | None = None,
        distribution: str = "(registered in process)",
    ) -> None:
        """Register a plugin object (a module, or any object with hook methods) and take its items."""
        label = str(entry_point or getattr(module, "__name__", repr(module)))
        try:
            self._pm.register(module, name=label)
        except Exception as exc:  # noqa: BLE001 - pluggy validation errors, a name taken twice
            self.errors.append(PluginLoadError(label, distribution, f"invalid plugin: {exc}"))
            return
        impls = [
            caller.name
            for caller in self._pm.get_hookcallers(module) or []
            if caller.name.startswith(HOOK_PREFIX)
        ]
        problems = hook_name_problems(module, impls)
        if problems:
            self._pm.unregister(module)
            self.errors.append(
                PluginLoadError(label, distribution, "not loaded: " + "; ".join(problems))
            )
            return
        others = [p for p in self._pm.get_plugins() if p is not module]
        for kind, hook_name in KIND_HOOKS.items():
            if hook_name not in impls:
                continue
            call = self._pm.subset_hook_caller(hook_name, remove_plugins=others)
            try:
                results = call()
            except Exception as exc:  # noqa: BLE001 - a plugin's hook raising is isolated
                self.errors.append(
                    PluginLoadError(
                        label,
                        distribution,
                        f"hook {hook_name} raised {type(exc).__name__}: {exc}",
                    )
                )
                continue
            for regs in results:
                for reg in regs or []:
                    self._add(kind, reg, label, distribution)

    def _add(self, kind: str, reg: object, label: str, dist: str) -> None:
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
            kind, reg.name, reg.factory, reg.summary, dist, label, reg.meta, reg.options
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
            f"no {kind} named {name!r} is registered. Available {_plural(kind)}: {available}.",
            f"Items are discovered through the {ENTRY_POINT_GROUP!r} entry-point group; "
            f"a distribution providing {name!r} must be installed and declare it under "
            f"[project.entry-points.{ENTRY_POINT_GROUP}].",
        ]
        if self.errors:
            msg.append("Plugins that failed to load:")
            msg.extend(f"  - {e}" for e in self.errors)
        if self.disabled:
            msg.append(f"Plugins disabled by {DISABLED_ENV}:")
            msg.extend(f"  - {d}" for d in self.disabled)
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
