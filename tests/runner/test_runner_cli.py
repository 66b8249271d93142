"""The run, table, compare and results commands (invoked directly through click)."""

from __future__ import annotations

import json
import math
import os
import statistics

import numpy as np
import pytest

from benchharness.cli.run import compare, results, run, table

PLUGIN = "runner_testplugins"  # tests/runner/runner_testplugins.py


def backends_wanted() -> set[str] | None:
    wanted = {
        b.strip() for b in os.environ.get("BENCHHARNESS_BACKENDS", "").split(",") if b.strip()
    }
    return wanted or None


pytestmark = pytest.mark.sim

BASE = ["--robot", "test-stub", "--plugin", PLUGIN, "--workers", "0", "--no-progress"]


def _json(result):
    return json.loads(result.output[result.output.index("{") :])


def test_table_shows_hand_computed_mean_and_std_beside_the_paper(invoke):
    # test-timed makes trial k of Rubiks-5-5 last exactly k simulated seconds after contact
    r = invoke(run, "--task", "Rubiks-5-5", "--strategy", "test-timed", *BASE, "--json")
    assert r.exit_code == 0, r.output
    data = _json(r)
    assert [t["score"] for t in data["trials"]] == pytest.approx([1, 2, 3, 4, 5])
    assert data["tier"]["completed"] is True
    # a failed single-trial tier: not completed
    r = invoke(run, "--task", "Rubiks-1-5", "--strategy", "test-wrong", *BASE)
    assert r.exit_code == 1
    assert "not completed" in r.output

    r = invoke(table)
    assert r.exit_code == 0
    mean, std = statistics.fmean([1, 2, 3, 4, 5]), statistics.stdev([1, 2, 3, 4, 5])
    assert f"{mean:.2f} / {std:.2f}" == "3.00 / 1.58"
    line = next(ln for ln in r.output.splitlines() if "Rubiks-5-5" in ln)
    assert "113.35 / 17.16" in line and "113.81 / 18.35" in line and "3.00 / 1.58" in line
    line = next(ln for ln in r.output.splitlines() if "Rubiks-1-5 " in ln)
    assert "139.07 / -" in line and "— (0/1)" in line
    assert "test-timed (test-stub, pybullet)" in r.output

    data = _json(invoke(table, "--json", "--run-tiers"))["rubiks"]
    assert [row["tier"] for row in data["rows"]] == ["Rubiks-1-5", "Rubiks-5-5"]
    ours = data["rows"][1]["ours"]["test-timed (test-stub, pybullet)"]
    assert ours["mean_s"] == pytest.approx(mean) and ours["std_s"] == pytest.approx(std)
    assert data["rows"][0]["published"]["Dead reckoning PR2"]["mean_s"] == 139.07


def test_partial_tier_is_not_shown_as_a_score(invoke):
    r = invoke(run, "--task", "Rubiks-5-5", "--strategy", "test-timed", *BASE, "--trials", "1-2")
    assert r.exit_code == 0
    line = next(ln for ln in invoke(table).output.splitlines() if "Rubiks-5-5" in ln)
    assert "… 2/5 run" in line


def test_bad_names_exit_2_with_the_plugin_managers_message(invoke):
    for opt, value, kind, plural in (
        ("--robot", "nope", "robot", "robots"),
        ("--strategy", "nope", "strategy", "strategies"),
        ("--backend", "nope", "backend", "backends"),
        ("--sensors", "a,nope", "sensor", "sensors"),
    ):
        args = ["--task", "Rubiks-1-5", "--strategy", "test-drop", *BASE]
        if opt in args:
            args[args.index(opt) + 1] = value
        else:
            args += [opt, value]
        r = invoke(run, *args)
        assert r.exit_code == 2, (opt, r.output)
        assert f"no {kind} named" in r.output and f"Available {plural}:" in r.output
    r = invoke(run, "--task", "Rubiks-9-9", "--strategy", "test-drop", *BASE)
    assert r.exit_code == 2 and "no task named 'Rubiks-9-9'" in r.output
    r = invoke(run, "--task", "Rubiks-1-5", "--strategy", "test-drop", *BASE, "--physics", "warp=1")
    assert r.exit_code == 2 and "unknown physics setting" in r.output


