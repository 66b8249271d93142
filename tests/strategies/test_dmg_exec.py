"""Executing DMG plans with the PR2 gripper on both backends, and the Level II contact-region tasks.

The reached grasp is measured from engine poses (object and tool frame)
and scored by the runner's own scoring (poses) and Algorithm 1 (contact
regions). Default-suite cases use a short task (one 30 deg rotation in the
start node) and a 1 s hold; the four published tasks are ``slow``.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from gripper_helpers import BACKENDS, make_context, task_item
from scipy.spatial.transform import Rotation

from benchharness.geometry import Pose
from benchharness.runner.contract import InhandItem
from benchharness.runner.scoring import score_inhand
from benchharness.strategies.dmg.execution import DMGExecConfig
from benchharness.strategies.pivoting.config import ExecutionConfig, HoldConfig

SHORT = DMGExecConfig(execution=ExecutionConfig(hold=HoldConfig(hold_time=1.0)))


def _short_item() -> InhandItem:
    """The published gelatin-box initial grasp; desired: the same contacts, gripper turned -30 deg about its z."""
    pub = task_item("inhand-level3-dmg", 0)
    q = (
        Rotation.from_quat(pub.initial[3:]) * Rotation.from_rotvec([0.0, 0.0, math.radians(-30.0)])
    ).as_quat()
    desired = np.concatenate([pub.initial[:3], q])
    return InhandItem(
        "test-dmg-short",
        "gelatin-rot30",
        "gelatin box",
        3,
        pub.initial.copy(),
        desired,
        contacts={"initial": pub.contacts["initial"], "desired": pub.contacts["initial"]},
    )


def _planner(execution=SHORT):
    from benchharness.strategies.dmg import make_planner

    return make_planner(execution=execution)


@pytest.mark.parametrize("backend", BACKENDS)
def test_short_dmg_task_executes_and_scores(backend):
    from benchharness.runner.contact_regions import contact_errors

    item = _short_item()
    ctx, b = make_context(backend, item)
    try:
        out = _planner().run_trial(ctx)
    finally:
        b.close()
    assert out.failure is None and not out.dropped, out.message
    assert out.extra["support"] == "table"  # "auto": a rest pose keeps the grasp axis horizontal
    assert [p[0] for p in out.extra["primitives"]] == ["rotate"]
    v = score_inhand(item, out)
    assert v.status.value == "success", v.message
    m = v.outcome["metrics"]
    assert m["err_or_percent"] < 1.0, m  # < ~1.6 deg off the desired orientation
    assert m["err_pos"] < 0.006, (
        m
    )  # set-up noise (2 mm per axis) and the snapping to a patch centre
    assert out.plan_time_s > 0 and out.exec_time_s > 0
    g = contact_errors(item.object, item.contacts["desired"], out.reached_contacts)
    assert 0.0 <= g["g_euc"] < 0.015 and g["g_min"] > 0


def test_pads_centre_on_what_they_land_on():
    """A blade whose top rises 20 deg along the approach (x) over a flat bottom, 2 mm thick at its back.

    The pads close along the hand's z until each meets the outermost point under its 36 x 23 mm
    face, so the hand moves along z to the midpoint of the top at the face's far end
    (x = 17.5 mm, the last grid column inside) and the bottom; points beyond the face do not count.
    """
    from benchharness.strategies.pivoting.rig import centre_between_pads

    x, y = np.meshgrid(np.arange(-0.0295, 0.03, 0.001), np.arange(-0.0195, 0.02, 0.001))
    top = 0.001 + (x + 0.03) * math.tan(math.radians(20.0))
    local = np.concatenate(
        [
            np.c_[x.ravel(), y.ravel(), top.ravel()],
            np.c_[x.ravel(), y.ravel(), np.full(x.size, -0.001)],
        ]
    )
    hand = Pose.from_rotation(
        np.array([0.1, 0.2, 0.3]), Rotation.from_euler("xyz", [0.3, -0.2, 1.0])
    )
    out = centre_between_pads(hand, hand.apply(local))  # the blade in the object frame
    expected = 0.5 * (0.001 + 0.0475 * math.tan(math.radians(20.0)) - 0.001)
    np.testing.assert_allclose(hand.inv().apply(out.p[None])[0], [0.0, 0.0, expected], atol=1e-12)
    np.testing.assert_allclose(out.rotation.as_matrix(), hand.rotation.as_matrix(), atol=1e-12)
    # nothing under the pads: the hand stays where it is
    far = centre_between_pads(hand, hand.apply(local + [0.1, 0.0, 0.0]))
    np.testing.assert_allclose(far.p, hand.p, atol=0)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_fixture_holds_the_object_until_the_final_lift(backend):
    """``support="fixture"``: the object stays where it was clamped through set-up and grasp change
    (the fixture, not the pads, holds it), then the opened fixture leaves it to the grasp."""
    item = _short_item()
    ctx, b = make_context(backend, item)
    try:
        out = _planner(replace(SHORT, support="fixture")).run_trial(ctx)
    finally:
        b.close()
    assert out.failure is None and not out.dropped, out.message
    assert out.extra["support"] == "fixture"
    clamped = np.asarray(out.extra["rest_pose"][:3]) + [0.0, 0.0, SHORT.fixture_height]
    poses = [e["object_pose"] for e in ctx.recorder.events if e["kind"] == "primitive"]
    assert poses
    for p in poses:
        assert np.linalg.norm(np.asarray(p[:3]) - clamped) < 2e-4, (p, clamped)
    v = score_inhand(item, out)
    assert v.status.value == "success", v.message
    assert v.outcome["metrics"]["err_pos"] < 0.006, v.outcome["metrics"]


def test_the_spatula_cannot_rest_on_the_table():
    """Its blade grasp's axis is vertical in every stable rest pose: on the table it is refused
    before any physics, where ``auto`` (the default) takes the fixture instead (the slow tests)."""
    item = task_item("inhand-level3-dmg", 2)
    assert item.object == "spatula"
    ctx, b = make_context("pybullet", item)
    try:
        out = _planner(replace(SHORT, support="table")).run_trial(ctx)
    finally:
        b.close()
    assert out.failure == "unreachable" and "no stable rest pose" in out.message
    assert out.extra["support"] == "table" and b.time == 0.0


def test_plan_to_region_ends_in_the_region():
    """Level II: the plan's final principal contact is on the patch nearest the desired one (within a patch)."""
    from benchharness.strategies.dmg.execution import plan_to_region
    from benchharness.strategies.dmg.planner import Grasp, surface_contacts

    item = task_item("inhand-level2-dmg-regions", 0)
    planner = _planner()
    pl, dmg = planner.placement(item.object), planner.graph(item.object)
    ini = Grasp(pl.to_ours(item.contacts["initial"]), pl.quat_to_ours(item.initial[3:]))
    des = pl.to_ours(item.contacts["desired"])
    p = plan_to_region(dmg, ini, des)
    assert p.reached_goal
    z = des[1] - des[0]
    on, _ = surface_contacts(dmg.mesh, des, z / np.linalg.norm(z))
    assert (
        np.linalg.norm(p.final.contacts[p.start.principal] - on[p.start.principal])
        < dmg.config.patch_size
    )
    assert not np.all(np.isfinite(item.desired))  # Level II: no desired hand pose


