"""The Rubik's metric: success, trial score, tier score and completion, log parsing."""

from __future__ import annotations

import json
import math

import pytest

from benchharness.cube import SOLVED_STRING, expected_final, format_sequence, get_tier
from benchharness.metrics.rubiks import (
    RubiksTrial,
    TrialLogError,
    mean_and_std,
    parse_csv_log,
    parse_json_log,
    read_log,
    score_log,
    score_tier,
    score_trial,
)

SEQ = "R U R' U'"
# Independent of the code under test: magiccube's state after R U R' U'.
SEQ_FINAL = "UULUUFUUFRRUBRRURRFFDFFUFFFDDRDDDDDDBLLLLLLLLBRRBBBBBB"


def trial(k=1, tier="Rubiks-1-5", sequence=SEQ, final=SEQ_FINAL, t0=10.0, t1=130.5, **kw):
    return RubiksTrial(tier, k, sequence, final, first_contact_s=t0, termination_s=t1, **kw)


def test_expected_final_agrees_with_the_oracle():
    magiccube = pytest.importorskip("magiccube")
    cube = magiccube.Cube(3, hist=False)
    cube.rotate(SEQ)
    assert cube.get_kociemba_facelet_positions() == SEQ_FINAL == expected_final(SEQ)


def test_successful_trial_score_is_termination_minus_first_contact():
    r = score_trial(trial())
    assert r.success and r.reason == "" and r.score_s == pytest.approx(120.5)


def test_failed_trial_has_no_score():
    r = score_trial(trial(final=SOLVED_STRING))
    assert not r.success and r.score_s is None
    assert (
        r.reason == "observed final state differs from the expected one at 12 facelets"
    )  # 3+3+2+1+1+2, by eye


def test_failed_trial_may_omit_times():
    r = score_trial(trial(final=SOLVED_STRING, t0=None, t1=None))
    assert not r.success


def test_initial_state_is_honoured():
    start = expected_final("F2 D")
    final = expected_final("F2 D " + SEQ)
    assert score_trial(trial(initial=start, final=final)).success
    assert not score_trial(trial(initial=start, final=SEQ_FINAL)).success


def test_illegal_but_well_formed_final_is_a_failure_with_reason():
    s = list(SEQ_FINAL)
    s[5], s[10] = s[10], s[5]  # flip the UR edge in place
    r = score_trial(trial(final="".join(s)))
    assert not r.success and r.reason.startswith(
        "observed final state is not a legal cube: edge flip"
    )


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"final": SEQ_FINAL[:53]}, "invalid observed final state: expected 54 facelets, got 53"),
        ({"sequence": "R U Q"}, 'unknown move "Q" at position 3'),
        ({"initial": "U" * 54}, "invalid initial state"),
        ({"t1": None}, "a successful trial needs first_contact_s and termination_s"),
        ({"t0": 20.0, "t1": 10.0}, "termination_s (10.0) is before first_contact_s (20.0)"),
    ],
)
def test_bad_trials_raise(kwargs, message):
    with pytest.raises(TrialLogError) as info:
        score_trial(trial(**kwargs))
    assert message in str(info.value)


def test_mean_and_sample_std_by_hand():
    # scores 100, 110, 120, 130, 140: mean 120; squared deviations 400+100+0+100+400 = 1000;
    # sample variance 1000/4 = 250 -> std sqrt(250) = 15.8114 (population would be sqrt(200)).
    mean, std = mean_and_std([100.0, 110.0, 120.0, 130.0, 140.0])
    assert mean == 120.0 and std == pytest.approx(math.sqrt(250))
    assert mean_and_std([42.0]) == (42.0, None)
    assert mean_and_std([]) == (None, None)


def five_trials(times, seed=7):
    tier = get_tier("Rubiks-5-5")
    seqs = tier.sequences(seed)
    return [
        RubiksTrial(
            "Rubiks-5-5",
            k,
            format_sequence(s),
            expected_final(s),
            first_contact_s=0.0,
            termination_s=t,
        )
        for k, (s, t) in enumerate(zip(seqs, times), start=1)
    ]


def test_completed_tier():
    score = score_tier(five_trials([100, 110, 120, 130, 140]), "Rubiks-5-5", seed=7)
    assert score.completed and score.successes == 5 and score.problems == ()
    assert score.mean_s == 120.0 and score.std_s == pytest.approx(15.811388, rel=1e-6)


def test_tier_names_are_matched_case_insensitively():
    score = score_tier([trial(tier="RUBIKS-1-5")], "rubiks-1-5")
    assert score.tier == "Rubiks-1-5" and score.completed


def test_custom_tier_needs_trials_required():
    with pytest.raises(TrialLogError, match="unknown tier"):
        score_tier([trial(tier="lab-1-4")], "lab-1-4")
    assert score_tier([trial(tier="lab-1-4")], "lab-1-4", trials_required=1).completed


def test_single_trial_tier_has_no_std():
    score = score_tier([trial()], "Rubiks-1-5")
    assert score.completed and score.mean_s == pytest.approx(120.5) and score.std_s is None


