"""The Ray executor on a real local cluster (2 CPUs, every port on 127.0.0.1, no dashboard).

Skipped without ray (``pip install 'benchharness[cluster]'``). The oracle for
the rows is the process pool: the same grid must store the same rows.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from pathlib import Path

import pytest

# Ray's single-machine mode (every port on 127.0.0.1), read when ray is imported
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
ray = pytest.importorskip(
    "ray", reason="ray is not installed (pip install 'benchharness[cluster]')"
)

from benchharness.runner import FailureCause, ResultsStore  # noqa: E402
from benchharness.runner.executors import run_grid  # noqa: E402
from benchharness.runner.grid import Grid, expand  # noqa: E402

HERE = Path(__file__).resolve().parent
pytestmark = pytest.mark.sim


@pytest.fixture(autouse=True)
def _worker_env(monkeypatch):
    """Ray workers are new interpreters: they find the test plugins through PYTHONPATH."""
    paths = [str(HERE), *[p for p in sys.path if p and Path(p).is_dir()]]
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(dict.fromkeys(paths)))
    monkeypatch.setenv("RAY_USAGE_STATS_ENABLED", "0")
    monkeypatch.delenv("RAY_ADDRESS", raising=False)


LOOPBACK = {"0100007F", "0000000000000000FFFF00000100007F", "00000000000000000000000001000000"}


def _listening() -> list[tuple[str, int]]:
    """(hex address, port) of every TCP socket listening in a process of this session (the cluster's)."""
    sid = os.getsid(0)
    inodes = set()
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            if os.getsid(int(pid)) != sid:
                continue
            for fd in os.listdir(f"/proc/{pid}/fd"):
                link = os.readlink(f"/proc/{pid}/fd/{fd}")
                if link.startswith("socket:["):
                    inodes.add(link[8:-1])
        except OSError:
            continue
    out = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with open(table) as f:
            for line in list(f)[1:]:
                cols = line.split()
                if cols[3] == "0A" and cols[9] in inodes:  # LISTEN
                    addr, port = cols[1].split(":")
                    out.append((addr, int(port, 16)))
    return out


def _rows(path):
    with ResultsStore(path, read_only=True) as store:
        return sorted(((t.run_key, t.trial_index), t.comparable()) for t in store.trials())


def test_ray_stores_the_rows_the_pool_stores(tmp_path):
    plan = expand(
        Grid(
            tasks=("Rubiks-5-5",),
            robots=("test-stub",),
            strategies=("test-drop", "test-simerror"),
            seeds=(0, 4),
            plugins=("runner_testplugins",),
        )
    )
    with ResultsStore(tmp_path / "pool.sqlite") as store:
        run_grid(plan.specs, store, executor="pool", workers=2)
    listening: list[tuple[str, int]] = []
    with ResultsStore(tmp_path / "ray.sqlite") as store:
        reports = run_grid(
            plan.specs,
            store,
            executor="ray",
            num_cpus=2,
            on_record=lambda rec: listening or listening.extend(_listening()),
        )
    assert listening, "no listening socket of the cluster found"
    outside = [a for a in listening if a[0] not in LOOPBACK]
    assert not outside, f"the local cluster listens beyond the loopback address: {outside}"
    assert [r.ran for r in reports] == [5, 5, 5, 5]
    pool, on_ray = _rows(tmp_path / "pool.sqlite"), _rows(tmp_path / "ray.sqlite")
    assert len(pool) == 20
    assert [k for k, _ in on_ray] == [k for k, _ in pool]
    assert on_ray == pool
    assert {row["failure_cause"] for _, row in pool} == {None, "simulator_error"}


def _kill_when_written(piddir: Path, trial: int, killed: list[int]) -> threading.Thread:
    def watch() -> None:
        mark = piddir / f"{trial}.pid"
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if mark.exists() and mark.read_text():
                pid = int(mark.read_text())
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
                return
            time.sleep(0.1)

    t = threading.Thread(target=watch, daemon=True)
    t.start()
    return t


@pytest.mark.parametrize("max_retries", [1, 0])
def test_killed_worker_retried_then_stored_once(tmp_path, monkeypatch, max_retries):
    piddir = tmp_path / "pids"
    piddir.mkdir()
    monkeypatch.setenv("SWEEP_TEST_PIDDIR", str(piddir))
    (spec,) = expand(
        Grid(
            tasks=("Rubiks-5-5",),
            robots=("test-stub",),
            strategies=("test-pidsleep",),
            plugins=("runner_testplugins", "sweep_testplugins"),
        )
    ).specs
    for i in (1, 2, 4, 5):  # only trial 3 sleeps (and is killed)
        (piddir / f"{i}.pid").write_text("")
    killed: list[int] = []
    watcher = _kill_when_written(piddir, 3, killed)
    path = tmp_path / "ray.sqlite"
    with ResultsStore(path) as store:
        (report,) = run_grid([spec], store, executor="ray", num_cpus=2, max_retries=max_retries)
    watcher.join(1)
    assert len(killed) == 1 and killed[0] != os.getpid()
    with ResultsStore(path, read_only=True) as store:
        rows = store.trials(run_key=spec.run_key)
        assert store.claims() == []
    assert [t.trial_index for t in rows] == [1, 2, 3, 4, 5]  # each exactly once
    three = rows[2]
    if max_retries:
        assert three.status.value == "success" and three.score == 3.0  # test-timed scores its index
    else:
        assert three.failure_cause is FailureCause.SIMULATOR_ERROR
        assert "failed 1 time(s)" in three.message and "Worker" in three.message
    assert [r.trial_index for r in report.records if r.trial_index == 3] == [3]
