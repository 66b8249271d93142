"""Pivoting with the PR2 gripper against the table, on both backends.

Checks against measurements the strategy does not command: the object's
pose read from the engine and the tool frame's pose (not the stage joint
targets). Default-suite cases use a 1 s hold instead of the protocol's 5 s.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from gripper_helpers import BACKENDS, make_context, task_item
from scipy.spatial.transform import Rotation

from benchharness.geometry import Pose
from benchharness.runner.scoring import score_inhand
from benchharness.strategies.pivoting.config import (
    ExecutionConfig,
    GripConfig,
    HoldConfig,
    PivotConfig,
    SetupConfig,
)

#: A pivot must end within this of the commanded angle (deg), measured on the object's engine pose.
PIVOT_TOLERANCE_DEG = 1.5
SHORT_HOLD = HoldConfig(hold_time=1.0)


def _rig(
    backend_name: str,
    seed: int = 0,
    setup: SetupConfig | None = None,
    grip: GripConfig | None = None,
):
    from benchharness.objects import load_object
    from benchharness.strategies.pivoting.rig import TableRig
    from benchharness.strategies.pivoting.tasks import initial_grasp, rest_pose

    item = task_item("inhand-level1-pivoting-generated", 0)  # gelatin box, -18.3 deg
    ctx, b = make_context(backend_name, item, seed)
    cfg = ExecutionConfig(setup=setup or SetupConfig(), grip=grip or GripConfig(), hold=SHORT_HOLD)
    # the generated box: its grasp axis is the object's x, which _tool_in_object_angle assumes
    model = load_object("gelatin box", model="generated")
    rest = rest_pose("gelatin box", (1, 0, 0), 0.0, "generated")
    rig = TableRig(b, ctx.robot, model, cfg, ctx.rng)
    rig.build(rest)
    return rig, b, initial_grasp("gelatin box", (1, 0, 0), 0.0, rest, "generated")


def _tool_in_object_angle(rig) -> float:
    """Angle of the tool's x axis about the grasp axis, in the object frame, from engine poses only (rad)."""
    obj = rig.backend.get_pose(rig.body)
    tool = rig.backend.get_link_pose(rig.robot.body, "r_gripper_tcp")
    x = obj.rotation.inv().apply(tool.rotation.apply([1.0, 0.0, 0.0]))
    return math.atan2(x[1], -x[2])  # in the object's y-z plane (grasp axis = object x), from "down"


@pytest.mark.parametrize("backend", BACKENDS)
def test_pivot_reaches_commanded_angle(backend):
    from benchharness.strategies.pivoting.strategy import run_pivots

    rig, b, hi = _rig(backend, setup=SetupConfig(position_std=0.0, angle_std=0.0))
    try:
        setup = rig.setup_grasp(hi, 0.028)
        obj0 = b.get_pose(rig.body)
        a0 = _tool_in_object_angle(rig)
        commanded = math.radians(25.0)
        target = setup * Pose.from_rotation(
            np.zeros(3), Rotation.from_rotvec([0.0, 0.0, commanded])
        )
        log = run_pivots(rig, target, PivotConfig(max_pivots=1))  # one open-loop pivot
        a1 = _tool_in_object_angle(rig)
        turned = math.degrees(a1 - a0)
        # the hand z axis is the object's -x or +x: compare magnitudes and the sense through the hand frame
        assert abs(abs(turned) - 25.0) < PIVOT_TOLERANCE_DEG, (turned, log)
        obj1 = b.get_pose(rig.body)
        moved = math.degrees((obj1.rotation * obj0.rotation.inv()).magnitude())
        assert moved < 2.0, (
            f"the table should hold the object while the gripper turns (it turned {moved:.2f} deg)"
        )
        hold = rig.lift_and_hold()
        assert not hold.dropped and hold.stable, hold.message
    finally:
        b.close()


