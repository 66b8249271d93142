"""Issue 13 item 13: the contact-region tool is a ``benchharness inhand`` subcommand.

``python -m benchharness.strategies.dmg.regions --help`` used to create a
file named ``--help``; with no argument it rewrote the tracked
tasks/inhand/level2_dmg_regions.csv; a missing store became an empty file.
Now ``inhand regions STORE`` only reads, and ``inhand region-tasks --out``
writes only where asked (the module itself is now
``benchharness.runner.contact_regions``, with no command of its own).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from click.testing import CliRunner

from benchharness.cli.main import cli

REPO = Path(__file__).resolve().parents[1]
TRACKED = REPO / "tasks" / "inhand" / "level2_dmg_regions.csv"


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _invoke(*args):
    return CliRunner().invoke(cli, ["inhand", *map(str, args)])


def test_help_and_errors_write_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = _digest(TRACKED)
    r = _invoke("regions", "--help")
    assert r.exit_code == 0 and "STORE" in r.output
    assert _invoke("region-tasks", "--help").exit_code == 0
    r = _invoke("regions", tmp_path / "missing.sqlite")
    assert r.exit_code == 2 and "missing.sqlite: no such results store" in r.stderr
    r = _invoke("region-tasks")  # --out is required: no default target
    assert r.exit_code == 2 and "--out" in r.output
    assert list(tmp_path.iterdir()) == []
    assert _digest(TRACKED) == before


def test_region_tasks_writes_only_where_asked_and_reproduces_the_tracked_file(tmp_path):
    pytest_out = tmp_path / "l2.csv"
    before = _digest(TRACKED)
    r = _invoke("region-tasks", "--out", pytest_out, "--json")
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout) == {"written": str(pytest_out)}
    assert pytest_out.read_text() == TRACKED.read_text()
    assert _digest(TRACKED) == before


def test_regions_reads_a_store_without_modifying_it(tmp_path):
    from benchharness.runner.store import ResultsStore

    path = tmp_path / "s.sqlite"
    ResultsStore(path).close()
    before = _digest(path)
    names = sorted(p.name for p in tmp_path.iterdir())
    r = _invoke("regions", path, "--json")
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout) == {"store": str(path), "trials": []}
    assert "No DMG trials" in _invoke("regions", path).output
    assert _digest(path) == before and sorted(p.name for p in tmp_path.iterdir()) == names
    other = tmp_path / "notes.txt"
    other.write_text("not a database")
    r = _invoke("regions", other)
    assert r.exit_code == 2 and "not a benchharness results store" in r.stderr
    assert other.read_text() == "not a database"
