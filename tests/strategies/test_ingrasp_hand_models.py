"""Allegro descriptions for the in-grasp strategy: which one a trial plans with, and the LL4MA lab's.

References: the published Level I grasps (their thumb rotation reaches 1.62 rad, the LL4MA
description's limit; the stock v4 file stops at 1.396) and the LL4MA description's own figures
(``allegro_virtual.robot.xacro``, cited in ``robots.descriptions.allegro``).
"""

from __future__ import annotations

import csv

import numpy as np
import pytest

from benchharness.plugin import get_manager
from benchharness.robots.allegro import allegro_config
from benchharness.robots.descriptions import allegro as descriptions
from benchharness.robots.robot import Robot
from benchharness.strategies.ingrasp.execution import InGraspExecutor
from benchharness.strategies.ingrasp.hand import HandKinematics
from benchharness.strategies.ingrasp.strategy import InGraspPlanner
from benchharness.strategies.ingrasp.tasks import published_level1_path, published_tasks


@pytest.fixture(scope="module")
def ll4ma_urdf(tmp_path_factory):
    path = tmp_path_factory.mktemp("ll4ma") / "allegro_biotac.urdf"
    path.write_text(descriptions.build(descriptions.LL4MA_BIOTAC).to_xml())
    return path


def test_the_published_thumb_rotation_is_the_ll4ma_limit(ll4ma_urdf):
    with open(published_level1_path(), newline="") as fh:
        thumb = max(float(r["grasp_thumb_j0"]) for r in csv.DictReader(fh))
    assert thumb == 1.62
    _, hi = HandKinematics(ll4ma_urdf).limits(("thumb",))
    assert hi[0] == thumb  # LL4MA: thumb_joint_0 upper="1.62"
    _, hi_v4 = HandKinematics().limits(("thumb",))
    assert hi_v4[0] == 1.396  # SimLab v4: 1.496 hardware less the 0.1 rad margin


def test_ll4ma_biotac_tips_reach_past_the_stock_tips(ll4ma_urdf):
    """A straight middle finger's tip sphere ends 38.7 mm past the distal joint on the stock hand
    and 60.9 mm on the LL4MA one (its BioTac contact mesh ends at 61.4 mm)."""
    distal_joint = 0.0007 + 0.0164 + 0.054 + 0.0384  # joint_4 origin z plus links 0..2 (both files)
    for urdf, spec, reach in (
        (None, descriptions.V4, 0.0387),
        (ll4ma_urdf, descriptions.LL4MA_BIOTAC, 0.0609),
    ):
        tip = HandKinematics(urdf).tip_poses_np(np.zeros((1, 4)), ("middle",))[0, 0]
        assert tip[2, 3] - distal_joint + spec.tip_r == pytest.approx(reach, abs=2e-4)


def test_a_trial_plans_with_its_robots_description(ll4ma_urdf):
    robot = Robot(allegro_config(urdf=ll4ma_urdf))
    planner = InGraspPlanner("relaxed-rigidity")
    hand = planner.hand_for(robot)
    assert hand.urdf_path == str(ll4ma_urdf.resolve())
    task = published_tasks()[0]  # apple-01: thumb rotation 1.6
    assert planner.problem(task, hand).q_rest[12] == pytest.approx(1.6)  # inside 1.62: not clamped
    assert planner.problem(task).q_rest[12] == pytest.approx(1.396)  # the stock hand clamps it
    assert planner.hand_for(get_manager().create("robot", "allegro")) is planner.hand


def test_a_plan_for_one_hand_is_not_executed_on_another(ll4ma_urdf):
    planner = InGraspPlanner("relaxed-rigidity", max_iterations=2)
    task = published_tasks()[0]
    be = get_manager().create("backend", "pybullet")
    try:
        with pytest.raises(ValueError, match="not the simulated robot's description"):
            InGraspExecutor(planner.hand).run(
                be,
                Robot(allegro_config(urdf=ll4ma_urdf)),
                planner.problem(task),
                planner.plan_task(task),
                task.object,
                np.random.default_rng(0),
            )
        assert be.time == 0.0
    finally:
        be.close()
