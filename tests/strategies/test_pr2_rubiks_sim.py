"""PR2 Rubik's baselines in simulation: the pick-up and a short tier (default suite), long trials (slow)."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

pytestmark = pytest.mark.sim

BACKENDS = ("pybullet", "sapien")


@pytest.mark.parametrize("backend", BACKENDS)
def test_pick_lifts_the_cube_to_the_twisting_pose_held_by_both_hands(make_ctx, backend):
    """The plan's Pick alone: side grasp on the table, lift, carry, second hand on (zero injected error)."""
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig
    from benchharness.strategies.pr2_rubiks.strategy import DeadReckoningStrategy

    ctx, b = make_ctx(backend, "R")
    cfg = replace(PR2RubiksConfig().zero_error(), max_actions=1)
    st = DeadReckoningStrategy(cfg)
    out = st.run_trial(ctx)
    assert out.failure is None, out.message
    true = st.cube.pose()
    np.testing.assert_allclose(true.p, cfg.twist_position, atol=0.006)  # lifted and carried
    assert (
        np.linalg.norm(true.p - st.est.p) < 0.006
    )  # belief (dead reckoning) agrees with the truth
    for side in ("left", "right"):
        assert st.hands[side].holding and st.hands[side].gripper.touching(st.cube.body)
    # first contact is found by the runner's step wrapper (not present in-process): the pair must be watched
    assert ctx.recorder.watched and ctx.recorder.watched[0][1] == ctx.robot.body
    assert out.final_state == ctx.item.initial  # no twist yet
    # every grasp records its belief's error along the work axis (the grip's approach: world y here)
    grasps = [e for e in ctx.recorder.events if e["kind"] == "grasp"]
    assert [e["label"] for e in grasps][:2] == ["pick", "second grasp"], grasps
    for e in grasps:
        assert abs(abs(e["work_axis"][1]) - 1.0) < 0.01, e
        assert abs(e["work_err_mm"]) < 6.0 and e["move_index"] == 0, e


def _run_cli(tmp_path, strategy: str, backend: str, task: str = "Rubiks-1-5"):
    store = tmp_path / "runs.sqlite"
    cmd = [
        sys.executable,
        "-m",
        "benchharness.cli.main",
        "run",
        "--task",
        task,
        "--robot",
        "pr2",
        "--strategy",
        strategy,
        "--backend",
        backend,
        "--seed",
        "0",
        "--workers",
        "0",
        "--store",
        str(store),
        "--json",
    ]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    import sqlite3

    con = sqlite3.connect(store)
    rows = con.execute(
        "select status, failure_cause, message, score, sim_s, diagnostics_json from trials"
    ).fetchall()
    return proc, rows


