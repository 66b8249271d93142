"""One trial at a time: causes, scores through the metric module, budgets, seeding."""

from __future__ import annotations

import time

import numpy as np
import pytest

from benchharness.cube import expected_final, generate_sequence
from benchharness.metrics import score_trials
from benchharness.runner import FailureCause, TimeBudget, TrialStatus, execute_trial
from benchharness.runner.seeding import trial_streams
from benchharness.runner.spec import parse_physics

pytestmark = pytest.mark.sim


@pytest.mark.parametrize(
    "strategy, status, cause, text",
    [
        ("test-drop", TrialStatus.SUCCESS, None, ""),
        (
            "test-wrong",
            TrialStatus.FAILURE,
            FailureCause.WRONG_STATE,
            "differs from the expected one",
        ),
        ("test-simerror", TrialStatus.FAILURE, FailureCause.SIMULATOR_ERROR, "became NaN"),
        (
            "test-crash",
            TrialStatus.FAILURE,
            FailureCause.STRATEGY_ERROR,
            "ValueError: bug in the strategy",
        ),
        ("test-slowsim", TrialStatus.FAILURE, FailureCause.TIMEOUT, "simulated-time budget of 2 s"),
        ("test-jammed", TrialStatus.FAILURE, FailureCause.JAMMED, "twist 1 jammed"),
        ("test-notoutcome", TrialStatus.FAILURE, FailureCause.STRATEGY_ERROR, "not TrialOutcome"),
    ],
)
def test_each_outcome_gets_its_cause(make_spec, strategy, status, cause, text):
    spec = make_spec(strategy, budget=TimeBudget(sim_s=2.0))
    rec = execute_trial(spec, 2)
    assert rec.status is status, rec.message
    assert rec.failure_cause is cause
    assert text in rec.message
    assert rec.trial_index == 2 and rec.run_key == spec.run_key
    if strategy in ("test-simerror", "test-crash", "test-slowsim"):
        assert "Traceback" in rec.traceback
    if cause is FailureCause.TIMEOUT:
        assert rec.sim_s == pytest.approx(2.0, abs=0.2)


def test_success_is_scored_from_first_contact_to_termination(make_spec):
    spec = make_spec("test-drop", task="Rubiks-1-10", seed=3)
    rec = execute_trial(spec, 1)
    assert rec.status is TrialStatus.SUCCESS
    # first contact was detected by the runner from the watched bodies, after the cube fell 5 cm
    assert 0.05 < rec.first_contact_s < 0.2
    assert rec.score == pytest.approx(rec.termination_s - rec.first_contact_s)
    assert rec.sim_s == pytest.approx(rec.termination_s)
    seq = generate_sequence(3, "Rubiks-1-10", 1, 10)
    assert rec.outcome["expected_final"] == expected_final(seq)
    assert rec.outcome["sequence"] == " ".join(str(m) for m in seq)
    est = rec.diagnostics["pose_estimates"]
    assert [e["move_index"] for e in est] == list(range(10))
    assert rec.diagnostics["counts"]["move"] == 10
    assert all(e["pos_err_m"] >= 0 for e in est)


def test_wrong_state_keeps_the_diagnostics(make_spec):
    rec = execute_trial(make_spec("test-wrong"), 1)
    assert rec.diagnostics["counts"]["unintended_rotation"] == 1
    assert rec.outcome["final_state"] != rec.outcome["expected_final"]


def test_a_strategy_that_never_steps_is_stopped_by_the_wall_alarm(make_spec):
    spec = make_spec("test-hang", budget=TimeBudget(wall_s=0.3))
    t0 = time.perf_counter()
    rec = execute_trial(spec, 1)
    assert time.perf_counter() - t0 < 10
    assert rec.failure_cause is FailureCause.TIMEOUT
    assert "wall-time budget" in rec.message


def test_strategy_for_another_benchmark_is_refused_in_the_trial(make_spec):
    rec = execute_trial(make_spec("test-inhand"), 1)
    assert rec.failure_cause is FailureCause.STRATEGY_ERROR
    assert "runs inhand tasks, not rubiks" in rec.message