def test_region_task_file_matches_derivation(tmp_path):
    from benchharness.paths import tasks_dir
    from benchharness.runner.contact_regions import write_region_tasks

    fresh = write_region_tasks(tmp_path / "r.csv")
    assert fresh.read_text() == (tasks_dir() / "inhand" / "level2_dmg_regions.csv").read_text()


def test_dmg_execution_refuses_other_robots():
    item = _short_item()
    from benchharness.backends.interface import PhysicsConfig
    from benchharness.plugin import get_manager
    from benchharness.runner.contract import TimeBudget, TrialContext
    from benchharness.runner.recorder import TrialRecorder

    m = get_manager()
    b = m.create("backend", "pybullet", config=PhysicsConfig())
    try:
        ctx = TrialContext(
            item=item,
            trial_index=1,
            robot=m.create("robot", "pr2"),
            backend=b,
            sensors={},
            rng=np.random.default_rng(0),
            budget=TimeBudget(),
            recorder=TrialRecorder(),
            physics=PhysicsConfig(),
        )
        with pytest.raises(ValueError, match="pr2-gripper"):
            _planner().run_trial(ctx)
    finally:
        b.close()


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("row", range(4))
def test_published_dmg_tasks(backend, row):
    """The four published tasks with the protocol's 5 s hold: three on the table, the spatula (whose
    blade cannot lie with the grasp axis horizontal) in the fixture."""
    item = task_item("inhand-level3-dmg", row)
    ctx, b = make_context(backend, item)
    try:
        out = _planner(DMGExecConfig()).run_trial(ctx)
    finally:
        b.close()
    assert out.extra["support"] == ("fixture" if item.object == "spatula" else "table")
    assert out.failure is None and not out.dropped, out.message
    v = score_inhand(item, out)
    assert v.outcome["metrics"]["err_pos"] < 0.01


@pytest.mark.slow
def test_dmg_execution_is_deterministic():
    reached = []
    for _ in range(2):
        ctx, b = make_context("pybullet", _short_item(), seed=5)
        try:
            reached.append(np.asarray(_planner().run_trial(ctx).reached))
        finally:
            b.close()
    np.testing.assert_allclose(reached[0], reached[1], atol=1e-9)


def test_the_support_is_a_strategy_option():
    from benchharness.plugin import get_manager
    from benchharness.runner.options import OptionError, normalise_options

    reg = get_manager().get("strategy", "dmg")
    assert normalise_options(reg.options, "dmg", ["execution.support=fixture"], reg.factory) == (
        ("execution.support", "fixture"),
    )
    with pytest.raises(OptionError, match="support"):
        normalise_options(reg.options, "dmg", ["execution.support=vise"], reg.factory)
    with pytest.raises(OptionError, match="fixture_height must be > 0"):
        normalise_options(reg.options, "dmg", ["execution.fixture_height=0"], reg.factory)