#: Rubiks-1-5, dead-reckoning-exact, seed 0 (score, sim_s, SHA-256 of the stored diagnostics JSON: every
#: event time and pose estimate). Speed-ups must not move a bit of a result; a change that moves results on
#: purpose re-records these and says why. Re-recorded for issue 16 item 2 (one-hand holds): the PR2 gripper
#: now closes at the published gap speed with each finger stopping where it touches, and its finger drives
#: carry their own weight, so every close ends sooner; a free hand's retreat is checked not to sweep
#: the held cube (first recorded at commit 7b3b4b1: PyBullet 98.07 /
#: 103.12 s, SAPIEN 93.37 / 98.43 s). Re-recorded for issue 15 item 1: a giver's alternative arm
#: postures come from the planner's stream spawned once from the trial's rng, no longer from a
#: generator seeded with the number of logged events (which a new diagnostic event changed; was
#: PyBullet 90.73 / 95.94 s, SAPIEN 85.75 / 90.93 s). Re-recorded for issue 16 (hand-over retreats): a
#: free hand's swing-arc waypoints are now sent seeded with the IK solution their joint path was checked
#: clear of the cube with (the arm then follows that solution, not one solved again from the
#: injected-error target; was PyBullet 88.22 / 93.43 s, SAPIEN 84.88 / 90.06 s, digest bf826d40e7351660).
#: Re-recorded for the giver postures found backwards (Rubiks-1-20): a giver grip with no smooth turn
#: near the arm's joints now comes from a posture solved backwards from its retreat (it was the least
#: bad one), reached by a detour; and the open hand's clearance points include the wrist sphere (was
#: PyBullet 90.16 / 95.37 s, SAPIEN 84.88 / 90.06 s). Re-recorded for issue 16 (Rubiks-1-50): a free
#: hand's joint-path clearance counts the table as well as the cube; the one ``detour`` event of the
#: trial (the right hand's shift-in stand-off, a branch change: detoured before as now) records the
#: direct move's clearance as 0.0 mm (its path went through the table) instead of the cube's 23.5 mm
#: (PyBullet) / 24.0 mm (SAPIEN); every other event, the score and the time are unchanged (digests
#: were 37b6ca951cc9bf16 / a31e5441fdaab0a4).
#: Re-recorded for the edge of reach (issue 16): the
#: PR2's hand-over turn carries the believed cube back to the twisting pose (``recentre_turn``); with zero
#: error the pick's carry puts the belief there up to float round-off, so the turn's waypoints move only
#: in their last bits: SAPIEN keeps its score and time to the bit (digest was a31e5441fdaab0a4), PyBullet's
#: trial ends 0.79 s later (was 93.48 / 98.69 s, digest 37b6ca951cc9bf16). Both still five twists as
#: intended. The reach margin and the unmoved failed move change neither (measured: rows unchanged).
#: With the table in the free-hand check as well (both merged) the score and time are those above; the
#: digests differ from either branch's alone (the detour event's 0.0 mm clearance).
#: Re-recorded for the cube's tilt (issue 16, ``recentre_tilt``): the PR2's hand-over turn also brings
#: the believed cube to faces-level. With zero error the belief is the camera's reading of the settled
#: cube, 0.0035 deg (PyBullet) / 0.000035 deg (SAPIEN) off faces-level, which the first turn takes out;
#: after it every correction is float round-off. And the giver postures found backwards (one here, on
#: both engines) now carry the ``recentre_turn`` shift their forward check has (here round-off too).
#: Each alone moves the trial: PyBullet with the postures' shift only (``recentre_tilt=false``) ends
#: 93.175 / 98.383 s; without either it is bit for bit the old row (measured). Both still five twists
#: as intended (was PyBullet 94.27083333333334 / 99.47916666666667 s, digest d705e9792f5a25ae;
#: SAPIEN 87.13749999999999 / 92.32083333333333 s, digest e6f9718f3cba7047).
#: Measured on one machine (the ``platform_key()`` below). Contact physics amplifies the last bit of a
#: float: a CPU with other SIMD paths in NumPy/SciPy/torch, or another release of one of them, gives the
#: same trial a different trajectory from the first differing bit (measured 2026-12-02: the last rows
#: above on the earlier machines; on an AMD EPYC with AVX-512 and NumPy 2.4.6 / SciPy 1.17.1 the PyBullet trial ends
#: 95.546 s, and SAPIEN's score is the same but its digest is not). So the rows are keyed by the platform
#: they were measured on; the rows recorded on the earlier machines (PyBullet 95.78750000000001 /
#: 100.99583333333334 / 11067dc53625b802, SAPIEN 87.35416666666666 / 92.5375 / 37af0c7964fb2805) had no
#: key and are kept here as history only.
REFERENCE_ROWS: dict[str, dict[str, tuple[float, float, str]]] = {
    # recorded 2026-12-05 with constraints.txt, the PR2 gripper's fingers symmetric (the published
    # mimic; BENCHMARKS.md "symmetric fingers"). With independent finger drives the rows were
    # (95.54583333333333, 100.75416666666666, 42cb036bff53a737) and (87.35416666666666, 92.5375,
    # 8c5ccfc18da625d2) here, and the Intel VM's (recorded 2026-12-03) are not re-recorded: that
    # platform now checks the trial against a second run, as any platform without a row
    "AMD EPYC | avx,avx2,avx512_bf16,avx512_bitalg,avx512_vbmi2,avx512_vnni,avx512_vp2intersect,avx512_vpopcntdq,avx512bw,avx512cd,avx512dq,avx512f,avx512ifma,avx512vbmi,avx512vl,avx_vnni,fma,sse4_1,sse4_2,sse4a | numpy 2.4.6 | scipy 1.17.1 | torch 2.13.0+cpu | pytorch-kinematics 0.10.0 | pybullet 3.2.7 | sapien 3.0.3 | filterpy 2.0.0": {
        "pybullet": (90.7375, 95.94583333333333, "3c5b4d6b02dac8eb"),
        "sapien": (87.57499999999999, 92.75833333333333, "e780c86792085777"),
    },
}


