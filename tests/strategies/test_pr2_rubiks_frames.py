"""PR2 Rubik's baselines without physics: registration, target frames, signs, the plan they execute."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.geometry import Pose
from benchharness.strategies.bimanual.frames import (
    body_axis_along,
    grip_candidates,
    grip_pose,
    rotate_about_point,
    turned_about_approach,
)
from benchharness.strategies.pr2_rubiks.config import ErrorConfig, PR2RubiksConfig

#: the cube as the protocol puts it on the table: U up, F (body -y) facing the robot (world -x)
TABLE_YAW = Rotation.from_euler("z", -90, degrees=True)


def test_strategies_are_registered_as_plugins():
    from benchharness.plugin import get_manager

    m = get_manager()
    names = m.names("strategy")
    assert {"dead-reckoning", "dead-reckoning-exact", "sensor-aided"} <= set(names)
    s = m.create("strategy", "dead-reckoning")
    assert s.benchmarks == ("rubiks",) and callable(s.run_trial)
    exact = m.create("strategy", "dead-reckoning-exact")
    assert exact.config.errors.is_zero and not s.config.errors.is_zero
    aided = m.create("strategy", "sensor-aided")
    assert aided.name == "sensor-aided" and not aided.config.errors.is_zero


def test_left_rotator_grip_against_hand_computed_frame():
    cube = Pose.from_rotation([0.6, 0.0, 0.8], TABLE_YAW)
    g = grip_pose(cube, "+y", 0.032, "+x")
    np.testing.assert_allclose(g.p, [0.6, 0.032, 0.8], atol=1e-12)
    m = g.rotation.as_matrix()
    np.testing.assert_allclose(
        m[:, 0], [0, -1, 0], atol=1e-12
    )  # tool x: approach, towards the cube
    np.testing.assert_allclose(m[:, 1], [1, 0, 0], atol=1e-12)  # tool y: the fingers, along world x
    np.testing.assert_allclose(m[:, 2], [0, 0, 1], atol=1e-12)  # right-handed


def test_grip_follows_a_yawed_and_shifted_estimate():
    """5° of estimated yaw and a 3 mm offset turn and move the target with them, about the estimated centre."""
    yaw = math.radians(5.0)
    est = Pose.from_rotation([0.603, -0.002, 0.8], Rotation.from_euler("z", yaw) * TABLE_YAW)
    g = grip_pose(est, "-y", 0.011, "+z")
    expect_p = np.array([0.603 + 0.011 * math.sin(yaw), -0.002 - 0.011 * math.cos(yaw), 0.8])
    np.testing.assert_allclose(g.p, expect_p, atol=1e-12)
    np.testing.assert_allclose(
        g.rotation.as_matrix()[:, 0], [-math.sin(yaw), math.cos(yaw), 0.0], atol=1e-12
    )
    np.testing.assert_allclose(g.rotation.as_matrix()[:, 1], [0, 0, 1], atol=1e-12)
    # the gripped face is the body's R face (+x body), which the table yaw puts at world -y
    np.testing.assert_allclose(body_axis_along(est, "-y"), [1, 0, 0])


def test_four_grip_candidates_share_position_and_approach():
    cube = Pose.from_rotation([0.6, 0.0, 0.8], TABLE_YAW)
    cands = grip_candidates(cube, "+y", 0.032)
    assert len(cands) == 4
    fingers = sorted(tuple(np.round(c.rotation.as_matrix()[:, 1], 9)) for c in cands)
    assert fingers == sorted([(1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)])
    for c in cands:
        np.testing.assert_allclose(c.p, [0.6, 0.032, 0.8], atol=1e-12)
        np.testing.assert_allclose(c.rotation.as_matrix()[:, 0], [0, -1, 0], atol=1e-12)


def test_hand_over_turn_and_wrist_roll_frames():
    grip = grip_pose(Pose([0.6, 0.0, 0.8]), "-y", 0.011, "+x")  # right holder, tool x = +y
    turned = rotate_about_point(grip, np.array([0.6, 0.0, 0.8]), "x", -math.pi / 2)
    np.testing.assert_allclose(
        turned.p, [0.6, 0.0, 0.811], atol=1e-12
    )  # -90° about x takes -y to +z
    np.testing.assert_allclose(
        turned.rotation.as_matrix()[:, 0], [0, 0, -1], atol=1e-12
    )  # now pointing down
    rolled = turned_about_approach(grip, math.pi / 2)
    np.testing.assert_allclose(rolled.p, grip.p)
    np.testing.assert_allclose(rolled.rotation.as_matrix()[:, 0], [0, 1, 0], atol=1e-12)
    # tool z = x × y = (0, 1, 0) × (1, 0, 0) = -z world; a +90° roll about tool x takes tool y onto tool z
    np.testing.assert_allclose(rolled.rotation.as_matrix()[:, 1], [0, 0, -1], atol=1e-12)


def test_wrist_roll_sign_of_a_twist():
    """+1 quarter turn is right-handed about world +y: about the left tool x (-y) that is -90° of roll."""
    from benchharness.strategies.pr2_rubiks.strategy import DeadReckoningStrategy
    from benchharness.strategies.regrasp import Twist

    assert DeadReckoningStrategy._roll_delta(Twist("left", "y", 2, 1)) == pytest.approx(
        -math.pi / 2
    )
    assert DeadReckoningStrategy._roll_delta(Twist("right", "y", 0, -2)) == pytest.approx(-math.pi)


def test_zero_error_config():
    cfg = PR2RubiksConfig()
    assert not cfg.errors.is_zero
    z = cfg.zero_error()
    assert z.errors.is_zero and z.errors == ErrorConfig().zero()
    assert z.rotator_offset == cfg.rotator_offset


def test_pad_spans_give_the_intended_slabs():
    """The 36 mm pad, set back on the four-bar arc at the 57 mm grip: rotator on the outer slab only,
    holder on outer + middle with half a cubie of margin (the pad geometry from pr2_description)."""
    from benchharness.robots.descriptions.pr2 import PAD_SIZE, pad_setback

    cfg = PR2RubiksConfig()
    half_pad, slab_edge, face = PAD_SIZE[0] / 2, 0.057 / 6, 0.0285
    back = pad_setback(0.057)
    assert back == pytest.approx(0.0047, abs=0.0002)  # 4.7 mm behind the tool frame at 57 mm

    def inner(offset):  # the pad's end nearest the cube centre, from the centre
        return offset + back - half_pad

    assert inner(cfg.rotator_offset) > slab_edge + 0.005  # inner end clear of the middle slab
    assert inner(cfg.holder_offset) < slab_edge - 0.009  # half a cubie onto the middle slab
    assert inner(cfg.holder_offset) > -slab_edge + 0.009  # and half a cubie short of the far slab
    for off in (cfg.rotator_offset, cfg.holder_offset):
        assert off + back + half_pad > face  # the pad reaches past the face


def test_side_pick_plans_execute_on_the_logical_cube():
    from benchharness.cube import SOLVED, apply, generate_sequence
    from benchharness.strategies.regrasp import HandModel, execute, plan_sequence

    model = HandModel(name="pr2", pick_approaches=PR2RubiksConfig().pick_approaches)
    for trial in range(1, 6):
        seq = generate_sequence(0, "Rubiks-5-20", trial, 20)
        plan = plan_sequence(seq, model)  # side picks only: the one pick implemented physically
        assert plan.actions[0].approach == "side"
        assert (
            execute(plan).state == apply(SOLVED, seq)
        ).all()  # execute raises on any broken rule
