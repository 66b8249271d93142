"""Which files the harness may open as its store, and what reading one may change (nothing)."""

from __future__ import annotations

import json
import os
import sqlite3
from pathlib import Path

import pytest

from benchharness.cli.run import results, run, table
from benchharness.runner import ResultsStore
from benchharness.runner import store as store_module

PLUGIN = "runner_testplugins"
RUN = ["--task", "Rubiks-5-5", "--robot", "test-stub", "--strategy", "test-drop"]
RUN += ["--plugin", PLUGIN, "--workers", "0", "--no-progress", "--json"]

pytestmark = pytest.mark.sim

# Schema version 1, as created by the first store (git show 0ffcf61:src/benchharness/runner/store.py).
V1_SCHEMA = """
CREATE TABLE IF NOT EXISTS schema_version (version INTEGER NOT NULL);
CREATE TABLE IF NOT EXISTS runs (
    run_key TEXT PRIMARY KEY, benchmark TEXT NOT NULL, task TEXT NOT NULL, robot TEXT NOT NULL,
    strategy TEXT NOT NULL, sensors TEXT NOT NULL, backend TEXT NOT NULL, seed INTEGER NOT NULL,
    physics_hash TEXT NOT NULL, options_hash TEXT NOT NULL, code_version TEXT NOT NULL,
    trials_total INTEGER NOT NULL, spec_json TEXT NOT NULL, created_at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS trials (
    run_key TEXT NOT NULL REFERENCES runs(run_key), trial_index INTEGER NOT NULL,
    benchmark TEXT NOT NULL, task TEXT NOT NULL, robot TEXT NOT NULL, strategy TEXT NOT NULL,
    sensors TEXT NOT NULL, backend TEXT NOT NULL, seed INTEGER NOT NULL,
    physics_hash TEXT NOT NULL, options_hash TEXT NOT NULL, code_version TEXT NOT NULL,
    status TEXT NOT NULL, score REAL, failure_cause TEXT, message TEXT NOT NULL DEFAULT '',
    wall_s REAL, sim_s REAL, first_contact_s REAL, termination_s REAL,
    outcome_json TEXT NOT NULL DEFAULT '{}', diagnostics_json TEXT NOT NULL DEFAULT '{}',
    traceback TEXT NOT NULL DEFAULT '', finished_at REAL NOT NULL,
    PRIMARY KEY (run_key, trial_index)
);
CREATE INDEX IF NOT EXISTS trials_by_task ON trials (task, strategy, backend);
"""


def _snapshot(path: Path) -> tuple[bytes, int, list[str]]:
    return path.read_bytes(), path.stat().st_mtime_ns, sorted(os.listdir(path.parent))


def _invoke(command, *args):
    from click.testing import CliRunner

    return CliRunner().invoke(command, list(args), catch_exceptions=False)


def _foreign(path: Path) -> Path:
    con = sqlite3.connect(path)
    con.executescript(
        "CREATE TABLE notes (id INTEGER PRIMARY KEY, body TEXT);"
        "INSERT INTO notes (body) VALUES ('my data');"
    )
    con.commit()
    con.close()
    return path


# -- 7: another application's database ---------------------------------------------------------


@pytest.mark.parametrize("with_trials_table", [False, True])
def test_another_applications_database_is_refused_untouched(tmp_path, with_trials_table):
    path = _foreign(tmp_path / "app.db")
    if with_trials_table:  # even one whose table names happen to match ours
        con = sqlite3.connect(path)
        con.execute("CREATE TABLE trials (x)")
        con.commit()
        con.close()
    before = _snapshot(path)
    for command, args in ((run, RUN), (table, []), (results, [])):
        r = _invoke(command, *args, "--store", str(path))
        assert r.exit_code == 2, (command.name, r.output)
        assert str(path) in r.stderr and "not a benchharness" in r.stderr
        assert "Traceback" not in r.stderr
    assert _snapshot(path) == before


def test_an_application_id_of_another_program_is_refused(tmp_path):
    path = tmp_path / "other.sqlite"
    con = sqlite3.connect(path)
    con.execute("PRAGMA application_id = 1234")
    con.execute("CREATE TABLE t (x)")
    con.commit()
    con.close()
    before = _snapshot(path)
    with pytest.raises(store_module.StoreError, match="application_id 1234"):
        ResultsStore(path)
    assert _snapshot(path) == before


def test_a_new_store_is_marked_as_ours(store_path):
    with ResultsStore(store_path):
        pass
    con = sqlite3.connect(store_path)
    assert con.execute("PRAGMA application_id").fetchone()[0] == store_module.APPLICATION_ID
    assert con.execute("PRAGMA user_version").fetchone()[0] == store_module.SCHEMA_VERSION
    con.close()


# -- 8: older schema ---------------------------------------------------------------------------


