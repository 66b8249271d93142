"""Where a grid's trials run: the local process pool, or a Ray cluster.

Both keep :mod:`.sweep`'s semantics: run keys, resume (stored trials are
skipped), claims in the store, and the driver as the one writer of the
SQLite store, writing each trial as it finishes.

* ``pool`` runs the whole grid through one process pool,
  :func:`.sweep.run_sweeps` (its worker processes, watchdog and crash retry):
  a freed worker takes the next trial of any run, so one-trial runs run side
  by side.
* ``ray`` submits every pending trial of the grid as one Ray task
  (``num_cpus=1``). Ray retries a task whose worker process dies
  (``max_retries`` times); after that the trial is stored as
  ``simulator_error`` with Ray's cause. Trials are deterministic in
  (run, index), so a retry gives the row a first attempt would have. On
  Ctrl-C/SIGTERM the driver stores what has finished, cancels the rest and
  releases its claims; a re-run resumes. Without ``address`` (or
  ``RAY_ADDRESS``) a local cluster is started bound to 127.0.0.1, with no
  dashboard and usage statistics off. The in-trial time budgets apply on Ray
  as everywhere; the pool's watchdog for trials stuck in native code does not.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from typing import Any, Literal

from .causes import FailureCause
from .records import TrialRecord
from .spec import RunSpec
from .store import ClaimOwner, ResultsStore
from .sweep import LEASE_S, SweepReport, _failure_record, _Signals, _start, prepare, run_sweeps
from .trial import execute_trial

__all__ = ["EXECUTORS", "RAY_MISSING", "loopback_env", "pending_trials", "run_grid"]

EXECUTORS = ("pool", "ray")
RAY_MISSING = "--executor ray needs ray: pip install 'benchharness[cluster]'"
#: Ray's retries of a trial whose worker process died, before it is stored as simulator_error.
DEFAULT_MAX_RETRIES = 2


def pending_trials(spec: RunSpec, store: ResultsStore, retry_failed: bool = False) -> list[int]:
    """The trials of ``spec`` not yet stored (all of them with ``retry_failed`` for failed rows)."""
    plan = prepare(spec)
    done = store.finished(spec.run_key, retry_failed=retry_failed)
    return [i for i in sorted(plan.items) if i not in done]


def ray_trial(spec: RunSpec, index: int) -> TrialRecord:
    """One trial in a Ray worker (never raises for a failing trial, like the pool's workers)."""
    return execute_trial(spec, index, None, contain_interrupts=True)


def run_grid(
    specs: Sequence[RunSpec],
    store: ResultsStore,
    *,
    executor: str = "pool",
    workers: int = 1,
    address: str | None = None,
    num_cpus: int | None = None,
    max_retries: int = DEFAULT_MAX_RETRIES,
    retry_failed: bool = False,
    on_record: Callable[[TrialRecord], None] | None = None,
) -> list[SweepReport]:
    """Run every pending trial of ``specs``; one :class:`SweepReport` per run, in order."""
    if executor == "pool":
        return run_sweeps(
            specs, store, workers=workers, retry_failed=retry_failed, on_record=on_record
        )
    if executor == "ray":
        return _run_ray(specs, store, address, num_cpus, max_retries, retry_failed, on_record)
    raise ValueError(f"--executor {executor!r}: one of {', '.join(EXECUTORS)}")


def loopback_env(address: str | None) -> str | None:
    """Environment for Ray, set before ``import ray``; the cluster address (None: start our own).

    Usage statistics off always. For a cluster of our own, Ray's single-machine
    mode (``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0``, read when ray is imported):
    without it Ray replaces a node address of 127.0.0.1 by the machine's
    outward address and its gRPC servers listen on every interface.
    """
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    address = address or os.environ.get("RAY_ADDRESS") or None
    if address is None:
        os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
    return address


def _init_ray(ray: Any, address: str | None, num_cpus: int | None) -> None:
    if address:
        ray.init(address=address, log_to_driver=False)
        return
    # A cluster of our own: every port on the loopback address, no dashboard.
    ray.init(
        address="local",
        num_cpus=num_cpus,
        include_dashboard=False,
        _node_ip_address="127.0.0.1",
        log_to_driver=False,
    )


def _run_ray(
    specs: Sequence[RunSpec],
    store: ResultsStore,
    address: str | None,
    num_cpus: int | None,
    max_retries: int,
    retry_failed: bool,
    on_record: Callable[[TrialRecord], None] | None,
) -> list[SweepReport]:
    address = loopback_env(address)
    try:
        import ray
        from ray.exceptions import RayError
    except ImportError:
        raise ValueError(RAY_MISSING) from None
    if max_retries < 0:
        raise ValueError(f"--max-retries {max_retries}: must be 0 or more")
    owner = ClaimOwner.new()
    reports = [  # every name checked before the cluster starts; the pool's own run reports
        _start(
            spec,
            store,
            owner,
            trials=None,
            retry_failed=retry_failed,
            video=None,
            wait_for_others=False,
        ).report
        for spec in specs
    ]
    since = time.time()
    started_here = not ray.is_initialized()
    if started_here:
        _init_ray(ray, address, num_cpus)
    task = ray.remote(num_cpus=1, max_retries=max_retries, retry_exceptions=False)(ray_trial)
    inflight: dict[Any, tuple[SweepReport, int, float]] = {}
    try:
        with _Signals() as signals, store.keep_claims(owner, LEASE_S):
            for report in reports:
                spec = report.spec
                store.ensure_run(spec, report.plan.benchmark, report.plan.total)
                for i in report.selected:
                    if i in report.skipped:
                        continue
                    redo: Literal["failed"] | None = "failed" if retry_failed else None
                    got = store.claim(
                        spec.run_key, i, owner, lease_s=LEASE_S, redo=redo, since=since
                    )
                    if got != "claimed":  # stored meanwhile, or another live sweep runs it
                        (report.by_others if got == "done" else report.busy).append(i)
                        continue
                    inflight[task.remote(spec, i)] = (report, i, time.monotonic())
            try:
                while inflight:
                    ready, _ = ray.wait(list(inflight), num_returns=1, timeout=1.0)
                    for ref in ready:
                        report, i, sent = inflight.pop(ref)
                        try:
                            rec = ray.get(ref)
                        except RayError as exc:
                            first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
                            rec = _failure_record(
                                report.spec,
                                i,
                                FailureCause.SIMULATOR_ERROR,
                                f"the Ray task running this trial failed {max_retries + 1} time(s) "
                                f"({type(exc).__name__}: {first})",
                                time.monotonic() - sent,
                            )
                        with signals.critical():
                            if store.write(rec, owner):
                                report.records.append(rec)
                                if on_record is not None:
                                    on_record(rec)
                            else:
                                report.by_others.append(i)
            except KeyboardInterrupt:
                for ref in inflight:
                    ray.cancel(ref, force=True)
                raise
    finally:
        if started_here:
            ray.shutdown()
    return reports
