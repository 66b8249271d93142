"""In-hand task sets hold what their names say, and trial numbers mean one (task, repeat).

Oracle: the paper's Level I protocol (Cruciani et al., RA-L 2020, IV-A1: ten
objects x two initial x five desired grasps = 100 tasks) and the level of
each converted row.
"""

from __future__ import annotations

import pytest

from benchharness.plugin import get_manager
from benchharness.runner.tasks import parse_trial_selection, plan_task, trial_task


def _plan(name: str, repeats: int = 1):
    return plan_task(name, get_manager().create("task", name), seed=0, repeats=repeats)


def test_level1_set_is_the_100_published_level1_tasks():
    plan = _plan("inhand-level1")
    assert plan.total == 100
    assert {it.level for it in plan.items.values()} == {1}
    objects = [it.object for it in plan.items.values()]
    assert len(set(objects)) == 10 and all(objects.count(o) == 10 for o in set(objects))


@pytest.mark.parametrize("name", ["inhand-level3-dmg", "inhand-level3-dmg-hand-poses"])
def test_level3_rows_live_in_level3_sets(name):
    plan = _plan(name)
    assert plan.total == 4 and {it.level for it in plan.items.values()} == {3}
    assert {it.object for it in plan.items.values()} == {
        "gelatin box",
        "cracker box",
        "spatula",
        "potted meat can",
    }


def test_trials_are_numbered_repeat_major_and_stable_across_repeats():
    one, five = _plan("inhand-level1"), _plan("inhand-level1", repeats=5)
    assert five.total == 500 and sorted(five.items) == list(range(1, 501))
    for k in range(1, 101):  # trials 1..100 are one pass over the set whatever --repeats is
        a, b = one.items[k], five.items[k]
        assert (a.task_id, a.repeat) == (b.task_id, b.repeat) == (a.task_id, 1)
    for r in range(1, 6):  # trial t + (r-1) n is repeat r of task row t
        it = five.items[6 + (r - 1) * 100]
        assert (it.task_id, it.repeat) == (one.items[6].task_id, r)
    # --trials selects among these numbers, so "6" is task row 6, repeat 1, with any --repeats
    assert parse_trial_selection("6,106", sorted(five.items)) == [6, 106]
    with pytest.raises(ValueError, match="no trial 101"):
        parse_trial_selection("101", sorted(one.items))


def test_trial_task_names_the_row_from_the_outcome_or_the_set():
    five = _plan("inhand-level1", repeats=5)
    it = five.items[206]
    assert trial_task("inhand-level1", 206) == (it.task_id, it.object, 3)
    stored = {"task_id": "x-01", "object": "apple", "repeat": 2}
    assert trial_task("inhand-level1", 1, stored) == ("x-01", "apple", 2)
    assert trial_task("Rubiks-1-5", 1) is None
    assert trial_task("no-such-task", 1) is None


def test_run_and_results_rows_name_task_and_object(tmp_path, monkeypatch):
    """The CLI tables and JSON carry each in-hand trial's task id and object."""
    import json
    import sys
    from pathlib import Path

    from click.testing import CliRunner

    from benchharness.cli.run import results, run

    monkeypatch.syspath_prepend(str(Path(__file__).parent / "runner"))
    sys.modules.pop("runner_testplugins", None)
    store = str(tmp_path / "s.sqlite")
    base = ["--robot", "test-stub", "--plugin", "runner_testplugins", "--workers", "0"]
    base += ["--no-progress", "--store", store]
    task = ["--task", "inhand-level3-dmg", "--strategy", "test-inhand", "--repeats", "2"]
    r = CliRunner().invoke(run, [*task, *base, "--trials", "2,6"], catch_exceptions=False)
    assert r.exit_code in (0, 1), r.output
    assert "task id" in r.output and "cracker_box-dmg1" in r.output and "cracker box" in r.output
    r = CliRunner().invoke(results, ["--store", store, "--json"], catch_exceptions=False)
    rows = json.loads(r.output)
    rows = rows["trials"] if isinstance(rows, dict) else rows
    # trials 2 and 6 are repeats 1 and 2 of the second row (n = 4)
    assert sorted((t["trial"], t["task_id"], t["object"], t["repeat"]) for t in rows) == [
        (2, "cracker_box-dmg1", "cracker box", 1),
        (6, "cracker_box-dmg1", "cracker box", 2),
    ]
