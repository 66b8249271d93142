"""One-hand holds that hold (issue 16, item 2): a cube held by one PR2 gripper must not turn in that grip
while the other hand closes on it, twists a layer and lets go.

The scene is the start of a real trial, scripted by the plan of the one-move sequence ``R`` with zero
injected error: the picker lifts the cube to the twisting pose and holds it alone, two slabs deep; the
other hand comes in, closes on the far slab (the two-stage close), twists it a quarter turn, opens and
backs off. From the moment the second hand starts its approach, the cube's orientation relative to the
holder's tool frame is read after every physics step from the backend (the true poses, which control
never reads) and must stay within 2 degrees of where it started.

Both finger relations the PR2 uses are covered: ``parallel`` (the second hand pinches the same pair of
faces) and ``crossing`` (its fingers at right angles to the holder's, as in shifts and hand-over takes:
there the closing fingers are vertical and a push at the far slab turns the cube about the holder's pad
axis). docs/strategies.md, "One-hand holds", has the measurements and what was changed.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

pytestmark = pytest.mark.sim

BACKENDS = ("pybullet", "sapien")
LIMIT_DEG = 2.0
#: steps within this long after the cube swaps between its rigid body and its three slabs are not traced:
#: ``end_twist`` turns the new rigid body by the mean snap residual about the twist axis by design
#: (cube_physics.mechanism, ``_snap_and_swap_to_rigid``), and the pads push it back within ~30 ms
#: (measured, PyBullet: one step at 2.3 deg, 0.4 deg 30 ms later); what the grip holds is traced after.
SWAP_TRANSIENT_S = 0.05


#: the second (right) hand's error as a calibration (position m, rotation vector deg, world): none; turned
#: 2 deg about the holder's pad axis (world x); 3 mm off along its own fingers (world z when crossing).
#: The default error sources put each arm 0.5 deg (1 sigma per axis) and 1.5 mm off and the belief a few
#: mm / degrees off (docs/strategies.md, "Error sources"): a closing hand is never exactly square.
ERRORS = {
    "exact": ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
    "turned 2 deg": ((0.0, 0.0, 0.0), (2.0, 0.0, 0.0)),
    "3 mm off": ((0.0, 0.0, 0.003), (0.0, 0.0, 0.0)),
}


def hold_scene(make_ctx, backend: str, finger_preference: str, error: str = "exact"):
    """Run pick + twist of ``R`` and trace the held cube; returns (outcome, strategy, trace, holder side).

    ``trace``: (sim time, degrees the cube turned relative to the lone holder's tool frame since the
    second hand's pre-grasp began) after every physics step from then to the end of the rotator's retreat,
    but the ``SWAP_TRANSIENT_S`` after each rigid <-> slabs swap.
    """
    from scipy.spatial.transform import Rotation

    from benchharness.geometry import Pose
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig
    from benchharness.strategies.pr2_rubiks.strategy import DeadReckoningStrategy

    ctx, b = make_ctx(backend, "R")
    cfg = replace(
        PR2RubiksConfig().zero_error(), max_actions=2, finger_preference=finger_preference
    )
    st = DeadReckoningStrategy(cfg)
    trace: list[tuple[float, float]] = []
    state: dict = {}
    dp, dr = ERRORS[error]
    camera = st._camera_estimate

    def camera_and_error(c):  # runs once, after the hands exist and before anything moves
        st.hands["right"].calibration = Pose.from_rotation(
            np.array(dp), Rotation.from_rotvec(np.radians(dr))
        )
        return camera(c)

    st._camera_estimate = camera_and_error  # type: ignore[method-assign]

    def relative():
        tcp = b.get_link_pose(st.robot.body, st.hands[state["holder"]].arm.config.tcp_link)
        return (
            tcp.rotation.inv() * st.cube.pose().rotation
        )  # the true pose (the middle slab in a twist)

    def after_step() -> None:
        if st.cube.body != state.get("body"):  # a rigid <-> slabs swap (begin_twist / end_twist)
            state["body"], state["swapped"] = st.cube.body, b.time
        if b.time - state["swapped"] < SWAP_TRANSIENT_S:
            return
        turned = (state["ref"].inv() * relative()).magnitude()
        trace.append((b.time, math.degrees(turned)))

    send = st.send

    def traced_send(hand, target, **kw):
        if "ref" not in state and str(kw.get("label", "")).startswith("second grasp"):
            holding = [s for s, h in st.hands.items() if h.holding]
            assert holding == [st.other(hand).side] == ["left"], holding  # the picker holds alone
            state["holder"] = holding[0]
            state["ref"] = relative()
            state["body"], state["swapped"] = st.cube.body, -1.0
            state["cb"] = b.add_step_callback(after_step)
        return send(hand, target, **kw)

    st.send = traced_send  # type: ignore[method-assign]
    out = st.run_trial(ctx)
    return out, st, trace, state.get("holder")


CASES = [
    ("parallel", "exact"),
    ("crossing", "exact"),
    ("crossing", "turned 2 deg"),  # before issue 16: SAPIEN 2.62 deg
    ("crossing", "3 mm off"),  # before issue 16: PyBullet 2.76 deg
]


@pytest.mark.parametrize(("finger_preference", "error"), CASES)
@pytest.mark.parametrize("backend", BACKENDS)
def test_cube_held_by_one_gripper_turns_less_than_2_degrees(
    make_ctx, backend, finger_preference, error
):
    """2-12 s a case: the held cube turns < 2 deg over the other hand's close, twist and let-go."""
    out, st, trace, holder = hold_scene(make_ctx, backend, finger_preference, error)
    assert out.failure is None, out.message
    events = st.ctx.recorder.events
    # the scene did what it claims: the second hand gripped (crossing or parallel as asked), the twist
    # turned its layer as intended, and the rotator let go and backed off (the holder still holds)
    checks = [e for e in events if e["kind"] == "check" and e["label"] == "second grasp"]
    assert len(checks) == 1
    holder_fingers = st.hands[holder].cmd.rotation.apply([0.0, 1.0, 0.0])
    assert abs(holder_fingers[0]) > 0.99  # the holder's pad axis is world x (ERRORS turns about it)
    dot = abs(float(np.dot(checks[0]["fingers"], holder_fingers)))
    assert dot > 0.9 if finger_preference == "parallel" else dot < 0.1, (dot, checks[0])
    moves = [e for e in events if e["kind"] == "move"]
    assert len(moves) == 1 and moves[0]["as_intended"], moves
    rotator = st.other(st.hands[holder])
    assert st.hands[holder].holding and not rotator.holding
    assert not rotator.gripper.touching(st.cube.body)
    assert len(trace) > 500  # approach, close, twist, open and retreat were all traced
    worst_t, worst = max(trace, key=lambda r: r[1])
    print(
        f"{backend}/{finger_preference}/{error}: worst turn {worst:.2f} deg at t = {worst_t:.2f} s"
    )
    assert worst < LIMIT_DEG, (
        f"{backend}/{finger_preference}/{error}: the cube held by the {holder} gripper turned {worst:.2f} deg "
        f"in its grip (t = {worst_t:.2f} s)"
    )


@pytest.mark.slow
def test_shift_in_stand_off_detours_round_the_held_cube(tmp_path):
    """PyBullet Rubiks-5-5 sensor-aided seed 0, trial 5 (~40 s wall): the right hand's move to its shift-in
    stand-off was a joint-space branch change that swept the open fingertip into the cube held by the left
    (32 deg, then wrong_state). Now it detours and the trial ends in the expected state."""
    import json
    import sqlite3
    import subprocess
    import sys

    store = tmp_path / "runs.sqlite"
    cmd = [
        sys.executable,
        "-m",
        "benchharness.cli.main",
        "run",
        "--task",
        "Rubiks-5-5",
        "--robot",
        "pr2",
        "--strategy",
        "sensor-aided",
        "--backend",
        "pybullet",
        "--seed",
        "0",
        "--trials",
        "5",
        "--workers",
        "0",
        "--store",
        str(store),
    ]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    rows = sqlite3.connect(store).execute("select status, diagnostics_json from trials").fetchall()
    assert len(rows) == 1, proc.stderr[-2000:]
    status, diag = rows[0]
    events = json.loads(diag)["events"]
    assert any(e["kind"] == "detour" and e["label"] == "shift in stand-off" for e in events)
    assert status == "success"


#: a lone hold left alone: settling after the rotator's release, then how long it is watched, and how far
#: the cube may move in the grip meanwhile. Measured over 60 s on PyBullet (2026-12-02, this scene): the
#: cube settles 0.3 mm / 0.4 deg in the first seconds after the release, then wanders with the arm's
#: servo jitter (the tool frame +-0.5 mm in the world) within 0.45 mm / 0.42 deg of where it started,
#: with no trend; SAPIEN 0.000. A slip is not that: the one seen on the earlier VM sank the cube 43 mm.
STILL_SETTLE_S, STILL_HOLD_S = 2.0, 10.0
STILL_LIMIT_MM, STILL_LIMIT_DEG = 1.0, 1.0


@pytest.mark.parametrize("backend", BACKENDS)
def test_cube_held_by_one_gripper_stays_put_while_nothing_moves(make_ctx, backend):
    """A lone hold does not creep: after the scene above the holder keeps the cube alone; 2 s after the
    release and over 10 s more nothing moves, and the cube, 94 g against ~20 N a pad (static friction 1),
    must stay within 1 mm and 1 deg of where it was in the holder's tool frame. On the earlier development VM a cube held
    alone this way sank 4.3 cm in ~10 s of PyBullet Rubiks-1-100 while the other hand detoured
    (docs/strategies.md, "Edge of reach"); this is that hold without the rest of the trial."""
    out, st, _, holder = hold_scene(make_ctx, backend, "parallel")
    assert out.failure is None, out.message
    b = st.b
    hand = st.hands[holder]
    assert hand.holding and not st.other(hand).holding

    def in_tool():
        tcp = hand.arm.tcp_pose()
        cube = st.cube.pose()
        return tcp.rotation.inv().apply(cube.p - tcp.p), tcp.rotation.inv() * cube.rotation

    b.step(round(STILL_SETTLE_S / b.config.timestep))
    p0, r0 = in_tool()
    b.step(round(STILL_HOLD_S / b.config.timestep))
    p1, r1 = in_tool()
    moved_mm = 1000 * float(np.linalg.norm(p1 - p0))
    turned_deg = math.degrees((r0.inv() * r1).magnitude())
    print(f"{backend}: lone hold, {STILL_HOLD_S:.0f} s: {moved_mm:.3f} mm, {turned_deg:.3f} deg")
    assert hand.gripper.touching(st.cube.body)
    assert moved_mm < STILL_LIMIT_MM and turned_deg < STILL_LIMIT_DEG, (moved_mm, turned_deg)
