"""``bench/profile_trial.py`` splits a sampled profile by kind of work: checked on stacks built by hand.

The BENCHMARKS figure "where a trial's CPU goes" rests on this split; these
stacks have known answers, and the engine's line is read from the backends'
sources, so renaming the engine step call fails here instead of silently
moving the engine's time into "control tick".
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parent.parent / "bench"


@pytest.fixture(scope="module")
def prof():  # type: ignore[no-untyped-def]
    sys.path.insert(0, str(BENCH))
    try:
        spec = importlib.util.spec_from_file_location("profile_trial", BENCH / "profile_trial.py")
        assert spec and spec.loader
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        return mod
    finally:
        sys.path.remove(str(BENCH))


def _frame(func: str, file: str, line: int = 1) -> str:
    return f"{func} ({file}:{line})"


def test_each_backend_has_one_engine_step_call(prof) -> None:  # type: ignore[no-untyped-def]
    lines = prof._engine_lines()
    assert sorted(x.split(":")[0] for x in lines) == sorted(prof.BACKEND_FILES)


def test_split_attributes_each_sample_to_one_kind(prof, tmp_path) -> None:  # type: ignore[no-untyped-def]
    (engine,) = [x for x in prof._engine_lines() if "sapien" in x]
    efile, eline = engine.split(":")
    root = [
        _frame("main", "benchharness/cli/main.py"),
        _frame("execute_trial", "benchharness/runner/trial.py"),
    ]
    step = [
        _frame("Robot.track", "benchharness/robots/robot.py"),
        _frame("Backend.step", "benchharness/backends/interface.py"),
    ]
    stacks = {
        # the engine's own line: engine, even below the control tick
        (*root, *step, _frame("SapienBackend._step_engine", efile, int(eline))): 50,
        # another line of the same function: our loop around the engine
        (*root, *step, _frame("SapienBackend._step_engine", efile, int(eline) + 2)): 7,
        # an IK solve inside a grasp choice is IK (the deepest match), not planning; its own FK
        # names no kind, so it stays IK's
        (
            *root,
            _frame("PR2Grasp.choose", "benchharness/strategies/pr2_rubiks/strategy.py"),
            _frame("RobotArm.ik", "benchharness/robots/parts.py"),
            _frame("KinematicChain._dls", "benchharness/robots/kinematics.py"),
            _frame("_SerialModel.fk_jacobian", "benchharness/robots/kinematics.py"),
        ): 11,
        (*root, _frame("PR2Grasp.choose", "benchharness/strategies/pr2_rubiks/strategy.py")): 5,
        (*root, _frame("_find_and_load", "<frozen importlib._bootstrap>")): 3,
        (*root, _frame("BimanualRubiksMachine._twist", "benchharness/strategies/x.py")): 2,
        (_frame("main", "benchharness/cli/main.py"), _frame("exit", "x.py")): 6,
        # the store's claim thread (its own stack, no execute_trial in it)
        (_frame("Thread._bootstrap", "threading.py"), _frame("Event.wait", "threading.py")): 3,
    }
    raw = tmp_path / "raw.txt"
    raw.write_text("".join(f"{';'.join(s)} {n}\n" for s, n in stacks.items()))
    counts = prof.split(str(raw))
    step_kind = next(k for k, _ in prof.KINDS if "control tick" in k)
    ik_kind = next(k for k, _ in prof.KINDS if "IK" in k)
    plan_kind = next(k for k, _ in prof.KINDS if "planning" in k)
    assert counts == {
        prof.ENGINE: 50,
        step_kind: 7,
        ik_kind: 11,
        plan_kind: 5,
        prof.IMPORTS: 3,
        prof.OTHER: 2,
        "outside the trial (start-up, exit, store)": 9,
    }
    rep = prof.report(counts)
    # imports and what ran outside the trial are not the trial's: 50 + 7 + 11 + 5 + 2 = 75
    assert rep["samples in the trial"] == 75
    assert rep["ratio (engine / trial)"] == round(50 / 75, 3)
    assert rep["bound: engine / (engine + per step)"] == round(50 / 57, 3)
