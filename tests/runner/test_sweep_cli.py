"""``benchharness sweep`` with the process pool: grids, skipped combinations, refusals, resume."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from benchharness.cli.sweep import sweep
from benchharness.runner import ResultsStore
from benchharness.runner.grid import Grid, expand, load_grid

PLUGIN = "runner_testplugins"
pytestmark = pytest.mark.sim


def _invoke(*args):
    return CliRunner().invoke(sweep, list(args), catch_exceptions=False)


def test_grid_is_the_product_and_run_keys_match_run(store_path):
    from benchharness.cli.run import run

    grid = Grid(
        tasks=("Rubiks-5-5",),
        robots=("test-stub",),
        strategies=("test-drop", "test-timed"),
        seeds=(0, 3),
        plugins=(PLUGIN,),
    )
    plan = expand(grid)
    assert [(s.strategy, s.seed) for s in plan.specs] == [
        ("test-drop", 0),
        ("test-drop", 3),
        ("test-timed", 0),
        ("test-timed", 3),
    ]
    # the same run as `benchharness run` of one grid point: the same key, so resume is shared
    r = CliRunner().invoke(
        run,
        [
            "--task",
            "Rubiks-5-5",
            "--robot",
            "test-stub",
            "--strategy",
            "test-drop",
            "--seed",
            "3",
            "--plugin",
            PLUGIN,
            "--workers",
            "0",
            "--store",
            str(store_path),
            "--json",
        ],
    )
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["run"] == plan.specs[1].to_json()
    res = _invoke(
        "--tasks",
        "Rubiks-5-5",
        "--robots",
        "test-stub",
        "--strategies",
        "test-drop,test-timed",
        "--seeds",
        "0,3",
        "--plugin",
        PLUGIN,
        "--workers",
        "1",
        "--store",
        str(store_path),
        "--json",
    )
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert [
        (r["run"]["strategy"], r["run"]["seed"], r["ran"], r["skipped"]) for r in out["runs"]
    ] == [
        ("test-drop", 0, 5, 0),
        ("test-drop", 3, 0, 5),  # stored by `run` above
        ("test-timed", 0, 5, 0),
        ("test-timed", 3, 5, 0),
    ]
    again = json.loads(
        _invoke(
            "--tasks",
            "Rubiks-5-5",
            "--robots",
            "test-stub",
            "--strategies",
            "test-drop,test-timed",
            "--seeds",
            "0,3",
            "--plugin",
            PLUGIN,
            "--store",
            str(store_path),
            "--json",
        ).stdout
    )
    assert sum(r["ran"] for r in again["runs"]) == 0
    with ResultsStore(store_path, read_only=True) as store:
        assert len(store.trials()) == 20


def test_pool_runs_one_trial_runs_of_a_grid_side_by_side(store_path, tmp_path, monkeypatch):
    """A grid of one-trial runs (the Rubiks-1-N tiers) keeps both workers busy: each trial of
    ``test-rendezvous`` finishes only while another trial runs beside it (it fails after 20 s
    alone), which a pool that ran the grid's runs one after another never gives it."""
    monkeypatch.setenv("SWEEP_TEST_PIDDIR", str(tmp_path))
    monkeypatch.setenv("SWEEP_TEST_MEET", "2")
    res = _invoke(
        "--tasks",
        "Rubiks-1-5",
        "--robots",
        "test-stub",
        "--strategies",
        "test-rendezvous",
        "--seeds",
        "0,1",
        "--plugin",
        PLUGIN,
        "--plugin",
        "sweep_testplugins",
        "--workers",
        "2",
        "--store",
        str(store_path),
        "--json",
    )
    assert res.exit_code == 0, res.output
    assert [r["ran"] for r in json.loads(res.stdout)["runs"]] == [1, 1]
    with ResultsStore(store_path, read_only=True) as store:
        rows = store.trials()
    assert [(t.seed, t.status.value, t.message) for t in sorted(rows, key=lambda t: t.seed)] == [
        (0, "success", ""),
        (1, "success", ""),
    ]
    assert len(list(tmp_path.glob("*.here"))) == 2  # two worker processes