def _v1_store(path: Path, tmp_path: Path) -> None:
    """A version-1 store holding trials 1 and 2 of ``RUN``, as version 1 wrote it.

    The rows are a real run's (made by ``run --trials 1-2`` in a scratch store),
    copied column by column into tables created with version 1's statements.
    """
    scratch = tmp_path / "scratch.sqlite"
    r = _invoke(run, *RUN, "--trials", "1-2", "--store", str(scratch))
    assert r.exit_code == 0, r.stderr
    con = sqlite3.connect(path)
    con.execute("PRAGMA journal_mode=WAL")
    con.executescript(V1_SCHEMA)
    con.execute("INSERT INTO schema_version (version) VALUES (1)")
    con.execute("ATTACH DATABASE ? AS scratch", (str(scratch),))
    for name in ("runs", "trials"):
        cols = ", ".join(r[1] for r in con.execute(f"PRAGMA main.table_info({name})"))
        con.execute(f"INSERT INTO main.{name} ({cols}) SELECT {cols} FROM scratch.{name}")
    con.commit()
    con.execute("DETACH DATABASE scratch")
    con.close()


def test_a_version_1_store_is_read_as_is_and_migrated_by_run(tmp_path):
    path = tmp_path / "old.sqlite"
    _v1_store(path, tmp_path)
    before = _snapshot(path)
    r = _invoke(results, "--json", "--store", str(path))
    assert r.exit_code == 0, r.stderr
    assert [t["trial"] for t in json.loads(r.stdout)["trials"]] == [1, 2]
    assert _snapshot(path) == before  # reading did not migrate it
    r = _invoke(run, *RUN, "--store", str(path))
    assert r.exit_code == 0, r.stderr
    data = json.loads(r.stdout[r.stdout.index("{") :])
    assert data["skipped"] == [1, 2] and data["ran"] == 3
    con = sqlite3.connect(path)
    assert (
        con.execute("SELECT max(version) FROM schema_version").fetchone()[0]
        == store_module.SCHEMA_VERSION
    )
    assert con.execute("PRAGMA application_id").fetchone()[0] == store_module.APPLICATION_ID
    assert con.execute("SELECT count(*) FROM trials").fetchone()[0] == 5
    con.close()


def test_a_store_of_an_unknown_older_version_is_refused_with_its_version(tmp_path):
    path = tmp_path / "v0.sqlite"
    con = sqlite3.connect(path)
    con.executescript(V1_SCHEMA)
    con.execute("INSERT INTO schema_version (version) VALUES (0)")
    con.commit()
    con.close()
    before = _snapshot(path)
    for command, args in ((run, RUN), (results, [])):
        r = _invoke(command, *args, "--store", str(path))
        assert r.exit_code == 2 and "schema version 0" in r.stderr, r.stderr
    assert _snapshot(path) == before


def test_a_store_missing_columns_of_its_version_is_refused(tmp_path):
    path = tmp_path / "damaged.sqlite"
    con = sqlite3.connect(path)
    con.executescript(V1_SCHEMA.replace("options_hash TEXT NOT NULL, code_version", "code_version"))
    con.execute("INSERT INTO schema_version (version) VALUES (1)")
    con.commit()
    con.close()
    for command, args in ((run, RUN), (table, []), (results, [])):
        r = _invoke(command, *args, "--store", str(path))
        assert r.exit_code == 2, r.output
        assert "options_hash" in r.stderr and str(path) in r.stderr


# -- 9: commands that read ---------------------------------------------------------------------


def test_reading_a_missing_store_is_an_error_and_creates_nothing(tmp_path):
    path = tmp_path / "no" / "such" / "store.sqlite"
    for command in (table, results):
        r = _invoke(command, "--store", str(path))
        assert r.exit_code == 2 and str(path) in r.stderr and "no results store" in r.stderr
    assert not (tmp_path / "no").exists()


def test_reading_an_empty_file_leaves_it_empty(tmp_path):
    path = tmp_path / "empty.sqlite"
    path.touch()
    for command in (table, results):
        r = _invoke(command, "--store", str(path))
        assert r.exit_code == 2 and str(path) in r.stderr
    assert path.stat().st_size == 0 and os.listdir(tmp_path) == ["empty.sqlite"]


def test_reading_a_store_changes_nothing(store_path):
    r = _invoke(run, *RUN, "--store", str(store_path))
    assert r.exit_code == 0, r.stderr
    before = _snapshot(store_path)
    for command in (table, results):
        r = _invoke(command, "--store", str(store_path))
        assert r.exit_code == 0, r.stderr
        assert "test-drop" in r.stdout
    assert _snapshot(store_path) == before


def test_run_accepts_an_empty_file(tmp_path):
    path = tmp_path / "made-by-mktemp.sqlite"
    path.touch()
    r = _invoke(run, *RUN, "--store", str(path), "--trials", "1")
    assert r.exit_code == 0, r.stderr
    with ResultsStore(path, read_only=True) as store:
        assert len(store.trials()) == 1
