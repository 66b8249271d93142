"""The DMG on the YCB scans (``DMGSurface(model="ycb")``): published frame, Table III's G_min, options.

Independent references: Table III of the benchmark paper (Cruciani et al., RA-L 2020) for G_min,
and the published DMG.ods desired grasps (``tasks/inhand/level3_dmg_tasks.csv``) for the goal
orientation.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from benchharness.inhand.fileformat import read_results, read_tasks
from benchharness.inhand.scoring import score_results
from benchharness.strategies.dmg.config import DMGSurface
from benchharness.strategies.dmg.strategy import DMGPlanner, write_dmg_results

ROOT = Path(__file__).resolve().parents[1]
#: Table III, G_min (cm), printed to three decimals
TABLE_III_GMIN_CM = {"spatula": 0.034, "potted meat can": 0.004}


@pytest.fixture(scope="module")
def scan_plans():
    tasks = read_tasks(ROOT / "tasks/inhand/level3_dmg_tasks.csv")
    planner = DMGPlanner(surface=DMGSurface(model="ycb"))
    rows = [list(tasks.object).index(o) for o in TABLE_III_GMIN_CM]
    return tasks, planner, [planner.plan_task(tasks, i) for i in rows]


def test_the_scan_is_planned_in_the_published_frame(scan_plans):
    _, planner, plans = scan_plans
    for p in plans:
        pl = planner.placement(p.object)
        np.testing.assert_array_equal(pl.R, np.eye(3))
        assert pl.c_pub == (0.0, 0.0, 0.0) and pl.o_ours == (0.0, 0.0, 0.0)
        assert planner.object_model(p.object).source == "ycb"


def test_the_goal_is_reached_up_to_the_tilt_of_the_scan_patch(scan_plans):
    """The angle about the closing axis is exact: all of the orientation error is the axis itself,
    the final patch's normal on the scan against the published desired closing axis."""
    tasks, _, plans = scan_plans
    for p in plans:
        i = list(tasks.task_id).index(p.task_id)
        assert p.plan.reached_goal, p.task_id
        want, got = Rotation.from_quat(tasks.desired[i, 3:]), Rotation.from_quat(p.final_quaternion)
        total = np.degrees((want.inv() * got).magnitude())
        za, zb = want.as_matrix()[:, 2], got.as_matrix()[:, 2]
        tilt = np.degrees(np.arccos(np.clip(abs(za @ zb), -1.0, 1.0)))
        assert total == pytest.approx(tilt, abs=0.05), p.task_id
        assert tilt < 12.0, p.task_id


def test_g_min_on_the_scans_is_table_iii(scan_plans, tmp_path):
    tasks, planner, plans = scan_plans
    scored = score_results(
        read_results(write_dmg_results(tasks, plans, planner, tmp_path / "r.csv"))
    )
    for obj, g in zip(scored.results.object, scored.scores.g_min):
        assert round(float(g) * 100, 3) == TABLE_III_GMIN_CM[obj], (obj, g)


def test_a_mesh_with_zero_area_faces_is_refused_not_looped_on():
    from benchharness.strategies.dmg.patches import discretise_surface

    box = trimesh.creation.box((0.02, 0.02, 0.02))
    faces = np.vstack([box.faces, [[0, 0, 1]]])  # a face with a repeated vertex: no normal
    mesh = trimesh.Trimesh(box.vertices, faces, process=False)
    with pytest.raises(ValueError, match="1 degenerate"):
        discretise_surface(mesh, 0.01)


def test_the_surface_is_a_strategy_option():
    from benchharness.plugin import get_manager
    from benchharness.runner.options import OptionError, normalise_options

    reg = get_manager().get("strategy", "dmg")
    assert normalise_options(reg.options, "dmg", ["model=ycb"], reg.factory) == (("model", "ycb"),)
    with pytest.raises(OptionError, match="model"):
        normalise_options(reg.options, "dmg", ["model=scan"], reg.factory)


def test_a_stored_trial_is_scored_on_the_model_it_ran_on():
    from benchharness.runner.contact_regions import planner_for_outcome

    assert planner_for_outcome({"extra": {"dmg_surface": "ycb"}}).surface.model == "ycb"
    assert (
        planner_for_outcome({"extra": {}}).surface.model == "generated"
    )  # stores before the field
