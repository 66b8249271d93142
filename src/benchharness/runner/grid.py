"""Sweep grids: tasks × robots × strategies × backends × seeds × physics, expanded into runs.

A grid is the product of its axes; each combination is one :class:`RunSpec`
with the run key ``benchharness run`` would give it, so a sweep resumes,
shares and reports exactly like the ``run`` commands it stands for.

Combinations that cannot run (a strategy that does not drive the robot, a
strategy written for the other benchmark) are expected in a product — three
Rubik's baselines and one in-hand method in one grid — so they are *skipped*
with a note. A name that takes part in no runnable combination at all is a
mistake, not a product: the grid is refused before anything runs.
"""

from __future__ import annotations

import itertools
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .contract import TimeBudget
from .spec import RunSpec, parse_physics

__all__ = ["Grid", "GridPlan", "expand", "load_grid"]

_AXES = ("tasks", "robots", "strategies", "backends", "seeds", "physics")


@dataclass(frozen=True)
class Grid:
    """The axes of a sweep (each a tuple: the product is the grid) and the settings shared by all."""

    tasks: tuple[str, ...]
    robots: tuple[str, ...]
    strategies: tuple[str, ...]
    backends: tuple[str, ...] = ("pybullet",)
    seeds: tuple[int, ...] = (0,)
    #: Each entry is one physics setting set (``KEY=VALUE`` strings), one grid axis.
    physics: tuple[tuple[str, ...], ...] = ((),)
    sensors: tuple[str, ...] = ()
    repeats: int = 1
    sim_budget: float | None = None
    wall_budget: float | None = None
    plugins: tuple[str, ...] = ()
    #: ``--strategy-option`` settings (``KEY=VALUE``) per strategy name; ``"*"`` applies to every
    #: strategy of the grid (the command line's, which come last). For one key, the later wins.
    strategy_options: tuple[tuple[str, tuple[str, ...]], ...] = ()


@dataclass
class GridPlan:
    specs: list[RunSpec] = field(default_factory=list)
    #: One line per combination left out, saying why.
    skipped: list[str] = field(default_factory=list)


def _tuple(value: Any, name: str, kind: type) -> tuple:
    items = value if isinstance(value, list) else [value]
    for v in items:
        if not isinstance(v, kind) or isinstance(v, bool):
            raise ValueError(f"grid {name}: {v!r} is not a {kind.__name__}")
    return tuple(items)


