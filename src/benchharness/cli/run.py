"""``benchharness run | table | compare | results``: simulation sweeps and their reports.

Thin: parse options into a :class:`~benchharness.runner.RunSpec`, call the
runner, print. Exit codes (as everywhere): 0 every selected trial succeeded,
1 some trial failed (a tier not completed), 2 bad input (unknown robot,
strategy, task ..., with the plugin manager's message). See docs/runner.md.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import click

from .common import EXIT_NEGATIVE, emit_json, fail, json_option, print_table
from .common import console as _rich_console
from .validate import SEED_MAX

_CTX = {"help_option_names": ["-h", "--help"], "max_content_width": 110}

#: A seed filter the store can hold (a larger one would be an SQLite OverflowError).
_SEED = click.IntRange(0, SEED_MAX)


def _console(stderr: bool = False):
    return _rich_console(stderr)


def _fmt(x: float | None, digits: int = 2) -> str:
    if x is None:
        return "—"
    try:
        if x != x:  # NaN
            return "—"
    except TypeError:
        return str(x)
    return f"{x:.{digits}f}" if abs(x) >= 10**-digits or x == 0 else f"{x:.2g}"


def _esc(text: object) -> str:
    """Cell text without rich markup (task ids and messages may hold brackets)."""
    from rich.markup import escape

    return escape(str(text))


def _names(text: str | None) -> tuple[str, ...]:
    return tuple(n.strip() for n in (text or "").split(",") if n.strip())


def store_option(f: Callable) -> Callable:
    return click.option(
        "--store",
        "store_path",
        type=click.Path(dir_okay=False, path_type=Path),
        default=None,
        help="Results store (SQLite). Default: $BENCHHARNESS_STORE, else ./benchharness-results.sqlite.",
    )(f)


def _open_store(path: Path | None, read_only: bool = False):
    """The store (exit 2 naming the path if it is not one); ``read_only`` for commands that read."""
    from ..runner.store import ResultsStore, StoreError

    try:
        return ResultsStore(path, read_only=read_only)
    except StoreError as exc:
        fail(str(exc))


def run_options(f: Callable) -> Callable:
    """Options shared by ``run`` and ``compare`` (everything but the backend)."""
    opts = [
        click.option(
            "--task",
            required=True,
            help="Rubik's tier (Rubiks-5-20) or in-hand task set (inhand-level1).",
        ),
        click.option("--robot", required=True, help="Robot plugin name (benchharness plugins)."),
        click.option("--strategy", required=True, help="Strategy plugin name."),
        click.option(
            "--seed",
            type=int,
            default=0,
            show_default=True,
            help="Run seed: the protocol's sequences and every trial's random streams.",
        ),
        click.option("--sensors", default="", help="Comma-separated sensor plugin names."),
        click.option(
            "--workers",
            type=int,
            default=None,
            help="Worker processes (default: half the cores, at least 1; 0 runs in this process).",
        ),
        click.option(
            "--trials",
            "trial_sel",
            default=None,
            help="Only these trial indices, e.g. 1,3-5 (default all).",
        ),
        click.option(
            "--repeats",
            type=int,
            default=1,
            show_default=True,
            help="In-hand: trials per task row.",
        ),
        click.option(
            "--strategy-option",
            "strategy_kv",
            multiple=True,
            metavar="KEY=VALUE",
            help="A field of the strategy's config, repeatable: pretouch_mode=grid, "
            "errors.tracking_std=0.002 (list them: benchharness plugins --options STRATEGY).",
        ),
        click.option(
            "--physics",
            "physics_kv",
            multiple=True,
            metavar="KEY=VALUE",
            help="PhysicsConfig setting, repeatable: timestep=1/500, solver_iterations=100, ...",
        ),
        click.option(
            "--sim-budget",
            type=float,
            default=None,
            help="Simulated seconds per trial (default Rubik's 120 + 60 per move; in-hand 120).",
        ),
        click.option(
            "--wall-budget",
            type=float,
            default=None,
            help="Wall-clock seconds per trial (default none, so results never depend on machine "
            "speed; a stuck trial is still ended after max(600 s, 10 x the simulated budget)).",
        ),
        click.option(
            "--plugin",
            "plugins",
            multiple=True,
            metavar="MODULE",
            help="Also register this importable plugin module (a strategy under development).",
        ),
        click.option(
            "--retry-failed",
            is_flag=True,
            help="Re-run stored failed trials instead of skipping them.",
        ),
        click.option(
            "--progress/--no-progress",
            default=None,
            help="Progress bar on stderr (default: when a terminal).",
        ),
        store_option,
        json_option,
    ]
    for o in reversed(opts):
        f = o(f)
    return f


def _spec(
    *,
    task: str,
    robot: str,
    strategy: str,
    backend: str,
    seed: int,
    sensors: str | None,
    repeats: int,
    physics_kv: tuple[str, ...],
    sim_budget: float | None,
    wall_budget: float | None,
    plugins: tuple[str, ...],
    strategy_kv: tuple[str, ...] = (),
    trial_sel: str | None = None,
    workers: int | None = None,
):
    """The run's :class:`RunSpec`, every argument checked before a store is opened (exit 2 naming one).

    Keyword-only: ``run`` and ``compare`` pass fourteen of the same click values, and a swapped pair
    of positional ones (two budgets, two tuples) would not fail, only mis-run."""
    from ..plugin import PluginNotFoundError
    from ..runner.contract import TimeBudget
    from ..runner.options import normalise_options
    from ..runner.plugins import check_strategy_robot, lookup
    from ..runner.spec import RunSpec, parse_physics
    from ..runner.tasks import parse_trial_selection, plan_task
    from .validate import check_seed

    try:
        check_seed(seed)
        physics = parse_physics(list(physics_kv))
    except ValueError as exc:
        fail(str(exc) if str(exc).startswith("--") else f"--physics: {exc}")
    if repeats < 1:
        fail("--repeats must be at least 1")
    if workers is not None and workers < 0:
        fail(f"--workers {workers}: must be 0 or more")
    for name, value in (("--sim-budget", sim_budget), ("--wall-budget", wall_budget)):
        if value is not None and not (value > 0 and value != float("inf")):  # NaN fails too
            fail(f"{name} {value}: must be a positive finite number of seconds")
    try:
        item = lookup("task", task, tuple(plugins))
        plan = plan_task(item.name, item.create(), seed, repeats)
        parse_trial_selection(trial_sel, sorted(plan.items))
        check_strategy_robot(strategy, robot, tuple(plugins))
        strategy_item = lookup("strategy", strategy, tuple(plugins))
        options = normalise_options(
            strategy_item.options, strategy_item.name, strategy_kv, strategy_item.factory
        )
    except (PluginNotFoundError, TypeError, ValueError) as exc:
        fail(str(exc))
    if sim_budget is None:
        if plan.benchmark == "rubiks":
            first = next(iter(plan.items.values()))
            sim_budget = 120.0 + 60.0 * len(first.sequence)
        else:
            sim_budget = 120.0
    return RunSpec(
        task=plan.name,
        robot=robot,
        strategy=strategy,
        backend=backend,
        seed=seed,
        sensors=_names(sensors),
        physics=physics,
        budget=TimeBudget(sim_budget, wall_budget),
        repeats=repeats,
        plugins=tuple(plugins),
        strategy_options=options,
    )


class _Progress:
    """A rich progress bar: trials done / total, failures, ETA."""

    def __init__(self, enabled: bool, label: str) -> None:
        self.enabled, self.label = enabled, label
        self.progress = None
        self.task = None
        self.failures = 0

    def start(self, report, pending: int) -> None:
        if not self.enabled:
            return
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        self.progress = Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("failures: {task.fields[failures]}"),
            TimeElapsedColumn(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
            console=_console(stderr=True),
            transient=False,
        )
        self.progress.start()
        self.task = self.progress.add_task(self.label, total=pending, failures=0)

    def record(self, rec) -> None:
        if self.progress is None:
            return
        self.failures += rec.failed
        self.progress.update(self.task, advance=1, failures=self.failures)

    def stop(self) -> None:
        if self.progress is not None:
            self.progress.stop()


def _sweep(spec, store, workers, trial_sel, retry_failed, progress, video=None):
    import sys

    from ..plugin import PluginNotFoundError
    from ..runner.sweep import default_workers, run_sweep

    workers = default_workers() if workers is None else workers  # checked by _spec
    show = sys.stderr.isatty() if progress is None else progress
    bar = _Progress(show, f"{spec.task} {spec.strategy}/{spec.robot}/{spec.backend}")
    try:
        return run_sweep(
            spec,
            store,
            workers=workers,
            trials=trial_sel,
            retry_failed=retry_failed,
            video=video,
            on_start=bar.start,
            on_record=bar.record,
        )
    except (PluginNotFoundError, ValueError, TypeError) as exc:
        fail(str(exc))
    except KeyboardInterrupt as exc:  # Ctrl-C or SIGTERM: finished trials are stored
        import signal

        bar.stop()
        n = store.count(spec.run_key)
        signum = getattr(exc, "signum", signal.SIGINT)
        fail(
            f"interrupted ({signal.Signals(signum).name}); {n} trial(s) of run {spec.run_key} "
            f"are in {store.path}. Re-run the same command to resume.",
            128 + signum,
        )
    finally:
        bar.stop()


def _trial_json(t) -> dict[str, Any]:
    from ..runner.tasks import trial_task

    tid = trial_task(t.task, t.trial_index, t.outcome)
    return {
        "run_key": t.run_key,
        "trial": t.trial_index,
        "task": t.task,
        **({"task_id": tid[0], "object": tid[1], "repeat": tid[2]} if tid else {}),
        "robot": t.robot,
        "strategy": t.strategy,
        "sensors": t.sensors,
        "backend": t.backend,
        "seed": t.seed,
        "status": t.status.value,
        "score": t.score,
        "failure_cause": t.failure_cause.value if t.failure_cause else None,
        "message": t.message,
        "wall_s": t.wall_s,
        "sim_s": t.sim_s,
        "first_contact_s": t.first_contact_s,
        "termination_s": t.termination_s,
        "code_version": t.code_version,
        "physics_hash": t.physics_hash,
    }


def _trials_table(rows, title: str, show_run: bool = False):
    from rich.table import Table

    from ..runner.tasks import trial_task

    table = Table(title=title)
    if show_run:
        for c in ("task", "method", "seed"):
            table.add_column(c, no_wrap=True)
    # in-hand trials: which task row and object (docs/runner.md, trial numbering)
    ids = [trial_task(t.task, t.trial_index, t.outcome) for t in rows]
    inhand = any(ids)
    for c, j in (
        ("trial", "right"),
        *((("task id", "left"), ("object", "left")) if inhand else ()),
        ("status", "left"),
        ("score", "right"),
        ("cause", "left"),
        ("sim s", "right"),
        ("wall s", "right"),
        ("message", "left"),
    ):
        table.add_column(c, justify=j)
    for t, tid in zip(rows, ids):
        lead = [_esc(t.task), _esc(t.method), str(t.seed)] if show_run else []
        table.add_row(
            *lead,
            str(t.trial_index),
            *([_esc(tid[0]), _esc(tid[1])] if tid else ["", ""] if inhand else []),
            t.status.value,
            _fmt(t.score, 3),
            t.failure_cause.value if t.failure_cause else "",
            _fmt(t.sim_s, 2),
            _fmt(t.wall_s, 2),
            _esc(t.message or ""),
        )
    return table


def _summary(spec, store, benchmark: str, total: int, selected: Sequence[int]):
    from ..cube import get_tier
    from ..runner.reports import rubiks_cell

    rows = [t for t in store.trials(run_key=spec.run_key) if t.trial_index in set(selected)]
    cell = None
    if benchmark == "rubiks":
        cell = rubiks_cell(store.trials(run_key=spec.run_key), get_tier(spec.task).trials)
    return rows, cell


# -- run ---------------------------------------------------------------------------------------


@click.command("run", context_settings=_CTX)
@run_options
@click.option(
    "--backend",
    default="pybullet",
    show_default=True,
    help="Backend plugin name (pybullet, sapien).",
)
@click.option(
    "--video",
    "video_path",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Record one trial as MP4 (GIF if the path ends .gif) through Backend.render.",
)
@click.option(
    "--video-trial", type=int, default=1, show_default=True, help="Which trial --video records."
)
@click.option(
    "--video-fps",
    type=float,
    default=8.0,
    show_default=True,
    help="Frames per *simulated* second.",
)
@click.option(
    "--video-view",
    type=click.Choice(["close", "wide"]),
    default="close",
    show_default=True,
    help="close: both hands and the cube (in-hand: the hand); wide: the whole robot.",
)
@click.option(
    "--video-size",
    default="400x300",
    show_default=True,
    help="Frame size WIDTHxHEIGHT.",
)
def run(
    task,
    robot,
    strategy,
    seed,
    sensors,
    workers,
    trial_sel,
    repeats,
    strategy_kv,
    physics_kv,
    sim_budget,
    wall_budget,
    plugins,
    retry_failed,
    progress,
    store_path,
    as_json,
    backend,
    video_path,
    video_trial,
    video_fps,
    video_view,
    video_size,
) -> None:
    """Run a task's trials with a robot, strategy, sensors and backend; store each as it ends.

    Re-running the same command resumes: trials already in the store under the
    same run key (task, robot, strategy, sensors, backend, seed, physics,
    budgets, code version) are skipped.

    \b
    Examples:
      benchharness run --task Rubiks-5-20 --robot pr2 --strategy sensor-aided --backend pybullet --seed 0
      benchharness run --task inhand-level1 --robot allegro --strategy relaxed-rigidity --repeats 5
      benchharness run --task Rubiks-1-5 --robot pr2 --strategy dead-reckoning --video trial1.mp4
      benchharness run --task Rubiks-5-5 --robot pr2 --strategy sensor-aided --strategy-option pretouch_mode=grid
    """
    spec = _spec(
        task=task,
        robot=robot,
        strategy=strategy,
        backend=backend,
        seed=seed,
        sensors=sensors,
        repeats=repeats,
        physics_kv=physics_kv,
        sim_budget=sim_budget,
        wall_budget=wall_budget,
        plugins=plugins,
        strategy_kv=strategy_kv,
        trial_sel=trial_sel,
        workers=workers,
    )
    video = None
    if video_path is not None:
        from ..runner.plugins import lookup
        from ..runner.video import VideoSpec

        try:
            item = lookup("backend", backend, spec.plugins)
        except Exception as exc:  # noqa: BLE001 - PluginNotFoundError: the manager's message
            fail(str(exc))
        caps = item.meta.get("capabilities") or {}
        if not caps.get("camera", False):
            fail(
                f"--video needs a backend that can render images; backend {backend!r} has no camera "
                f"(capabilities.camera is false). Use --backend pybullet."
            )
        from .validate import check_video_trial

        try:
            check_video_trial(video_trial, trial_sel)
            if not (video_fps > 0 and video_fps != float("inf")):
                raise ValueError(f"--video-fps {video_fps}: must be a positive finite number")
            try:
                w, h = (int(v) for v in video_size.lower().split("x"))
            except ValueError:
                raise ValueError(
                    f"--video-size {video_size!r}: WIDTHxHEIGHT, e.g. 640x480"
                ) from None
            video = VideoSpec(video_path, video_trial, video_fps, view=video_view, size=(w, h))
        except ValueError as exc:
            fail(str(exc))
    with _open_store(store_path) as store:
        t0 = time.perf_counter()
        report = _sweep(spec, store, workers, trial_sel, retry_failed, progress, video)
        elapsed = time.perf_counter() - t0
        rows, cell = _summary(
            spec, store, report.plan.benchmark, report.plan.total, report.selected
        )
        video_info = None
        if video is not None:
            rec = next((r for r in report.records if r.trial_index == video.trial_index), None)
            video_info = rec.diagnostics.get("video") if rec is not None else None
        failed = any(r.status.value == "failure" for r in rows)
        if as_json:
            emit_json(
                {
                    "run": spec.to_json(),
                    "store": str(store.path),
                    "benchmark": report.plan.benchmark,
                    "trials_total": report.plan.total,
                    "selected": report.selected,
                    "ran": report.ran,
                    "skipped": report.skipped,
                    "by_other_runs": sorted(report.by_others),
                    "failures": sum(r.status.value == "failure" for r in rows),
                    "elapsed_s": elapsed,
                    "tier": None if cell is None else cell.to_dict(),
                    "video": video_info,
                    "trials": [_trial_json(t) for t in rows],
                }
            )
        else:
            console = _console()
            print_table(
                _trials_table(
                    rows,
                    _esc(
                        f"{spec.task}: {spec.strategy} on {spec.robot}, {spec.backend}, seed {spec.seed}"
                    ),
                ),
                console,
            )
            console.print(
                f"run {spec.run_key} in {store.path}: ran {report.ran}, skipped {len(report.skipped)} "
                f"already stored, {elapsed:.1f} s"
                + (
                    f"; {len(report.by_others)} run by another process of the same command"
                    if report.by_others
                    else ""
                )
            )
            if cell is not None:
                from ..runner.reports import format_cell

                state = "completed" if cell.completed else "not completed"
                console.print(
                    f"{spec.task}: {state} — {format_cell(cell)} s "
                    f"({cell.successes}/{cell.trials_required} trials in the expected state)"
                )
            if video_info:
                console.print(
                    f"video: {video_info['path']} ({video_info['frames']} frames at {video_info['fps']:g} fps, "
                    f"{video_info.get('view', '')} view, {video_info.get('render_cpu_s', 0):.1f} s CPU rendering)"
                    + (f" — {video_info['note']}" if video_info.get("note") else "")
                )
        if failed:
            raise SystemExit(EXIT_NEGATIVE)


# -- table -------------------------------------------------------------------------------------


@click.command("table", context_settings=_CTX)
@store_option
@click.option(
    "--benchmark",
    type=click.Choice(["rubiks", "inhand"]),
    default=None,
    help="Which paper's tables (default: each benchmark present in the store).",
)
@click.option("--strategy", "strategies", multiple=True, help="Only these strategies (repeatable).")
@click.option("--backend", "backends", multiple=True, help="Only these backends (repeatable).")
@click.option("--robot", "robots", multiple=True, help="Only these robots (repeatable).")
@click.option("--seed", "seeds", multiple=True, type=_SEED, help="Only these seeds (repeatable).")
@click.option(
    "--run-tiers",
    is_flag=True,
    help="Rubik's: only tiers with results (default all twelve, as in the paper).",
)
@click.option(
    "--plot",
    "plot_path",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="In-hand: also write the Figure-7 box plot (per object, one box per method) to this .png/.svg.",
)
@json_option
def table(
    store_path, benchmark, strategies, backends, robots, seeds, run_tiers, plot_path, as_json
) -> None:
    """Our results in the papers' layouts, with the published figures beside them.

    \b
    Rubik's (Table I): tiers × methods, mean / std of the trial scores in
    seconds (sample std; "-" for single-trial tiers) where the tier was
    completed, "—" where not (with successes/M), "… k/M run" while trials
    are missing. In-hand: Table II (per method: drops %, medians of err_pos,
    err_pos%, err_or%) and Table III (per task); ``--plot`` draws the
    paper's Figure 7 (box plots per object and method).

    \b
    Examples:
      benchharness table --benchmark rubiks --run-tiers
      benchharness table --benchmark inhand --plot figure7.png
    """
    from ..runner.contact_regions import stored_contact_scorer
    from ..runner.reports import (
        format_cell,
        inhand_box_plot,
        inhand_table2,
        inhand_table3,
        rubiks_table,
    )

    if plot_path is not None and plot_path.suffix.lower() not in (".png", ".svg"):
        fail(f"--plot: {plot_path} must end in .png or .svg")

    with _open_store(store_path, read_only=True) as store:
        filters = dict(
            strategy=list(strategies) or None,
            backend=list(backends) or None,
            robot=list(robots) or None,
            seed=list(seeds) or None,
        )
        trials = store.trials(benchmark=benchmark, **filters)
    present = {t.benchmark for t in trials}
    wanted = (
        [benchmark]
        if benchmark
        else [b for b in ("rubiks", "inhand") if b in present] or ["rubiks"]
    )
    out: dict[str, Any] = {}
    console = None if as_json else _console()
    if "rubiks" in wanted:
        tab = rubiks_table(trials, all_tiers=not run_tiers)
        if as_json:
            out["rubiks"] = tab.to_dict()
        else:
            from rich.table import Table

            t = Table(
                title="Rubik's cube benchmark (Table I layout): mean / std of trial time, s; — not completed"
            )
            t.add_column("Tier", no_wrap=True)
            for _, label in tab.published:
                t.add_column(f"{label} (paper)", justify="right")
            for c in tab.columns:
                t.add_column(_esc(c.label), justify="right")
            for tier in tab.tiers:
                t.add_row(
                    tier,
                    *[tab.published_cell(tier, k) for k, _ in tab.published],
                    *[format_cell(tab.cells.get((tier, c.label))) for c in tab.columns],
                )
            print_table(t, console)
            if not tab.columns:
                console.print(
                    "No Rubik's results in the store yet (benchharness run --task Rubiks-...)."
                )
            for c in tab.columns:
                if "," in c.code_version:
                    console.print(f"{_esc(c.label)}: runs from code versions {c.code_version}")
    if "inhand" in wanted:
        t2, t3 = (
            inhand_table2(trials),
            inhand_table3(trials, contact_scorer=stored_contact_scorer()),
        )
        if as_json:
            out["inhand"] = {"table2": t2, "table3": t3}
        else:
            from rich.table import Table

            from ..runner.published import TABLE_III_ROWS

            t = Table(title="In-hand benchmark (Table II layout): medians over trials")
            for c, j in (
                ("method", "left"),
                ("source", "left"),
                ("n", "right"),
                ("drops %", "right"),
                ("err_pos (cm)", "right"),
                ("err_pos%", "right"),
                ("err_or%", "right"),
                ("other failures", "right"),
                ("plan time (s)", "right"),
            ):
                t.add_column(c, justify=j)
            for r in t2:
                t.add_row(
                    _esc(r["method"]),
                    r["source"],
                    str(r.get("trials", "")),
                    _fmt(r.get("drops_percent"), 1),
                    _fmt(r.get("err_pos_cm")),
                    _fmt(r.get("err_pos_percent")),
                    _fmt(r.get("err_or_percent")),
                    str(r.get("failed_other", "")),
                    _fmt(r.get("plan_time_s")),
                )
            print_table(t, console)
            methods: dict[str, list] = {}
            for r in t3:
                methods.setdefault(r["method"], []).append(r)
            for method, rows in methods.items():
                t = Table(title=_esc(f"Table III layout: {method} per task (ours | paper DMG)"))
                t.add_column("metric")
                for r in rows:
                    t.add_column(_esc(f"{r['object']} [{r['task_id']}]"), justify="right")
                for key, label in TABLE_III_ROWS.items():
                    cells = []
                    for r in rows:
                        paper = r["paper"].get(key)
                        ours = r["ours"].get(key)
                        cells.append(
                            f"{_fmt(ours, 3)} | {_fmt(paper, 3) if paper is not None else ''}"
                        )
                    t.add_row(label, *cells)
                t.add_row("drops %", *[_fmt(r["drops_percent"], 1) for r in rows])
                print_table(t, console)
    if plot_path is not None:
        try:
            inhand_box_plot(trials, plot_path)
        except ValueError as e:
            fail(f"--plot: {e}")
        if as_json:
            out["plot"] = str(plot_path)
        else:
            console.print(f"Box plot (Figure 7 layout) written to {plot_path}")
    if as_json:
        emit_json(out)


# -- compare -----------------------------------------------------------------------------------


@click.command("compare", context_settings=_CTX)
@run_options
@click.option(
    "--backends",
    default="pybullet,sapien",
    show_default=True,
    help="Comma-separated backends to compare.",
)
def compare(
    task,
    robot,
    strategy,
    seed,
    sensors,
    workers,
    trial_sel,
    repeats,
    strategy_kv,
    physics_kv,
    sim_budget,
    wall_budget,
    plugins,
    retry_failed,
    progress,
    store_path,
    as_json,
    backends,
) -> None:
    """Run the same trials on several backends and show them side by side.

    Each backend's run is an ordinary stored run (so it resumes, and shows up
    in ``table``); the comparison is per trial: status, score, failure cause,
    simulated and wall time, and per backend the tier score and the
    real-time factor (simulated s / wall s).

    \b
    Example:
      benchharness compare --backends pybullet,sapien --task Rubiks-1-5 --robot pr2 --strategy sensor-aided
    """
    from ..runner.reports import compare_backends
    from .validate import check_backends

    try:
        names = check_backends(_names(backends))
    except ValueError as exc:
        fail(str(exc))
    # every backend's run checked before the store is opened
    specs = [
        _spec(
            task=task,
            robot=robot,
            strategy=strategy,
            backend=b,
            seed=seed,
            sensors=sensors,
            repeats=repeats,
            physics_kv=physics_kv,
            sim_budget=sim_budget,
            wall_budget=wall_budget,
            plugins=plugins,
            strategy_kv=strategy_kv,
            trial_sel=trial_sel,
            workers=workers,
        )
        for b in names
    ]
    runs = []
    with _open_store(store_path) as store:
        benchmark = None
        required = None
        for b, spec in zip(names, specs):
            report = _sweep(spec, store, workers, trial_sel, retry_failed, progress)
            benchmark = report.plan.benchmark
            required = report.plan.total if trial_sel is None else None
            sel = set(report.selected)
            runs.append(
                (b, [t for t in store.trials(run_key=spec.run_key) if t.trial_index in sel])
            )
    data = compare_backends(runs, required)
    from ..runner.tasks import trial_task

    for row in data["trials"]:  # in-hand trials: which task row and object
        tid = trial_task(task, row["trial"])
        if tid:
            row["task_id"], row["object"] = tid[0], tid[1]
    if as_json:
        emit_json({"task": task, "benchmark": benchmark, "backends": list(names), **data})
        return
    from rich.table import Table

    console = _console()
    t = Table(title=f"{task}: {strategy} on {robot}, seed {seed} — per backend")
    t.add_column("trial", justify="right")
    inhand = any("task_id" in row for row in data["trials"])
    if inhand:
        t.add_column("task id")
        t.add_column("object")
    for b in names:
        t.add_column(f"{b}: status", no_wrap=True)
        t.add_column(f"{b}: score", justify="right")
        t.add_column(f"{b}: sim s", justify="right")
    for row in data["trials"]:
        cells = [str(row["trial"])]
        if inhand:
            cells += [_esc(row.get("task_id", "")), _esc(row.get("object", ""))]
        for b in names:
            c = row[b]
            if c is None:
                cells += ["", "", ""]
            else:
                cells += [c["cause"] or c["status"], _fmt(c["score"], 3), _fmt(c["sim_s"], 2)]
        t.add_row(*cells)
    print_table(t, console)
    s = Table(title="summary")
    for c in (
        "backend",
        "trials",
        "successes",
        "completed",
        "mean / std s",
        "failure causes",
        "real-time factor",
    ):
        s.add_column(c)
    for b in names:
        v = data["summary"][b]
        causes = ", ".join(f"{k}×{n}" for k, n in v["causes"].items())
        ms = "" if v["mean_s"] is None else f"{v['mean_s']:.2f} / {_fmt(v['std_s'])}"
        s.add_row(
            b,
            str(v["trials"]),
            str(v["successes"]),
            "" if v["completed"] is None else str(v["completed"]).lower(),
            ms,
            causes,
            _fmt(v["real_time_factor"], 2),
        )
    print_table(s, console)
    if benchmark == "inhand":
        h = Table(title="in-hand, per backend (Table II layout): medians over scored trials")
        for c in ("backend", "n", "discarded", "drops %", "err_pos (cm)", "err_pos%", "err_or%"):
            h.add_column(c, justify="left" if c == "backend" else "right")
        for b in names:
            v = data["summary"][b]["inhand"] or {}
            h.add_row(
                b,
                str(v.get("trials", 0)),
                str(v.get("discarded", 0)),
                _fmt(v.get("drops_percent"), 1),
                _fmt(v.get("err_pos_cm")),
                _fmt(v.get("err_pos_percent")),
                _fmt(v.get("err_or_percent")),
            )
        print_table(h, console)


# -- results -----------------------------------------------------------------------------------


@click.command("results", context_settings=_CTX)
@store_option
@click.option("--failures", is_flag=True, help="Only failed trials.")
@click.option("--task", "tasks", multiple=True, help="Only these tasks (repeatable).")
@click.option("--strategy", "strategies", multiple=True, help="Only these strategies (repeatable).")
@click.option("--backend", "backends", multiple=True, help="Only these backends (repeatable).")
@click.option("--robot", "robots", multiple=True, help="Only these robots (repeatable).")
@click.option("--seed", "seeds", multiple=True, type=_SEED, help="Only these seeds (repeatable).")
@click.option("--run", "run_prefix", default=None, help="Only the run whose key starts with this.")
@click.option("--traceback", "show_tb", is_flag=True, help="Print each failed trial's traceback.")
@click.option(
    "--plot-pose-error",
    "plot_path",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Write a PNG of cube pose-estimate error against move index, per method.",
)
@json_option
def results(
    store_path,
    failures,
    tasks,
    strategies,
    backends,
    robots,
    seeds,
    run_prefix,
    show_tb,
    plot_path,
    as_json,
) -> None:
    """List stored trials with status, score and failure cause.

    \b
    Examples:
      benchharness results --failures --traceback
      benchharness results --task Rubiks-1-50 --plot-pose-error drift.png
    """
    with _open_store(store_path, read_only=True) as store:
        rows = store.trials(
            failures_only=failures,
            task=list(tasks) or None,
            strategy=list(strategies) or None,
            backend=list(backends) or None,
            robot=list(robots) or None,
            seed=list(seeds) or None,
        )
    if run_prefix:
        rows = [t for t in rows if t.run_key.startswith(run_prefix)]
    plotted = None
    off_scale: list = []
    if plot_path is not None:
        from ..runner.plots import plot_pose_error

        try:
            drawn = plot_pose_error(rows, plot_path)
        except ValueError as exc:
            fail(str(exc), EXIT_NEGATIVE)
        plotted, off_scale = str(drawn.path), list(drawn.outliers)
    if as_json:
        data = []
        for t in rows:
            d = _trial_json(t)
            if show_tb:
                d["traceback"] = t.traceback
            d["diagnostics_counts"] = t.diagnostics.get("counts", {})
            # every kind of event the trial recorded (detour, arm_contact, warning, ...), counted here
            # from the stored events: the stored counts above hold only the scoring's own
            kinds = Counter(str(e.get("kind")) for e in t.diagnostics.get("events", []))
            d["event_counts"] = dict(sorted(kinds.items()))
            data.append(d)
        emit_json(
            {"trials": data, "plot": plotted, "plot_off_scale": [o.to_dict() for o in off_scale]}
        )
        return
    console = _console()
    print_table(
        _trials_table(rows, f"{'failed ' if failures else ''}trials ({len(rows)})", show_run=True),
        console,
    )
    if show_tb:
        for t in rows:
            if t.traceback:
                console.rule(f"{t.task} {t.method} seed {t.seed} trial {t.trial_index}")
                console.print(t.traceback, markup=False, highlight=False)
    if plotted:
        console.print(f"pose-error plot written to {plotted}")
        for o in off_scale:
            console.print(f"  off-scale (drawn on the top edge): {_esc(o.describe())}")