def platform_key() -> str:
    """What a bit-exact result depends on beyond the code and the seed: CPU model and SIMD, libraries.

    ``constraints.txt`` pins the libraries for a fresh clone; the CPU cannot be pinned.
    """
    import importlib.metadata as md
    import platform

    model, flags = platform.machine(), set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, val = line.partition(":")
                if key.strip() == "model name":
                    model = val.strip()
                elif key.strip() == "flags":
                    flags = set(val.split())
    except OSError:
        pass
    simd = sorted(x for x in flags if x.startswith(("avx", "fma", "sse4")))
    libs = [
        f"{n} {md.version(n)}"
        for n in ("numpy", "scipy", "torch", "pytorch-kinematics", "pybullet", "sapien", "filterpy")
    ]
    return " | ".join([model, ",".join(simd), *libs])


@pytest.mark.parametrize("backend", BACKENDS)
def test_short_tier_runs_end_to_end_on_both_backends(tmp_path, backend):
    """Default suite: a whole Rubiks-1-5 trial through `benchharness run` (10-25 s per engine).

    Pick, five physical twists with hand-overs and shifts, release, validator,
    score. Zero injected error, so the strategy has no excuse: the trial must
    end in the expected state on each engine, after all five twists turned
    their layers as intended (a CI that only checks the pipeline ran would
    pass with a baseline that never succeeds).
    """
    proc, rows = _run_cli(tmp_path, "dead-reckoning-exact", backend)
    assert len(rows) == 1, proc.stderr[-2000:]
    status, cause, message, score, sim_s, diag = rows[0]
    assert status == "success", (status, cause, message)
    assert score is not None and 0 < score < sim_s
    d = json.loads(diag)
    assert d["counts"].get("move", 0) == 5, d["counts"]
    assert (
        d["counts"].get("unintended_rotation", 0) == 0
        and d["counts"].get("blocked_rotation", 0) == 0
    )
    assert sim_s > 30
    # bit for bit the result recorded on this platform (REFERENCE_ROWS); on a platform with no row, bit
    # for bit the same trial run again in a fresh process (same seed, same machine: the same result)
    row = (score, sim_s, hashlib.sha256(diag.encode()).hexdigest()[:16])
    recorded = REFERENCE_ROWS.get(platform_key(), {}).get(backend)
    if recorded is None:
        (tmp_path / "again").mkdir()
        _, again = _run_cli(tmp_path / "again", "dead-reckoning-exact", backend)
        status2, _, _, score2, sim_s2, diag2 = again[0]
        assert (status2, score2, sim_s2, hashlib.sha256(diag2.encode()).hexdigest()[:16]) == (
            status,
            *row,
        ), f"not reproducible on {platform_key()!r}"
    else:
        assert row == recorded, f"platform {platform_key()!r}"


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
def test_exact_dead_reckoning_completes_rubiks_1_5(tmp_path, backend):
    """End to end through `benchharness run`: zero injected error must end in the expected state."""
    proc, rows = _run_cli(tmp_path, "dead-reckoning-exact", backend)
    assert len(rows) == 1, proc.stderr[-2000:]
    status, cause, message, score, sim_s, diag = rows[0]
    assert status == "success", (cause, message)
    assert score is not None and 0 < score < sim_s
    d = json.loads(diag)
    assert d["counts"].get("move", 0) == 5


@pytest.mark.slow
def test_exact_dead_reckoning_completes_rubiks_1_20_on_sapien(tmp_path):
    """20 moves (13 hand-overs, 3 shifts) with zero injected error: every twist as intended.

    Needs the continuous rolls (no unwinding mid-turn), the arc swings round
    the cube, the two-stage close and the collision-free wrist (docs/strategies.md).
    PyBullet does not complete this trial yet (the cube pivots in a grip; see there).
    """
    proc, rows = _run_cli(tmp_path, "dead-reckoning-exact", "sapien", task="Rubiks-1-20")
    assert len(rows) == 1, proc.stderr[-2000:]
    status, cause, message, score, sim_s, diag = rows[0]
    assert status == "success", (cause, message)
    d = json.loads(diag)
    moves = [e for e in d["events"] if e["kind"] == "move"]
    assert len(moves) == 20 and all(e["as_intended"] for e in moves)