def test_unknown_backend_is_a_simulator_error_inside_a_trial(make_spec):
    rec = execute_trial(make_spec(backend="no-such-engine"), 1)
    assert rec.failure_cause is FailureCause.SIMULATOR_ERROR
    assert "no backend named 'no-such-engine'" in rec.message


def test_same_trial_same_result_and_no_global_random_state(make_spec):
    np.random.seed(1234)
    before = np.random.get_state()[1].copy()
    a = execute_trial(make_spec("test-drop", seed=7), 3)
    b = execute_trial(make_spec("test-drop", seed=7), 3)
    assert a.comparable() == b.comparable()
    assert np.array_equal(np.random.get_state()[1], before)
    c = execute_trial(make_spec("test-drop", seed=8), 3)
    assert c.outcome["sequence"] != a.outcome["sequence"]


def test_trial_streams_depend_only_on_seed_task_and_index():
    def draw(*args):
        s = trial_streams(*args, n_sensors=2)
        return s.strategy.random(3).tolist(), [g.random() for g in s.sensors], s.backend_seed

    assert draw(0, "Rubiks-5-20", 2) == draw(0, "rubiks-5-20", 2)
    others = [draw(1, "Rubiks-5-20", 2), draw(0, "Rubiks-5-10", 2), draw(0, "Rubiks-5-20", 3)]
    assert all(o[0] != draw(0, "Rubiks-5-20", 2)[0] for o in others)
    s, sensors, _ = draw(0, "Rubiks-5-20", 2)
    assert sensors[0] != sensors[1] and s[0] not in sensors


def test_run_key_covers_physics_budget_and_code(make_spec):
    base = make_spec()
    assert make_spec().run_key == base.run_key
    changed = [
        make_spec(physics=parse_physics(["timestep=1/500"])),
        make_spec(budget=TimeBudget(sim_s=31.0)),
        make_spec(code="0.0.0+gdeadbeef"),
        make_spec(seed=1),
        make_spec(sensors=("tof",)),
    ]
    assert len({base.run_key, *[s.run_key for s in changed]}) == 6
    assert parse_physics(["timestep=1/500"]).timestep == pytest.approx(0.002)
    with pytest.raises(ValueError, match="unknown physics setting 'warp'"):
        parse_physics(["warp=9"])


def test_inhand_trials_are_scored_by_score_trials(make_spec):
    spec = make_spec("test-inhand", task="inhand-level3-dmg", repeats=3)
    recs = [execute_trial(spec, i) for i in range(1, 13)]
    dropped = [r for r in recs if r.failure_cause is FailureCause.DROPPED]
    ok = [r for r in recs if r.status is TrialStatus.SUCCESS]
    assert dropped and ok and len(dropped) + len(ok) == 12
    for r in ok:
        o = r.outcome
        s = score_trials(
            np.array([o["initial"]]), np.array([o["desired"]]), np.array([o["reached"]])
        )
        assert r.score == pytest.approx(float(s.err_pos[0]))
        assert o["metrics"]["err_pos_percent"] == pytest.approx(float(s.err_pos_percent[0]))
    assert all(r.score is None and r.outcome["dropped"] for r in dropped)
    # repeat-major numbering (docs/runner.md): trials 1, 5, 9 are the first task row, repeats 1-3
    assert [recs[k].outcome["repeat"] for k in (0, 4, 8)] == [1, 2, 3]
    assert len({recs[k].outcome["task_id"] for k in (0, 4, 8)}) == 1


def test_sensors_are_slots_with_their_own_streams(make_spec):
    spec = make_spec("test-drop", task="Rubiks-1-10", sensors=("test-noise",))
    a, b = execute_trial(spec, 1), execute_trial(spec, 1)
    assert a.status is TrialStatus.SUCCESS and a.comparable() == b.comparable()
    blind = execute_trial(make_spec("test-drop", task="Rubiks-1-10"), 1)
    err = lambda r: max(e["pos_err_m"] for e in r.diagnostics["pose_estimates"])  # noqa: E731
    assert err(a) < err(blind)
    # the strategy's own stream does not depend on how many sensors there are
    assert (
        trial_streams(0, "Rubiks-1-10", 1, 0).strategy.random(4).tolist()
        == trial_streams(0, "Rubiks-1-10", 1, 3).strategy.random(4).tolist()
    )