def test_tier_with_a_failure_is_not_completed():
    trials = five_trials([100, 110, 120, 130, 140])
    trials[2] = RubiksTrial("Rubiks-5-5", 3, trials[2].sequence, SOLVED_STRING, note="dropped")
    score = score_tier(trials, "Rubiks-5-5")
    assert not score.completed and score.successes == 4
    assert score.mean_s == pytest.approx(120.0)  # over the four successes: 100, 110, 130, 140
    assert score.problems[0].startswith("trial 3 failed: observed final state differs")


def test_missing_and_repeated_trials():
    trials = five_trials([100, 110, 120, 130, 140])
    score = score_tier(trials[:4], "Rubiks-5-5")
    assert not score.completed and score.problems == ("trial 5 not logged",)
    score = score_tier(trials + [trials[0]], "Rubiks-5-5")
    assert not score.completed and "trial 1 logged more than once" in score.problems
    stray = RubiksTrial(
        "Rubiks-5-5", 6, trials[0].sequence, trials[0].final, first_contact_s=0, termination_s=1
    )
    assert "trial 6 outside 1..5" in score_tier(trials + [stray], "Rubiks-5-5").problems


def test_seed_check_rejects_a_sequence_that_is_not_the_generators():
    trials = five_trials([100, 110, 120, 130, 140], seed=8)  # generated for seed 8
    score = score_tier(trials, "Rubiks-5-5", seed=7)
    assert not score.completed and score.successes == 0
    assert "not the generator's for seed 7, Rubiks-5-5, trial 1" in score.results[0].reason
    assert score_tier(trials, "Rubiks-5-5", seed=8).completed


def test_score_log_groups_tiers_and_canonicalises_names():
    trials = five_trials([100, 110, 120, 130, 140]) + [trial(tier="rubiks-1-5")]
    scores = score_log(trials)
    assert [s.tier for s in scores] == ["Rubiks-5-5", "Rubiks-1-5"]
    assert all(s.completed for s in scores)
    with pytest.raises(TrialLogError, match="unknown tier 'Rubiks-3-3'"):
        score_log([trial(tier="Rubiks-3-3")])


CSV = """tier,trial,initial,sequence,final,first_contact_s,termination_s,note
Rubiks-1-5,1,,R U R' U',UULUUFUUFRRUBRRURRFFDFFUFFFDDRDDDDDDBLLLLLLLLBRRBBBBBB,10,130.5,
"""


def test_csv_log():
    (t,) = parse_csv_log(CSV)
    assert t == RubiksTrial("Rubiks-1-5", 1, SEQ, SEQ_FINAL, SOLVED_STRING, 10.0, 130.5, "")
    with pytest.raises(TrialLogError, match="line 2: missing final"):
        parse_csv_log("tier,trial,sequence,final\nRubiks-1-5,1,R,\n")
    with pytest.raises(
        TrialLogError, match="line 2: first_contact_s must be a number of seconds, got 'soon'"
    ):
        parse_csv_log("tier,trial,sequence,final,first_contact_s\nRubiks-1-5,1,R,X,soon\n")
    with pytest.raises(TrialLogError, match="unknown field colour"):
        parse_csv_log("tier,trial,sequence,final,colour\nRubiks-1-5,1,R,X,red\n")
    with pytest.raises(TrialLogError, match="trial must be an integer"):
        parse_csv_log("tier,trial,sequence,final\nRubiks-1-5,one,R,X\n")


def test_json_log_forms(tmp_path):
    rec = {
        "trial": 1,
        "sequence": ["R", "U", "R'", "U'"],
        "final": SEQ_FINAL,
        "first_contact_s": 10,
        "termination_s": 130.5,
    }
    as_object = parse_json_log(json.dumps({"tier": "Rubiks-1-5", "trials": [rec]}))
    as_list = parse_json_log(json.dumps([{**rec, "tier": "Rubiks-1-5"}]))
    assert as_object == as_list == parse_csv_log(CSV)
    with pytest.raises(TrialLogError, match="not valid JSON"):
        parse_json_log("{")
    p = tmp_path / "log.json"
    p.write_text(json.dumps([{**rec, "tier": "Rubiks-1-5"}]))
    assert read_log(p) == as_list
    with pytest.raises(TrialLogError, match="cannot read"):
        read_log(tmp_path / "missing.csv")
    (tmp_path / "empty.csv").write_text("tier,trial,sequence,final\n")
    with pytest.raises(TrialLogError, match="holds no trials"):
        read_log(tmp_path / "empty.csv")


def test_example_logs_in_the_repository():
    from benchharness.paths import tasks_dir

    ok = score_log(read_log(tasks_dir() / "rubiks" / "examples" / "trials.csv"), seed=7)
    assert [s.completed for s in ok] == [True]
    assert ok[0].mean_s == pytest.approx((409.55 + 382.25 + 445.20 + 392.30 + 419.50) / 5)
    bad = score_log(read_log(tasks_dir() / "rubiks" / "examples" / "trials_failed.json"), seed=7)
    assert [s.completed for s in bad] == [False]
