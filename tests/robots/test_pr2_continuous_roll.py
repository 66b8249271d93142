"""PR2 forearm and wrist roll are continuous: IK stays on the seed's branch, both engines turn them past 2*pi.

Why it matters: a Rubik's twist or a hand-over turn adds quarter turns to the
wrist (and the forearm follows); with rolls bounded to +-pi the arm had to
unwind a full turn mid-motion, sweeping the held cube (docs/strategies.md).
"""

from __future__ import annotations

import numpy as np
import pytest

from benchharness.robots.kinematics import pose_error


def _left_arm(robots):
    return robots["pr2"].arm("left_arm")


def test_roll_joints_are_continuous_and_unlimited(robots):
    arm = _left_arm(robots)
    assert list(np.flatnonzero(arm.continuous)) == [4, 6]  # forearm roll, wrist roll
    assert np.all(np.isinf(arm.lower[arm.continuous])) and np.all(
        np.isinf(arm.upper[arm.continuous])
    )


def test_ik_follows_the_rolls_past_pi_without_unwinding(robots):
    """Step the wrist and forearm rolls onwards past +-pi and 2*pi: every solution is next to its seed."""
    arm = _left_arm(robots)
    rng = np.random.default_rng(3)
    q = np.array([0.05, 1.0, 0.5, -2.0, 2.6, -0.9, 2.4])  # forearm and wrist roll just short of pi
    for _ in range(14):
        q_next = q.copy()
        q_next[4] += 0.3
        q_next[6] += 0.45
        q_next[:4] += 0.02 * rng.normal(size=4)
        target = arm.fk(q_next)
        res = arm.ik(target, seed_q=q)
        assert res.success[0]
        dp, dr = pose_error(arm.fk(res.q), target)
        assert dp[0] < 1e-3 and dr[0] < 1e-2
        # the 7-DOF arm is redundant, so not q_next exactly, but never a 2*pi (or any branch) jump
        assert np.max(np.abs(res.q[0] - q)) < 0.8, (q, res.q[0])
        q = res.q[0]
    assert (
        q[4] > 2 * np.pi - 1.5 and q[6] > 2 * np.pi + 0.5
    )  # both went on past pi (and the wrist past 2*pi)


def test_batched_ik_with_seeds_on_either_side_of_pi(robots):
    """Rows with different seeds (one near the +-pi seam, one not) each come back on their own branch."""
    arm = _left_arm(robots)
    seeds = np.array(
        [[0.05, 1.0, 0.5, -2.0, 3.1, -0.9, -3.2], [0.5, 0.6, 1.2, -1.8, 0.3, -0.5, 7.0]]
    )
    goals = seeds + np.array([0.03, -0.02, 0.02, 0.03, 0.1, 0.04, -0.1])
    res = arm.ik(arm.fk(goals), seed_q=seeds)
    assert res.success.all()
    assert np.max(np.abs(res.q - seeds)) < 0.5


@pytest.mark.sim
@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_both_engines_drive_the_rolls_past_two_pi(make_backend, make_robot, backend):
    """SAPIEN must load a continuous joint unwrapped (a wrapped PhysX revolute spins wildly past 2*pi)."""
    be = make_backend(backend)
    be.add_ground()
    robot = make_robot("pr2")
    robot.spawn(be)
    arm = robot.arm("left_arm")
    for wrist in (4.0, 7.0, -7.5):
        q = arm.positions().copy()
        q[4], q[6] = wrist / 2, wrist
        res = arm.move_to_joints(q, duration=1.5, settle=0.2)
        assert res.max_tracking_error < 0.05, (wrist, res.max_tracking_error)
        np.testing.assert_allclose(arm.positions()[[4, 6]], [wrist / 2, wrist], atol=0.01)


@pytest.mark.sim
@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_full_wrist_flex_is_free_of_self_collision(make_backend, make_robot, backend):
    """The palm clears the forearm over the whole hard wrist-flex range (-2.18..0 rad) at any wrist roll."""
    be = make_backend(backend)
    robot = make_robot("pr2")
    robot.spawn(be)
    arm = robot.arm("left_arm")
    names = list(arm.joints)
    hard = robot.urdf_joints["l_wrist_flex_joint"]
    assert (
        hard.lower == -2.18
    )  # pr2_description forearm_v0/forearm.urdf.xacro (PR2/pr2_common@c36a5c9c)
    for flex in np.linspace(0.0, hard.lower, 8):
        for roll in (0.0, np.pi / 4, np.pi / 2):
            q = arm.positions().copy()
            q[5], q[6] = flex, roll
            be.set_joint_positions(robot.body, q, joints=names)
            be.step(1)
            hits = {
                (c.link_a, c.link_b)
                for c in be.contacts(robot.body, robot.body)
                if c.distance < 0.0
            }
            assert not hits, (flex, roll, hits)