@pytest.mark.slow
def test_sensor_aided_completes_rubiks_1_20_on_sapien(tmp_path):
    """Seed 0, default errors (~3 min wall): every twist as intended. It failed after 9 twists until a
    giver grip with no smooth turn near the arm's joints was found by solving the turn backwards from its
    retreat (`giver_posture` events; docs/strategies.md, "Giver postures found backwards")."""
    proc, rows = _run_cli(tmp_path, "sensor-aided", "sapien", task="Rubiks-1-20")
    assert len(rows) == 1, proc.stderr[-2000:]
    status, cause, message, score, sim_s, diag = rows[0]
    assert status == "success", (cause, message)
    d = json.loads(diag)
    moves = [e for e in d["events"] if e["kind"] == "move"]
    assert len(moves) == 20 and all(e["as_intended"] for e in moves)
    assert any(e["kind"] == "giver_posture" for e in d["events"])


@pytest.mark.slow
@pytest.mark.parametrize("strategy", ("dead-reckoning", "sensor-aided"))
@pytest.mark.parametrize("backend", BACKENDS)
def test_with_default_errors_the_trial_is_run_and_scored(tmp_path, backend, strategy):
    """With the default error sources the trial runs and is scored (success or a physical failure cause)."""
    proc, rows = _run_cli(tmp_path, strategy, backend)
    assert len(rows) == 1, proc.stderr[-2000:]
    status, cause, message, score, sim_s, diag = rows[0]
    assert cause != "strategy_error" and cause != "simulator_error", message
    if status == "success":
        assert score is not None
    else:
        assert cause in ("wrong_state", "dropped", "jammed", "unreachable", "timeout")
    d = json.loads(diag)
    assert d["pose_estimates"], "no true-vs-believed pose was recorded"


def test_twisting_pose_keeps_every_planned_grip_and_turn_inside_the_soft_limits():
    """The default twisting pose (and the pick below it) is reachable with margin inside the PR2's soft
    limits for every grip family and both hand-over turns; the former (0.60, 0, 0.80) m had no smooth
    turn about z inside them — the cause of the soft-limit Rubiks-5-10 failures (docs/strategies.md)."""
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig
    from benchharness.strategies.pr2_rubiks.workspace import _left_arm, margins

    cfg = PR2RubiksConfig()
    b, arm = _left_arm()
    try:
        assert arm.robot.config.soft_limits
        pick = (*cfg.cube_xy, cfg.table_height + 0.0285)
        for centre in (cfg.twist_position, pick):
            m = margins(arm, centre, cfg)
            assert min(v for v, _ in m.values()) > 0.2, (centre, m)  # rad inside every soft limit
        old = margins(arm, (0.60, 0.0, 0.80), cfg)
        assert old["turn_z"][0] == float("-inf")
    finally:
        b.close()


@pytest.mark.parametrize("backend", BACKENDS)
def test_sensor_aided_pick_sweeps_the_fingertip_across_the_face_edges(make_ctx, backend):
    """The pick alone, default errors: the picking hand really sweeps its fingertip sensor across the
    face's side and top edges before it grips, and the 6-DOF filter puts the belief within a millimetre or
    two of the truth on every axis (the arm's 1.5 mm calibration offset included) with a sub-millimetre std."""
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig
    from benchharness.strategies.pr2_rubiks.strategy import SensorAidedStrategy

    ctx, b = make_ctx(backend, "R")
    st = SensorAidedStrategy(replace(PR2RubiksConfig(), max_actions=1))
    out = st.run_trial(ctx)
    assert out.failure is None, out.message
    pre = [e for e in ctx.recorder.events if e["kind"] == "pretouch"]
    first = pre[0]
    assert first["label"] == "pick" and first["mode"] == "sweep"
    assert [s.split("(")[0] for s in first["sweeps"]] == ["across", "up", "down"]
    assert first["edges_used"] >= 3 and first["used"] > 60
    assert 6.0 < first["cost_s"] < 12.0  # the sweeps take simulated time
    assert all(s < 1.0 for s in first["std_mm"]) and all(s < 2.0 for s in first["std_deg"])
    assert all(abs(e) < 3.0 for e in first["err_mm"]), first
    assert all(abs(e) < 3.0 for e in first["rot_err_deg"]), first
    assert abs(first["work_err_mm"]) < 2.5


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
def test_sensor_aided_completes_rubiks_1_5_with_default_errors(tmp_path, backend):
    """A whole Rubiks-1-5 with the default injected errors: sweeps before every grasp, every grasp made
    from a belief within half a cubie (9.5 mm) of the truth along the work axis, the trial solved."""
    proc, rows = _run_cli(tmp_path, "sensor-aided", backend)
    assert len(rows) == 1, proc.stderr[-2000:]
    status, cause, message, score, sim_s, diag = rows[0]
    assert status == "success", (status, cause, message)
    d = json.loads(diag)
    pre = [e for e in d["events"] if e["kind"] == "pretouch"]
    assert len(pre) >= 10  # the pick, the second grasp, and every regrasp and hand-over grip after
    assert all(e["mode"] == "sweep" and e["cost_s"] > 3.0 for e in pre)
    assert all(abs(e["work_err_mm"]) < 9.5 for e in pre), [e["work_err_mm"] for e in pre]


