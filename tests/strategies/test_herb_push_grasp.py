"""HERB push-grasp strategy: registration, frames, the push-grasp against the true cube on both backends, a trial.

The stop-distance test is the point of push-grasping: a belief that is
wrong along the approach by ``BELIEF_ERROR`` must not make the grasp wrong by
as much. The check is independent of the strategy's own belief: it reads
the *true* cube pose from the engine and the hand's true tool frame, and
compares the face's true depth in the tool frame with the depth the grasp
was designed for (the thumb's reach, from FK of the measured joints).
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.backends.interface import Box
from benchharness.geometry import Pose

CUBE_HALF = 0.0285
BELIEF_ERROR = 0.008  # m, along the approach; 2-3 x what the head camera gives


def test_registered_for_herb_and_refuses_other_robots(make_ctx):
    from benchharness.plugin import get_manager

    m = get_manager()
    for name in ("push-grasp", "push-grasp-exact"):
        strat = m.create("strategy", name)
        assert strat.name == "push-grasp" and "rubiks" in strat.benchmarks
        assert strat.grasp.robot_name == "herb"
    assert m.create("strategy", "push-grasp-exact").config.errors.is_zero
    ctx, _ = make_ctx("pybullet", "R")  # the fixture's robot is the PR2
    with pytest.raises(ValueError, match="herb"):
        m.create("strategy", "push-grasp").run_trial(ctx)


def test_push_grip_frames_against_hand_computed_ones():
    from benchharness.strategies.herb_rubiks.frames import (
        HERB_FROM_PR2,
        push_grip_candidates,
        reanchor_along_approach,
    )

    assert np.isclose(np.linalg.det(HERB_FROM_PR2.as_matrix()), 1.0)
    cube = Pose.from_rotation([0.6, 0.0, 1.0], Rotation.from_euler("z", -90, degrees=True))
    grips = push_grip_candidates(cube, "+y", 0.03)
    assert len(grips) == 4
    for g in grips:
        z = g.rotation.apply([0, 0, 1])
        assert np.allclose(z, [0, -1, 0], atol=1e-9)  # approach along -y onto the +y face
        assert np.allclose(g.p, [0.6, CUBE_HALF + 0.03, 1.0], atol=1e-9)
        assert abs(g.rotation.apply([1, 0, 0])[1]) < 1e-9  # the pinch crosses the approach
    # a belief 5 mm too far along -y: the thumb met the face at the designed stand-off -> belief moves back
    belief = Pose(cube.p + [0, -0.005, 0], cube.q)
    fixed, shift = reanchor_along_approach(belief, grips[0], 0.03)
    assert shift == pytest.approx(-0.005, abs=1e-12)
    assert np.allclose(fixed.p, cube.p, atol=1e-12)


@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
def test_push_grasp_removes_belief_error_along_the_approach(make_backend, make_robot, backend):
    """Push-grasp a cube on a pedestal from above with the belief 8 mm off, both ways; check with the true pose."""
    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.herb_rubiks.frames import reanchor_along_approach, thumb_face_depth
    from benchharness.strategies.herb_rubiks.push import (
        close_outer_fingers,
        preshape,
        push_until_contact,
    )

    be = make_backend(backend)
    be.add_ground()
    robot = make_robot("herb")
    robot.spawn(be)
    arm, hand = robot.arm("left_arm"), robot.hand("left_hand")
    # pointing straight down in front of the left shoulder
    down = Pose.from_rotation([0.85, 0.22, 0.95], Rotation.from_euler("y", np.pi))
    assert arm.move_to_pose(down, seed=0).ik_success
    home = arm.tcp_pose()
    top = home.p[2] - 0.09
    be.add_body(
        [Box((0.02, 0.02, (top - 2 * CUBE_HALF) / 2))],
        Pose([home.p[0], home.p[1], (top - 2 * CUBE_HALF) / 2]),
        1.0,
        fixed=True,
        name="pedestal",
    )
    cube = be.add_body(
        [Box((CUBE_HALF,) * 3)],
        Pose([home.p[0], home.p[1], top - CUBE_HALF + 5e-4]),
        0.094,
        friction=1.0,
        name="cube",
    )
    cfg = HerbPushGraspConfig()
    preshape(hand, cfg.spread, cfg.rotator_thumb_flex, outer_flex=cfg.outer_open_flex)
    robot.settle(0.2)
    design = thumb_face_depth(arm.tcp_pose(), be.get_link_pose(robot.body, "l_bh_finger_33_link"))
    assert 0.025 < design < 0.04
    for sign in (1.0, -1.0):
        true = be.get_pose(cube)
        belief = Pose(
            true.p + [0.0, 0.0, -sign * BELIEF_ERROR], true.q
        )  # approach is -z: sign>0 = believed farther
        # the grasp the belief asks for, 3 cm before the believed contact
        grip = Pose([true.p[0], true.p[1], belief.p[2] + CUBE_HALF + design], home.q)
        start = Pose(grip.p + [0.0, 0.0, 0.03], grip.q)
        assert arm.move_to_pose(start, settle=0.2).ik_success
        res = push_until_contact(
            robot, arm, hand, cube, start, limit=0.06, speed=0.03, force_threshold=1.0
        )
        assert res.contact and any(link.endswith("finger_33_link") for link in res.links)
        # independent check: true face depth in the hand's true tool frame vs the designed depth
        tcp, true = arm.tcp_pose(), be.get_pose(cube)
        face_in_tool = float(
            np.dot(true.p + [0, 0, CUBE_HALF] - tcp.p, tcp.rotation.apply([0, 0, 1]))
        )
        grasp_error = abs(face_in_tool - design)
        believed_error = abs(
            float(grip.p[2] - tcp.p[2]) - 0.0
        )  # where dead reckoning would have put the hand
        assert grasp_error < 0.003, (backend, sign, grasp_error)
        assert grasp_error < BELIEF_ERROR / 2
        assert (
            believed_error > BELIEF_ERROR - 0.003
        )  # the hand did stop ~8 mm away from the believed grasp
        fixed, shift = reanchor_along_approach(belief, res.commanded, design)
        print(  # the figures of docs/benchmarks/herb_push_grasp.md (pytest -s)
            f"{backend} belief {sign * BELIEF_ERROR * 1e3:+.0f} mm: travel {res.travel * 1e3:.1f} mm, "
            f"grasp depth error {grasp_error * 1e3:.2f} mm, belief after "
            f"{abs(fixed.p[2] - true.p[2]) * 1e3:.2f} mm, stop force {res.force:.1f} N"
        )
        assert abs(fixed.p[2] - true.p[2]) < 0.003
        assert abs(shift) == pytest.approx(BELIEF_ERROR, abs=0.003)
        assert (
            np.linalg.norm(true.p[:2] - [home.p[0], home.p[1]]) < 0.002
        )  # the push did not shove the cube
        close_outer_fingers(hand, 2.0)
        assert hand.touching(cube)
        u = hand.command.copy()
        u[1] = u[2] = cfg.outer_open_flex
        hand.set_command(u)
        robot.settle(0.4)


def test_hand_over_clearance_geometry():
    """The taker's closing fingers against the other hand's finger boxes (no physics, hand-computed cases)."""
    from benchharness.strategies.herb_rubiks.frames import (
        DIST_CORNERS,
        band_clear,
        finger_extent,
        thumb_tip_lateral,
    )

    # an obstacle box across the palm (tool y) from 0 to 20 mm, 30-60 mm beyond the tool frame
    lo, hi = np.array([-0.05, 0.0, 0.03]), np.array([0.05, 0.02, 0.06])
    assert not band_clear(
        lo, hi, 0.0, 0.012, 0.049, 0.003
    )  # fingers at 0 +- 12 mm reach 49 mm: they meet it
    assert band_clear(
        lo, hi, -0.016, 0.012, 0.049, 0.003
    )  # slid 16 mm the other way: 16 - 12 >= 3 mm
    assert not band_clear(lo, hi, -0.014, 0.012, 0.049, 0.003)  # 14 mm: 2 mm < the 3 mm clearance
    assert band_clear(lo, hi, 0.035, 0.012, 0.049, 0.003)  # past its far side
    assert band_clear(lo, hi, 0.0, 0.012, 0.025, 0.003)  # a shorter reach stops short of it
    # finger_extent: a link box placed relative to the *believed* tool pose, seen from another frame
    tool_meas = Pose([1.0, 2.0, 3.0])
    link = Pose([1.0, 2.0, 3.05])  # 50 mm beyond the measured tool frame along z, unrotated
    lo2, hi2 = finger_extent(
        Pose([0.0, 0.0, 0.0]), tool_meas, [(link, DIST_CORNERS)], Pose([0.0, 0.0, 0.0])
    )
    # the distal box (robots/descriptions/herb.py): x 3..50 mm along the link, y +-7 mm, z +-11 mm
    assert np.allclose(lo2, [0.003, -0.007, 0.039], atol=1e-9) and np.allclose(
        hi2, [0.05, 0.007, 0.061], atol=1e-9
    )
    # thumb tip: a distal link (x along it) curled 60 deg from the approach towards tool -y, its
    # closing side (link y) towards the approach, touches with its far end's corners on that side
    # (x = 50 mm, y = +7 mm): tool y = -50 mm sin 60 + 7 mm cos 60
    s60, c60 = np.sin(np.radians(60)), np.cos(np.radians(60))
    cols = np.array([[0.0, -s60, c60], [0.0, c60, s60], [-1.0, 0.0, 0.0]]).T
    distal = Pose.from_rotation([0.0, 0.0, 0.03], Rotation.from_matrix(cols))
    expect = -0.05 * s60 + 0.007 * c60
    assert thumb_tip_lateral(Pose([0.0, 0.0, 0.0]), distal) == pytest.approx(expect, abs=1e-9)


def test_giver_posture_found_backwards_is_scored_and_recorded():
    """A giver with no smooth turn from the arm's joints takes the best chain found backwards
    (``_backward_give``: placement preference, joint change, forward-checked turn travel); none: None."""
    from types import SimpleNamespace

    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.herb_rubiks.strategy import PushGrasp

    events: list[tuple[str, dict]] = []
    q_now = np.zeros(7)
    grips = [Pose([0.0, 0.0, float(i)]) for i in range(2)]
    # chains: placement 0 twice (joint change 1.0 / 0.2 rad), placement 1 once (change 0.1)
    qs = np.array([[1.0] + [0.0] * 6, [0.2] + [0.0] * 6, [0.1] + [0.0] * 6])
    travel = np.array([2.0, 3.0, np.inf])  # placement 1's chain fails the forward check
    m = SimpleNamespace(
        ctx=SimpleNamespace(
            recorder=SimpleNamespace(event=lambda kind, **kw: events.append((kind, kw)))
        ),
        turn_postures=lambda hand, base, poses, axis, angle, n_seeds: ([0, 0, 1], qs),
        turn_travel=lambda hand, base, poses, q, axis, angle: (travel, travel),
    )
    g = PushGrasp(HerbPushGraspConfig())
    hand = SimpleNamespace(side="right")
    places = [(grips[0], 0.5, 0.0), (grips[1], 0.5, 0.004)]
    found = g._backward_give(m, hand, Pose([0, 0, 0]), q_now, places, ("z", np.pi / 2))
    assert found is not None
    pose, slide, q = found
    # scores: 0.5 - 0.1 - 0.2 = 0.2 and 0.5 - 0.02 - 0.3 = 0.18: the first chain
    assert pose is grips[0] and slide == 0.0 and np.allclose(q, qs[0])
    assert events[-1][0] == "giver_posture" and events[-1][1]["chains"] == 3
    assert events[-1][1]["checked"] == 2
    # no chain found backwards: None, recorded
    m.turn_postures = lambda *a, **k: ([], np.zeros((0, 7)))
    assert g._backward_give(m, hand, Pose([0, 0, 0]), q_now, places, ("z", np.pi / 2)) is None
    assert events[-1] == ("giver_posture", {"hand": "right", "chains": 0})
    # off
    g0 = PushGrasp(HerbPushGraspConfig(giver_backward_seeds=0))
    assert g0._backward_give(m, hand, Pose([0, 0, 0]), q_now, places, ("z", np.pi / 2)) is None


def test_giver_changes_to_the_checked_branch_only_when_its_turn_would_not_be_smooth():
    """``_keep_turn_branch``: at the stand-off, a giver whose grip from here has no smooth hand-over turn
    while the checked solution has one moves to the checked branch (a ``give_branch`` event, the
    stand-off sent seeded with it); a smooth turn from here moves nothing."""
    from types import SimpleNamespace

    from benchharness.strategies.herb_rubiks.strategy import BarrettState, PushGrasp

    here = np.zeros(7)
    checked = np.full(7, 2.0)

    class Arm:
        def base_pose(self):
            return Pose([0.0, 0.0, 0.0])

        def positions(self):
            return here.copy()

        def ik(self, targets, seed_q):
            # IK stays on the branch of its seed
            q = np.atleast_2d(np.asarray(seed_q, dtype=float))
            return SimpleNamespace(success=np.array([True]), q=q.copy())

    def turn_travel(hand, base, grips, q, axis, angle, with_retreat=True):
        smooth = bool(np.allclose(q[0], checked)) or here_smooth[0]
        return np.array([1.0 if smooth else np.inf]), np.array([0.5 if smooth else 4.6])

    sent, events, here_smooth = [], [], [False]
    hand = SimpleNamespace(side="right", arm=Arm(), cmd=Pose([0.0, 0.0, 0.1]), state=BarrettState())
    hand.state.turn_q = checked

    def ik_q(h, pose, seed):  # the machine's: the arm's IK, None if it fails
        res = h.arm.ik(None, seed_q=seed)
        return np.asarray(res.q[0], dtype=float) if res.success[0] else None

    m = SimpleNamespace(
        turn_travel=turn_travel,
        ik_q=ik_q,
        send=lambda h, target, **kw: sent.append((target, kw)),
        ctx=SimpleNamespace(
            recorder=SimpleNamespace(event=lambda kind, **kw: events.append((kind, kw)))
        ),
    )
    grip, start = Pose([0.0, 0.0, 0.2]), Pose([0.0, 0.0, 0.17])
    g = PushGrasp()
    g._keep_turn_branch(m, hand, grip, start, ("z", -np.pi / 2), "hand-over give grip")
    assert len(sent) == 1 and sent[0][0] is hand.cmd and np.allclose(sent[0][1]["seed_q"], checked)
    assert events == [
        (
            "give_branch",
            {
                "hand": "right",
                "label": "hand-over give grip",
                "largest_step_here": 4.6,
                "joint_change": 2.0,
            },
        )
    ]
    # the turn from here is smooth: nothing moves
    here_smooth[0] = True
    g._keep_turn_branch(m, hand, grip, start, ("z", -np.pi / 2), "hand-over give grip")
    assert len(sent) == 1 and len(events) == 1


def _herb_ctx(backend: str, sequence: str, seed: int = 0):
    """A TrialContext with HERB, built in-process as the runner builds one (tier label Rubiks-1-1)."""
    from benchharness.backends.interface import PhysicsConfig
    from benchharness.cube import parse_sequence
    from benchharness.plugin import get_manager
    from benchharness.runner.contract import RubiksItem, TimeBudget, TrialContext
    from benchharness.runner.recorder import TrialRecorder

    m = get_manager()
    phys = PhysicsConfig(seed=seed)
    b = m.create("backend", backend, config=phys)
    item = RubiksItem("Rubiks-1-1", 1, 1, tuple(parse_sequence(sequence)), seed)
    rec = TrialRecorder(clock=lambda: float(b.time))
    ctx = TrialContext(
        item=item,
        trial_index=1,
        robot=m.create("robot", "herb"),
        backend=b,
        sensors={},
        rng=np.random.default_rng(seed),
        budget=TimeBudget(),
        recorder=rec,
        physics=phys,
    )
    return ctx, b


@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
def test_short_trial_with_a_hand_over_succeeds_on_both_engines(backend):
    """Default suite: a whole HERB trial of ``D'`` on the shared bimanual machine (15-30 s per engine).

    Its plan is the machine's every step but a shift: pick from the table, the second grasp, a hand-over
    (the two-slab giver grips again one slab deep while the taker holds, turns the cube, the taker
    push-grasps it, the giver re-grips), one physical twist, release. With the default injected errors;
    the expected state comes from the cube core.
    """
    from benchharness.cube import SOLVED, apply, to_string
    from benchharness.strategies.herb_rubiks.strategy import PushGraspStrategy

    ctx, b = _herb_ctx(backend, "D'")
    try:
        out = PushGraspStrategy().run_trial(ctx)
    finally:
        b.close()
    assert out.failure is None, out.message
    assert out.final_state == to_string(apply(SOLVED, "D'"))
    events = ctx.recorder.to_json()["events"]
    moves = [e for e in events if e["kind"] == "move"]
    assert len(moves) == 1 and moves[0]["as_intended"], moves
    assert not [e for e in events if e["kind"] == "unintended_rotation"]
    labels = {e.get("label") for e in events if e["kind"] == "check"}
    assert {
        "hand-over hold",
        "hand-over give grip",
        "hand-over take",
        "hand-over re-grip",
    } <= labels


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
def test_whole_one_move_trial_with_injected_errors(backend):
    """A whole trial (pick from the table, push-grasps, one twist by the physical cube, release) of ``R``.

    PyBullet was a strict xfail (the middle slab turned with the layer) until the rotator's pinch was made
    shallower (98 deg) so that its fingertips stay off the middle slab (docs/herb_push_grasp.md).

    The expected state comes from the cube core, independently of the strategy and the physical cube.
    """
    from benchharness.cube import SOLVED, apply, to_string
    from benchharness.strategies.herb_rubiks.strategy import PushGraspStrategy

    ctx, b = _herb_ctx(backend, "R")
    try:
        out = PushGraspStrategy().run_trial(ctx)
        assert out.failure is None, out.message
        assert out.final_state == to_string(
            apply(SOLVED, "R")
        )  # the cube core, independent of the strategy
        moves = [e for e in ctx.recorder.to_json()["events"] if e["kind"] == "move"]
        assert len(moves) == 1 and moves[0]["as_intended"]
        pushes = [e for e in ctx.recorder.to_json()["events"] if e["kind"] == "push"]
        # every push put its grasp on its slab: the true error along the push (read after the stop; it
        # includes the held cube yielding under the push, 5.2 mm measured on PyBullet) under half a slab
        assert len(pushes) == 2 and all(
            abs(p["true_error_along_approach_mm"]) < 9.5 for p in pushes
        )
    finally:
        b.close()


def _run_cli(tmp_path, task: str, backend: str, seed: int = 0) -> list[dict]:
    """`benchharness run --task TASK --robot herb --strategy push-grasp --seed SEED`: the stored trials (JSON)."""
    import json

    store = tmp_path / "herb.sqlite"
    cmd = [
        sys.executable,
        "-m",
        "benchharness.cli.main",
        "run",
        "--task",
        task,
        "--robot",
        "herb",
        "--strategy",
        "push-grasp",
        "--backend",
        backend,
        "--seed",
        str(seed),
        "--workers",
        "0",
        "--store",
        str(store),
        "--json",
        "--no-progress",
    ]
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    assert out.returncode in (0, 1), out.stderr[-2000:]
    assert "strategy_error" not in out.stdout and "simulator_error" not in out.stdout, out.stdout[
        -3000:
    ]
    res = subprocess.run(
        [sys.executable, "-m", "benchharness.cli.main", "results", "--store", str(store), "--json"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr[-2000:]
    return json.loads(res.stdout)["trials"]


@pytest.mark.slow
@pytest.mark.parametrize(("backend", "seed"), [("pybullet", 1), ("sapien", 0)])
def test_rubiks_1_5_through_the_cli_is_scored(tmp_path, backend, seed):
    """`benchharness run --task Rubiks-1-5 --robot herb --strategy push-grasp`: runs, is stored and scored.

    On both engines the whole trial succeeds on the shared machine (issue 15 item 2): all 5 moves as
    intended, the final state checked by the protocol validator (docs/benchmarks/herb_push_grasp.md).
    PyBullet at seed 1: at seed 0 its fourth hand-over finds no giver grip and the trial ends
    `unreachable` (docs/herb_push_grasp.md, "The free hand checked against the cube"; seeds 1, 2, 4
    complete the tier there).
    """
    trials = _run_cli(tmp_path, "Rubiks-1-5", backend, seed)
    assert len(trials) == 1
    trial = trials[0]
    assert trial["status"] == "success", trial
    assert (
        trial["diagnostics_counts"]["move"] == 5
        and trial["diagnostics_counts"]["unintended_rotation"] == 0
    )


@pytest.mark.slow
@pytest.mark.parametrize(
    ("task", "backend", "least"),
    [
        ("Rubiks-1-10", "sapien", 1),
        ("Rubiks-1-20", "sapien", 1),
        ("Rubiks-1-20", "pybullet", 1),
        ("Rubiks-5-5", "sapien", 5),
        ("Rubiks-5-5", "pybullet", 5),
    ],
)
def test_longer_tiers_complete_at_least_as_measured(tmp_path, task, backend, least):
    """Longer tiers through `benchharness run` (seed 0): at least as many trials succeed as last measured
    (docs/herb_push_grasp.md, "The free hand checked against the cube", AMD VM), every success with all
    its moves as intended. Issue 15's targets are the Rubiks-1-20 and 5-5 rows; PyBullet Rubiks-1-10 is
    not here: it ends `wrong_state` at seed 0 on this VM (it completed on the Intel VM).

    Trials are deterministic for a given code version; a change that completes fewer is a regression
    to explain, one that completes more should raise these figures.
    """
    trials = _run_cli(tmp_path, task, backend)
    ok = [t for t in trials if t["status"] == "success"]
    assert len(ok) >= least, [(t["status"], t["failure_cause"], t["message"]) for t in trials]
    moves = int(task.split("-")[2])
    assert all(
        t["diagnostics_counts"]["move"] == moves
        and t["diagnostics_counts"].get("unintended_rotation", 0) == 0
        for t in ok
    )


@pytest.mark.slow
def test_a_turn_with_no_smooth_grip_on_a_tilted_belief_is_levelled(tmp_path):
    """SAPIEN Rubiks-1-100 seed 0 (~1 min): at 256.3 s, after 3 moves, the left giver's +90 deg turn about
    z found no smooth grip, from the arm's branch or backwards (``giver_posture`` chains 0) on a believed
    cube 6.3 deg off faces-level; the least bad grip's turn ended 16.6 mm from its target and the trial
    ended `unreachable` at 276.14 s (before ``level_stuck_turns``). Now the choice is made again with that
    turn levelled: backward chains are found, the turn is made, the cube is given and twisted on. Run to
    the 12th action (three more twists). Measured on the Intel platform of test_pr2_rubiks_sim.py's
    reference rows; on another CPU the trajectory differs from the first differing bit and this turn may
    never be met, so the test runs only there."""
    import json
    import sqlite3

    from test_pr2_rubiks_sim import REFERENCE_ROWS, platform_key

    intel = [k for k in REFERENCE_ROWS if k.startswith("Intel(R) Xeon(R) Processor")]
    if platform_key() not in intel:
        pytest.skip(f"measured on {intel[0]!r}")
    store = tmp_path / "runs.sqlite"
    cmd = [sys.executable, "-m", "benchharness", "run", "--task", "Rubiks-1-100", "--robot", "herb"]
    cmd += ["--strategy", "push-grasp", "--backend", "sapien", "--seed", "0", "--workers", "0"]
    cmd += ["--strategy-option", "max_actions=16", "--store", str(store)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    rows = sqlite3.connect(store).execute("select failure_cause, diagnostics_json from trials")
    rows = rows.fetchall()
    assert len(rows) == 1, proc.stderr[-2000:]
    cause, diag = rows[0]
    events = json.loads(diag)["events"]
    levelled = [e for e in events if e["kind"] == "turn_levelled"]
    assert len(levelled) == 1 and levelled[0]["hand"] == "left", levelled
    assert levelled[0]["tilt_deg"] == pytest.approx(6.27, abs=0.01)
    after = events[events.index(levelled[0]) + 1 :]
    postures = [e for e in after if e["kind"] == "giver_posture"]
    assert postures and postures[0]["chains"] > 0
    assert any(e["kind"] == "check" and e["label"] == "hand-over given" for e in after)
    moves = [e for e in events if e["kind"] == "move"]
    assert len(moves) >= 5 and all(m["as_intended"] for m in moves), moves
    assert cause != "unreachable"
    assert any(e["kind"] == "stopped" for e in events)


def test_hand_points_fill_the_pre_shaped_hand_where_an_independent_fk_puts_it(
    make_backend, make_robot
):
    """HERB's ``hand_points`` (the machine's sweep checks keep them off the cube): read from the engine's
    link poses at the hand's joints, each part's points must lie in that part's collision shape where
    yourdfpy's FK of the same URDF and joint readings puts it relative to the tool frame, and the
    flexed thumb must be among them (the part that struck the held cube, docs/herb_push_grasp.md)."""
    from types import SimpleNamespace

    import yourdfpy

    from benchharness.robots.descriptions.herb import DIST_BOX, PALM_CYLINDER, PROX_BOX
    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.herb_rubiks.frames import (
        DIST_FILL,
        PALM_FILL,
        PROX_FILL,
        thumb_face_depth,
    )
    from benchharness.strategies.herb_rubiks.push import preshape
    from benchharness.strategies.herb_rubiks.strategy import PushGrasp

    be = make_backend("pybullet")
    robot = make_robot("herb")
    robot.spawn(be)
    arm, hand = robot.arm("right_arm"), robot.hand("right_hand")
    cfg = HerbPushGraspConfig()
    preshape(hand, cfg.spread, cfg.rotator_thumb_flex, outer_flex=cfg.outer_open_flex)
    points = PushGrasp(cfg).hand_points(
        SimpleNamespace(b=be, robot=robot), SimpleNamespace(arm=arm)
    )

    urdf = yourdfpy.URDF.load(
        str(robot.urdf_path), load_meshes=False, build_collision_scene_graph=False
    )
    q = robot.joint_positions()
    urdf.update_cfg(dict(zip(robot.joint_names, q)))
    tool = urdf.get_transform("r_bh_tcp", urdf.base_link)
    parts = [("r_bh_palm_link", PALM_FILL)] + [
        (f"r_bh_finger_{f}{n}_link", PROX_FILL if n == 2 else DIST_FILL)
        for f in (1, 2, 3)
        for n in (2, 3)
    ]
    assert len(points) == sum(len(fill) for _, fill in parts)
    start = 0
    for name, fill in parts:
        own = points[start : start + len(fill)]
        start += len(fill)
        link = np.linalg.inv(urdf.get_transform(name, urdf.base_link)) @ tool
        local = own @ link[:3, :3].T + link[:3, 3]  # the part's points in its own link frame (FK)
        if name.endswith("palm_link"):
            (radius, length), centre = PALM_CYLINDER
            d = local - np.asarray(centre)
            assert np.all(np.hypot(d[:, 0], d[:, 1]) <= radius + 1e-3), name
            assert np.all(np.abs(d[:, 2]) <= length / 2 + 1e-3), name
        else:
            size, centre = PROX_BOX if name.endswith("2_link") else DIST_BOX
            assert np.all(np.abs(local - np.asarray(centre)) <= np.asarray(size) / 2 + 1e-3), name
    # the pre-shaped thumb's distal box reaches as far along the approach (tool z) as the push expects the
    # face (its ``face_depth``, from the same link's engine pose), past the tool frame; the open outer
    # fingers reach farther still (62.8 mm against the thumb's 35.9 mm here)
    thumb_distal = points[-len(DIST_FILL) :]
    reach = float(np.max(thumb_distal[:, 2]))
    distal = be.get_link_pose(robot.body, "r_bh_finger_33_link")
    assert reach > 0.0
    assert reach == pytest.approx(thumb_face_depth(arm.tcp_pose(), distal), abs=1e-6)


#: PyBullet Rubiks-1-20 seed 1 before HERB's hand was checked (fb9ed1c), t = 259.06 s: the right arm's
#: measured joints as it left for its give grip's stand-off, the joints it ended at, its hand's pre-shape
#: (r_bh_j11, j21, j12, j13, j22, j23, j32, j33) and the belief (centre, quaternion xyzw). On the way its
#: thumb struck the cube the left hand held (93 N) and turned it 70 deg (docs/herb_push_grasp.md).
SWEEP_Q_START = np.array([1.5619, -0.7167, 0.7291, 1.9214, -0.9674, 0.8254, -0.2463])
SWEEP_Q_END = np.array([-1.1453, 0.4666, -2.0407, 1.8251, -4.3345, -1.6, 0.0234])
SWEEP_FINGERS = np.array([1.5701, 1.5698, 1.0475, 0.3365, 1.0476, 0.3365, 1.7506, 0.562])
SWEEP_BELIEF = Pose([0.9, -0.0015, 1.1002], [0.53941, 0.45476, -0.52702, -0.47381])


def test_the_stand_off_move_that_struck_the_held_cube_is_not_clear(make_backend, make_robot):
    """The machine's sweep check with HERB's hand points refuses that move (its joint path), and the
    engine, independently, finds a right-hand link inside a cube placed at the belief along the same path
    while neither end touches it."""
    from benchharness.strategies.bimanual.machine import Hand
    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.herb_rubiks.strategy import PushGraspStrategy

    be = make_backend("pybullet")
    robot = make_robot("herb")
    robot.spawn(be)
    arm, gripper = robot.arm("right_arm"), robot.hand("right_hand")
    be.set_joint_positions(robot.body, SWEEP_FINGERS, joints=list(gripper.joints))
    be.set_joint_positions(robot.body, SWEEP_Q_START, joints=list(arm.joints))
    cube = be.add_body([Box((CUBE_HALF,) * 3)], SWEEP_BELIEF, 0.094, fixed=True, name="cube")
    machine = PushGraspStrategy(HerbPushGraspConfig())
    machine.b, machine.robot, machine.est = be, robot, SWEEP_BELIEF
    hand = Hand("right", arm, gripper, Pose(np.zeros(3)), arm.tcp_pose())

    points = machine._hand_points(hand)
    assert points is not None
    assert machine.sweep_clearance(hand, SWEEP_Q_START, SWEEP_Q_START, points, n=1) > 0.02
    assert not machine._clears(hand, SWEEP_Q_START, SWEEP_Q_END, points)

    def touching(q: np.ndarray) -> set[str]:
        be.set_joint_positions(robot.body, q, joints=list(arm.joints))
        be.set_joint_positions(robot.body, SWEEP_FINGERS, joints=list(gripper.joints))
        be.step(1)
        return {c.link_a for c in be.contacts(robot.body, cube) if c.link_a}

    path = [SWEEP_Q_START + t * (SWEEP_Q_END - SWEEP_Q_START) for t in np.linspace(0.0, 1.0, 33)]
    hits = [touching(q) for q in path]
    assert not hits[0] and not hits[-1]
    assert any(h & {"r_bh_finger_32_link", "r_bh_finger_33_link"} for h in hits), hits
