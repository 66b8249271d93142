"""The bimanual machine at the edge of an arm's reach (issue 16): a move whose IK does not converge is not
made, and a grip's stand-off keeps a margin for the injected errors (docs/strategies.md, "Edge of reach")."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.geometry import Pose


class _Rec:
    def __init__(self):
        self.events = []

    def event(self, kind, **data):
        self.events.append((kind, data))


@pytest.mark.sim
@pytest.mark.parametrize("skip", [False, True], ids=["fails", "skipped"])
def test_send_out_of_reach_fails_without_moving_the_arm(make_ctx, skip):
    """The PR2's left arm nearly straight (elbow flex 10 mrad from its limit), sent 2 mm farther out from
    the shoulder than its tool frame is: no IK solution. The IK's best attempt is a restart on another
    branch (the upper-arm and forearm rolls ~2.7 rad away, as measured in SAPIEN Rubiks-5-20 trial 5),
    to which the arm used to move before the failure was raised; now the send fails `unreachable`, the
    joints and the forward kinematics' tool frame stay where they were and the command is not taken.
    With ``skip_unreached`` (a swing's arc waypoint, which the swing leaves out) the send returns False
    instead of failing, and likewise moves nothing."""
    from benchharness.strategies.bimanual.machine import Hand, StrategyFailure
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig
    from benchharness.strategies.pr2_rubiks.strategy import SensorAidedStrategy

    ctx, b = make_ctx("pybullet")
    b.add_ground()
    robot = ctx.robot
    robot.spawn(b)
    m = SensorAidedStrategy(PR2RubiksConfig().zero_error())
    m.ctx, m.b, m.robot = ctx, b, robot
    arm = robot.arm("left_arm")
    q0 = np.array([0.3, 0.2, 0.5, arm.upper[3] - 0.01, 0.3, -0.5, 0.0])
    arm.move_to_joints(q0, duration=2.0, settle=0.5)
    m.hands = {
        side: Hand(
            side,
            robot.arm(f"{side}_arm"),
            robot.gripper(f"{side}_gripper"),
            Pose(np.zeros(3)),
            robot.arm(f"{side}_arm").tcp_pose(),
        )
        for side in ("left", "right")
    }
    hand = m.hands["left"]
    q_before, tcp = arm.positions(), arm.tcp_pose()
    shoulder = arm.base_pose().apply(arm.joint_origins(q_before[None])[0][1])
    out = (tcp.p - shoulder) / np.linalg.norm(tcp.p - shoulder)
    target = Pose(tcp.p + 0.002 * out, tcp.q)
    # independently of the machine: no solution, and the IK's best attempt is on another branch
    res = arm.ik((arm.base_pose().inv() * target).as_matrix()[None], seed_q=q_before)
    assert not res.success[0]
    assert np.max(np.abs(res.q[0] - q_before)) > 2.0
    if skip:
        assert m.send(hand, target, label="test", skip_unreached=True) is False
    else:
        with pytest.raises(StrategyFailure, match="not moved") as err:
            m.send(hand, target, label="test")
        assert err.value.cause == "unreachable"
    assert np.max(np.abs(arm.positions() - q_before)) < 0.01
    fk = arm.base_pose() * Pose.from_matrix(arm.chain.fk(arm.positions()[None])[0])
    assert np.linalg.norm(fk.p - tcp.p) < 2e-3
    assert hand.cmd.allclose(tcp, 1e-12, 1e-12)


class _SphereArm:
    """IK that succeeds where the tool frame lies within ``reach`` of a shoulder point (no orientation)."""

    def __init__(self, shoulder, reach):
        self.shoulder, self.reach = np.asarray(shoulder, dtype=float), reach
        self.calls = 0

    def base_pose(self):
        return Pose(np.zeros(3))

    def positions(self):
        return np.zeros(7)

    def ik(self, mats, seed_q=None):
        self.calls += 1
        p = np.asarray(mats)[:, :3, 3]
        ok = np.linalg.norm(p - self.shoulder, axis=1) <= self.reach
        return SimpleNamespace(success=ok, q=np.zeros((len(mats), 7)))


def _machine(**cfg):
    from dataclasses import replace

    from benchharness.strategies.bimanual.machine import Hand
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig
    from benchharness.strategies.pr2_rubiks.strategy import SensorAidedStrategy

    m = SensorAidedStrategy(replace(PR2RubiksConfig(), **cfg))
    m.ctx = SimpleNamespace(recorder=_Rec())
    # the left hand grips the cube at the origin from +y: tool x (the approach) along -y
    grip = Pose.from_rotation([0.0, 0.03, 0.0], Rotation.from_euler("z", -90, degrees=True))
    shoulder = np.array([0.0, -0.40, 0.0])
    return m, Hand, grip, shoulder


def test_standoff_comes_in_until_reachable_with_the_injected_errors_margin():
    """A shoulder 40 cm beyond the cube on the approach line, the stand-off ``far_distance`` (15 cm)
    back on the other side: reachable; moved 3 sigma of the injected position error (calibration and
    tracking) either way along the world axes it is not for a reach just past it, so the stand-off comes
    in 2 cm at a time to the farthest whose whole margin box (computed here from the sphere) is in reach."""
    m, Hand, grip, shoulder = _machine()
    cfg, err = m.config, m.config.errors
    assert grip.rotation.apply([1.0, 0.0, 0.0]) == pytest.approx([0.0, -1.0, 0.0])
    margin = 3.0 * np.hypot(err.calib_pos_std, err.tracking_std)
    far = m.back_off(grip, cfg.far_distance)
    assert far.p == pytest.approx([0.0, 0.18, 0.0])

    def box_in_reach(p, reach):
        # the farthest corner of the margin's +-axis moves from the shoulder: along the shoulder line
        return all(
            np.linalg.norm(p + s * margin * a - shoulder) <= reach
            for a in np.eye(3)
            for s in (1, -1)
        )

    # reach: the 15 cm stand-off itself is in reach, its margin box is not (it pokes 5.4 mm farther)
    reach = float(np.linalg.norm(far.p - shoulder)) + 0.002
    arm = _SphereArm(shoulder, reach)
    hand = Hand("left", arm, None, Pose(np.zeros(3)), grip)
    got = m.standoff(hand, grip, np.zeros(7), "t")
    d = float(np.linalg.norm(got.p - grip.p))
    assert got.q == pytest.approx(grip.q)
    expect = next(
        x
        for x in np.arange(cfg.far_distance, cfg.retreat_distance - 1e-9, -0.02)
        if box_in_reach(m.back_off(grip, x).p, reach)
    )
    assert d == pytest.approx(expect) and d < cfg.far_distance
    assert m.ctx.recorder.events[-1] == (
        "standoff",
        {"hand": "left", "label": "t", "distance_m": round(expect, 3)},
    )
    # the old stand-off (no margin) is what the arm reaches for the believed pose alone
    m0, Hand, grip, shoulder = _machine(reach_sigmas=None)
    hand0 = Hand("left", _SphereArm(shoulder, reach), None, Pose(np.zeros(3)), grip)
    assert m0.standoff(hand0, grip, np.zeros(7), "t").p == pytest.approx(far.p)
    # zero injected error: the margin is 0 and the 15 cm stand-off is kept
    mz, Hand, grip, shoulder = _machine()
    mz = type(mz)(mz.config.zero_error())
    mz.ctx = SimpleNamespace(recorder=_Rec())
    hz = Hand("left", _SphereArm(shoulder, reach), None, Pose(np.zeros(3)), grip)
    assert mz.reach_margin() == (0.0, 0.0)
    assert mz.standoff(hz, grip, np.zeros(7), "t").p == pytest.approx(far.p)
    assert mz.ctx.recorder.events == []


def test_retreat_steps_stop_where_the_injected_errors_margin_leaves_the_reach():
    """A retreat's steps (``_chain``, as ``release_hand``'s side route makes them) backing away from the
    shoulder: each step's own IK succeeds up to the sphere, but a step whose 3-sigma margin box (computed
    here) pokes out of it fails, and the chain stops at the last step before; without ``reach_sigmas``
    every step the believed target reaches is taken."""
    m, Hand, grip, shoulder = _machine()
    err = m.config.errors
    margin = 3.0 * np.hypot(err.calib_pos_std, err.tracking_std)
    steps = [m.back_off(grip, 0.02 * (i + 1)) for i in range(6)]  # y = 0.05 .. 0.15, away from it
    # the 4th step (y = 0.11, 0.51 m from the shoulder) in reach, its margin box not
    reach = float(np.linalg.norm(steps[3].p - shoulder)) + 0.002
    for cfg, expect in (({}, 3), ({"reach_sigmas": None}, 4)):
        # no FK model here: neither the sweep check nor the arm check is what is tested
        m, Hand, grip, shoulder = _machine(arm_check=False, **cfg)
        m._clears = lambda *a: True
        hand = Hand("left", _SphereArm(shoulder, reach), None, Pose(np.zeros(3)), grip)
        out, _, _ = m._chain(hand, np.zeros(7), steps, "retreat step", np.zeros((1, 3)), True)
        assert len(out) == expect
        in_box = [
            all(
                np.linalg.norm(s.p + k * margin * a - shoulder) <= reach
                for a in np.eye(3)
                for k in (1, -1)
            )
            for s in steps
        ]
        if cfg:
            assert in_box[:3] == [True] * 3  # the margin is not what stops the old chain
        else:
            assert in_box[:4] == [True, True, True, False]


class _RecordingArm:
    """IK that succeeds everywhere (joints at zero) and keeps every target it was asked for."""

    lower = np.full(7, -1.0)
    upper = np.full(7, 1.0)

    def __init__(self):
        self.targets = []

    def base_pose(self):
        return Pose(np.zeros(3))

    def positions(self):
        return np.zeros(7)

    def ik(self, mats, seed_q=None):
        self.targets += list(np.asarray(mats))
        return SimpleNamespace(success=np.ones(len(mats), dtype=bool), q=np.zeros((len(mats), 7)))


def _faces_level_offset(rotation):
    """Angle (rad) from ``rotation`` to the nearest of the 24 axis-aligned rotations, computed here."""
    group = Rotation.create_group("O")
    return float(np.min((group * rotation.inv()).magnitude()))


def test_handover_turn_brings_a_tilted_believed_cube_back_to_faces_level():
    """``recentre_tilt`` (the PR2's): a believed cube 7 deg off faces-level and 2 cm from the twisting pose
    ends the hand-over turn faces-level (to 1e-9 rad) with its centre at ``twist_position``, the level
    correction i/n of the way at waypoint i; ``turn_travel`` and ``turn_postures`` ask the IK for those
    very waypoints. A faces-level belief, or ``recentre_tilt`` off (HERB's), gives exactly the old turn:
    about the centre, shifted back to ``twist_position``."""
    from benchharness.strategies.bimanual.frames import rotate_about_point
    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig

    assert not HerbPushGraspConfig().recentre_tilt
    m, Hand, grip, _ = _machine()
    assert m.config.recentre_tilt and m.config.recentre_turn
    twist = np.asarray(m.config.twist_position)
    tilt = Rotation.from_euler("xyz", [5.0, -4.0, 3.0], degrees=True)
    m.est = Pose.from_rotation(
        twist + [0.01, -0.015, 0.008], tilt * Rotation.from_euler("z", -90, degrees=True)
    )
    assert np.degrees(_faces_level_offset(m.est.rotation)) > 7.0
    grip = m.est * Pose.from_rotation([0.0, 0.03, 0.0], Rotation.from_euler("z", -90, degrees=True))
    in_grip = grip.inv() * m.est  # the cube in the tool frame, held rigidly
    for axis, angle in (("x", -math.pi / 2), ("z", math.pi / 2), ("x", math.pi)):
        path = m.turn_path(axis, angle)
        n = 8
        cube = [path.at(grip, i, n) * in_grip for i in range(n + 1)]
        assert _faces_level_offset(cube[-1].rotation) < 1e-9
        assert cube[-1].p == pytest.approx(twist, abs=1e-12)
        turn = Rotation.from_rotvec(np.eye(3)["xyz".index(axis)] * angle)
        # the correction is the smallest one (the belief's offset from faces-level), spread evenly: i/n
        # of its rotation vector at waypoint i
        v = (cube[-1].rotation * (turn * m.est.rotation).inv()).as_rotvec()
        assert np.linalg.norm(v) == pytest.approx(_faces_level_offset(m.est.rotation), abs=1e-9)
        for i in range(n + 1):
            turn_i = Rotation.from_rotvec(np.eye(3)["xyz".index(axis)] * angle * i / n)
            want = Rotation.from_rotvec(v * i / n) * turn_i * m.est.rotation
            assert (cube[i].rotation * want.inv()).magnitude() < 1e-9
            assert cube[i].p == pytest.approx(m.est.p + (twist - m.est.p) * i / n, abs=1e-12)

    # turn_travel and turn_postures plan those waypoints
    path, n = m.turn_path("x", -math.pi / 2), m.config.handover_waypoints
    arm = _RecordingArm()
    hand = Hand("left", arm, None, Pose(np.zeros(3)), grip)
    m.turn_travel(hand, Pose(np.zeros(3)), [grip], np.zeros((1, 7)), "x", -math.pi / 2, False)
    assert len(arm.targets) == n
    for i, t in enumerate(arm.targets, start=1):
        assert np.array_equal(t, path.at(grip, i, n).as_matrix())
    arm.targets.clear()
    m._hand_points = lambda hand: None
    m.plan_rng = np.random.default_rng(0)
    m.turn_postures(hand, Pose(np.zeros(3)), [grip], "x", -math.pi / 2, n_seeds=1)
    for i in range(n + 1):
        want = path.at(grip, i, n).as_matrix()
        assert any(np.array_equal(t, want) for t in arm.targets)

    # no tilt to take out, or the option off: exactly the old turn
    def old(pose, est, axis, angle, i, n):  # the turn before recentre_tilt, as _handover made it
        turned = rotate_about_point(pose, est.p, axis, angle * i / n)
        return Pose(turned.p + (twist - est.p) * (i / n), turned.q)

    tilted = m.est
    level = Pose.from_rotation(tilted.p, Rotation.identity())
    for mm, est in ((m, level), (_machine(recentre_tilt=False)[0], tilted)):
        mm.est = est
        path = mm.turn_path("z", math.pi / 2)
        assert not np.any(path.level)
        for i in range(5):
            got, want = path.at(grip, i, 4), old(grip, est, "z", math.pi / 2, i, 4)
            assert np.array_equal(got.p, want.p) and np.array_equal(got.q, want.q)


def test_a_stuck_turn_is_levelled_once_and_only_where_no_turn_is_levelled_already():
    """``level_stuck_turns`` (HERB's): a giver's choice that found no smooth turn on a believed cube 6.3 deg
    off faces-level (the belief SAPIEN Rubiks-1-100 seed 0 had at its failed turn) asks for the choice
    again with that turn levelled: ``turn_path`` then ends faces-level (the offset computed here from the
    24-rotation group, to 1e-9 rad) and a ``turn_levelled`` event says by how much. It is asked once per
    hand-over; a faces-level belief, the option off, or every turn levelled already (the PR2's
    ``recentre_tilt``) leave the turn as it was and say no."""
    from dataclasses import replace

    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.herb_rubiks.strategy import PushGraspStrategy

    def herb(**cfg):
        m = PushGraspStrategy(replace(HerbPushGraspConfig(), **cfg))
        m.ctx = SimpleNamespace(recorder=_Rec())
        return m

    belief = Rotation.from_quat([-0.69983, -0.03688, -0.71226, -0.03947])
    assert np.degrees(_faces_level_offset(belief)) == pytest.approx(6.27, abs=0.01)
    twist = np.asarray(HerbPushGraspConfig().twist_position)
    est = Pose.from_rotation(twist + [0.0, 0.0032, -0.0004], belief)
    grip = est * Pose.from_rotation([0.0, 0.0, 0.087], Rotation.from_euler("y", 180, degrees=True))
    in_grip = grip.inv() * est
    hand = SimpleNamespace(side="left")

    m = herb()
    assert m.config.level_stuck_turns and not m.config.recentre_tilt
    m.est = est
    assert not np.any(m.turn_path("z", math.pi / 2).level)  # not levelled before it is asked
    assert m.level_stuck_turn(hand)
    assert m.ctx.recorder.events == [("turn_levelled", {"hand": "left", "tilt_deg": 6.27})]
    end = m.turn_path("z", math.pi / 2).at(grip, 4, 4) * in_grip
    assert _faces_level_offset(end.rotation) < 1e-9
    assert not m.level_stuck_turn(hand)  # once a hand-over
    assert len(m.ctx.recorder.events) == 1

    for mm, e in (
        (herb(), Pose.from_rotation(est.p, Rotation.from_euler("z", -90, degrees=True))),
        (herb(level_stuck_turns=False), est),
        (herb(recentre_tilt=True), est),
    ):
        mm.est = e
        assert not mm.level_stuck_turn(hand)
        assert not mm.level_turn and mm.ctx.recorder.events == []


#: the inputs of one checked swing, recorded (PyBullet Rubiks-5-5 seed 0 trial 3, t = 244.47 s, at 152efdd:
#: the right hand's hand-over re-grip): the arm's joints, its commanded tool pose, the stand-off, the
#: believed cube, the arm's base (world) and the trial's injected calibration of that arm (SAPIEN's trial 3
#: draws the same one), poses as (position, quaternion x y z w)
_SWING_244 = {
    "q": [
        -0.6003719538755002,
        -1.476589878755763,
        0.4445584287956909,
        2.8763725650208563,
        0.5073098221183098,
        -1.4341462978004618,
        2.074535486213225,
    ],
    "cmd": (
        [0.7181065893332236, 0.008234905864029491, 1.0957784402133681],
        [-0.6984415545011888, 0.02428777439329527, -0.7152155550426016, -0.007497251902313817],
    ),
    "far": (
        [0.891069105396176, -0.19975492826495925, 1.0951458343885732],
        [-0.007505512877098108, -0.6984332935264046, -0.7152238160173858, -0.024279513418510867],
    ),
    "est": (
        [0.8998833869490701, -0.002608252885807271, 1.0999366178768446],
        [0.7152155550426016, -0.00749725190231386, -0.6984415545011888, -0.024287774393295155],
    ),
    "base": (
        [0.0053783804178237915, -0.05080476403236389, 0.6925790309906006],
        [0.7070903591565018, 3.275723255323458e-05, 0.7071232013176751, -3.2758749590485e-05],
    ),
    "cal": (
        [-7.035385397987487e-05, -0.0012593669548052943, -0.003587919833316346],
        [0.0010451919671103066, -0.006095278010839253, -0.0015747407602490786, 0.999979637468314],
    ),
}


def test_swing_route_keeps_the_errors_margin_on_herbs_own_kinematics():
    """A recorded HERB re-grip swing replayed on the WAM's own IK (no engine). Without the margin the
    route check takes a two-leg route whose first waypoint, in front of the cube near the torso, the arm
    reaches for the believed pose; sent with the trial's calibration (no tracking draw) it is out of
    reach: the IK's best is, by forward kinematics, more than ``ik_slack`` (5 mm) and 1.4 deg from it, the
    figures of SAPIEN Rubiks-5-5 trial 3's `unreachable` at ffe4661 (docs/herb_push_grasp.md, "Arc
    waypoints and the injected errors"). With HERB's ``swing_reach_sigmas`` that route is passed over,
    and every waypoint of the route taken, sent with the same calibration, and every neighbour in its
    3-sigma box are reached: forward kinematics of the chained IK solutions lands on each target."""
    from dataclasses import replace

    from benchharness.plugin.manager import get_manager
    from benchharness.robots.kinematics import pose_error
    from benchharness.strategies.bimanual.machine import Hand
    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.herb_rubiks.strategy import PushGraspStrategy

    d = _SWING_244
    base = Pose(*d["base"])
    q0 = np.array(d["q"])
    arm = get_manager().create("robot", "herb").arm("right_arm")

    class Arm:  # the real arm's kinematics, its base where it was (no engine)
        lower, upper = arm.lower, arm.upper

        def base_pose(self):
            return base

        def positions(self):
            return q0

        def ik(self, mats, seed_q=None):
            return arm.ik(mats, seed_q=seed_q)

    def route(**cfg):
        m = PushGraspStrategy(replace(HerbPushGraspConfig(), **cfg))
        m.est = Pose(*d["est"])
        m.ctx = SimpleNamespace(recorder=_Rec())
        hand = Hand("right", Arm(), None, Pose(*d["cal"]), Pose(*d["cmd"]))
        far = Pose(*d["far"])
        c = m.est.p
        r0, r1 = np.linalg.norm(hand.cmd.p - c), np.linalg.norm(far.p - c)
        u0, u1 = (hand.cmd.p - c) / r0, (far.p - c) / r1
        poses = m._swing_route(hand, far, "re-grip stand-off", u0, u1, float(r0), float(r1))
        return m, hand, poses

    def solve(target, seed):
        """IK from ``seed``, then FK of its answer: (solution, mm, deg off the target)."""
        res = arm.ik((base.inv() * target).as_matrix()[None], seed_q=seed)
        got = base * Pose.from_matrix(arm.fk(res.q[:1])[0])
        dp, dr = pose_error(got.as_matrix()[None], target.as_matrix()[None])
        return res.q[0], 1000 * float(dp[0]), math.degrees(float(dr[0]))

    m0, hand0, old = route(swing_reach_sigmas=None)
    assert m0.ctx.recorder.events[-1][1]["legs"] == 2 and len(old) == 5
    assert old[0].p == pytest.approx([0.719, -0.040, 1.095], abs=1e-3)
    _, mm_b, deg_b = solve(old[0], q0)
    assert mm_b < 0.01 and deg_b < 0.01  # the believed waypoint: reached
    _, mm_s, deg_s = solve(m0.actual(hand0, old[0], np.zeros(3)), q0)
    assert mm_s > 1000 * m0.config.ik_slack and deg_s > 1.4  # as sent: out of reach

    m1, hand1, new = route()
    assert m1.config.swing_reach_sigmas == 3.0
    kind, data = m1.ctx.recorder.events[-1]
    assert kind == "swing" and data["margin_skipped"] == 1 and "margin" not in data
    assert all(not w.p == pytest.approx(old[0].p, abs=1e-3) for w in new)
    err = m1.config.errors
    dp = 3.0 * np.hypot(err.calib_pos_std, err.tracking_std)
    dr = 3.0 * math.radians(err.calib_rot_std_deg)
    q = q0
    for w in new:
        q, mm_w, deg_w = solve(w, q)
        assert mm_w < 0.01 and deg_w < 0.01
        sent = m1.actual(hand1, w, np.zeros(3))
        box = [sent] + [
            Pose(w.p + s * dp * a, w.q)
            if turn is None
            else Pose.from_rotation(w.p, Rotation.from_rotvec(s * dr * a) * w.rotation)
            for a in np.eye(3)
            for s in (1.0, -1.0)
            for turn in (None, True)
        ]
        for target in box:
            _, mm_t, deg_t = solve(target, q)
            assert mm_t < 0.1 and deg_t < 0.05, (w.p, target.p)
