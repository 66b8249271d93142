"""Issue 13 item 10: bad ``run`` / ``compare`` input is refused before any trial runs.

Each case: exit 2, one line on stderr naming the offending value, and no
trial in the store (the command never reached the sweep). The physics
checks live on ``PhysicsConfig`` itself, so the Python API is guarded too.
"""

from __future__ import annotations

import json
import math
import sqlite3

import pytest
from click.testing import CliRunner

from benchharness.backends.interface import PhysicsConfig
from benchharness.cli.run import compare, run

PLUGIN = "runner_testplugins"  # tests/runner/runner_testplugins.py
BASE = ["--robot", "test-stub", "--plugin", PLUGIN, "--workers", "0", "--no-progress"]
RUN = ["--task", "Rubiks-1-5", "--strategy", "test-drop", *BASE]
RUN5 = ["--task", "Rubiks-5-5", "--strategy", "test-drop", *BASE]


def _trials_stored(path) -> int:
    if not path.exists():
        return 0
    with sqlite3.connect(path) as db:
        tables = {r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        return db.execute("SELECT COUNT(*) FROM trials").fetchone()[0] if "trials" in tables else 0


def _refused(command, args, store_path, *needles):
    existed = store_path.exists()
    r = CliRunner().invoke(command, [*args, "--store", str(store_path)], catch_exceptions=False)
    # refused before the store is opened: no file is created for a command that runs nothing
    assert store_path.exists() == existed
    assert r.exit_code == 2, r.output
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, r.stderr
    for n in needles:
        assert n in lines[0], (n, lines[0])
    assert _trials_stored(store_path) == 0
    return lines[0]


@pytest.mark.parametrize(
    "setting, needle",
    [
        ("timestep=0", "timestep=0"),
        ("timestep=-0.004", "timestep=-0.004"),
        ("timestep=1/0", "'1/0'"),
        ("timestep=nan", "timestep=nan"),
        ("solver_iterations=0", "solver_iterations=0"),
        ("solver_iterations=-5", "solver_iterations=-5"),
        ("default_friction=-1", "default_friction=-1"),
        ("torsional_friction=nan", "torsional_friction=nan"),
        ("gravity=0,0,nan", "gravity="),
        ("contact_offset=0", "contact_offset=0"),
    ],
)
def test_bad_physics_is_refused_before_any_trial(store_path, setting, needle):
    _refused(run, [*RUN, "--physics", setting], store_path, "--physics", needle)


def test_physics_config_itself_refuses_what_no_engine_can_simulate():
    for kw in (
        {"timestep": 0.0},
        {"timestep": -1 / 240},
        {"timestep": math.nan},
        {"timestep": math.inf},
        {"solver_iterations": 0},
        {"solver_velocity_iterations": -1},
        {"default_friction": -0.1},
        {"gravity": (0.0, math.nan, -9.81)},
        {"seed": -1},
    ):
        name = next(iter(kw))
        with pytest.raises(ValueError, match=name):
            PhysicsConfig(**kw)
    # the defaults and ordinary settings are accepted
    assert PhysicsConfig(timestep=1 / 500, solver_iterations=100, default_friction=0.0).timestep


def test_reversed_trial_range_is_refused(store_path):
    _refused(run, [*RUN5, "--trials", "5-3"], store_path, "'5-3'")


@pytest.mark.parametrize("command", [run, compare])
def test_a_trial_the_task_lacks_is_refused_before_the_store_is_opened(store_path, command):
    _refused(command, [*RUN5, "--trials", "2,7"], store_path, "no trial 7", "1..5")


@pytest.mark.parametrize("command", [run, compare])
def test_negative_workers_are_refused_before_the_store_is_opened(store_path, command):
    _refused(command, [*RUN, "--workers", "-1"], store_path, "--workers -1")


@pytest.mark.parametrize("seed", [str(2**63), str(2**64 + 5), "-1"])
def test_seed_beyond_the_store_is_refused(store_path, seed):
    _refused(run, [*RUN, "--seed", seed], store_path, f"--seed {seed}")


def test_largest_storable_seed_is_accepted_and_stored(store_path):
    r = CliRunner().invoke(
        run, [*RUN, "--seed", str(2**63 - 1), "--store", str(store_path), "--json"]
    )
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["run"]["seed"] == 2**63 - 1


def test_video_trial_outside_the_selected_trials_is_refused(store_path, tmp_path):
    args = [*RUN5, "--trials", "1-2"]
    _refused(
        run,
        [*args, "--video", str(tmp_path / "v.gif"), "--video-trial", "4"],
        store_path,
        "--video-trial 4",
        "--trials 1-2",
    )
    assert not (tmp_path / "v.gif").exists()


def test_compare_the_same_backend_twice_is_refused(store_path):
    _refused(compare, [*RUN, "--backends", "pybullet,pybullet"], store_path, "'pybullet'")


def test_errors_under_json_are_one_json_object_on_stderr(store_path):
    line = _refused(run, [*RUN, "--physics", "timestep=0", "--json"], store_path)
    data = json.loads(line)
    assert data["exit_code"] == 2 and "timestep=0" in data["error"]


@pytest.mark.parametrize("command", ["table", "results"])
def test_seed_filter_beyond_the_store_is_one_line_not_an_overflow(store_path, command):
    from benchharness.cli.main import cli

    r = CliRunner().invoke(cli, [command, "--seed", str(2**64), "--store", str(store_path)])
    assert r.exit_code == 2 and "Traceback" not in r.output
    (line,) = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert "--seed" in line and str(2**64) in line


@pytest.mark.parametrize("opt", ["--sim-budget", "--wall-budget"])
@pytest.mark.parametrize("value", ["nan", "inf", "-1"])
def test_non_finite_or_negative_budgets_are_refused(store_path, opt, value):
    _refused(run, [*RUN, opt, value], store_path, f"{opt} {float(value)}")


def test_nan_video_fps_is_refused(store_path, tmp_path):
    _refused(
        run,
        [*RUN, "--video", str(tmp_path / "v.gif"), "--video-fps", "nan"],
        store_path,
        "--video-fps nan",
    )
