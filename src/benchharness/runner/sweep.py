"""Sweeps: the trials of a run, in a process pool, written by the parent as they finish.

* Resume: trials already in the store under the same run key are skipped,
  so re-running the same command after a kill carries on where it stopped.
* Workers are *spawned* (not forked): a fresh interpreter per worker, no
  inherited engine state or locks. Each trial builds its own world, so
  results depend only on (run, trial index), not on the worker count.
* At most ``workers`` trials are in flight. If a worker process dies (an
  engine segfault), the trials it may have been running are retried once in a
  fresh pool; a trial that kills its worker twice is recorded as
  ``simulator_error``. Nothing that happens in a trial ends the sweep.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass, field

from .causes import FailureCause, TrialStatus
from .plugins import lookup
from .records import TrialRecord
from .spec import RunSpec
from .store import ResultsStore
from .tasks import TaskPlan, parse_trial_selection
from .trial import execute_trial, plan_for
from .video import VideoSpec

__all__ = ["SweepReport", "default_workers", "prepare", "run_sweep"]


def default_workers() -> int:
    """Half the cores (physics is CPU-bound and the parent needs some), at least 1."""
    return max(1, (os.cpu_count() or 2) // 2)


@dataclass
class SweepReport:
    spec: RunSpec
    plan: TaskPlan
    selected: list[int]
    skipped: list[int] = field(default_factory=list)
    records: list[TrialRecord] = field(default_factory=list)

    @property
    def ran(self) -> int:
        return len(self.records)

    @property
    def failures(self) -> int:
        return sum(r.status is TrialStatus.FAILURE for r in self.records)


def prepare(spec: RunSpec) -> TaskPlan:
    """Check every name before any trial starts (the plugin manager's error if one is unknown)."""
    plan = plan_for(spec)
    lookup("backend", spec.backend, spec.plugins)
    lookup("robot", spec.robot, spec.plugins)
    for s in spec.sensors:
        lookup("sensor", s, spec.plugins)
    item = lookup("strategy", spec.strategy, spec.plugins)
    supported = item.meta.get("benchmarks") or getattr(item.factory, "benchmarks", None)
    if supported is not None and plan.benchmark not in tuple(supported):
        raise ValueError(
            f"strategy {spec.strategy!r} runs {', '.join(supported)} tasks, not {plan.benchmark} ({plan.name})"
        )
    return plan


def _stdout_to_stderr() -> None:
    """Point file descriptor 1 at stderr for the rest of this process.

    Engines print banners from C at import (PyBullet's "build time" line);
    in a sweep stdout belongs to the parent's report (``--json``), so worker
    processes send anything written to stdout to stderr instead.
    """
    import sys

    try:
        sys.stdout.flush()
        os.dup2(2, 1)
    except OSError:
        pass


@contextmanager
def _quiet_stdout() -> Iterator[None]:
    """:func:`_stdout_to_stderr` for the duration of an in-process (``workers=0``) sweep."""
    import sys

    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError):
        yield
        return
    try:
        os.dup2(2, 1)
        yield
    finally:
        try:
            sys.stdout.flush()
        except ValueError:
            pass
        os.dup2(saved, 1)
        os.close(saved)


def _crash_record(spec: RunSpec, index: int, detail: str) -> TrialRecord:
    return TrialRecord(
        spec.run_key,
        index,
        TrialStatus.FAILURE,
        None,
        FailureCause.SIMULATOR_ERROR,
        f"the worker process died while running this trial, twice ({detail})",
        0.0,
        None,
        None,
        None,
    )


def run_sweep(
    spec: RunSpec,
    store: ResultsStore,
    *,
    workers: int = 1,
    trials: str | None = None,
    retry_failed: bool = False,
    video: VideoSpec | None = None,
    on_start: Callable[[SweepReport, int], None] | None = None,
    on_record: Callable[[TrialRecord], None] | None = None,
) -> SweepReport:
    """Run the pending trials of ``spec``; ``workers=0`` runs them in this process (debugging)."""
    plan = prepare(spec)
    selected = parse_trial_selection(trials, sorted(plan.items))
    store.ensure_run(spec, plan.benchmark, plan.total)
    done = store.finished(spec.run_key, retry_failed=retry_failed)
    forced = {video.trial_index} if video is not None else set()
    if video is not None and video.trial_index not in plan.items:
        raise ValueError(f"--video-trial {video.trial_index}: this task has trials 1..{plan.total}")
    pending = [i for i in selected if i not in done or i in forced]
    report = SweepReport(
        spec, plan, selected, skipped=[i for i in selected if i in done and i not in forced]
    )
    if on_start is not None:
        on_start(report, len(pending))

    def finish(rec: TrialRecord) -> None:
        store.write(rec)
        report.records.append(rec)
        if on_record is not None:
            on_record(rec)

    if workers <= 0:
        for i in pending:
            with _quiet_stdout():
                rec = execute_trial(spec, i, video)
            finish(rec)
        return report

    ctx = multiprocessing.get_context("spawn")
    queue = list(pending)
    suspects: list[int] = []
    while queue:
        broken = _drain(ctx, workers, queue, suspects, spec, video, finish)
        if not broken:
            break
    # Trials that were in flight when a worker died: once more, each alone, to find the culprit.
    for i in sorted(suspects):
        alone: list[int] = [i]
        again: list[int] = []
        if _drain(ctx, 1, alone, again, spec, video, finish):
            finish(_crash_record(spec, i, "BrokenProcessPool"))
    return report


def _drain(
    ctx,
    workers: int,
    queue: list[int],
    suspects: list[int],
    spec: RunSpec,
    video: VideoSpec | None,
    finish: Callable[[TrialRecord], None],
) -> bool:
    """Run ``queue`` in one pool until empty or the pool breaks (then True; the
    in-flight trials are moved to ``suspects``)."""
    pool = ProcessPoolExecutor(
        max_workers=max(1, min(workers, len(queue))), mp_context=ctx, initializer=_stdout_to_stderr
    )
    inflight: dict[Future, int] = {}
    try:
        while queue or inflight:
            while queue and len(inflight) < workers:
                i = queue.pop(0)
                inflight[pool.submit(execute_trial, spec, i, video)] = i
            finished, _ = wait(inflight, return_when=FIRST_COMPLETED)
            broke = False
            for fut in finished:
                i = inflight.pop(fut)
                try:
                    rec = fut.result()
                except BrokenProcessPool:
                    suspects.append(i)
                    broke = True
                    continue
                finish(rec)
            if broke:
                suspects.extend(inflight.values())
                inflight.clear()
                pool.shutdown(wait=False, cancel_futures=True)
                return True
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return False
