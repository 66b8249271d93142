"""Sweeps: the trials of a run, in worker processes, written by the parent as they finish.

* Resume: trials already in the store under the same run key are skipped,
  so re-running the same command after a kill carries on where it stopped.
* Sharing: a trial is claimed in the store before it runs
  (:meth:`ResultsStore.claim`, a lease renewed while this sweep lives), so two
  sweeps of the same run split the trials; when its own are done a sweep waits
  for the ones another live sweep is running, and takes over any whose owner
  died (at once on this host, when the lease lapses from another).
* A grid (:func:`run_sweeps`) shares one pool across its runs: a worker that
  frees up takes the next claimable trial of the first run that has one, so
  a grid of one-trial runs (the Rubiks-1-N tiers) keeps every worker busy.
* Workers are *spawned* (not forked): a fresh interpreter per worker, no
  inherited engine state or locks. Each trial builds its own world, so
  results depend only on (run, trial index), not on the worker count.
* Workers die with the parent: ``PR_SET_PDEATHSIG`` on Linux, and on every
  platform a lifeline pipe whose end only the parent holds (a worker thread
  exits the process when it reads end-of-file). They ignore SIGINT: the
  parent owns interruption. On Ctrl-C or SIGTERM the parent stores every
  result already sent, ends the workers (in-flight trials are not stored and
  run again on resume), releases its claims and raises
  :class:`SweepInterrupted`.
* Watchdog: the parent ends a worker whose trial outlives
  :func:`watchdog_limit` (a trial stuck in native code, where neither the
  per-step check nor the alarm can reach it) and stores a ``timeout``.
* If a worker process dies (an engine segfault) the trial it was running is
  retried once in a fresh worker; a trial that kills its worker twice is
  recorded as ``simulator_error``. Nothing that happens in a trial ends the
  sweep.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from multiprocessing.connection import wait
from typing import Any, Literal

from .causes import FailureCause, TrialStatus
from .contract import TimeBudget
from .plugins import check_strategy_robot, lookup
from .records import TrialRecord
from .spec import RunSpec
from .store import ClaimOwner, ResultsStore
from .tasks import TaskPlan, parse_trial_selection
from .trial import execute_trial, plan_for
from .video import VideoSpec
from .workers import Worker

__all__ = [
    "SweepInterrupted",
    "SweepReport",
    "default_workers",
    "prepare",
    "run_sweep",
    "run_sweeps",
    "watchdog_limit",
]

#: Claims last this long unless renewed (every quarter of it): how long another
#: machine waits before taking over the trials of a sweep that died.
LEASE_S = 120.0
#: With no ``--wall-budget``, the parent's backstop is this many times the
#: simulated budget (at least :data:`BACKSTOP_MIN_S`): trials run at 3-10
#: simulated seconds per wall second here, so only a stuck trial reaches it.
BACKSTOP_FACTOR = 10.0
BACKSTOP_MIN_S = 600.0


def default_workers() -> int:
    """Half the cores (physics is CPU-bound and the parent needs some), at least 1."""
    return max(1, (os.cpu_count() or 2) // 2)


def watchdog_limit(budget: TimeBudget) -> float | None:
    """Wall seconds after which the parent ends a trial's worker (None: never).

    An explicit wall budget: after the in-trial alarm (1.1 × budget + 1 s) has
    had 5 s (and a tenth of the budget) to speak. Otherwise a backstop derived
    from the simulated budget, max(600 s, 10 × sim budget); it is not part of
    the run key, since it stops only trials that would otherwise never end.
    """
    if budget.wall_s is not None:
        return budget.wall_s * 1.1 + 1.0 + max(5.0, 0.1 * budget.wall_s)
    if budget.sim_s is not None:
        return max(BACKSTOP_MIN_S, BACKSTOP_FACTOR * budget.sim_s)
    return None


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C (SIGINT) or SIGTERM during a sweep; finished trials are stored."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


@dataclass
class SweepReport:
    spec: RunSpec
    plan: TaskPlan
    selected: list[int]
    skipped: list[int] = field(default_factory=list)
    records: list[TrialRecord] = field(default_factory=list)
    #: Trials stored by another sweep of the same run while this one ran.
    by_others: list[int] = field(default_factory=list)
    #: Trials another live sweep was still running when this one stopped waiting.
    busy: list[int] = field(default_factory=list)

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
    # the Python API too, not only the CLI
    check_strategy_robot(spec.strategy, spec.robot, spec.plugins)
    supported = item.meta.get("benchmarks") or getattr(item.factory, "benchmarks", None)
    if supported is not None and plan.benchmark not in tuple(supported):
        raise ValueError(
            f"strategy {spec.strategy!r} runs {', '.join(supported)} tasks, not {plan.benchmark} ({plan.name})"
        )
    return plan


@contextmanager
def _quiet_stdout() -> Iterator[None]:
    """Stdout to stderr for the duration of an in-process (``workers=0``) trial.

    Engines print banners from C at import (PyBullet's "build time" line); in a
    sweep stdout belongs to the parent's report (``--json``).
    """
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


def _failure_record(spec: RunSpec, index: int, cause: FailureCause, message: str, wall: float):
    return TrialRecord(
        spec.run_key, index, TrialStatus.FAILURE, None, cause, message, wall, None, None, None
    )


# -- signals -------------------------------------------------------------------------------------


class _Signals:
    """SIGINT and SIGTERM raise :class:`SweepInterrupted`, except inside :meth:`critical`
    (storing a result), where they are held until it ends."""

    def __init__(self) -> None:
        self._depth = 0
        self._held: int | None = None
        self._old: dict[int, Any] = {}

    def __enter__(self) -> _Signals:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._old[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, old in self._old.items():
            signal.signal(sig, old)

    def _handle(self, signum: int, frame: object) -> None:
        if self._depth:
            self._held = signum
            return
        raise SweepInterrupted(signum)

    @contextmanager
    def critical(self) -> Iterator[None]:
        self._depth += 1
        try:
            yield
        finally:
            self._depth -= 1
        if not self._depth and self._held is not None:
            signum, self._held = self._held, None
            raise SweepInterrupted(signum)


# -- which trial next ------------------------------------------------------------------------------


class _Claims:
    """The trials this sweep still has to see stored, claimed one at a time as workers free up."""

    def __init__(
        self,
        store: ResultsStore,
        spec: RunSpec,
        pending: list[int],
        report: SweepReport,
        *,
        retry_failed: bool,
        forced: set[int],
        wait_for_others: bool,
        owner: ClaimOwner,
    ) -> None:
        self.store, self.spec, self.report = store, spec, report
        self.queue = list(pending)
        self.busy: list[int] = []
        self.retry_failed, self.forced = retry_failed, forced
        self.wait_for_others = wait_for_others
        self.owner = owner
        self.since = time.time()
        self._next_look = 0.0

    def next(self) -> int | None:
        """The next trial claimed for this sweep, or None if none is claimable now."""
        if self.busy and not self.queue and time.monotonic() >= self._next_look:
            self.queue, self.busy = self.busy, []  # look again at the other sweeps' trials
            self._next_look = time.monotonic() + 1.0
        while self.queue:
            i = self.queue.pop(0)
            redo: Literal["failed", "any"] | None = (
                "any" if i in self.forced else ("failed" if self.retry_failed else None)
            )
            got = self.store.claim(
                self.spec.run_key, i, self.owner, lease_s=LEASE_S, redo=redo, since=self.since
            )
            if got == "claimed":
                return i
            if got == "busy":
                self.busy.append(i)
            else:
                self.report.by_others.append(i)
        return None

    def waiting(self) -> bool:
        """True while trials are left that another live sweep runs (and we wait for them)."""
        if self.busy and not self.wait_for_others:
            self.report.busy = sorted(self.busy)
            return False
        return bool(self.busy or self.queue)

    def requeue(self, i: int) -> None:
        self.queue.insert(0, i)  # still ours: the claim is re-taken at once


def _next_job(runs: list[_Claims]) -> tuple[_Claims, int] | None:
    """The next claimable trial of the first run (in grid order) that has one."""
    for claims in runs:
        if (i := claims.next()) is not None:
            return claims, i
    return None


def _waiting(runs: list[_Claims]) -> bool:
    return any([claims.waiting() for claims in runs])  # every run's (each records its busy trials)


def _run_in_workers(
    ctx: Any,
    workers: int,
    runs: list[_Claims],
    video: VideoSpec | None,
    finish: Callable[[_Claims, TrialRecord], None],
    signals: _Signals,
) -> None:
    pool: list[Worker] = []
    run_of: dict[Worker, _Claims] = {}  # the run of each worker's last trial
    crashed: set[tuple[str, int]] = set()

    def give(w: Worker, job: tuple[_Claims, int]) -> None:
        run_of[w] = job[0]
        w.give((job[0].spec, job[1], video))

    def limit(w: Worker) -> float | None:
        return watchdog_limit(run_of[w].spec.budget)

    try:
        while True:
            for w in [w for w in pool if w.index is None and not w.proc.is_alive()]:
                w.stop()  # an idle worker that died: replaced below if there is work
                pool.remove(w)
            for w in pool:
                if w.index is None and (job := _next_job(runs)) is not None:
                    give(w, job)
            while len(pool) < workers and (job := _next_job(runs)) is not None:
                pool.append(Worker(ctx))
                give(pool[-1], job)
            running = [w for w in pool if w.index is not None]
            if not running:
                if not _waiting(runs):
                    return
                time.sleep(0.5)
                continue
            now = time.monotonic()
            deadlines = [
                (w.started if w.started is not None else w.sent + 60.0) + lim
                for w in running
                if (lim := limit(w)) is not None
            ]
            timeout = max(0.0, min([*deadlines, now + 1.0]) - now)
            ready = wait([w.conn for w in running] + [w.proc.sentinel for w in running], timeout)
            for w in running:
                while w.index is not None and w.conn in ready and w.conn.poll():
                    try:
                        msg = w.conn.recv()
                    except (EOFError, OSError):
                        break
                    if msg[0] == "started":
                        w.started = time.monotonic()
                    else:
                        w.index = None
                        with signals.critical():
                            finish(run_of[w], msg[1])
                if w.index is not None and not w.proc.is_alive():  # died mid-trial
                    i, w.index = w.index, None
                    claims = run_of[w]
                    w.stop(kill=True)
                    pool.remove(w)
                    if (claims.spec.run_key, i) in crashed:
                        detail = f"exit code {w.proc.exitcode}"
                        with signals.critical():
                            finish(
                                claims,
                                _failure_record(
                                    claims.spec,
                                    i,
                                    FailureCause.SIMULATOR_ERROR,
                                    f"the worker process died while running this trial, twice ({detail})",
                                    time.monotonic() - w.sent,
                                ),
                            )
                    else:
                        crashed.add((claims.spec.run_key, i))
                        claims.requeue(i)
            now = time.monotonic()
            for w in list(pool):
                t0 = w.started if w.started is not None else w.sent + 60.0  # 60 s to start up
                if w.index is not None and (lim := limit(w)) is not None and now - t0 > lim:
                    i, w.index = w.index, None
                    claims = run_of[w]
                    w.stop(kill=True)
                    pool.remove(w)
                    budget = claims.spec.budget.wall_s
                    why = (
                        f"wall-time budget of {budget:g} s spent"
                        if budget is not None
                        else f"no wall-time budget set; the backstop of {lim:g} s "
                        f"(max({BACKSTOP_MIN_S:g} s, {BACKSTOP_FACTOR:g} × the simulated budget)) "
                        "passed"
                    )
                    with signals.critical():
                        finish(
                            claims,
                            _failure_record(
                                claims.spec,
                                i,
                                FailureCause.TIMEOUT,
                                f"{why} and the trial did not stop (stuck outside Python?); "
                                f"the parent ended its worker process after {now - t0:.1f} s",
                                now - t0,
                            ),
                        )
    except KeyboardInterrupt:
        # Store what already finished (results sent but not yet read); stop the rest.
        for w in pool:
            try:
                while w.index is not None and w.conn.poll():
                    msg = w.conn.recv()
                    if msg[0] == "done":
                        w.index = None
                        finish(run_of[w], msg[1])
            except (EOFError, OSError):
                pass
        raise
    finally:
        for w in pool:
            w.stop(kill=w.index is not None)


def _start(
    spec: RunSpec,
    store: ResultsStore,
    owner: ClaimOwner,
    *,
    trials: str | None,
    retry_failed: bool,
    video: VideoSpec | None,
    wait_for_others: bool,
) -> _Claims:
    """One run's report and its queue of pending trials (every name checked first)."""
    plan = prepare(spec)
    selected = parse_trial_selection(trials, sorted(plan.items))
    if video is not None and video.trial_index not in plan.items:
        raise ValueError(f"--video-trial {video.trial_index}: this task has trials 1..{plan.total}")
    done = store.finished(spec.run_key, retry_failed=retry_failed)
    forced = {video.trial_index} if video is not None else set()
    pending = [i for i in selected if i not in done or i in forced]
    report = SweepReport(
        spec, plan, selected, skipped=[i for i in selected if i in done and i not in forced]
    )
    return _Claims(
        store,
        spec,
        pending,
        report,
        retry_failed=retry_failed,
        forced=forced,
        wait_for_others=wait_for_others,
        owner=owner,
    )


def _drive(
    runs: list[_Claims],
    store: ResultsStore,
    owner: ClaimOwner,
    workers: int,
    video: VideoSpec | None,
    on_record: Callable[[TrialRecord], None] | None,
) -> None:
    """Run the runs' pending trials: in one pool of ``workers`` processes, or here (``workers=0``)."""
    for claims in runs:
        store.ensure_run(claims.spec, claims.report.plan.benchmark, claims.report.plan.total)

    def finish(claims: _Claims, rec: TrialRecord) -> None:
        if not store.write(rec, claims.owner):
            claims.report.by_others.append(rec.trial_index)  # our lease lapsed; the taker stores it
            return
        claims.report.records.append(rec)
        if on_record is not None:
            on_record(rec)

    with _Signals() as signals, store.keep_claims(owner, LEASE_S):
        if workers > 0:
            ctx = multiprocessing.get_context("spawn")
            _run_in_workers(ctx, workers, runs, video, finish, signals)
            return
        while True:
            job = _next_job(runs)
            if job is None:
                if not _waiting(runs):
                    return
                time.sleep(0.5)
                continue
            with _quiet_stdout():
                rec = execute_trial(job[0].spec, job[1], video)
            with signals.critical():
                finish(job[0], rec)


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
    wait_for_others: bool = True,
) -> SweepReport:
    """Run the pending trials of ``spec``; ``workers=0`` runs them in this process (debugging).

    ``workers=0`` has no watchdog (nothing outside the trial could end it):
    only the per-step budget check and the wall alarm apply. Raises
    :class:`SweepInterrupted` on Ctrl-C/SIGTERM once finished trials are stored.
    """
    owner = ClaimOwner.new()
    claims = _start(
        spec,
        store,
        owner,
        trials=trials,
        retry_failed=retry_failed,
        video=video,
        wait_for_others=wait_for_others,
    )
    if on_start is not None:
        on_start(claims.report, len(claims.queue))
    _drive([claims], store, owner, workers, video, on_record)
    return claims.report


def run_sweeps(
    specs: Sequence[RunSpec],
    store: ResultsStore,
    *,
    workers: int = 1,
    retry_failed: bool = False,
    on_record: Callable[[TrialRecord], None] | None = None,
    wait_for_others: bool = True,
) -> list[SweepReport]:
    """Every pending trial of several runs (a grid) through one pool; one report per run, in order.

    Why one pool, not :func:`run_sweep` per run: the Rubiks-1-N tiers are runs
    of one trial, and a grid of them run in turn kept one worker of two busy
    (measured: 12 one-trial runs with ``--workers 2`` took the 1-worker wall
    time, BENCHMARKS.md "2026-12-03: sweep wall time"). Trials are given out in grid order;
    each depends only on (run, index), so the rows are the same for any
    worker count.
    """
    owner = ClaimOwner.new()  # one lease holder for the whole grid
    runs = [
        _start(
            spec,
            store,
            owner,
            trials=None,
            retry_failed=retry_failed,
            video=None,
            wait_for_others=wait_for_others,
        )
        for spec in specs
    ]
    _drive(runs, store, owner, workers, None, on_record)
    return [claims.report for claims in runs]
