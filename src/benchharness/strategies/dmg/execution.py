"""Executing DMG plans physically with the PR2 gripper (``--strategy dmg --robot pr2-gripper``).

The paper evaluates the planned solutions only and leaves execution open
("it can use pushing against the environment, bi-manual pushing, etc.").
We execute a plan with the table-supported primitives of
:mod:`benchharness.strategies.pivoting.rig`:

* the object rests on the table in a stable pose chosen so that the grasp
  axis is horizontal and the whole plan keeps the gripper clear of the
  table (:func:`choose_rest`); where no pose serves (the spatula), an ideal
  fixture holds it above the table instead until the final lift
  (``DMGExecConfig.support``);
* the robot grasps it at the task's initial grasp (plus set-up noise) and the
  set-up grasp is measured;
* each primitive of the plan is one loosen / move / tighten cycle: a
  **rotation** turns the loosened gripper about the contact normal (the
  grasp axis, through the tool centre point), a **translation** slides the
  loosened fingers along the object through the patch centres of the path;
  the table holds the object while the pads slide. Hand targets are
  expressed in the tracked object frame at the start of each primitive;
* finally the grasp is tightened, the object lifted off the table and held
  for 5 s (stability, drop detection), and the reached grasp (hand pose and
  the fingers' measured contact points) is reported in the task's frame.

Level II tasks (desired contact region only) are planned to the region:
the goal is any admissible state on the patch nearest the desired principal
contact, the cheapest one from the start (:func:`plan_to_region`).

Planning time (the query) and execution time (simulated seconds from the
first primitive to the last tightening) are reported separately; the graph
construction ("DMG time") goes to ``extra``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose
from ...runner.contract import TrialContext, TrialOutcome
from ..pivoting.config import ExecutionConfig

__all__ = [
    "DMGExecConfig",
    "execute_trial",
    "plan_waypoints",
    "plan_to_region",
    "choose_rest",
    "Waypoint",
]


@dataclass(frozen=True)
class DMGExecConfig:
    """Execution parameters (see :class:`~benchharness.strategies.pivoting.config.ExecutionConfig`).

    ``regrip_between_primitives``: tighten after every primitive (True, the
    default) or only at the end of the plan. ``corrections``: after each
    primitive, up to this many loosen / move / tighten corrections towards
    the primitive's end pose on the tracked object, until within
    ``correction_position`` (m) and ``correction_angle`` (deg)
    (:meth:`~benchharness.strategies.pivoting.rig.TableRig.servo`). ``require_goal``: fail as
    ``unreachable`` when the planner could not connect the goal (False: the
    best-effort plan is executed and scored, as the planner's own results).
    ``support``: what holds the object while the grasp changes: ``"table"``
    (it rests on the table in a stable pose that keeps the grasp axis
    horizontal; no such pose: ``unreachable``), ``"fixture"`` (an ideal clamp
    holds it ``fixture_height`` m above the table in its most probable stable
    pose, opened before the final lift; :meth:`TableRig.build
    <benchharness.strategies.pivoting.rig.TableRig.build>`), ``"auto"`` (the
    default: the table where a rest pose serves, else the fixture).
    """

    execution: ExecutionConfig = field(default_factory=ExecutionConfig)
    #: tighten after every primitive (false: only at the end of the plan)
    regrip_between_primitives: bool = True
    #: fail as unreachable when the planner could not connect the goal (false: execute the best effort)
    require_goal: bool = False
    #: closed-loop corrections after each primitive (0: open loop)
    corrections: int = 2
    #: m, a correction's position tolerance
    correction_position: float = 0.001
    #: deg, a correction's angle tolerance
    correction_angle: float = 1.0
    #: what holds the object while the grasp changes: the table, an ideal fixture, or auto (the
    #: table where a rest pose keeps the grasp axis horizontal, else the fixture)
    support: Literal["auto", "table", "fixture"] = "auto"
    #: m, how far above the table the fixture holds the object
    fixture_height: float = 0.2

    def __post_init__(self) -> None:
        if self.support not in ("auto", "table", "fixture"):
            raise ValueError(f"support must be 'auto', 'table' or 'fixture', got {self.support!r}")
        if not (math.isfinite(self.fixture_height) and self.fixture_height > 0):
            raise ValueError(f"fixture_height must be > 0 m, got {self.fixture_height!r}")


@dataclass(frozen=True)
class Waypoint:
    """A hand pose on the plan (our object frame) and the primitive that reaches it."""

    kind: str  #: "setup", "rotate" or "translate"
    pose: Pose
    patch: int


def _hand_pose(dmg, patch: int, theta: float) -> Pose:
    c = 0.5 * (dmg.patches.centers[patch] + dmg.opposite[patch])
    return Pose.from_rotation(c, Rotation.from_matrix(dmg.gripper_axes(patch, theta)))


def plan_waypoints(dmg, plan) -> list[Waypoint]:
    """The plan's hand poses, one per graph state (angles exact at both ends), with their primitive kind."""
    step = math.radians(dmg.config.angle_step)
    out: list[Waypoint] = []
    prev = None
    for i, s in enumerate(plan.states):
        patch, k = dmg.unstate(s)
        if i == 0:
            pose = _hand_pose(dmg, patch, plan.start.theta)
            kind = "setup"
        elif i == len(plan.states) - 1:
            pose = Pose.from_rotation(
                plan.final.position, Rotation.from_quat(plan.final.quaternion)
            )
            kind = "rotate" if patch == prev else "translate"
        else:
            pose = _hand_pose(dmg, patch, k * step)
            kind = "rotate" if patch == prev else "translate"
        out.append(Waypoint(kind, pose, patch))
        prev = patch
    if len(plan.states) == 1:  # a rotation within the start node
        out.append(
            Waypoint(
                "rotate",
                Pose.from_rotation(plan.final.position, Rotation.from_quat(plan.final.quaternion)),
                out[0].patch,
            )
        )
    return out


def group_primitives(waypoints: list[Waypoint]) -> list[tuple[str, list[Pose]]]:
    """Consecutive waypoints of one kind as one primitive: (kind, poses)."""
    groups: list[tuple[str, list[Pose]]] = []
    for w in waypoints[1:]:
        if groups and groups[-1][0] == w.kind:
            groups[-1][1].append(w.pose)
        else:
            groups.append((w.kind, [w.pose]))
    return groups


def plan_to_region(dmg, initial, desired_contacts: np.ndarray):
    """Level II: plan from ``initial`` (a :class:`~.planner.Grasp`) to any grasp with the principal
    finger on the patch nearest the desired principal contact; the cheapest such state wins."""
    import networkx as nx

    from .planner import (
        DMGNoPathError,
        DMGPath,
        _final_grasp,
        _primitives,
        snap_grasp,
        surface_contacts,
    )

    t0 = time.perf_counter()
    start = snap_grasp(dmg, initial)
    c = np.asarray(desired_contacts, float)[:2]
    z = c[1] - c[0] if start.principal == 0 else c[0] - c[1]
    z = z / np.linalg.norm(z)
    on, _ = surface_contacts(dmg.mesh, c, z)
    p = on[start.principal]
    pt = dmg.patches
    usable = np.flatnonzero(dmg.admissible.any(axis=1) & (pt.normals @ -z >= 0.5))
    if len(usable) == 0:
        raise DMGNoPathError("no admissible state faces the desired region")
    patch = int(usable[np.argmin(np.linalg.norm(pt.centers[usable] - p, axis=1))])
    dist, paths = nx.single_source_dijkstra(dmg.graph, start.state, weight="weight")
    goals = [
        dmg.state(patch, k)
        for k in np.flatnonzero(dmg.admissible[patch])
        if dmg.state(patch, k) in dist
    ]
    reached = bool(goals)
    if not goals:  # disconnected: the reachable state nearest the region
        goals = [
            min(
                sorted(dist),
                key=lambda s: (np.linalg.norm(pt.centers[dmg.unstate(s)[0]] - p), dist[s]),
            )
        ]
    best = min(goals, key=lambda s: (dist[s], s))
    path = paths[best]
    end_patch, end_k = dmg.unstate(path[-1])
    theta_end = end_k * math.radians(dmg.config.angle_step)
    prims = _primitives(dmg, path, start.theta, theta_end)
    final = _final_grasp(dmg, end_patch, theta_end, start.principal)
    goal = snap_grasp(dmg, final, principal=start.principal)
    return DMGPath(
        start=start,
        goal=goal,
        states=tuple(int(s) for s in path),
        primitives=prims,
        final=final,
        cost=float(dist[best]),
        reached_goal=reached,
        plan_time_s=time.perf_counter() - t0,
    )


def choose_rest(
    model,
    poses: list[Pose],
    width: float,
    cfg: ExecutionConfig,
    fixture_height: float | None = None,
) -> tuple[Pose, float]:
    """Where the object lies while the grasp changes, and the gripper's worst clearance there.

    On the table (``fixture_height`` None): the stable rest pose that keeps
    the grasp axis horizontal with the most gripper clearance over ``poses``.
    In a fixture ``fixture_height`` m above the table: the most probable
    stable pose, whatever the grasp axis, whose clearance is at least
    ``cfg.motion.min_clearance`` (else the one with the most).
    ``poses`` are hand poses in the object frame (set-up, pre-grasp and the
    plan); returns (rest pose on a table at z = 0, its worst clearance in m).
    """
    from ..pivoting.rig import clearance, stable_rest_poses

    axis = poses[0].rotation.apply([0.0, 0.0, 1.0])
    fixture = fixture_height is not None
    # in a fixture any stable pose serves: the grasp axis may point anywhere
    rests = stable_rest_poses(
        model.surface, model.mass.com, axis, **({"max_tilt_deg": 90.0} if fixture else {})
    )
    if not rests:
        return None, -np.inf
    opening = width + 0.03
    floor = cfg.motion.table_height - (fixture_height or 0.0)
    scored = [
        (min(clearance(r * h, opening, floor, width) for h in poses), i, r)
        for i, r in enumerate(rests)
    ]
    if fixture:
        for c, _, rest in scored:
            if c >= cfg.motion.min_clearance:
                return rest, c
    c, _, rest = max(scored, key=lambda t: (t[0], -t[1]))
    return rest, c


def _task_set(item):
    from ...inhand.records import TaskSet

    c = item.contacts or {}
    return TaskSet(
        task_id=np.array([item.task_id], dtype=object),
        object=np.array([item.object], dtype=object),
        level=np.array([item.level]),
        initial=np.asarray(item.initial, float)[None],
        desired=np.asarray(item.desired, float)[None],
        contacts={k: np.asarray(v, float)[None] for k, v in c.items()},
    )


def execute_trial(planner, ctx: TrialContext, config: DMGExecConfig | None = None) -> TrialOutcome:
    """One DMG trial on the simulator (see the module docstring)."""
    from ..pivoting.rig import RigFailure, TableRig
    from .planner import DMGNoPathError, Grasp, surface_contacts

    cfg = config or DMGExecConfig()
    ex = cfg.execution
    item = ctx.item
    if getattr(item, "benchmark", None) != "inhand":
        raise ValueError("the DMG strategy runs in-hand tasks")
    if getattr(ctx.robot, "name", "") != "pr2-gripper":
        raise ValueError(
            f"DMG execution drives the pr2-gripper robot, got {getattr(ctx.robot, 'name', ctx.robot)!r}"
        )
    for stage in ("initial", "desired"):
        c = (item.contacts or {}).get(stage)
        if c is None or len(c) < 2:
            raise ValueError(f"task {item.task_id!r}: the DMG needs two {stage} contact points")
    obj = item.object
    level2 = int(item.level) == 2 or not np.all(np.isfinite(item.desired))
    pl = planner.placement(obj)
    dmg = planner.graph(obj)  # built once per object and strategy instance: "DMG time"
    ini_c = pl.to_ours(np.asarray(item.contacts["initial"], float)[:2])
    ini_q = pl.quat_to_ours(np.asarray(item.initial[3:], float))
    try:
        if level2:
            plan = plan_to_region(
                dmg,
                Grasp(ini_c, ini_q),
                pl.to_ours(np.asarray(item.contacts["desired"], float)[:2]),
            )
        else:
            plan = planner.plan_task(_task_set(item), 0).plan
    except DMGNoPathError as e:
        return TrialOutcome(
            failure="unreachable",
            message=f"no DMG plan: {e}",
            extra={"dmg_time_s": dmg.build_time_s, "dmg_surface": planner.surface.model},
        )
    info = {
        "dmg_time_s": dmg.build_time_s,
        "dmg_surface": planner.surface.model,  # the model the contact errors must be scored on
        "reached_goal_node": plan.reached_goal,
        "primitives": [
            (p.kind, round(math.degrees(p.angle), 2) if p.kind == "rotate" else round(p.length, 4))
            for p in plan.primitives
        ],
    }
    if cfg.require_goal and not plan.reached_goal:
        return TrialOutcome(
            failure="unreachable",
            message="the DMG goal is not connected to the start",
            plan_time_s=plan.plan_time_s,
            extra=info,
        )
    # the set-up grasp: the task's initial grasp moved onto our mesh along its closing line
    zi = Rotation.from_quat(ini_q).apply([0.0, 0.0, 1.0])
    on, _ = surface_contacts(dmg.mesh, ini_c, zi)
    principal = plan.start.principal  # task index of the principal finger (our left finger)
    setup_pose = Pose.from_rotation(on.mean(axis=0), Rotation.from_quat(ini_q))
    width = float(np.linalg.norm(on[0] - on[1]))
    waypoints = plan_waypoints(dmg, plan)
    prims = group_primitives(waypoints)
    model = planner.object_model(obj)
    pre = Pose(
        setup_pose.p - setup_pose.rotation.apply([ex.setup.approach_clearance, 0.0, 0.0]),
        setup_pose.q,
    )
    hand_poses = [setup_pose, pre] + [w.pose for w in waypoints]
    fixture = None
    rest, worst = None, -np.inf
    if cfg.support != "fixture":
        rest, worst = choose_rest(model, hand_poses, width, ex)
    on_table = rest is not None and worst >= ex.motion.min_clearance
    if cfg.support == "fixture" or (cfg.support == "auto" and not on_table):
        fixture = cfg.fixture_height
        rest, worst = choose_rest(model, hand_poses, width, ex, fixture)
    info["support"] = "table" if fixture is None else "fixture"
    info["rest_clearance_mm"] = None if rest is None else worst * 1e3
    if rest is None or worst < ex.motion.min_clearance:
        if rest is None:
            why = (
                "the object has no stable pose"
                if fixture
                else "no stable rest pose keeps the grasp axis horizontal"
            )
        else:
            why = f"on every stable rest pose the plan brings the gripper within {worst * 1e3:.1f} mm of the table"
        return TrialOutcome(
            failure="unreachable",
            message=f"cannot execute {'in the fixture' if fixture else 'on the table'}: {why}",
            plan_time_s=plan.plan_time_s,
            extra=info,
        )
    info["rest_pose"] = rest.as_array().tolist()
    rig = TableRig(ctx.backend, ctx.robot, model, ex, ctx.rng)
    rig.build(rest, fixture_height=fixture)
    try:
        setup = rig.setup_grasp(setup_pose, width)
        t_exec = ctx.backend.time
        corrections = []
        for k, (kind, poses) in enumerate(prims):
            ctx.recorder.event(
                "primitive",
                index=k,
                primitive=kind,
                waypoints=len(poses),
                object_pose=ctx.backend.get_pose(rig.body).as_array(),
                hand_in_object=rig.hand_in_object().as_array(),
            )
            rig.loosen()
            rig.follow(poses)
            if cfg.regrip_between_primitives:
                rig.tighten()
            if cfg.corrections > 0:
                if not cfg.regrip_between_primitives:
                    rig.tighten()
                corrections.append(
                    rig.servo(
                        poses[-1],
                        cfg.correction_position,
                        math.radians(cfg.correction_angle),
                        cfg.corrections,
                    )
                )
        info["corrections"] = corrections
        if not cfg.regrip_between_primitives:
            rig.tighten()
        exec_time = ctx.backend.time - t_exec
        centroids = rig.contact_points_object()
        hold = rig.lift_and_hold()
        contacts = None if hold.dropped else rig.pad_contacts_object()
    except RigFailure as e:
        return TrialOutcome(
            failure=e.cause,
            dropped=e.cause == "dropped",
            message=str(e),
            plan_time_s=plan.plan_time_s,
            extra=info,
        )
    reached = rig.hand_in_object()

    def published(pose: Pose) -> np.ndarray:
        return np.concatenate([pl.to_published(pose.p[None])[0], pl.quat_to_published(pose.q)])

    reached_contacts = None
    if contacts is not None:  # rig order: left (principal) finger first -> task order
        ordered = np.empty((2, 3))
        ordered[principal], ordered[1 - principal] = contacts[0], contacts[1]
        reached_contacts = pl.to_published(ordered).tolist()
    if centroids is not None:
        info["contact_centroids"] = pl.to_published(centroids).tolist()
    info.update(
        hold={
            "stable": hold.stable,
            "drift_mm": hold.drift_position * 1e3,
            "drift_deg": hold.drift_angle_deg,
            "lift_slip_mm": hold.lift_slip_position * 1e3,
            "lift_slip_deg": hold.lift_slip_angle_deg,
        },
        planned_final=np.concatenate(
            [
                pl.to_published(plan.final.position[None])[0],
                pl.quat_to_published(plan.final.quaternion),
            ]
        ).tolist(),
    )
    return TrialOutcome(
        reached=None if hold.dropped else published(reached),
        setup=published(setup),
        dropped=hold.dropped,
        plan_time_s=plan.plan_time_s,
        exec_time_s=exec_time,
        reached_contacts=reached_contacts,
        message=hold.message,
        extra=info,
    )
