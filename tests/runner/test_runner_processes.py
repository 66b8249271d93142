"""Process hygiene of a sweep: kill, SIGTERM, Ctrl-C, a stuck trial, a strategy that exits,
two runs of the same command at once.

The runs are real ``benchharness run`` processes on tiny test strategies
(``runner_testplugins``): what is checked is the operating system's view
(which processes still exist, found by a marker in their environment) and
what the store holds afterwards.
"""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

from benchharness.runner import FailureCause, ResultsStore, TimeBudget, TrialStatus, run_sweep
from benchharness.runner.store import StoreError
from benchharness.runner.trial import execute_trial

HERE = Path(__file__).resolve().parent  # holds runner_testplugins.py
PLUGIN = "runner_testplugins"
CODE = "import sys; from benchharness.cli.run import run; run(sys.argv[1:])"

pytestmark = pytest.mark.sim
linux_only = pytest.mark.skipif(
    not Path("/proc/self/environ").exists(), reason="finds processes through /proc"
)


def _args(store: Path, strategy: str = "test-drop", workers: int = 2, *extra: str) -> list[str]:
    return [
        "--task",
        "Rubiks-5-5",
        "--robot",
        "test-stub",
        "--strategy",
        strategy,
        "--plugin",
        PLUGIN,
        "--workers",
        str(workers),
        "--store",
        str(store),
        "--json",
        "--no-progress",
        *extra,
    ]


def _env(**extra: str) -> dict[str, str]:
    path = os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")])
    return dict(os.environ, PYTHONPATH=path, **extra)


def _marked(mark: str) -> list[int]:
    """Live (non-zombie) processes whose environment holds ``RUNNER_TEST_MARK=mark``."""
    needle = f"RUNNER_TEST_MARK={mark}".encode()
    found = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            if needle not in (d / "environ").read_bytes().split(b"\0"):
                continue
            state = (d / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if state not in ("Z", "X"):
            found.append(int(d.name))
    return found


def _count(path: Path) -> int:
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True, timeout=5)
        try:
            return con.execute("SELECT count(*) FROM trials").fetchone()[0]
        finally:
            con.close()
    except sqlite3.Error:
        return 0


