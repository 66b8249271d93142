"""``benchharness sweep``: a grid of runs (tasks × robots × strategies × backends × seeds × physics).

Thin: build a :class:`~benchharness.runner.grid.Grid` from a TOML file and/or
the comma-list options, expand it (every name checked before anything runs),
hand the runs to an executor (the local process pool, or Ray), print one row
per run. Exit codes as for ``run``: 0 all trials succeeded, 1 some failed,
2 bad input. See docs/runner.md, "Sweeps".
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import click

from .common import EXIT_NEGATIVE, emit_json, fail, json_option, print_table
from .run import _CTX, _console, _esc, _names, _open_store, _Progress, store_option


def _ints(text: str, option: str) -> tuple[int, ...]:
    out = []
    for part in _names(text):
        try:
            out.append(int(part))
        except ValueError:
            fail(f"{option} {part!r}: not an integer")
    return tuple(out)


@click.command("sweep", context_settings=_CTX)
@click.argument("grid_file", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--tasks", default=None, help="Comma list of tasks (Rubiks-1-5,inhand-level1).")
@click.option("--robots", default=None, help="Comma list of robot plugin names.")
@click.option("--strategies", default=None, help="Comma list of strategy plugin names.")
@click.option("--backends", default=None, help="Comma list of backends (default pybullet).")
@click.option("--seeds", default=None, help="Comma list of run seeds (default 0).")
@click.option(
    "--physics",
    "physics_sets",
    multiple=True,
    metavar="K=V,K=V",
    help="One physics setting set (comma list of KEY=VALUE); repeat for more grid points.",
)
@click.option(
    "--strategy-option",
    "strategy_kv",
    multiple=True,
    metavar="KEY=VALUE",
    help="A strategy config field for every strategy of the grid, repeatable (per strategy: "
    "[strategy_options.NAME] in the grid file).",
)
@click.option("--sensors", default=None, help="Comma list of sensors, for every run.")
@click.option("--repeats", type=int, default=None, help="In-hand: trials per task row (default 1).")
@click.option("--sim-budget", type=float, default=None, help="Simulated seconds per trial.")
@click.option("--wall-budget", type=float, default=None, help="Wall-clock seconds per trial.")
@click.option("--plugin", "plugins", multiple=True, metavar="MODULE", help="Extra plugin module.")
@click.option(
    "--executor",
    type=click.Choice(["pool", "ray"]),
    default="pool",
    show_default=True,
    help="Local process pool, or Ray (pip install 'benchharness[cluster]').",
)
@click.option(
    "--address",
    default=None,
    help="Ray: an existing cluster (default $RAY_ADDRESS, else a local one on 127.0.0.1).",
)
@click.option(
    "--workers", type=int, default=None, help="Pool: worker processes (default half the cores)."
)
@click.option("--num-cpus", type=int, default=None, help="Ray, local cluster: CPUs (default all).")
@click.option(
    "--max-retries",
    type=int,
    default=2,
    show_default=True,
    help="Ray: re-runs of a trial whose worker died, before it is stored as simulator_error.",
)
@click.option("--retry-failed", is_flag=True, help="Re-run stored failed trials.")
@click.option(
    "--progress/--no-progress", default=None, help="Progress bar (default: when a terminal)."
)
@store_option
@json_option
def sweep(
    grid_file,
    tasks,
    robots,
    strategies,
    backends,
    seeds,
    physics_sets,
    strategy_kv,
    sensors,
    repeats,
    sim_budget,
    wall_budget,
    plugins,
    executor,
    address,
    workers,
    num_cpus,
    max_retries,
    retry_failed,
    progress,
    store_path,
    as_json,
) -> None:
    """Run a grid of runs, each with the run key (and resume) that ``run`` would give it.

    Combinations that cannot run (a strategy that does not drive the robot, or
    written for the other benchmark) are skipped with a note; a name in no
    runnable combination is refused (exit 2) before anything runs.

    \b
    Examples:
      benchharness sweep --tasks Rubiks-1-5,Rubiks-2-5 --robots pr2 \\
          --strategies sensor-aided,dead-reckoning --backends pybullet,sapien --seeds 0,1
      benchharness sweep grid.toml --executor ray --address 10.0.0.1:6379
    """
    from ..runner.grid import Grid, expand, load_grid
    from ..runner.sweep import default_workers

    base: dict = {}
    if grid_file is not None:
        try:
            base = {f.name: getattr(load_grid(grid_file), f.name) for f in dataclasses.fields(Grid)}
        except ValueError as exc:
            fail(str(exc))
    for name, text in (("tasks", tasks), ("robots", robots), ("strategies", strategies)):
        if text is not None:
            base[name] = _names(text)
    if backends is not None:
        base["backends"] = _names(backends)
    if seeds is not None:
        base["seeds"] = _ints(seeds, "--seeds")
    if physics_sets:
        base["physics"] = tuple(_names(p) for p in physics_sets)
    if sensors is not None:
        base["sensors"] = _names(sensors)
    if plugins:
        base["plugins"] = tuple(base.get("plugins", ())) + tuple(plugins)
    if strategy_kv:
        base["strategy_options"] = tuple(base.get("strategy_options", ())) + (
            ("*", tuple(strategy_kv)),
        )
    for name, value in (
        ("repeats", repeats),
        ("sim_budget", sim_budget),
        ("wall_budget", wall_budget),
    ):
        if value is not None:
            base[name] = value
    for need in ("tasks", "robots", "strategies"):
        if not base.get(need):
            fail(f"--{need}: name at least one (or give a grid TOML file)")
    workers = default_workers() if workers is None else workers
    if workers < 0:
        fail("--workers must be 0 or more")
    if num_cpus is not None and num_cpus < 1:
        fail(f"--num-cpus {num_cpus}: must be at least 1")
    if max_retries < 0:
        fail(f"--max-retries {max_retries}: must be 0 or more")
    try:
        plan = expand(Grid(**base))
    except ValueError as exc:
        fail(str(exc))
    if executor == "ray":
        from ..runner.executors import RAY_MISSING, loopback_env

        loopback_env(address)
        try:
            import ray  # noqa: F401
        except ImportError:
            fail(RAY_MISSING)
    err = _console(stderr=True)
    for note in plan.skipped:
        err.print(_esc(note), soft_wrap=True)

    from ..plugin import PluginNotFoundError
    from ..runner.executors import pending_trials, run_grid

    with _open_store(store_path) as store:
        try:
            total = sum(len(pending_trials(s, store, retry_failed)) for s in plan.specs)
        except (PluginNotFoundError, ValueError, TypeError) as exc:
            fail(str(exc))
        show = sys.stderr.isatty() if progress is None else progress
        bar = _Progress(show, f"sweep of {len(plan.specs)} runs ({executor})")
        bar.start(None, total)
        t0 = time.perf_counter()
        try:
            reports = run_grid(
                plan.specs,
                store,
                executor=executor,
                workers=workers,
                address=address,
                num_cpus=num_cpus,
                max_retries=max_retries,
                retry_failed=retry_failed,
                on_record=bar.record,
            )
        except (PluginNotFoundError, ValueError, TypeError) as exc:
            bar.stop()
            fail(str(exc))
        except KeyboardInterrupt as exc:
            import signal

            bar.stop()
            signum = getattr(exc, "signum", signal.SIGINT)
            n = sum(store.count(s.run_key) for s in plan.specs)
            fail(
                f"interrupted ({signal.Signals(signum).name}); {n} trial(s) of this sweep are in "
                f"{store.path}. Re-run the same command to resume.",
                128 + signum,
            )
        finally:
            bar.stop()
        elapsed = time.perf_counter() - t0
        rows = []
        failed_any = False
        for r in reports:
            stored = store.trials(run_key=r.spec.run_key)
            failures = sum(t.status.value == "failure" for t in stored)
            failed_any |= failures > 0
            rows.append(
                {
                    "run": r.spec.to_json(),
                    "run_key": r.spec.run_key,
                    "trials_total": r.plan.total,
                    "stored": len(stored),
                    "ran": r.ran,
                    "skipped": len(r.skipped),
                    "by_other_runs": sorted(r.by_others),
                    "failures": failures,
                }
            )
        if as_json:
            emit_json(
                {
                    "store": str(store.path),
                    "executor": executor,
                    "runs": rows,
                    "skipped_combinations": plan.skipped,
                    "elapsed_s": elapsed,
                }
            )
        else:
            from rich.table import Table

            table = Table(title=f"sweep: {len(rows)} runs ({executor})")
            for col in (
                "run",
                "task",
                "strategy / robot / backend",
                "seed",
                "stored",
                "ran",
                "failed",
            ):
                table.add_column(col)
            for row, r in zip(rows, reports):
                s = r.spec
                table.add_row(
                    row["run_key"][:12],
                    _esc(s.task),
                    _esc(f"{s.strategy} / {s.robot} / {s.backend}"),
                    str(s.seed),
                    f"{row['stored']}/{row['trials_total']}",
                    str(row["ran"]),
                    str(row["failures"]),
                )
            console = _console()
            print_table(table, console)
            console.print(
                f"store {store.path}: {sum(r.ran for r in reports)} trials ran, {elapsed:.1f} s"
            )
        if failed_any:
            raise SystemExit(EXIT_NEGATIVE)