@pytest.mark.slow
def test_a_stand_off_move_through_the_cube_ends_the_trial_unreachable(tmp_path):
    """SAPIEN Rubiks-5-200 dead reckoning seed 0, trial 2 (~45 s): at 517.6 s the right hand's move to
    its hand-over re-grip stand-off found no detour and its straight joint path entered the believed
    cube. Made anyway (before), it knocked the cube 31.6 mm / 19.6 deg, the next twist turned the
    wrong layer and the trial ended `dropped` at 523.0 s, a cause that hid what happened. The trial
    now ends there, `unreachable`, with the reason. Measured on the Intel platform whose reference
    rows are above; on another CPU the trajectory differs from the first differing bit and this
    move may never be met, so the test runs only there."""
    intel = [k for k in REFERENCE_ROWS if k.startswith("Intel(R) Xeon(R) Processor")]
    if platform_key() not in intel:
        pytest.skip(f"measured on {intel[0]!r}")
    import sqlite3

    store = tmp_path / "runs.sqlite"
    cmd = [sys.executable, "-m", "benchharness.cli.main", "run", "--task", "Rubiks-5-200"]
    cmd += ["--robot", "pr2", "--strategy", "dead-reckoning", "--backend", "sapien", "--seed", "0"]
    cmd += ["--trials", "2", "--workers", "0", "--store", str(store)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    rows = sqlite3.connect(store).execute(
        "select status, failure_cause, message, sim_s from trials"
    )
    rows = rows.fetchall()
    assert len(rows) == 1, proc.stderr[-2000:]
    status, cause, message, sim_s = rows[0]
    assert (status, cause) == ("failure", "unreachable"), message
    assert "hand-over re-grip stand-off passes through the believed cube" in message
    assert sim_s < 518.0  # before the knocked cube's twist (523.0 s)


@pytest.mark.slow
def test_sensor_aided_rubiks_1_10_on_pybullet_skips_a_waypoint_and_detours_back_to_its_pre_grasp(
    tmp_path,
):
    """PyBullet Rubiks-1-10 sensor-aided seed 0 (~60 CPU-s). At 274.0 s a re-grip stand-off's arc waypoint
    was 1.4 mm, 0.4 deg out of reach with the injected errors and ended the trial `unreachable`: it is
    now left out (``swing_skip``), as a waypoint out of reach for the belief already was. At 352.0 s the
    move back from the last pre-touch sweep to the re-grip's pre-grasp swung the upper-arm and forearm
    rolls +1.48 / -1.75 rad on a joint path through the believed cube, the held cube turned 23 deg and
    the last twist was misaligned (`wrong_state`): that move is now checked and takes a detour. The trial
    completes. Measured on the Intel platform of the reference rows above; elsewhere the trajectory
    differs from the first differing bit and these moves may never be met, so it runs only there."""
    intel = [k for k in REFERENCE_ROWS if k.startswith("Intel(R) Xeon(R) Processor")]
    if platform_key() not in intel:
        pytest.skip(f"measured on {intel[0]!r}")
    proc, rows = _run_cli(tmp_path, "sensor-aided", "pybullet", task="Rubiks-1-10")
    assert len(rows) == 1, proc.stderr[-2000:]
    status, cause, message, score, sim_s, diag = rows[0]
    events = json.loads(diag)["events"]
    skips = [e for e in events if e["kind"] == "swing_skip"]
    detours = [e for e in events if e["kind"] == "detour" and e["label"].endswith("pre-grasp")]
    assert [round(e["t"], 1) for e in skips] == [274.0]
    assert [round(e["t"], 1) for e in detours] == [352.0]
    assert status == "success", (status, cause, message)
    assert score == pytest.approx(349.70, abs=0.01)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("task", "backend", "t", "hand", "way_out", "score"),
    [
        ("Rubiks-5-10", "pybullet", 264.8, "right", "up", 343.138),
        ("Rubiks-5-100", "sapien", 588.1, "left", "side", 2910.354),
    ],
    ids=["up", "side"],
)
def test_a_detour_goes_up_or_aside_where_the_way_back_along_the_approach_is_blocked(
    tmp_path, task, backend, t, hand, way_out, score
):
    """Sensor-aided seed 0, trial 3 of PyBullet Rubiks-5-10 (~60 CPU-s) and of SAPIEN Rubiks-5-100 (~4.5
    CPU-min). At ``t`` a free hand in front of the cube had to reach its re-grip stand-off beside it:
    the direct joint path passes through the believed cube and no detour out along its approach clears
    (PyBullet: a giver retreated sideways with its wrist flex on its soft limit), so the trial ended
    `unreachable`. The way out straight up (PyBullet) or towards the stand-off's side (SAPIEN), the
    turn and the way in are clear: the hand takes that detour (a ``detour`` event with ``way_out``) and
    the trial completes. Intel platform only, as the test above."""
    intel = [k for k in REFERENCE_ROWS if k.startswith("Intel(R) Xeon(R) Processor")]
    if platform_key() not in intel:
        pytest.skip(f"measured on {intel[0]!r}")
    import sqlite3

    store = tmp_path / "runs.sqlite"
    cmd = [sys.executable, "-m", "benchharness.cli.main", "run", "--task", task, "--robot", "pr2"]
    cmd += ["--strategy", "sensor-aided", "--backend", backend, "--seed", "0", "--trials", "3"]
    cmd += ["--workers", "0", "--store", str(store)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    rows = sqlite3.connect(store).execute(
        "select status, failure_cause, message, score, diagnostics_json from trials"
    )
    rows = rows.fetchall()
    assert len(rows) == 1, proc.stderr[-2000:]
    status, cause, message, got, diag = rows[0]
    ways = [e for e in json.loads(diag)["events"] if e["kind"] == "detour" and "way_out" in e]
    assert [(round(e["t"], 1), e["hand"], e["label"], e["way_out"]) for e in ways] == [
        (t, hand, "hand-over re-grip stand-off", way_out)
    ]
    assert status == "success", (status, cause, message)
    assert got == pytest.approx(score, abs=1e-3)


#: Issue 16's targets for sensor-aided (seed 0): the paper's PR2 completed Rubiks-1-50 (1123.04 s),
#: Rubiks-1-100 (2207.97 s) and Rubiks-5-20 (416.61 ± 23.10 s) with pre-touch sensing (Table I of the
#: Rubik's benchmark paper); ours must complete them on both engines. Where a platform is known not to,
#: the reason it does not (traced) is kept here and the case is a strict xfail there.
#: (The Intel VM's PyBullet Rubiks-1-100, `wrong_state` after the free arm's elbow pushed the holding
#: arm 27 mm, was listed here until the machine's arm check covered the retreat where such contacts
#: happened (BENCHMARKS.md, 2026-12-04 "arm check"); it has not been re-run on that CPU.)
KNOWN_MISSES: dict[tuple[str, str, str], str] = {}


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("task", ("Rubiks-1-50", "Rubiks-1-100", "Rubiks-5-20"))
def test_sensor_aided_completes_the_tiers_the_papers_pr2_completed(tmp_path, task, backend):
    """Every trial of the tier ends in the expected state with every twist as intended (1-50 ~3-5
    CPU-min, 1-100 ~5-9, 5-20 ~5-7 per engine)."""
    key = platform_key()
    known = next(
        (
            why
            for (t, b, cpu), why in KNOWN_MISSES.items()
            if (t, b) == (task, backend) and key.startswith(cpu)
        ),
        None,
    )
    from benchharness.cube.tiers import get_tier

    tier = get_tier(task)
    proc, rows = _run_cli(tmp_path, "sensor-aided", backend, task=task)
    assert len(rows) == tier.trials, proc.stderr[-2000:]
    ok = all(status == "success" for status, *_ in rows)
    if known is not None:
        assert not ok, f"{task} on {backend} now completes here: remove it from KNOWN_MISSES"
        pytest.xfail(known)
    for status, cause, message, _score, _sim_s, diag in rows:
        assert status == "success", (cause, message)
        moves = [e for e in json.loads(diag)["events"] if e["kind"] == "move"]
        assert len(moves) == tier.moves and all(e["as_intended"] for e in moves)