def test_results_lists_failures_with_causes(invoke):
    for strategy in ("test-simerror", "test-jammed", "test-drop"):
        invoke(run, "--task", "Rubiks-1-5", "--strategy", strategy, *BASE)
    r = invoke(results, "--failures", "--json", "--traceback")
    data = _json(r)["trials"]
    assert sorted(t["failure_cause"] for t in data) == ["jammed", "simulator_error"]
    assert any("SimulationError" in t["traceback"] for t in data)
    text = invoke(results).output
    assert "simulator_error" in text and "jammed" in text and "success" in text
    assert (
        invoke(results, "--strategy", "test-drop", "--json").output.count('"status": "success"')
        == 1
    )


def test_results_json_counts_each_kind_of_event_the_store_holds(invoke, store_path):
    import sqlite3
    from collections import Counter

    invoke(run, "--task", "Rubiks-1-10", "--strategy", "test-drop", *BASE)
    data = _json(invoke(results, "--json"))["trials"]
    stored = sqlite3.connect(store_path).execute("select trial_index, diagnostics_json from trials")
    want = {i: dict(Counter(e["kind"] for e in json.loads(d)["events"])) for i, d in stored}
    assert want and {t["trial"]: t["event_counts"] for t in data} == want
    assert any(want.values())  # the trial recorded events of some kind


