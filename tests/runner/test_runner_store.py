"""The SQLite results store: schema, durability settings, resume bookkeeping."""

from __future__ import annotations

import sqlite3

import pytest

from benchharness.runner import (
    FailureCause,
    ResultsStore,
    RunSpec,
    TrialRecord,
    TrialStatus,
    default_store_path,
)
from benchharness.runner.store import SCHEMA_VERSION, StoreError


def _spec(**kw) -> RunSpec:
    return RunSpec(
        task="Rubiks-5-5", robot="pr2", strategy="dead-reckoning", backend="pybullet", **kw
    )


def _rec(spec: RunSpec, i: int, ok: bool = True) -> TrialRecord:
    if ok:
        return TrialRecord(
            spec.run_key,
            i,
            TrialStatus.SUCCESS,
            10.0 + i,
            None,
            "",
            0.5,
            20.0,
            1.0,
            11.0 + i,
            {"final_state": "x"},
            {"events": [{"kind": "move", "t": 1.5}]},
        )
    return TrialRecord(
        spec.run_key,
        i,
        TrialStatus.FAILURE,
        None,
        FailureCause.WRONG_STATE,
        "differs",
        0.5,
        float("nan"),
        None,
        None,
        {},
        {},
        "Traceback ...",
    )


def test_schema_version_and_wal(store_path):
    with ResultsStore(store_path):
        pass
    con = sqlite3.connect(store_path)
    assert con.execute("SELECT version FROM schema_version").fetchall() == [(SCHEMA_VERSION,)]
    assert con.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    cols = [r[1] for r in con.execute("PRAGMA table_info(trials)")]
    for c in (
        "run_key",
        "task",
        "robot",
        "strategy",
        "sensors",
        "backend",
        "seed",
        "physics_hash",
        "code_version",
        "trial_index",
        "status",
        "score",
        "failure_cause",
        "wall_s",
        "sim_s",
        "diagnostics_json",
    ):
        assert c in cols
    con.close()
    with ResultsStore(store_path):  # reopening does not add a second version row
        pass
    assert (
        sqlite3.connect(store_path).execute("SELECT count(*) FROM schema_version").fetchone()[0]
        == 1
    )


def test_newer_schema_is_refused(store_path):
    with ResultsStore(store_path):
        pass
    con = sqlite3.connect(store_path)
    con.execute("UPDATE schema_version SET version = ?", (SCHEMA_VERSION + 1,))
    con.commit()
    con.close()
    with pytest.raises(StoreError, match="newer than this benchharness"):
        ResultsStore(store_path)


def test_not_a_store(tmp_path):
    bad = tmp_path / "x.sqlite"
    bad.write_text("not sqlite at all" * 100)
    with pytest.raises(StoreError, match="not a benchharness results store"):
        ResultsStore(bad)


def test_default_path_and_env(monkeypatch, tmp_path):
    monkeypatch.delenv("BENCHHARNESS_STORE", raising=False)
    assert default_store_path().name == "benchharness-results.sqlite"
    monkeypatch.setenv("BENCHHARNESS_STORE", str(tmp_path / "elsewhere.sqlite"))
    assert default_store_path() == tmp_path / "elsewhere.sqlite"
    with ResultsStore() as store:
        assert store.path == tmp_path / "elsewhere.sqlite"


def test_rows_roundtrip_and_resume_bookkeeping(store_path):
    spec = _spec()
    with ResultsStore(store_path) as store:
        store.ensure_run(spec, "rubiks", 5)
        store.ensure_run(spec, "rubiks", 5)  # idempotent
        store.write(_rec(spec, 1))
        store.write(_rec(spec, 2, ok=False))
        assert store.finished(spec.run_key) == {1, 2}
        assert store.finished(spec.run_key, retry_failed=True) == {1}
        rows = store.trials(run_key=spec.run_key)
    assert [r.trial_index for r in rows] == [1, 2]
    ok, bad = rows
    assert ok.comparable() == _rec(spec, 1).comparable()  # the row is the record it stored
    assert (
        ok.status is TrialStatus.SUCCESS
        and ok.score == 11.0
        and ok.diagnostics["events"][0]["kind"] == "move"
    )
    assert (ok.task, ok.robot, ok.strategy, ok.backend, ok.seed) == (
        "Rubiks-5-5",
        "pr2",
        "dead-reckoning",
        "pybullet",
        0,
    )
    assert ok.physics_hash == spec.physics_hash and ok.code_version == spec.code
    assert bad.failure_cause is FailureCause.WRONG_STATE and bad.sim_s is None and bad.traceback
    with ResultsStore(store_path) as store:  # a second connection sees what the first committed
        assert store.count(spec.run_key) == 2
        assert [r.trial_index for r in store.trials(failures_only=True)] == [2]
        assert store.trials(task="rubiks-5-5", strategy=["dead-reckoning"]) and not store.trials(
            backend="sapien"
        )


def test_write_needs_the_run(store_path):
    with ResultsStore(store_path) as store, pytest.raises(StoreError, match="ensure_run"):
        store.write(_rec(_spec(), 1))