def test_product_skips_other_benchmark_with_a_note(store_path):
    res = _invoke(
        "--tasks",
        "Rubiks-5-5,inhand-level1",
        "--robots",
        "test-stub",
        "--strategies",
        "test-drop,test-inhand",
        "--plugin",
        PLUGIN,
        "--workers",
        "0",
        "--store",
        str(store_path),
        "--json",
    )
    out = json.loads(res.stdout)
    assert [(r["run"]["task"], r["run"]["strategy"]) for r in out["runs"]] == [
        ("Rubiks-5-5", "test-drop"),
        ("inhand-level1", "test-inhand"),
    ]
    assert out["skipped_combinations"] == [
        "skipped Rubiks-5-5 × test-inhand/test-stub: strategy 'test-inhand' runs inhand tasks, "
        "not rubiks (Rubiks-5-5)",
        "skipped inhand-level1 × test-drop/test-stub: strategy 'test-drop' runs rubiks tasks, "
        "not inhand (inhand-level1)",
    ]
    assert "skipped Rubiks-5-5 × test-inhand" in res.stderr
    assert res.exit_code == 1  # the test in-hand strategy drops the object in some trials


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--strategies", "test-inhand"], "strategy 'test-inhand' is in no runnable combination"),
        (["--strategies", "nope"], "no strategy named 'nope'"),
        (["--strategies", "test-drop", "--seeds", "0,x"], "--seeds 'x': not an integer"),
        (["--strategies", "test-drop", "--physics", "timestep=abc"], "--physics"),
        (["--strategies", "test-drop", "--backends", "nobackend"], "nobackend"),
    ],
)
def test_bad_grid_refused_before_anything_runs(store_path, args, message):
    res = _invoke(
        "--tasks",
        "Rubiks-5-5",
        "--robots",
        "test-stub",
        "--plugin",
        PLUGIN,
        *args,
        "--store",
        str(store_path),
    )
    assert res.exit_code == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], res.stderr
    assert not store_path.exists()


def test_grid_from_toml_with_physics_axis(tmp_path, store_path):
    path = tmp_path / "grid.toml"
    path.write_text(
        'tasks = ["Rubiks-5-5"]\nrobots = "test-stub"\nstrategies = ["test-timed"]\n'
        f'plugins = ["{PLUGIN}"]\nseeds = [1]\n'
        '[[physics]]\ntimestep = "1/240"\n[[physics]]\ntimestep = "1/480"\n'
    )
    grid = load_grid(path)
    assert grid.physics == (("timestep=1/240",), ("timestep=1/480",))
    specs = expand(grid).specs
    assert [s.physics.timestep for s in specs] == [1 / 240, 1 / 480]
    assert len({s.run_key for s in specs}) == 2
    res = _invoke(str(path), "--workers", "0", "--store", str(store_path), "--json")
    assert res.exit_code == 0, res.output
    assert [r["stored"] for r in json.loads(res.stdout)["runs"]] == [5, 5]
    bad = tmp_path / "bad.toml"
    bad.write_text('tasks = ["Rubiks-5-5"]\nrobot = "x"\n')
    res = _invoke(str(bad), "--store", str(store_path))
    assert res.exit_code == 2 and "unknown key 'robot'" in res.stderr


def test_the_whole_table_one_grid_is_each_baseline_on_its_published_robot():
    """``bench/table1_all.toml`` is the whole Table I sweep of issue 12 (BENCHMARKS.md): the paper's
    twelve tiers for its three baselines on both engines, each baseline on the robot it was
    published on (the two PR2 methods, HERB's push-grasp), and the grid's other pairs skipped."""
    from collections import Counter
    from pathlib import Path

    from benchharness.cube.tiers import load_tiers

    path = Path(__file__).resolve().parents[2] / "bench" / "table1_all.toml"
    plan = expand(load_grid(path))
    per_method = Counter((s.strategy, s.robot, s.backend) for s in plan.specs)
    assert per_method == {
        (strategy, robot, backend): 12
        for strategy, robot in (
            ("dead-reckoning", "pr2"),
            ("sensor-aided", "pr2"),
            ("push-grasp", "herb"),
        )
        for backend in ("sapien", "pybullet")
    }
    tasks = list(dict.fromkeys(s.task for s in plan.specs))
    assert tasks == list(load_tiers()) and len(plan.skipped) == 3 * 12  # the paper's order
