"""The bimanual Rubik's state machine: every two-armed robot's Rubik's strategy is it, with its own grasp module.

No physics: registration and class contracts, the swing's arcs and route
check. Whole trials of the machine driving each robot are in
test_pr2_rubiks_sim.py (the PR2, Rubiks-1-5 on both engines) and
test_herb_push_grasp.py (HERB, a one-move trial with a hand-over on both
engines; Rubiks-1-5 and longer tiers as slow tests).
"""

from __future__ import annotations

import dataclasses
import inspect
import math

import numpy as np
import pytest

from benchharness.strategies.bimanual.config import BimanualConfig
from benchharness.strategies.bimanual.frames import along
from benchharness.strategies.bimanual.machine import BimanualRubiksMachine, GraspModule

STRATEGIES = {
    "dead-reckoning": "pr2",
    "dead-reckoning-exact": "pr2",
    "sensor-aided": "pr2",
    "push-grasp": "herb",
    "push-grasp-exact": "herb",
}


@pytest.mark.parametrize("name", sorted(STRATEGIES))
def test_every_rubiks_strategy_is_the_machine_with_a_grasp_module(name):
    from benchharness.plugin import get_manager

    s = get_manager().create("strategy", name)
    assert isinstance(s, BimanualRubiksMachine)
    # a robot's strategy class adds a name and builds its grasp module, nothing else: the state machine
    # (pick, twist, regrasp, hand-over, swing, turn travel, retreat) is never overridden
    own = {n for n in vars(type(s)) if not n.startswith("__") or n == "__init__"}
    assert own <= {"name", "__init__"}, own
    assert isinstance(s.config, BimanualConfig)
    assert s.config is s.grasp.config
    for member in ("config", "approach_axis", "finger_axis", "gripper_name", "robot_name"):
        assert hasattr(s.grasp, member), member
    for method in (
        "hand_model",
        "hand_state",
        "take_relation",
        "choose",
        "ready",
        "close_in",
        "open",
        "regrip_before_twist",
        "twist_diagnostics",
    ):
        ours = inspect.signature(getattr(s.grasp, method))
        theirs = inspect.signature(getattr(GraspModule, method))
        assert list(ours.parameters) == list(theirs.parameters)[1:], method  # bound: no self
    assert s.grasp.robot_name in (None, STRATEGIES[name])


def test_the_two_robots_share_the_machine_and_differ_in_their_grasp_modules():
    from benchharness.plugin import get_manager

    m = get_manager()
    pr2, herb = m.create("strategy", "dead-reckoning"), m.create("strategy", "push-grasp")
    assert type(pr2).__mro__[1] is BimanualRubiksMachine is type(herb).__mro__[1]
    assert type(pr2.grasp) is not type(herb.grasp)
    # the tool frames differ (PR2: x = approach, y = fingers; HERB: z = approach, fingers across x)
    assert (pr2.grasp.approach_axis, pr2.grasp.finger_axis) == (0, 1)
    assert (herb.grasp.approach_axis, herb.grasp.finger_axis) == (2, 0)
    # the planner's hand models are each robot's (HERB's wrist is limited, the PR2's continuous)
    assert pr2.grasp.hand_model().wrist_roll_limit is None
    assert herb.grasp.hand_model().wrist_roll_limit is not None


def test_configs_share_the_common_fields():
    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig

    common = {f.name for f in dataclasses.fields(BimanualConfig)}
    for cls in (PR2RubiksConfig, HerbPushGraspConfig):
        assert issubclass(cls, BimanualConfig)
        cfg = cls()
        assert {f.name for f in dataclasses.fields(cfg)} >= common
        z = cfg.zero_error()
        assert type(z) is cls and z.errors.is_zero and not cfg.errors.is_zero
    with pytest.raises(TypeError):  # the scene is a robot's to give
        BimanualConfig()  # type: ignore[call-arg]
    # tuning knobs are config fields, not class attributes of the strategies
    assert PR2RubiksConfig().handover_retreat == HerbPushGraspConfig().handover_retreat == 0.12
    assert PR2RubiksConfig().giver_seeds == 6 and PR2RubiksConfig().finger_preference == "parallel"


def test_along_builds_the_exact_tool_vector():
    """Moves along the approach are ``[d, 0, 0]`` to the bit, as the PR2 code always wrote them."""
    d = 0.07
    assert along(0, d).tolist() == [d, 0.0, 0.0]
    assert along(2, -d).tolist() == [0.0, 0.0, -d]
    assert np.signbit(along(0, -d)[1]) == np.False_


def _herb_machine():
    from benchharness.strategies.herb_rubiks.strategy import PushGraspStrategy

    return PushGraspStrategy()


