"""The bimanual machine at the edge of an arm's reach (issue 16): a move whose IK does not converge is not
made, and a grip's stand-off keeps a margin for the injected errors (docs/strategies.md, "Edge of reach")."""

from __future__ import annotations

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
def test_send_out_of_reach_fails_without_moving_the_arm(make_ctx):
    """The PR2's left arm nearly straight (elbow flex 10 mrad from its limit), sent 2 mm farther out from
    the shoulder than its tool frame is: no IK solution. The IK's best attempt is a restart on another
    branch (the upper-arm and forearm rolls ~2.7 rad away, as measured in SAPIEN Rubiks-5-20 trial 5),
    to which the arm used to move before the failure was raised; now the send fails `unreachable`, the
    joints and the forward kinematics' tool frame stay where they were and the command is not taken."""
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
        m, Hand, grip, shoulder = _machine(**cfg)
        m._clears = lambda *a: True  # no FK model here: the sweep check is not what is tested
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