def test_pose_error_plot(invoke, tmp_path):
    invoke(run, "--task", "Rubiks-1-10", "--strategy", "test-drop", *BASE)
    png = tmp_path / "drift.png"
    r = invoke(results, "--plot-pose-error", str(png))
    assert r.exit_code == 0, r.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_video_mp4_and_a_clear_error_without_a_camera(invoke, tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    mp4 = tmp_path / "trial.mp4"
    r = invoke(
        run, "--task", "Rubiks-1-5", "--strategy", "test-drop", *BASE, "--video", str(mp4), "--json"
    )
    assert r.exit_code == 0, r.output
    data = _json(r)
    info, sim_s = data["video"], data["trials"][0]["sim_s"]
    # frame k shows the world once k / fps simulated seconds have passed: ceil(duration x fps)
    assert info["fps"] == 8 and info["view"] == "close" and info["size"] == [400, 300]
    assert info["frames"] == math.ceil(sim_s * 8 - 1e-6) >= 2
    assert mp4.read_bytes()[4:8] == b"ftyp"
    import imageio_ffmpeg

    n, secs = imageio_ffmpeg.count_frames_and_secs(str(mp4))  # decoded by ffmpeg: a valid MP4
    assert n == info["frames"] and secs == pytest.approx(n / 8, abs=0.05)
    r = invoke(
        run,
        "--task",
        "Rubiks-1-5",
        "--strategy",
        "test-drop",
        *BASE,
        "--backend",
        "sapien",
        "--video",
        str(tmp_path / "x.mp4"),
    )
    assert r.exit_code == 2 and "has no camera" in r.output


def test_gif_video(invoke, tmp_path):
    gif = tmp_path / "trial.gif"
    r = invoke(run, "--task", "Rubiks-1-5", "--strategy", "test-drop", *BASE, "--video", str(gif))
    assert r.exit_code == 0 and gif.read_bytes()[:6] == b"GIF89a"


def test_inhand_run_and_tables(invoke):
    r = invoke(
        run,
        "--task",
        "inhand-level3-dmg",
        "--strategy",
        "test-inhand",
        "--repeats",
        "5",
        *BASE,
        "--json",
    )
    trials = _json(r)["trials"]
    assert len(trials) == 20 and r.exit_code == 1  # some drops
    drops = sum(t["failure_cause"] == "dropped" for t in trials)
    data = _json(invoke(table, "--benchmark", "inhand", "--json"))["inhand"]
    ours = [row for row in data["table2"] if row["source"] == "ours"]
    assert len(ours) == 1 and ours[0]["trials"] == 20
    assert ours[0]["drops_percent"] == pytest.approx(100 * drops / 20)
    scores = [t["score"] for t in trials if t["status"] == "success"]
    assert ours[0]["err_pos_cm"] == pytest.approx(100 * float(np.median(scores)))
    assert {row["method"] for row in data["table2"] if row["source"] == "paper"} >= {
        "relaxed-rigidity"
    }
    # planning time: the median over every trial that planned, drops included (0.1 k s for trial k)
    assert ours[0]["plan_time_s"] == pytest.approx(float(np.median(0.1 * np.arange(1, 21))))
    paper_plan = {
        row["method"]: row["plan_time_s"] for row in data["table2"] if row["source"] == "paper"
    }
    assert paper_plan == {
        "point-contact": 14.8,
        "ik-rigid": 4.4,
        "relaxed-position": 0.5,
        "relaxed-position-orientation": 0.3,
        "relaxed-rigidity": 0.5,
    }
    t3 = data["table3"]
    assert {row["object"] for row in t3} == {
        "gelatin box",
        "cracker box",
        "spatula",
        "potted meat can",
    }
    assert all(row["paper"]["err_pos_cm"] > 0 for row in t3)
    text = invoke(table, "--benchmark", "inhand").output
    assert "relaxed-rigidity" in text and "gelatin box [gelatin_box-dmg2]" in text
    assert "plan time (s)" in text and "14.80" in text and "1.05" in text


@pytest.mark.skipif(
    backends_wanted() is not None and not {"pybullet", "sapien"} <= backends_wanted(),
    reason="needs both backends",
)
def test_compare_runs_the_tier_on_both_backends(invoke):
    r = invoke(
        compare,
        "--task",
        "Rubiks-1-5",
        "--strategy",
        "test-drop",
        *BASE,
        "--backends",
        "pybullet,sapien",
        "--json",
    )
    assert r.exit_code == 0, r.output
    data = _json(r)
    assert set(data["summary"]) == {"pybullet", "sapien"}
    row = data["trials"][0]
    for b in ("pybullet", "sapien"):
        assert row[b]["status"] == "success", row[b]
        assert not math.isnan(row[b]["score"])
    text = invoke(compare, "--task", "Rubiks-1-5", "--strategy", "test-drop", *BASE).output
    assert "pybullet: status" in text and "sapien: status" in text and "real-time factor" in text
    assert (
        invoke(
            compare,
            "--task",
            "Rubiks-1-5",
            "--strategy",
            "test-drop",
            *BASE,
            "--backends",
            "pybullet",
        ).exit_code
        == 2
    )


def test_inhand_figure7_plot_and_compare_summary(invoke, tmp_path):
    r = invoke(
        run, "--task", "inhand-level3-dmg", "--strategy", "test-inhand", "--repeats", "3", *BASE
    )
    png = tmp_path / "fig7.png"
    r = invoke(table, "--benchmark", "inhand", "--plot", str(png), "--json")
    assert r.exit_code == 0, r.output
    assert _json(r)["plot"] == str(png) and png.read_bytes()[:4] == b"\x89PNG"
    assert invoke(table, "--plot", str(tmp_path / "x.pdf")).exit_code == 2
    if backends_wanted() is not None and not {"pybullet", "sapien"} <= backends_wanted():
        return
    r = invoke(compare, "--task", "inhand-level3-dmg", "--strategy", "test-inhand", *BASE, "--json")
    assert r.exit_code in (0, 1), r.output
    data = _json(r)
    for b in ("pybullet", "sapien"):
        v = data["summary"][b]["inhand"]
        assert v["trials"] == 4
        # the medians are those of the stored trials of that backend (Table II's own computation)
        ok = [t[b] for t in data["trials"] if t[b]["status"] == "success"]
        assert v["err_pos_cm"] == pytest.approx(100 * float(np.median([t["score"] for t in ok])))
    assert (
        "Table II layout"
        in invoke(compare, "--task", "inhand-level3-dmg", "--strategy", "test-inhand", *BASE).output
    )


def test_table_plot_without_inhand_trials_is_a_clear_error(invoke, tmp_path, store_path):
    from benchharness.runner.store import ResultsStore

    ResultsStore(store_path).close()  # a store with no trials (reading never creates one)
    r = invoke(table, "--plot", str(tmp_path / "f.png"))
    assert r.exit_code == 2 and "no in-hand trials" in r.output


def test_table3_contact_rows_come_from_the_scorer_and_only_for_successes(invoke, store_path):
    from benchharness.runner.reports import inhand_table3
    from benchharness.runner.store import ResultsStore

    invoke(run, "--task", "inhand-level3-dmg", "--strategy", "test-inhand", "--repeats", "3", *BASE)
    with ResultsStore(store_path) as store:
        trials = store.trials(benchmark="inhand")
    seen = []

    def scorer(t):  # G values that identify the trial: repeat k -> k cm
        seen.append(t.status.value)
        return {"g_euc": 0.01 * t.outcome["repeat"], "g_geo": 0.02, "g_min": 0.001}

    rows = inhand_table3(trials, contact_scorer=scorer)
    assert set(seen) == {"success"}
    for r in rows:
        ok = [
            t.outcome["repeat"]
            for t in trials
            if t.outcome["task_id"] == r["task_id"] and t.status.value == "success"
        ]
        want = float(np.median(ok)) if ok else None
        assert r["ours"]["g_euc_cm"] == (pytest.approx(want) if ok else None)
        assert r["ours"]["g_geo_cm"] == (pytest.approx(2.0) if ok else None)
        assert r["paper"]["graph_time_s"] > 10  # the paper's DMG time, Table III
    assert all(r["ours"]["g_euc_cm"] is None for r in inhand_table3(trials))


def test_one_method_is_one_column_across_tiers_with_their_own_default_budgets(invoke):
    # the default simulated-time budget grows with a tier's moves, so each tier has its own options hash
    for tier in ("Rubiks-1-5", "Rubiks-1-10"):
        assert invoke(run, "--task", tier, "--strategy", "test-timed", *BASE).exit_code == 0
    data = _json(invoke(table, "--json", "--run-tiers"))["rubiks"]
    labels = {lab for row in data["rows"] for lab in row["ours"]}
    assert labels == {"test-timed (test-stub, pybullet)"}
    # the same tier run again with other options is a different run: then the method splits by options
    # hash (one column per distinct hash: the store cannot tell a default budget from a chosen one)
    assert (
        invoke(
            run, "--task", "Rubiks-1-5", "--strategy", "test-timed", *BASE, "--sim-budget", "500"
        ).exit_code
        == 0
    )
    data = _json(invoke(table, "--json", "--run-tiers"))["rubiks"]
    labels = {lab for row in data["rows"] for lab in row["ours"]}
    assert len(labels) == 3 and all(
        lab.startswith("test-timed (test-stub, pybullet) options ") for lab in labels
    )


def test_a_sweep_straddling_a_commit_is_one_column_and_a_rerun_at_another_commit_splits(
    invoke, monkeypatch
):
    from benchharness.runner.spec import code_version

    def at(version: str) -> None:
        monkeypatch.setenv("BENCHHARNESS_CODE_VERSION", version)
        code_version.cache_clear()

    try:
        at("0.1.0+gaaaa")
        assert invoke(run, "--task", "Rubiks-1-5", "--strategy", "test-timed", *BASE).exit_code == 0
        at("0.1.0+gbbbb")
        assert (
            invoke(run, "--task", "Rubiks-1-10", "--strategy", "test-timed", *BASE).exit_code == 0
        )
        res = invoke(table, "--run-tiers")
        data = _json(invoke(table, "--json", "--run-tiers"))["rubiks"]
        assert [c["code_version"] for c in data["columns"]] == ["0.1.0+gaaaa, 0.1.0+gbbbb"]
        assert {lab for row in data["rows"] for lab in row["ours"]} == {
            "test-timed (test-stub, pybullet)"
        }
        assert "runs from code versions 0.1.0+gaaaa, 0.1.0+gbbbb" in res.output
        # the same tier again at a third commit: that method's runs split by code version
        at("0.1.0+gcccc")
        assert invoke(run, "--task", "Rubiks-1-5", "--strategy", "test-timed", *BASE).exit_code == 0
        data = _json(invoke(table, "--json", "--run-tiers"))["rubiks"]
        labels = {lab for row in data["rows"] for lab in row["ours"]}
        assert labels == {
            f"test-timed (test-stub, pybullet) code 0.1.0+g{v}" for v in ("aaaa", "bbbb", "cccc")
        }
    finally:
        monkeypatch.delenv("BENCHHARNESS_CODE_VERSION")
        code_version.cache_clear()