def test_swing_arc_waypoints_stay_on_the_sphere_and_pass_the_via():
    """``_arc``: at most ``swing_step_deg`` apart, distance interpolated from r0 to r1, ends left out; a
    two-leg route passes through its via direction with the via's orientation."""
    from scipy.spatial.transform import Rotation

    m = _herb_machine()
    step = m.config.swing_step_deg
    c = np.array([0.9, 0.0, 1.1])
    u0, u1, up = np.array([-1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    q0 = Rotation.identity().as_quat()
    qv = Rotation.from_euler("x", 90, degrees=True).as_quat()
    one = m._arc(c, [u0, u1], [q0, q0], 0.15, 0.20)
    assert len(one) == int(np.ceil(90 / step)) - 1
    dirs = [u0] + [(w.p - c) / np.linalg.norm(w.p - c) for w in one] + [u1]
    for a, b in zip(dirs[:-1], dirs[1:]):
        assert np.degrees(np.arccos(np.clip(np.dot(a, b), -1, 1))) <= step + 1e-9
    radii = [np.linalg.norm(w.p - c) for w in one]
    assert all(0.15 < r < 0.20 for r in radii) and radii == sorted(radii)
    two = m._arc(c, [u0, up, u1], [q0, qv, q0], 0.15, 0.15)
    at_via = [w for w in two if np.allclose((w.p - c) / 0.15, up, atol=1e-9)]
    assert len(at_via) == 1 and abs(float(np.dot(at_via[0].q, qv))) == pytest.approx(1.0)
    assert all(np.linalg.norm(w.p - c) == pytest.approx(0.15) for w in two)


class _FakeArm:
    """IK that succeeds only where ``reachable(position)`` says, without moving a joint."""

    def __init__(self, reachable):
        self.reachable = reachable
        self.config = None

    def base_pose(self):
        from benchharness.geometry import Pose

        return Pose(np.zeros(3))

    def positions(self):
        return np.zeros(7)

    def ik(self, mats, seed_q=None):
        from types import SimpleNamespace

        ok = [bool(self.reachable(np.asarray(t)[:3, 3])) for t in mats]
        return SimpleNamespace(success=ok, q=np.zeros((len(mats), 7)))


class _Rec:
    def __init__(self):
        self.events = []

    def event(self, kind, **data):
        self.events.append((kind, data))


def _swing_setup(reachable, **cfg):
    from dataclasses import replace
    from types import SimpleNamespace

    from benchharness.geometry import Pose
    from benchharness.strategies.bimanual.machine import Hand
    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.herb_rubiks.strategy import PushGraspStrategy

    m = PushGraspStrategy(replace(HerbPushGraspConfig(), **cfg))
    c = np.array([0.9, 0.0, 1.1])
    m.est = Pose(c)
    m.ctx = SimpleNamespace(recorder=_Rec())
    arm = _FakeArm(reachable)
    start, far = Pose(c + [-0.15, 0.0, 0.0]), Pose(c + [0.0, 0.15, 0.0])
    hand = Hand("left", arm, None, Pose(np.zeros(3)), start)
    u0, u1 = np.array([-1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    return m, hand, far, u0, u1, c


def test_checked_swing_takes_the_first_route_the_arm_can_follow():
    """``swing_routes``: the direct arc is refused when a waypoint is out of reach, and a two-leg route
    over the top is taken whole (recorded as a ``swing`` event); none passes: a warning and no waypoints.
    No margin for the injected errors here (the reachable set is a plane and a half-space): the next test
    has it."""
    nm = {"swing_reach_sigmas": None}
    m, hand, far, u0, u1, c = _swing_setup(
        lambda p: p[2] > c[2] + 0.03 or abs(p[2] - c[2]) < 1e-9, **nm
    )
    # the ends are level with the cube (reachable), the direct arc's waypoints too: it is taken
    route = m._swing_route(hand, far, "t", u0, u1, 0.15, 0.15)
    assert route and all(abs(w.p[2] - c[2]) < 1e-9 for w in route)
    assert m.ctx.recorder.events[-1] == (
        "swing",
        {"hand": "left", "label": "t", "legs": 1, "waypoints": len(route)},
    )
    # only above the cube (and the ends) is reachable: the route goes over the top
    m, hand, far, u0, u1, c = _swing_setup(
        lambda p: (
            p[2] > c[2] + 0.03
            or np.linalg.norm(p - (c + [-0.15, 0, 0])) < 1e-9
            or np.linalg.norm(p - (c + [0, 0.15, 0])) < 1e-9
        ),
        **nm,
    )
    route = m._swing_route(hand, far, "t", u0, u1, 0.15, 0.15)
    assert route and all(w.p[2] > c[2] + 0.03 for w in route)
    kind, data = m.ctx.recorder.events[-1]
    assert kind == "swing" and data["legs"] == 2
    # nothing between the ends is reachable: no route, a warning
    m, hand, far, u0, u1, c = _swing_setup(lambda p: False, **nm)
    assert m._swing_route(hand, far, "t", u0, u1, 0.15, 0.15) == []
    assert m.ctx.recorder.events[-1][0] == "warning"


def test_checked_swing_passes_over_a_route_whose_waypoint_leaves_the_reach_with_the_errors():
    """``swing_reach_sigmas`` (HERB: 3): the arm reaches only down to 1 mm below the cube's centre. The
    direct arc (level with the centre) and the four level arcs through the middle have an IK solution at
    every waypoint but not 3 sigma of the injected position error lower, so the route over the top is
    taken, every waypoint of which (checked here from the geometry, not the machine) keeps the whole
    margin box in reach. Without a margin the level direct arc is taken, as before; with nothing above
    reachable either, the first level arc is taken with a warning and ``margin=False``."""
    floor = 0.001
    m, hand, far, u0, u1, c = _swing_setup(lambda p: p[2] >= c[2] - floor)
    err = m.config.errors
    assert m.config.swing_reach_sigmas == 3.0 and m.config.reach_sigmas is None
    dp = 3.0 * np.hypot(err.calib_pos_std, err.tracking_std)  # 5.4 mm

    def box_in_reach(p):
        return all(p[2] + s * dp * a[2] >= c[2] - floor for a in np.eye(3) for s in (1, -1))

    route = m._swing_route(hand, far, "t", u0, u1, 0.15, 0.15)
    assert route and all(box_in_reach(w.p) for w in route)
    assert min(w.p[2] for w in route) > c[2] + 0.04  # over the top: 18 deg steps of a 15 cm arc
    kind, data = m.ctx.recorder.events[-1]
    assert kind == "swing" and data["legs"] == 2 and data["margin_skipped"] == 5
    # no margin (the old check): the direct arc, whose waypoints the errors can put out of reach
    m0, hand0, far0, *_ = _swing_setup(lambda p: p[2] >= c[2] - floor, swing_reach_sigmas=None)
    old = m0._swing_route(hand0, far0, "t", u0, u1, 0.15, 0.15)
    assert old and all(abs(w.p[2] - c[2]) < 1e-9 for w in old)
    assert not any(box_in_reach(w.p) for w in old)
    assert m0.ctx.recorder.events[-1] == (
        "swing",
        {"hand": "left", "label": "t", "legs": 1, "waypoints": len(old)},
    )
    # only the level band reachable: no route keeps the margin, the first on the branch is taken
    m1, hand1, far1, *_ = _swing_setup(lambda p: abs(p[2] - c[2]) <= floor)
    got = m1._swing_route(hand1, far1, "t", u0, u1, 0.15, 0.15)
    assert [w.p.tolist() for w in got] == [w.p.tolist() for w in old]
    (k1, warn), (k2, swing) = m1.ctx.recorder.events[-2:]
    assert k1 == "warning" and "margin" in warn["message"]
    assert k2 == "swing" and swing["legs"] == 1 and swing["margin"] is False


def test_swing_routes_and_giver_depth_are_herb_options_the_pr2_leaves_off():
    """The PR2's results are pinned bit for bit (test_pr2_rubiks_sim.py): its config keeps the direct arc
    and gives as it holds; HERB checks its swing routes and gives one slab deep."""
    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig

    pr2, herb = PR2RubiksConfig(), HerbPushGraspConfig()
    assert not pr2.swing_routes and pr2.giver_depth is None and pr2.ik_slack is None
    assert pr2.recentre_turn and herb.recentre_turn
    assert herb.swing_routes and herb.giver_depth == 1 and herb.ik_slack == 0.005


class _RollArm:
    """An arm for ``roll_about``: a fixed tool pose, IK that returns its seed (a step of ``jump`` rad on
    joint 0 at waypoint ``jump_at``), and a record of the joint moves."""

    def __init__(self, tool, jump_at=None, jump=0.0):
        self.tool, self.jump_at, self.jump = tool, jump_at, jump
        self.lower, self.upper = np.full(7, -3.0), np.full(7, 3.0)
        self.calls = 0
        self.moves = []

    def base_pose(self):
        from benchharness.geometry import Pose

        return Pose(np.zeros(3))

    def positions(self):
        return np.zeros(7)

    def tcp_pose(self):
        return self.tool

    def ik(self, mats, seed_q=None):
        from types import SimpleNamespace

        self.calls += 1
        q = np.array(seed_q, dtype=float)
        if self.calls == self.jump_at:
            q[0] += self.jump
        return SimpleNamespace(success=[True], q=q[None])

    def move_to_joints(self, q, duration=None, settle=0.3):
        self.moves.append((np.array(q), duration, settle))


def _roll_setup(arm):
    from types import SimpleNamespace

    from benchharness.geometry import Pose
    from benchharness.strategies.bimanual.machine import Hand
    from benchharness.strategies.herb_rubiks.strategy import PushGraspStrategy

    m = PushGraspStrategy()
    m.ctx = SimpleNamespace(recorder=_Rec())
    return m, Hand("right", arm, None, Pose(np.zeros(3)), arm.tool)


def test_twist_turns_the_tool_about_the_layers_axis_not_the_palms():
    """A layer whose axis is 4 mm off the palm's along the fingers (PyBullet Rubiks-1-20, U2 at move 14):
    the wrist roll would carry it round a circle 8 mm across in a half turn; ``roll_waypoints`` keep the
    point on the layer's axis where it is and the approach parallel, and end at the tool rolled by the
    angle; ``roll_about`` moves through their chained IK to the wrist goal."""
    from scipy.spatial.transform import Rotation

    from benchharness.geometry import Pose

    tool = Pose.from_rotation([0.9, -0.07, 1.1], Rotation.from_euler("x", -90, degrees=True))
    m, hand = _roll_setup(_RollArm(tool))
    fx = tool.rotation.apply([1.0, 0.0, 0.0])  # HERB: pinch across tool x, approach along tool z
    az = tool.rotation.apply([0.0, 0.0, 1.0])
    offset = -0.004
    centre, poses = m.roll_waypoints(tool, offset, math.pi, 12)
    assert np.allclose(centre, tool.p + offset * fx)
    assert len(poses) == 12
    for p in poses:
        # the layer's axis stays put, the approach stays parallel to it
        assert np.allclose(p.p + offset * p.rotation.apply([1.0, 0.0, 0.0]), centre, atol=1e-12)
        assert np.allclose(p.rotation.apply([0.0, 0.0, 1.0]), az, atol=1e-12)
    end = tool.rotation * Rotation.from_rotvec([0.0, 0.0, math.pi])
    assert np.allclose((poses[-1].rotation * end.inv()).as_rotvec(), 0.0, atol=1e-9)
    # the palm's axis (the plain wrist roll's) orbits: 8 mm off where it was after the half turn
    assert np.linalg.norm(poses[-1].p - tool.p) == pytest.approx(0.008)
    q_goal = np.zeros(7)
    q_goal[-1] = math.pi
    assert m.roll_about(hand, offset, q_goal, 2.0, 0)
    n = math.ceil(180 / m.config.roll_step_deg)
    assert len(hand.arm.moves) == n
    assert hand.arm.moves[-1][0][-1] == pytest.approx(math.pi)
    assert [d for _, d, _ in hand.arm.moves] == pytest.approx([2.0 / n] * n)
    assert [s for _, _, s in hand.arm.moves] == [0.0] * (n - 1) + [0.2]
    assert m.ctx.recorder.events[-1] == (
        "roll",
        {"hand": "right", "offset_mm": -4.0, "waypoints": n},
    )


def test_roll_about_refuses_a_branch_jump_and_moves_nothing():
    from scipy.spatial.transform import Rotation

    from benchharness.geometry import Pose

    tool = Pose.from_rotation([0.9, -0.07, 1.1], Rotation.from_euler("x", -90, degrees=True))
    m, hand = _roll_setup(_RollArm(tool, jump_at=3, jump=2.0))
    q_goal = np.zeros(7)
    q_goal[-1] = math.pi / 2
    assert not m.roll_about(hand, 0.002, q_goal, 1.0, 4)
    assert hand.arm.moves == []
    kind, data = m.ctx.recorder.events[-1]
    assert kind == "warning" and "twist 5: no smooth roll" in data["message"]


def test_herb_roll_offset_reads_the_fingers_only_when_on():
    """HERB's ``roll_offset``: None with ``roll_about_fingers`` off (the default: the twist rolls the wrist);
    on, the middle of the fingers' inner sides, unless they are not a cube's width apart."""
    from dataclasses import replace

    from benchharness.strategies.herb_rubiks.config import HerbPushGraspConfig
    from benchharness.strategies.herb_rubiks.strategy import PushGraspStrategy

    sides = (-0.0325, 0.0245, 0.037, 0.037)  # 57 mm apart, their middle 4 mm towards tool -x
    off = PushGraspStrategy()
    off.grasp._pinch_sides = lambda m, hand: sides  # type: ignore[method-assign]
    assert off.grasp.roll_offset(off, None) is None
    on = PushGraspStrategy(replace(HerbPushGraspConfig(), roll_about_fingers=True))
    on.grasp._pinch_sides = lambda m, hand: sides  # type: ignore[method-assign]
    assert on.grasp.roll_offset(on, None) == pytest.approx(-0.004)
    on.grasp._pinch_sides = lambda m, hand: (-0.04, 0.03, 0.037, 0.037)  # type: ignore[method-assign]
    assert on.grasp.roll_offset(on, None) is None