def load_grid(path: Path) -> Grid:
    """A grid from TOML: top-level keys named like :class:`Grid`'s fields (lists or single values).

    ``physics`` is a list of tables (``[[physics]]`` or ``physics = [{timestep = "1/500"}]``),
    each one setting set; values as on the command line. ``[strategy_options.NAME]`` tables
    hold one strategy's ``--strategy-option`` settings (``pretouch_mode = "grid"``; a list is
    a comma list).
    """
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # Python 3.10
        import tomli as tomllib

    try:
        data = tomllib.loads(Path(path).read_text())
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: cannot read ({exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not TOML ({exc})") from None
    known = {f for f in Grid.__dataclass_fields__}
    unknown = sorted(set(data) - known)
    if unknown:
        raise ValueError(f"{path}: unknown key {unknown[0]!r} (known: {', '.join(sorted(known))})")
    for need in ("tasks", "robots", "strategies"):
        if need not in data:
            raise ValueError(f"{path}: {need!r} is missing")
    kw: dict[str, Any] = {}
    for name in ("tasks", "robots", "strategies", "backends", "sensors", "plugins"):
        if name in data:
            kw[name] = _tuple(data[name], name, str)
    if "seeds" in data:
        kw["seeds"] = _tuple(data["seeds"], "seeds", int)
    if "physics" in data:
        sets = data["physics"] if isinstance(data["physics"], list) else [data["physics"]]
        if not all(isinstance(s, dict) for s in sets):
            raise ValueError(f"{path}: physics must be a list of tables of settings")
        kw["physics"] = tuple(tuple(f"{k}={v}" for k, v in s.items()) for s in sets) or ((),)
    if "strategy_options" in data:
        table = data["strategy_options"]
        if not isinstance(table, dict) or not all(isinstance(v, dict) for v in table.values()):
            raise ValueError(
                f"{path}: strategy_options must be tables [strategy_options.STRATEGY] of settings"
            )
        kw["strategy_options"] = tuple(
            (name, tuple(f"{k}={_toml_text(v)}" for k, v in opts.items()))
            for name, opts in table.items()
        )
    for name, kind in (("repeats", int), ("sim_budget", float), ("wall_budget", float)):
        if name in data:
            v = data[name]
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ValueError(f"grid {name}: {v!r} is not a number")
            kw[name] = kind(v)
    return Grid(**kw)


def _toml_text(value: Any) -> str:
    """A TOML value as the command line would spell it (``true``, ``0.25,0.35``)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list):
        return ",".join(_toml_text(v) for v in value)
    return str(value)


def _strategy_options(grid: Grid, item: Any) -> tuple[tuple[str, str], ...]:
    """The canonical options of one strategy of the grid (ValueError naming strategy and key)."""
    from .options import normalise_options

    pairs: list[str] = []
    for name, opts in grid.strategy_options:
        if name in ("*", item.name):
            pairs += list(opts)
    # for one key the later entry wins (the command line's "*" entries come after the file's)
    merged = {p.split("=", 1)[0].strip().replace("-", "_"): p for p in pairs}
    try:
        return normalise_options(item.options, item.name, list(merged.values()), item.factory)
    except ValueError as exc:
        raise ValueError(f"strategy {item.name}: {exc}") from None


def expand(grid: Grid) -> GridPlan:
    """The grid's runs in axis order; raises ValueError (naming it) for a value that cannot run at all.

    Every name is looked up, every physics set parsed and every task planned
    here, so nothing runs unless the whole grid is valid.
    """
    from ..plugin import PluginNotFoundError
    from .plugins import check_strategy_robot, lookup
    from .tasks import plan_task

    for name in _AXES:
        if not getattr(grid, name):
            raise ValueError(f"grid {name}: empty")
    if grid.repeats < 1:
        raise ValueError("--repeats must be at least 1")
    for name, value in (("--sim-budget", grid.sim_budget), ("--wall-budget", grid.wall_budget)):
        if value is not None and not (value > 0 and value != float("inf")):
            raise ValueError(f"{name} {value}: must be a positive finite number of seconds")
    try:
        physics = [parse_physics(list(p)) for p in grid.physics]
    except ValueError as exc:
        raise ValueError(f"--physics: {exc}") from None
    for seed in grid.seeds:
        if not 0 <= seed <= 2**63 - 1:
            raise ValueError(f"--seeds {seed}: must be an integer in 0..{2**63 - 1} (2**63 - 1)")
    plugins = tuple(grid.plugins)
    try:
        for kind, names in (
            ("backend", grid.backends),
            ("robot", grid.robots),
            ("sensor", grid.sensors),
        ):
            for n in names:
                lookup(kind, n, plugins)
        strategies = {s: lookup("strategy", s, plugins) for s in grid.strategies}
        for name, _ in grid.strategy_options:
            if name != "*" and name not in strategies:
                raise ValueError(f"strategy_options: {name!r} is not a strategy of this grid")
        options = {s: _strategy_options(grid, item) for s, item in strategies.items()}
        plans = {}
        for t in grid.tasks:
            item = lookup("task", t, plugins)
            for seed in grid.seeds:
                plans[t, seed] = plan_task(item.name, item.create(), seed, grid.repeats)
    except PluginNotFoundError as exc:
        raise ValueError(str(exc)) from None
    out = GridPlan()
    used: dict[str, set[str]] = {"tasks": set(), "robots": set(), "strategies": set()}
    first_reason: dict[tuple[str, str], str] = {}
    for task, robot, strategy, backend, seed, phys in itertools.product(
        grid.tasks, grid.robots, grid.strategies, grid.backends, grid.seeds, physics
    ):
        plan = plans[task, seed]
        item = strategies[strategy]
        supported = item.meta.get("benchmarks") or getattr(item.factory, "benchmarks", None)
        why = None
        if supported is not None and plan.benchmark not in tuple(supported):
            why = f"strategy {strategy!r} runs {', '.join(supported)} tasks, not {plan.benchmark} ({plan.name})"
        else:
            try:
                check_strategy_robot(strategy, robot, plugins)
            except (TypeError, ValueError) as exc:
                why = str(exc)
        if why is not None:
            for axis, v in (("tasks", task), ("robots", robot), ("strategies", strategy)):
                first_reason.setdefault((axis, v), why)
            note = f"skipped {task} × {strategy}/{robot}: {why}"
            if note not in out.skipped:
                out.skipped.append(note)
            continue
        used["tasks"].add(task)
        used["robots"].add(robot)
        used["strategies"].add(strategy)
        sim = grid.sim_budget
        if sim is None:
            if plan.benchmark == "rubiks":
                first = next(iter(plan.items.values()))
                sim = 120.0 + 60.0 * len(getattr(first, "sequence", ()))
            else:
                sim = 120.0
        out.specs.append(
            RunSpec(
                task=plan.name,
                robot=robot,
                strategy=strategy,
                backend=backend,
                seed=seed,
                sensors=tuple(grid.sensors),
                physics=phys,
                budget=TimeBudget(sim, grid.wall_budget),
                repeats=grid.repeats,
                plugins=plugins,
                strategy_options=options[strategy],
            )
        )
    for axis in ("strategies", "robots", "tasks"):
        for v in getattr(grid, axis):
            if v not in used[axis]:
                raise ValueError(
                    f"{axis[:-1] if axis != 'strategies' else 'strategy'} {v!r} is in no runnable "
                    f"combination of this grid: {first_reason[axis, v]}"
                )
    return out
