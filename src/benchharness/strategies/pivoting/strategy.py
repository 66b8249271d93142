"""The pivoting baseline (Level I): turn the grasp about the grasp axis by controlling the grip force.

One trial (``benchharness run --task inhand-level1-pivoting --robot pr2-gripper --strategy pivoting``):

1. the object rests on the table in the task's rest pose; the gripper
   grasps it at the task's initial grasp plus set-up noise, firmly
   (:class:`~.config.GripConfig.hold_force`); the set-up grasp is
   *measured* (the runner discards trials more than 10 % off);
2. pivot: the grip is loosened to a light squeeze, the gripper turns about
   its grasp axis (the wrist's centre is between the pads) by the remaining
   angle, measured on the tracked object, while the table holds the object;
   the grip is tightened again. Repeated until the remaining angle is below
   the tolerance or ``max_pivots`` are spent;
3. lift off the table and hold for 5 s (stability, drops).

The reached grasp is the hand pose in the object frame measured at the end
of the hold; planning time is the (tiny) time to compute the pivot targets,
execution time the simulated time from the first loosening to the last
tightening.
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose
from ...runner.contract import TrialContext, TrialOutcome
from .config import PivotConfig
from .rig import RigFailure, TableRig

__all__ = ["PivotingStrategy", "run_pivots", "grasp_axis_angle"]


def grasp_axis_angle(current: Pose, target: Pose) -> tuple[float, float]:
    """(angle about the hand z axis, angle off it) of ``current^-1 target`` in radians."""
    rv = (current.rotation.inv() * target.rotation).as_rotvec()
    return float(rv[2]), float(np.hypot(rv[0], rv[1]))


def run_pivots(rig: TableRig, target: Pose, cfg: PivotConfig, step_deg: float = 10.0) -> list[dict]:
    """Closed-loop pivots of ``rig``'s grasp towards ``target`` (hand pose, object frame); returns a log.

    Each pivot: measure the hand in the tracked object frame, turn by the
    remaining angle about the hand's z axis (loosened), tighten. Waypoints
    every ``step_deg`` keep the slerp on the grasp axis.
    """
    log = []
    for k in range(cfg.max_pivots):
        now = rig.hand_in_object()
        err, off = grasp_axis_angle(now, target)
        log.append(
            {"pivot": k, "remaining_deg": math.degrees(err), "off_axis_deg": math.degrees(off)}
        )
        if abs(err) <= cfg.tolerance_rad:
            break
        n = max(1, int(math.ceil(abs(math.degrees(err)) / step_deg)))
        path = [
            Pose(now.p, (now.rotation * Rotation.from_rotvec([0.0, 0.0, err * j / n])).as_quat())
            for j in range(1, n + 1)
        ]
        rig.loosen()
        rig.follow(path)
        rig.tighten()
    else:
        now = rig.hand_in_object()
        err, off = grasp_axis_angle(now, target)
        log.append(
            {
                "pivot": cfg.max_pivots,
                "remaining_deg": math.degrees(err),
                "off_axis_deg": math.degrees(off),
            }
        )
    return log


class PivotingStrategy:
    """Pivoting with a parallel gripper against the table (Level I); see the module docstring."""

    benchmarks = ("inhand",)
    name = "pivoting"

    def __init__(self, config: PivotConfig | None = None) -> None:
        self.config = config or PivotConfig()

    def run_trial(self, ctx: TrialContext) -> TrialOutcome:
        from ...objects import load_object
        from .tasks import PIVOT_TASK_FILES, grasp_axis, rest_pose

        item = ctx.item
        if getattr(item, "benchmark", None) != "inhand":
            raise ValueError("the pivoting strategy runs in-hand tasks")
        extra = item.extra or {}
        # a task's hand poses are in the frame of the model it was derived on; a file without
        # the column predates the scans and was derived on the generated shapes
        kind = str(extra.get("model") or "generated")
        if kind not in PIVOT_TASK_FILES:
            raise ValueError(
                f"task {item.task_id!r}: model must be 'ycb' or 'generated', not {kind!r}"
            )
        axis_text = extra.get("grasp_axis")
        if axis_text:
            axis = tuple(float(v) for v in str(axis_text).split())
        else:
            try:
                axis = tuple(grasp_axis(str(item.object), kind))
            except ValueError as e:
                raise ValueError(f"task {item.task_id!r}: no grasp_axis column and {e}") from None
        if getattr(ctx.robot, "name", "") != "pr2-gripper":
            raise ValueError(
                f"the pivoting strategy drives the pr2-gripper robot, got {getattr(ctx.robot, 'name', ctx.robot)!r}"
            )
        cfg = self.config
        ex = cfg.execution
        t0 = time.perf_counter()
        model = load_object(
            item.object,
            **({"resolution": ex.resolution} if kind == "generated" else {"model": "ycb"}),
        )
        rest_text = extra.get("rest_pose")
        rest = (
            Pose.from_array([float(v) for v in str(rest_text).split()])
            if rest_text
            else rest_pose(
                item.object,
                axis,
                grasp_axis_angle(Pose.from_array(item.initial), Pose.from_array(item.desired))[0],
                kind,
            )
        )
        initial = Pose.from_array(item.initial)
        desired = Pose.from_array(item.desired)
        width = float(
            np.ptp(np.asarray(model.surface.vertices) @ (np.asarray(axis) / np.linalg.norm(axis)))
        )
        plan_time = time.perf_counter() - t0  # the pivot "plan": targets from the task, rest pose
        rig = TableRig(ctx.backend, ctx.robot, model, ex, ctx.rng)
        rig.build(rest)
        try:
            setup = rig.setup_grasp(initial, width)
            ctx.recorder.event("setup", hand_in_object=setup.as_array().tolist())
            t_exec = ctx.backend.time
            log = run_pivots(rig, desired, cfg)
            exec_time = ctx.backend.time - t_exec
            ctx.recorder.event("pivots", log=log)
            centroids = rig.contact_points_object()
            hold = rig.lift_and_hold()
            contacts = None if hold.dropped else rig.pad_contacts_object()
        except RigFailure as e:
            return TrialOutcome(
                failure=e.cause,
                dropped=e.cause == "dropped",
                message=str(e),
                plan_time_s=plan_time,
                extra={"object": item.object},
            )
        reached = rig.hand_in_object()
        extra = {
            "pivots": log,
            "hold": {
                "stable": hold.stable,
                "drift_mm": hold.drift_position * 1e3,
                "drift_deg": hold.drift_angle_deg,
                "lift_slip_mm": hold.lift_slip_position * 1e3,
                "lift_slip_deg": hold.lift_slip_angle_deg,
            },
            "pivot_deg": math.degrees(grasp_axis_angle(initial, desired)[0]),
            "reached_pivot_deg": math.degrees(grasp_axis_angle(setup, reached)[0]),
            "final_about_axis_deg": math.degrees(grasp_axis_angle(reached, desired)[0]),
            "final_off_axis_deg": math.degrees(grasp_axis_angle(reached, desired)[1]),
            "contact_centroids": None if centroids is None else centroids.tolist(),
        }
        return TrialOutcome(
            reached=None if hold.dropped else reached.as_array(),
            setup=setup.as_array(),
            dropped=hold.dropped,
            plan_time_s=plan_time,
            exec_time_s=exec_time,
            reached_contacts=None if contacts is None else contacts.tolist(),
            message=hold.message,
            extra=extra,
        )