@pytest.mark.parametrize("task", ["inhand-level1-pivoting", "inhand-level1-pivoting-generated"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_pivoting_trial_scored_by_runner(backend, task):
    from benchharness.strategies.pivoting.strategy import PivotingStrategy

    item = task_item(task, 1)  # gelatin box (the YCB scan, or the generated box), +20.3 deg
    ctx, b = make_context(backend, item)
    try:
        cfg = PivotConfig(execution=ExecutionConfig(hold=SHORT_HOLD))
        out = PivotingStrategy(cfg).run_trial(ctx)
    finally:
        b.close()
    assert not out.dropped and out.failure is None, out.message
    v = score_inhand(item, out)
    assert v.status.value == "success", v.message
    m = v.outcome["metrics"]
    assert m["err_pos"] < 0.005
    assert out.plan_time_s is not None and out.exec_time_s > 0
    # the closed loop stops within 1 deg of the desired grasp about the axis (set-up noise included)
    assert abs(out.extra["final_about_axis_deg"]) < PIVOT_TOLERANCE_DEG
    # ... turning about that axis only: the generated box's faces are parallel planes (its gelatin
    # box ends 0.01-0.44 deg off the axis, measured); the scan's are not (0.47 mm rms out of plane,
    # each ~0.5 deg off the axis) and its pads re-seat: 0.2-1.7 deg over 100 executions
    # (docs/benchmarks/parallel_gripper_sim.md)
    assert out.extra["final_off_axis_deg"] < (1.0 if task.endswith("generated") else 2.5)
    if task.endswith("generated"):
        assert m["err_or_percent"] < 1.0  # 1 % ~ 1.6 deg
    assert len(out.reached_contacts) == 2


@pytest.mark.parametrize("backend", BACKENDS)
def test_drop_is_detected(backend):
    """A 0.1 N grip cannot hold the 97 g box (needs 2 mu F > m g): lifting it must count as a drop."""
    rig, b, hi = _rig(backend)
    try:
        rig.setup_grasp(hi, 0.028)
        rig.config = replace(
            rig.config, grip=GripConfig(hold_force=0.1)
        )  # the lift's firm grip is too weak
        hold = rig.lift_and_hold()
    finally:
        b.close()
    assert hold.dropped, hold.message


@pytest.mark.parametrize("backend", BACKENDS)
def test_pivot_is_deterministic(backend):
    from benchharness.strategies.pivoting.strategy import run_pivots

    finals = []
    for _ in range(2):
        rig, b, hi = _rig(backend, seed=3)
        try:
            setup = rig.setup_grasp(hi, 0.028)
            target = setup * Pose.from_rotation(np.zeros(3), Rotation.from_rotvec([0.0, 0.0, 0.3]))
            run_pivots(rig, target, PivotConfig(max_pivots=1))
            finals.append(
                np.concatenate([b.get_pose(rig.body).as_array(), rig.hand_in_object().as_array()])
            )
        finally:
            b.close()
    np.testing.assert_allclose(finals[0], finals[1], atol=1e-9)


@pytest.mark.parametrize("model", ["ycb", "generated"])
def test_pivot_task_files_match_derivation(model):
    """Each committed task file is its model's fresh derivation (numbers to 1e-9: the scans' rest
    poses come from trimesh's stable poses of a 16k-triangle hull, whose last bits follow the CPU)."""
    from benchharness.inhand.fileformat import read_tasks
    from benchharness.paths import tasks_dir
    from benchharness.strategies.pivoting.tasks import PIVOT_TASK_FILES, derive_pivot_tasks

    fresh = derive_pivot_tasks(model=model)
    stored = read_tasks(tasks_dir() / "inhand" / PIVOT_TASK_FILES[model])
    hint = "stale: run python -m benchharness.strategies.pivoting.tasks"
    assert list(stored.task_id) == list(fresh.task_id), hint
    assert list(stored.object) == list(fresh.object), hint
    np.testing.assert_allclose(stored.initial, fresh.initial, atol=1e-9, err_msg=hint)
    np.testing.assert_allclose(stored.desired, fresh.desired, atol=1e-9, err_msg=hint)
    for k in ("source_task", "pivot_deg", "grasp_axis", "model"):
        assert list(stored.extra[k]) == list(fresh.extra[k]), (k, hint)
    rest = np.array([[float(v) for v in r.split()] for r in stored.extra["rest_pose"]])
    rest_fresh = np.array([[float(v) for v in r.split()] for r in fresh.extra["rest_pose"]])
    np.testing.assert_allclose(rest, rest_fresh, atol=2e-6, err_msg=hint)
    assert set(stored.extra["model"]) == {model}


def test_scan_pivot_tasks_grip_the_scan_across_its_flat_faces():
    """On the YCB scan the grasp axis is the gelatin box's thin axis (29.8 mm across, the published
    28 mm plus the scan's bulge), horizontal in the rest pose, the box standing on a 28 x 85 mm side
    (72.7 mm tall: the published 73), the tool frame 20 mm below the top and on the faces' mid-plane."""
    from benchharness.inhand.fileformat import read_tasks
    from benchharness.objects import load_object
    from benchharness.paths import tasks_dir
    from benchharness.strategies.pivoting.tasks import GRASP_DEPTH, grasp_axis

    ts = read_tasks(tasks_dir() / "inhand" / "level1_pivoting.csv")
    assert (
        set(ts.object) == {"gelatin box"} and len(ts.task_id) == 10
    )  # the scan's Lego cannot stand
    surface = load_object("gelatin box").surface
    a = grasp_axis("gelatin box")
    v = np.asarray(surface.vertices)
    assert np.ptp(v @ a) == pytest.approx(0.0298, abs=5e-4)
    rest = Pose.from_array([float(x) for x in ts.extra["rest_pose"][0].split()])
    w = rest.apply(v)
    assert np.ptp(w[:, 2]) == pytest.approx(0.0727, abs=1e-3)  # standing, 72.7 mm tall
    assert abs(rest.rotation.apply(a)[2]) < math.sin(math.radians(5))  # grasp axis horizontal
    for i in range(len(ts.task_id)):
        h = rest * Pose.from_array(ts.initial[i])
        assert abs(h.rotation.apply([0, 0, 1.0]) @ rest.rotation.apply(a)) == pytest.approx(1.0)
        assert h.p[2] == pytest.approx(w[:, 2].max() - GRASP_DEPTH, abs=1e-6)  # rest: 6 digits
        # on the mid-plane: as far from the faces on either side along the grasp axis
        s = (w - h.p) @ rest.rotation.apply(a)
        assert s.max() + s.min() == pytest.approx(0.0, abs=5e-4)
    # the generated shapes are built axis-aligned (docs/objects.md): their axes are exactly the frame's
    assert list(grasp_axis("gelatin box", "generated")) == [1.0, 0.0, 0.0]
    assert list(grasp_axis("Lego Duplo", "generated")) == [0.0, 1.0, 0.0]
    with pytest.raises(ValueError, match="not a pivoting object"):
        grasp_axis("apple")
    with pytest.raises(
        ValueError, match="cannot be pivoted on its 'ycb' model: the YCB scan's ends"
    ):
        grasp_axis("Lego Duplo", "ycb")


def test_pivot_angle_and_grasp_geometry():
    from benchharness.strategies.pivoting.tasks import (
        GRASP_DEPTH,
        initial_grasp,
        pivot_angle,
        rest_pose,
    )

    q0 = [0.0, 0.0, 0.0, 1.0]
    q1 = Rotation.from_rotvec([0.0, -0.3, 0.1]).as_quat()
    assert pivot_angle(q0, q1) == pytest.approx(-math.hypot(0.3, 0.1))
    rest = rest_pose("gelatin box", (1, 0, 0), 0.4, "generated")
    h = rest * initial_grasp("gelatin box", (1, 0, 0), 0.4, rest, "generated")
    assert abs(h.rotation.apply([0, 0, 1.0])[2]) < 1e-9  # grasp axis horizontal
    assert h.p[2] == pytest.approx(
        0.0365 * 2 + 5e-4 - GRASP_DEPTH, abs=1e-3
    )  # upright box, 20 mm below its top


def test_bad_inputs_are_refused():
    from benchharness.strategies.pivoting.strategy import PivotingStrategy
    from benchharness.strategies.pivoting.tasks import initial_grasp

    with pytest.raises(ValueError, match="allowed"):
        initial_grasp("cracker box", (0, 1, 0), 0.0)  # 158 mm across
    item = replace(task_item("inhand-level1-pivoting", 0), extra={}, object="apple")
    ctx, b = make_context("pybullet", item)
    try:
        with pytest.raises(ValueError, match="apple' is not a pivoting object"):
            PivotingStrategy().run_trial(ctx)
    finally:
        b.close()
    item = task_item("inhand-level1-pivoting", 0)
    item = replace(item, extra={**item.extra, "model": "scan"})
    ctx, b = make_context("pybullet", item)
    try:
        with pytest.raises(ValueError, match="model must be 'ycb' or 'generated', not 'scan'"):
            PivotingStrategy().run_trial(ctx)
    finally:
        b.close()
