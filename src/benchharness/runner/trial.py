"""One trial, start to finish: build the context, call the strategy, score, clean up.

Runs in a sweep worker (or inline). Whatever happens inside — a
:class:`~benchharness.backends.SimulationError`, any exception, a spent
budget, a ``SystemExit`` (``sys.exit`` in a library's error path) — becomes
a :class:`TrialRecord` with a cause and the traceback. ``KeyboardInterrupt``
is the user's Ctrl-C when the trial runs in the sweep's own process and
escapes there; in a worker process (which ignores SIGINT: the parent owns
interruption) it can only come from the strategy's code and is contained
too (``contain_interrupts=True``).
"""

from __future__ import annotations

import time
import traceback as tb
from dataclasses import replace
from functools import lru_cache
from typing import Any

from ..backends.interface import SimulationError
from .causes import FailureCause, TrialStatus
from .contract import SensorSlot, TrialContext, TrialOutcome, TrialTimeout
from .plugins import create_item, create_strategy, lookup
from .recorder import TrialRecorder
from .records import TrialRecord
from .scoring import Verdict, score_inhand, score_rubiks
from .seeding import trial_streams
from .spec import RunSpec
from .stepping import StepHooks, wall_alarm
from .tasks import TaskPlan, plan_task
from .video import TrialFilm, VideoSpec

__all__ = ["execute_trial", "plan_for", "check_strategy_supports"]


@lru_cache(maxsize=16)
def _plan(task: str, seed: int, repeats: int, plugins: tuple[str, ...]) -> TaskPlan:
    item = lookup("task", task, plugins)
    return plan_task(item.name, item.create(), seed, repeats)


def plan_for(spec: RunSpec) -> TaskPlan:
    return _plan(spec.task, int(spec.seed), int(spec.repeats), tuple(spec.plugins))


def check_strategy_supports(strategy: Any, benchmark: str, name: str) -> None:
    supported = getattr(strategy, "benchmarks", None)
    if supported is not None and benchmark not in tuple(supported):
        raise ValueError(f"strategy {name!r} runs {', '.join(supported)} tasks, not {benchmark}")
    if not callable(getattr(strategy, "run_trial", None)):
        raise TypeError(
            f"strategy {name!r} ({type(strategy).__name__}) has no run_trial(ctx) method"
        )


def _failure(
    spec: RunSpec,
    index: int,
    cause: FailureCause,
    message: str,
    wall0: float,
    ctx: TrialContext | None,
    trace: str = "",
    outcome: dict | None = None,
) -> TrialRecord:
    sim_s = None
    first = None
    diag: dict = {}
    if ctx is not None:
        try:
            sim_s = ctx.sim_elapsed
        except Exception:  # noqa: BLE001 - the backend may be broken; the failure is what matters
            sim_s = None
        first = ctx.recorder.first_contact_s
        diag = ctx.recorder.to_json()
    return TrialRecord(
        spec.run_key,
        index,
        TrialStatus.FAILURE,
        None,
        cause,
        message,
        time.perf_counter() - wall0,
        sim_s,
        first,
        None,
        outcome or {},
        diag,
        trace,
    )


def execute_trial(
    spec: RunSpec,
    index: int,
    video: VideoSpec | None = None,
    *,
    contain_interrupts: bool = False,
) -> TrialRecord:
    """Run trial ``index`` (1-based) of ``spec``; never raises for a failing trial."""
    wall0 = time.perf_counter()
    plan = plan_for(spec)
    item = plan.items[index]
    streams = trial_streams(spec.seed, plan.name, index, len(spec.sensors))
    backend = None
    ctx: TrialContext | None = None
    hooks: StepHooks | None = None
    film: TrialFilm | None = None
    stage = "creating the backend"
    try:
        physics = replace(spec.physics, seed=streams.backend_seed)
        backend = create_item("backend", spec.backend, spec.plugins, config=physics)
        # colours and render-only shapes only for the trial being filmed (physics is the same)
        backend.set_visuals(video is not None and video.trial_index == index)
        stage = "creating the robot, sensors and strategy"
        robot = create_item("robot", spec.robot, spec.plugins)
        sensors = {}
        for name, rng in zip(spec.sensors, streams.sensors):
            sensor = lookup("sensor", name, spec.plugins)
            sensors[name] = SensorSlot(name, rng, sensor.factory, dict(sensor.meta))
        strategy = create_strategy(spec)
        check_strategy_supports(strategy, plan.benchmark, spec.strategy)
        recorder = TrialRecorder(clock=lambda: float(backend.time))
        ctx = TrialContext(
            item=item,
            trial_index=index,
            robot=robot,
            backend=backend,
            sensors=sensors,
            rng=streams.strategy,
            budget=spec.budget,
            recorder=recorder,
            physics=physics,
            run=spec.key_fields(),
            wall_start=wall0,
            sim_start=float(backend.time),
        )
        if video is not None and video.trial_index == index:
            film = TrialFilm(video, ctx, strategy)
            hooks = StepHooks(ctx, film)
        else:
            hooks = StepHooks(ctx)
        hooks.install()
        stage = "running the strategy"
        with wall_alarm(spec.budget.wall_s):
            outcome = strategy.run_trial(ctx)
        if not isinstance(outcome, TrialOutcome):
            return _failure(
                spec,
                index,
                FailureCause.STRATEGY_ERROR,
                f"run_trial returned {type(outcome).__name__}, not TrialOutcome",
                wall0,
                ctx,
            )
        end = float(backend.time)
        sim_s = end - ctx.sim_start
        if spec.budget.sim_s is not None and sim_s > spec.budget.sim_s:
            raise TrialTimeout(
                f"simulated-time budget of {spec.budget.sim_s:g} s spent ({sim_s:.3f} s)"
            )
        first = (
            outcome.first_contact_s
            if outcome.first_contact_s is not None
            else recorder.first_contact_s
        )
        termination = outcome.termination_s if outcome.termination_s is not None else end
        if plan.benchmark == "rubiks":
            verdict: Verdict = score_rubiks(item, outcome, first, termination)  # type: ignore[arg-type]
        else:
            verdict = score_inhand(item, outcome)  # type: ignore[arg-type]
        diag = recorder.to_json()
        if film is not None:
            diag["video"] = film.info()
        return TrialRecord(
            spec.run_key,
            index,
            verdict.status,
            verdict.score,
            verdict.cause,
            verdict.message,
            time.perf_counter() - wall0,
            sim_s,
            first,
            termination,
            verdict.outcome,
            diag,
        )
    except TrialTimeout as exc:
        return _failure(spec, index, FailureCause.TIMEOUT, str(exc), wall0, ctx, tb.format_exc())
    except SimulationError as exc:
        return _failure(
            spec,
            index,
            FailureCause.SIMULATOR_ERROR,
            f"{type(exc).__name__}: {exc}",
            wall0,
            ctx,
            tb.format_exc(),
        )
    except (Exception, SystemExit, KeyboardInterrupt) as exc:  # any of them ends this trial only
        if isinstance(exc, KeyboardInterrupt) and not contain_interrupts:
            raise
        cause = FailureCause.SIMULATOR_ERROR if backend is None else FailureCause.STRATEGY_ERROR
        return _failure(
            spec, index, cause, f"{stage}: {type(exc).__name__}: {exc}", wall0, ctx, tb.format_exc()
        )
    finally:
        if hooks is not None:
            hooks.uninstall()
        if film is not None:
            try:
                film.close()
            except Exception:  # noqa: BLE001 - a failed encoder must not hide the trial's result
                pass
        if backend is not None:
            try:
                backend.close()
            except Exception:  # noqa: BLE001
                pass
