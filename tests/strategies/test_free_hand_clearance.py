"""A free hand's joint-space move is checked clear of the table as well as of the cube (issue 16).

Measured (SAPIEN Rubiks-1-50 sensor-aided seed 0, move 38): the right hand's move to a hand-over
re-grip's stand-off, checked clear of the believed cube only, swept the wrist flex link into the
table's edge (295 N); the arm stuck there, 258 mm from its target, and the re-grip closed on nothing.
The joints below are that move's start (the arm's measured joints) and goal (the planned grip's
stand-off solution), the belief where the cube then was (drifted 2 cm down and 3 cm left over the
38 moves). The check is compared with the wrist's own geometry (its sphere round the wrist flex
joint, from the joint frames) and with the engine's contacts.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchharness.geometry import Pose
from benchharness.strategies.bimanual.machine import SWEEP_SAMPLES, Hand
from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig
from benchharness.strategies.pr2_rubiks.strategy import WRIST_RADIUS, SensorAidedStrategy

Q_START = np.array([-0.325, 0.421, -2.672, -1.21, -4.804, -1.921, 5.514])
Q_GOAL = np.array([-0.375, 1.081, -0.374, -1.117, -1.275, -1.488, 6.246])
BELIEF = Pose(np.array([0.575, 0.029, 0.579]))


@pytest.fixture(scope="module")
def scene():
    from benchharness.backends.interface import Box, PhysicsConfig
    from benchharness.plugin import get_manager

    m = get_manager()
    b = m.create("backend", "pybullet", config=PhysicsConfig(seed=0))
    machine = SensorAidedStrategy(PR2RubiksConfig())
    centre, (tx, ty, tz) = machine.table_box()
    table = b.add_body([Box((float(tx), float(ty), float(tz)))], Pose(centre), 1.0, fixed=True)
    robot = m.create("robot", "pr2")
    robot.spawn(b)
    machine.est = BELIEF
    arm = robot.arm("right_arm")
    hand = Hand("right", arm, None, Pose(np.zeros(3)), Pose(np.zeros(3)))
    yield machine, hand, b, robot, table
    b.close()


def _wrist_to_table(machine, hand, q: np.ndarray) -> float:
    """Distance (m) of the wrist flex link's sphere from the table box (negative: inside), from the
    wrist flex joint's origin (the sphere's centre) by forward kinematics."""
    origin = hand.arm.joint_origins(q[None])[0][5]
    w = hand.arm.base_pose().as_matrix()
    c = w[:3, :3] @ origin + w[:3, 3]
    centre, half = machine.table_box()
    return float(np.linalg.norm(np.maximum(np.abs(c - centre) - half, 0.0))) - WRIST_RADIUS


def _touches_table(b, robot, table, q: np.ndarray) -> set[str]:
    """Links of the right arm the engine finds touching the table with the arm at ``q``."""
    b.set_joint_positions(robot.body, q, joints=list(robot.arm("right_arm").joints))
    b.step(1)
    return {c.link_a for c in b.contacts(robot.body, table) if c.link_a and c.link_a[0] == "r"}


def test_stand_off_move_through_the_table_is_not_clear(scene):
    machine, hand, b, robot, table = scene
    points = machine._hand_points(hand)
    assert points is not None
    s = np.linspace(0.0, 1.0, 16)
    wrist = np.array([_wrist_to_table(machine, hand, Q_START + t * (Q_GOAL - Q_START)) for t in s])
    # both ends are clear of the table, the wrist's path between them is not
    assert wrist[0] > 0.05 and wrist[-1] > 0.05
    assert wrist.min() < 0.0
    # the check's points sample the wrist's sphere: their distance is that of the sphere's surface, at
    # most a grid cell more
    clear = machine.sweep_clearance(hand, Q_START, Q_GOAL, points)
    assert clear <= max(wrist.min(), 0.0) + 0.01
    assert not machine._clears(hand, Q_START, Q_GOAL, points)
    # the ends alone are clear (a check of the goal posture would not see it)
    assert machine._clears(hand, Q_START, Q_START, points)
    assert machine.sweep_clearance(hand, Q_GOAL, Q_GOAL, points, n=1) >= 0.02
    # the engine agrees: the right wrist is in the table at the worst point of the path, not at the ends
    worst = Q_START + s[int(np.argmin(wrist))] * (Q_GOAL - Q_START)
    assert "r_wrist_flex_link" in _touches_table(b, robot, table, worst)
    assert not _touches_table(b, robot, table, Q_GOAL)


def test_a_sweep_checks_start_is_its_first_configuration_bit_for_bit(scene):
    """``_clears`` reads the start's distance off the path's first configuration instead of checking
    the start alone (issue 12: a second FK and point transform per check); equal bit for bit to the
    start checked alone, on paths drawn over the arm's joint range."""
    machine, hand, *_ = scene
    points = machine._hand_points(hand)
    lo, hi = hand.arm.chain.lower, hand.arm.chain.upper
    rng = np.random.default_rng(4)
    for _ in range(25):
        q0, q1 = rng.uniform(lo, hi), rng.uniform(lo, hi)
        cube, table = machine._sweep_gaps(hand, q0, q1, points, SWEEP_SAMPLES)
        alone = machine.sweep_clearance(hand, q0, q0, points, n=1)
        assert min(float(cube[0]), float(table[0])) == alone
