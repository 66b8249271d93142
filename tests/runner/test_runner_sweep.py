"""Sweeps: process pools, determinism across worker counts, resume after a real kill."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from benchharness.runner import FailureCause, ResultsStore, run_sweep

HERE = Path(__file__).resolve().parent  # holds runner_testplugins.py
PLUGIN = "runner_testplugins"

pytestmark = pytest.mark.sim


def _stored(path, run_key):
    with ResultsStore(path) as store:
        return [t.comparable() for t in store.trials(run_key=run_key)]


def test_same_seed_same_results_for_any_worker_count(make_spec, tmp_path):
    spec = make_spec("test-drop", task="Rubiks-5-10", seed=11)
    results = {}
    for workers in (0, 1, 2):
        path = tmp_path / f"w{workers}.sqlite"
        with ResultsStore(path) as store:
            report = run_sweep(spec, store, workers=workers)
        assert report.ran == 5 and report.failures == 0
        results[workers] = _stored(path, spec.run_key)
    assert results[0] == results[1] == results[2]
    assert len({r["score"] for r in results[0]}) > 1  # the trials really differ from each other


def test_failures_never_end_a_sweep_and_resume_skips_them(make_spec, store_path):
    spec = make_spec("test-simerror")
    with ResultsStore(store_path) as store:
        seen = []
        report = run_sweep(spec, store, workers=0, on_record=seen.append)
        assert report.ran == 5 and report.failures == 5 and len(seen) == 5
        assert {r.failure_cause for r in report.records} == {FailureCause.SIMULATOR_ERROR}
        again = run_sweep(spec, store, workers=0)
        assert again.ran == 0 and again.skipped == [1, 2, 3, 4, 5]
        retry = run_sweep(spec, store, workers=0, retry_failed=True, trials="2,4")
        assert [r.trial_index for r in retry.records] == [2, 4]


def test_unknown_names_fail_before_any_trial(make_spec, store_path):
    from benchharness.plugin import PluginNotFoundError

    with ResultsStore(store_path) as store:
        with pytest.raises(PluginNotFoundError, match="no strategy named 'nope'"):
            run_sweep(make_spec("nope"), store, workers=0)
        with pytest.raises(ValueError, match="runs inhand tasks, not rubiks"):
            run_sweep(make_spec("test-inhand"), store, workers=0)
        assert store.runs() == []


def _count(path) -> int:
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True, timeout=5)
        try:
            return con.execute("SELECT count(*) FROM trials").fetchone()[0]
        finally:
            con.close()
    except sqlite3.Error:
        return 0


def test_killed_sweep_resumes_where_it_stopped(store_path):
    args = [
        "--task",
        "Rubiks-5-5",
        "--robot",
        "test-stub",
        "--strategy",
        "test-drop",
        "--plugin",
        PLUGIN,
        "--workers",
        "1",
        "--store",
        str(store_path),
        "--json",
        "--no-progress",
    ]
    code = "import sys; from benchharness.cli.run import run; run(sys.argv[1:])"
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")])
    )
    slow = dict(env, RUNNER_TEST_SLEEP="0.6")
    proc = subprocess.Popen(
        [sys.executable, "-c", code, *args],
        env=slow,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 60
        while _count(store_path) < 2 and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the run and its pool worker: mid-sweep, no clean-up
        proc.wait()
    done = _count(store_path)
    assert 2 <= done < 5, f"expected the kill mid-sweep, found {done} trials stored"
    with ResultsStore(store_path) as store:
        before = {t.trial_index: t.finished_at for t in store.trials()}
    resume = [a if a != "1" else "0" for a in args]  # --workers is not part of the run key
    out = subprocess.run(
        [sys.executable, "-c", code, *resume], env=env, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    import json

    data = json.loads(out.stdout[out.stdout.index("{") :])
    assert data["ran"] == 5 - done and data["skipped"] == sorted(before)
    with ResultsStore(store_path) as store:
        rows = store.trials()
    assert [t.trial_index for t in rows] == [1, 2, 3, 4, 5]
    assert all(t.finished_at == before[t.trial_index] for t in rows if t.trial_index in before)
    assert all(t.status.value == "success" for t in rows)