def _wait(cond, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cond():
            return True
        time.sleep(0.05)
    return cond()


class _Run:
    """A ``benchharness run`` in its own session; ``close`` kills whatever is left of it."""

    def __init__(self, store: Path, *, strategy="test-drop", workers=2, extra=(), **env: str):
        self.mark = uuid.uuid4().hex
        self.proc = subprocess.Popen(
            [sys.executable, "-c", CODE, *_args(store, strategy, workers, *extra)],
            env=_env(RUNNER_TEST_MARK=self.mark, **env),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )

    def workers(self) -> list[int]:
        return [p for p in _marked(self.mark) if p != self.proc.pid]

    def close(self) -> None:
        for pid in _marked(self.mark):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.communicate()


@pytest.fixture
def launch():
    runs: list[_Run] = []

    def start(*a, **kw) -> _Run:
        runs.append(_Run(*a, **kw))
        return runs[-1]

    yield start
    for r in runs:
        r.close()


# -- 1, 2: the parent killed, terminated or interrupted ---------------------------------------


@linux_only
def test_sigkill_of_the_run_takes_its_workers_with_it(launch, store_path):
    r = launch(store_path, RUNNER_TEST_HANG_FROM="1")  # every trial still running at the kill
    assert _wait(lambda: len(r.workers()) >= 2, 60), "the two workers never started"
    time.sleep(1.0)  # mid-trial
    r.proc.send_signal(signal.SIGKILL)  # the parent only: no clean-up code of its runs
    r.proc.wait(10)
    assert _wait(lambda: not r.workers(), 10), f"workers outlived their parent: {r.workers()}"


@linux_only
@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_sigterm_and_ctrl_c_stop_in_flight_trials_and_keep_finished_ones(
    launch, store_path, sig, code
):
    # trials 1 and 2 finish at once; 3 and 4 would take two minutes
    r = launch(store_path, RUNNER_TEST_HANG_FROM="3")
    assert _wait(lambda: _count(store_path) >= 2 and len(r.workers()) >= 2, 60)
    time.sleep(0.5)
    t0 = time.monotonic()
    r.proc.send_signal(sig)  # the parent only, as `kill` does (a terminal's Ctrl-C: below)
    out, err = r.proc.communicate(timeout=30)
    assert time.monotonic() - t0 < 15, "waited for the in-flight trials"
    assert r.proc.returncode == code, err
    assert "Re-run the same command to resume" in err
    assert _wait(lambda: not r.workers(), 10), f"workers outlived the run: {r.workers()}"
    with ResultsStore(store_path, read_only=True) as store:
        rows = store.trials()
        assert [t.trial_index for t in rows] == [1, 2]
        assert all(t.status is TrialStatus.SUCCESS for t in rows)
        assert store.claims() == []  # nothing is left claimed: a re-run takes trials 3-5 at once


def test_sigterm_stops_an_in_process_sweep_too(launch, store_path):
    r = launch(store_path, workers=0, RUNNER_TEST_HANG_FROM="3")
    assert _wait(lambda: _count(store_path) >= 2, 60)
    time.sleep(0.5)
    r.proc.send_signal(signal.SIGTERM)
    out, err = r.proc.communicate(timeout=30)
    assert r.proc.returncode == 143, err
    with ResultsStore(store_path, read_only=True) as store:
        assert [t.trial_index for t in store.trials()] == [1, 2] and store.claims() == []


@linux_only
def test_ctrl_c_in_a_terminal_reaches_the_whole_group(launch, store_path):
    r = launch(store_path, RUNNER_TEST_HANG_FROM="3")
    assert _wait(lambda: _count(store_path) >= 2 and len(r.workers()) >= 2, 60)
    os.killpg(r.proc.pid, signal.SIGINT)  # what the terminal does on Ctrl-C
    out, err = r.proc.communicate(timeout=30)
    assert r.proc.returncode == 130, err
    assert _wait(lambda: not r.workers(), 10)
    with ResultsStore(store_path, read_only=True) as store:
        assert [t.trial_index for t in store.trials()] == [1, 2]  # no in-flight trial stored


# -- 3: a trial stuck where the wall alarm cannot reach it ------------------------------------


def test_the_parent_ends_a_stuck_trial_at_the_wall_budget(make_spec, store_path):
    spec = make_spec("test-stuck", task="Rubiks-1-5", budget=TimeBudget(sim_s=30.0, wall_s=0.5))
    t0 = time.monotonic()
    with ResultsStore(store_path) as store:
        report = run_sweep(spec, store, workers=1)
        (row,) = store.trials(run_key=spec.run_key)
    assert time.monotonic() - t0 < 30  # the strategy sleeps 60 s with the alarm blocked
    assert report.ran == 1
    assert row.failure_cause is FailureCause.TIMEOUT
    assert "wall-time budget of 0.5 s" in row.message and "ended" in row.message


def test_without_a_wall_budget_the_backstop_ends_a_stuck_trial(make_spec, store_path, monkeypatch):
    from benchharness.runner import sweep

    # the real backstop is max(600 s, 10 × sim budget); scaled down here so the test takes seconds
    monkeypatch.setattr(sweep, "BACKSTOP_MIN_S", 0.0)
    monkeypatch.setattr(sweep, "BACKSTOP_FACTOR", 0.5)
    spec = make_spec("test-stuck", task="Rubiks-1-5", budget=TimeBudget(sim_s=2.0))
    assert sweep.watchdog_limit(spec.budget) == pytest.approx(1.0)
    with ResultsStore(store_path) as store:
        run_sweep(spec, store, workers=1)
        (row,) = store.trials(run_key=spec.run_key)
    assert row.failure_cause is FailureCause.TIMEOUT
    assert "no wall-time budget set; the backstop of 1 s" in row.message


def test_default_wall_backstop_is_derived_from_the_simulated_budget():
    from benchharness.runner.sweep import watchdog_limit

    assert watchdog_limit(TimeBudget(sim_s=120.0)) == pytest.approx(max(600.0, 10 * 120.0))
    assert watchdog_limit(TimeBudget(sim_s=1320.0)) == pytest.approx(13200.0)
    # an explicit wall budget: the alarm inside the trial speaks first, then the parent
    explicit = watchdog_limit(TimeBudget(sim_s=1320.0, wall_s=10.0))
    assert 10.0 * 1.1 + 1.0 < explicit < 30.0


# -- 4: SystemExit / KeyboardInterrupt raised by a strategy -----------------------------------


@pytest.mark.parametrize(
    "strategy, text", [("test-exit", "SystemExit: 3"), ("test-interrupt", "KeyboardInterrupt")]
)
def test_a_strategy_that_exits_fails_its_trial_only(make_spec, store_path, strategy, text):
    spec = make_spec(strategy)
    with ResultsStore(store_path) as store:
        report = run_sweep(spec, store, workers=1)
        rows = store.trials(run_key=spec.run_key)
    assert report.ran == 5 and len(rows) == 5
    assert {t.failure_cause for t in rows} == {FailureCause.STRATEGY_ERROR}
    assert all(text in t.message and "Traceback" in t.traceback for t in rows)


def test_system_exit_is_contained_in_process_too(make_spec):
    rec = execute_trial(make_spec("test-exit"), 1)
    assert rec.failure_cause is FailureCause.STRATEGY_ERROR and "SystemExit: 3" in rec.message


def test_a_trial_that_kills_its_worker_twice_is_a_simulator_error(make_spec, store_path):
    spec = make_spec("test-segfault")
    with ResultsStore(store_path) as store:
        report = run_sweep(spec, store, workers=2)
        rows = {t.trial_index: t for t in store.trials(run_key=spec.run_key)}
    assert report.ran == 5 and sorted(rows) == [1, 2, 3, 4, 5]
    assert rows[2].failure_cause is FailureCause.SIMULATOR_ERROR
    assert "died while running this trial, twice" in rows[2].message
    assert f"exit code {-signal.SIGSEGV}" in rows[2].message
    assert all(rows[i].status is TrialStatus.SUCCESS for i in (1, 3, 4, 5))


# -- 5: two runs of the same command at once --------------------------------------------------


def test_two_concurrent_runs_share_the_trials(launch, store_path, tmp_path):
    log = tmp_path / "executions.log"
    env = dict(RUNNER_TEST_SLEEP="2", RUNNER_TEST_LOG=str(log))  # ~10 s for one run alone
    first = launch(store_path, workers=1, **env)

    def claimed() -> bool:
        try:
            with ResultsStore(store_path, read_only=True) as store:
                return bool(store.claims())
        except (StoreError, sqlite3.Error):  # not created yet
            return False

    assert _wait(claimed, 60)  # the first run is under way: the second starts mid-run
    runs = [first, launch(store_path, workers=1, **env)]
    outs = []
    for r in runs:
        out, err = r.proc.communicate(timeout=120)
        assert r.proc.returncode == 0, err
        outs.append(json.loads(out[out.index("{") :]))
    executed = sorted(int(line.split()[1]) for line in log.read_text().splitlines())
    assert executed == [1, 2, 3, 4, 5], f"each trial once, found {executed}"
    assert sum(o["ran"] for o in outs) == 5 and all(o["ran"] >= 1 for o in outs)
    for o in outs:  # each run ends with the whole run's results, its own and the other's
        assert sorted(t["trial"] for t in o["trials"]) == [1, 2, 3, 4, 5]
    with ResultsStore(store_path, read_only=True) as store:
        assert len(store.trials()) == 5 and store.claims() == []


def test_a_claim_whose_owner_died_is_taken_over(make_spec, store_path):
    from benchharness.runner.store import ClaimOwner

    spec = make_spec("test-drop")
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True
    )
    with ResultsStore(store_path) as store:
        store.ensure_run(spec, "rubiks", 5)
        ghost = ClaimOwner.new()
        ghost = ClaimOwner(ghost.host, int(dead.stdout), ghost.token + "-ghost")  # exited already
        assert store.claim(spec.run_key, 1, ghost, lease_s=600) == "claimed"
        elsewhere = ClaimOwner("another-host", 1, "t")  # live as far as this host can tell
        assert store.claim(spec.run_key, 2, elsewhere, lease_s=600) == "claimed"
        report = run_sweep(spec, store, workers=0, trials="1", wait_for_others=False)
        assert [r.trial_index for r in report.records] == [1]
        report = run_sweep(spec, store, workers=0, trials="2", wait_for_others=False)
        assert report.records == [] and report.busy == [2]
