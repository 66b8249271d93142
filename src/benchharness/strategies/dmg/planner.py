"""Planning on the DMG: grasps in, primitive motions out (the paper's "Plan time").

A grasp (two contact points and the gripper quaternion, gripper frame as in
:class:`~benchharness.strategies.dmg.config.DMGGripperModel`) is mapped to a
graph state: the *principal* finger is the contact whose outward normal best
opposes the gripper's ``z`` axis; the state is the admissible (patch, angle)
among the patches nearest that contact minimising ``distance +
rotation_weight * angle difference``. The shortest path (Dijkstra,
networkx) between the start and goal states is read off as alternating
primitives: rotate about the contact normal, translate along the surface.

As in the DMG, the fingers end on patch centres (the principal's patch
centre and its opposite contact), so the reached contacts are off the desired
ones by up to about half a patch. The final angle is continuous: when the
desired angle lies in the final node's run of admissible angles (within half
a step) the last rotation ends exactly on it, as a rotation within a node
can.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .graph import DMGraph

__all__ = [
    "Grasp",
    "Rotate",
    "Translate",
    "Primitive",
    "SnappedGrasp",
    "DMGPath",
    "snap_grasp",
    "surface_contacts",
    "plan",
    "DMGNoPathError",
]


class DMGNoPathError(RuntimeError):
    """The start grasp cannot be placed on the graph at all."""


@dataclass(frozen=True)
class Grasp:
    """Two fingertip contacts (m) and the gripper orientation (``qx, qy, qz, qw``).

    ``position`` is the midpoint of the contacts: the benchmark derives the
    gripper position from it (paper IV-B1) and the published DMG data uses it
    unchanged.
    """

    contacts: np.ndarray
    quaternion: np.ndarray

    @property
    def position(self) -> np.ndarray:
        return np.mean(np.asarray(self.contacts, float), axis=0)

    @property
    def pose(self) -> np.ndarray:
        """``[x, y, z, qx, qy, qz, qw]`` as in the task and results files."""
        return np.concatenate([self.position, np.asarray(self.quaternion, float)])


@dataclass(frozen=True)
class Rotate:
    """Turn the gripper about the contact normal of ``patch`` by ``angle``.

    Radians, right-handed about the *outward* surface normal at the principal
    finger (the patch frame's sense), i.e. ``-angle`` about the gripper ``z``.
    """

    patch: int
    angle: float
    kind: Literal["rotate"] = "rotate"


@dataclass(frozen=True)
class Translate:
    """Slide the principal finger over ``patches`` (first = start); ``length`` is the polyline length (m)."""

    patches: tuple[int, ...]
    length: float
    kind: Literal["translate"] = "translate"


Primitive = Rotate | Translate


@dataclass(frozen=True)
class SnappedGrasp:
    """A grasp placed on the graph: state, principal contact index, exact angle (rad).

    ``distance`` is from the principal contact (projected onto the mesh) to
    the chosen patch centre."""

    state: int
    patch: int
    angle_index: int
    principal: int
    theta: float
    distance: float


@dataclass(frozen=True)
class DMGPath:
    """A DMG plan. ``reached_goal`` is False when the goal state is not
    connected to the start: the plan then ends at the connected state nearest
    the goal (by the snapping cost), the planner's best effort."""

    start: SnappedGrasp
    goal: SnappedGrasp
    states: tuple[int, ...]
    primitives: tuple[Primitive, ...]
    final: Grasp
    cost: float
    reached_goal: bool
    plan_time_s: float

    @property
    def translation_length(self) -> float:
        return float(sum(p.length for p in self.primitives if isinstance(p, Translate)))

    @property
    def total_rotation(self) -> float:
        return float(sum(abs(p.angle) for p in self.primitives if isinstance(p, Rotate)))


def _quat_to_matrix(q) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(np.asarray(q, float)).as_matrix()


def _matrix_to_quat(m) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    q = Rotation.from_matrix(m).as_quat()
    return q if q[3] >= 0 else -q


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def surface_contacts(mesh, contacts, z_axis) -> tuple[np.ndarray, int]:
    """The grasp's contacts moved onto ``mesh`` along its closing line.

    Returns the two surface points (same order as ``contacts``) and the index
    of the principal contact (the one behind the other along ``z_axis``).
    The line through the contacts along ``z_axis`` is cut with the mesh and
    the entry/exit pair nearest the given contacts is taken, so contacts that
    are slightly off our shape (a scan thicker than our model, a thin plate)
    land on the faces the fingers press on, not merely the nearest faces --
    on a 2 mm blade the nearest point to a finger 1 mm inside is often on the
    other side. Falls back to the nearest surface points if the line misses.
    """
    import trimesh

    c = np.asarray(contacts, float).reshape(-1, 3)[:2]
    z = np.asarray(z_axis, float) / np.linalg.norm(z_axis)
    principal = int(np.argmin(c @ z))
    other = 1 - principal
    span = float(np.linalg.norm(mesh.extents)) + float(np.linalg.norm(c[0] - c[1]))
    origin = c[principal] - span * z
    loc, _, tri = mesh.ray.intersects_location([origin], [z], multiple_hits=True)
    out = None
    if len(loc):
        t = (loc - origin) @ z
        order = np.argsort(t, kind="stable")
        loc, tri = loc[order], tri[order]
        entering = mesh.face_normals[tri] @ z < 0
        exits = np.flatnonzero(~entering)
        best = np.inf
        for j in np.flatnonzero(entering):
            after = exits[exits > j]
            if len(after) == 0:
                continue
            ex = int(after[0])
            cost = np.linalg.norm(loc[j] - c[principal]) + np.linalg.norm(loc[ex] - c[other])
            if cost < best:
                best, out = cost, (loc[j], loc[ex])
    pts = np.empty((2, 3))
    if out is None:
        pts[:] = trimesh.proximity.closest_point(mesh, c)[0]
    else:
        pts[principal], pts[other] = out
    return pts, principal


def snap_grasp(
    dmg: DMGraph, grasp: Grasp, principal: int | None = None, candidates: int = 12
) -> SnappedGrasp:
    """Place a grasp on the graph (see the module docstring).

    ``principal`` forces which contact is the principal finger (the goal uses
    the start's, since DMG primitives never swap the fingers' sides).
    """
    pt = dmg.patches
    R = _quat_to_matrix(grasp.quaternion)
    xg, zg = R[:, 0], R[:, 2]
    on_surface, behind = surface_contacts(dmg.mesh, grasp.contacts, zg)
    if principal is None:
        principal = behind
    p0 = on_surface[principal]
    # only patches facing the principal finger (normal against z): on a thin
    # plate the nearest patch, or the nearest surface point, can be on the far side
    facing = pt.normals @ -zg >= 0.5
    usable = np.flatnonzero(dmg.admissible.any(axis=1) & facing)
    if len(usable) == 0:
        raise DMGNoPathError(
            "no admissible state faces the gripper (object too wide for the gripper?)"
        )
    d = np.linalg.norm(pt.centers[usable] - p0, axis=1)
    order = np.argsort(d, kind="stable")[:candidates]
    step = np.deg2rad(dmg.config.angle_step)
    best = None
    for i in order:
        patch = int(usable[i])
        theta = float(np.arctan2(xg @ pt.tangent2[patch], xg @ pt.tangent1[patch]))
        ks = np.flatnonzero(dmg.admissible[patch])
        diff = np.abs(_wrap(ks * step - theta))
        j = int(np.argmin(diff))
        cost = float(d[i] + dmg.config.rotation_weight * diff[j])
        if best is None or cost < best[0] - 1e-12:
            best = (cost, patch, int(ks[j]), theta, float(d[i]))
    _, patch, k, theta, dist = best
    return SnappedGrasp(dmg.state(patch, k), patch, k, principal, theta, dist)


def _final_grasp(dmg: DMGraph, patch: int, theta: float, principal: int) -> Grasp:
    p = dmg.patches.centers[patch]
    q = dmg.opposite[patch]
    contacts = np.empty((2, 3))
    contacts[principal] = p
    contacts[1 - principal] = q
    return Grasp(contacts, _matrix_to_quat(dmg.gripper_axes(patch, theta)))


def _primitives(
    dmg: DMGraph, states, theta_start: float, theta_end: float
) -> tuple[Primitive, ...]:
    """Merge runs of rotation / translation edges into primitives.

    The start and end angles are exact (the grasp's own angle, the desired
    angle) while the states in between are discrete, so the turn from the
    start angle onto the first state and from the last state onto the end
    angle are folded into the adjacent rotation (or added as one).
    """
    step = np.deg2rad(dmg.config.angle_step)
    K = dmg.n_angles
    pk = [dmg.unstate(s) for s in states]
    last = len(pk) - 1
    lead = float(_wrap(pk[0][1] * step - theta_start))
    trail = float(_wrap(theta_end - pk[-1][1] * step))
    out: list[Primitive] = []
    if last == 0 or pk[1][0] != pk[0][0]:
        out.append(Rotate(pk[0][0], lead))
        lead = 0.0
    i = 0
    while i < last:
        j = i
        if pk[i + 1][0] == pk[i][0]:
            total = lead if i == 0 else 0.0
            while j < last and pk[j + 1][0] == pk[j][0]:
                total += step if (pk[j + 1][1] - pk[j][1]) % K == 1 else -step
                j += 1
            if j == last:
                total += trail
                trail = 0.0
            out.append(Rotate(pk[i][0], float(total)))
        else:
            length = 0.0
            while j < last and pk[j + 1][0] != pk[j][0]:
                length += float(
                    np.linalg.norm(
                        dmg.patches.centers[pk[j + 1][0]] - dmg.patches.centers[pk[j][0]]
                    )
                )
                j += 1
            out.append(Translate(tuple(p for p, _ in pk[i : j + 1]), length))
        i = j
    out.append(Rotate(pk[-1][0], trail))
    return tuple(p for p in out if not (isinstance(p, Rotate) and abs(p.angle) < 1e-12))


def _miss(dmg: DMGraph, state: int, goal: SnappedGrasp) -> float:
    """How far a state is from the goal, in the snapping cost's terms."""
    pt = dmg.patches
    p, k = dmg.unstate(state)
    xg = dmg.gripper_axes(goal.patch, goal.theta)[:, 0]
    theta = np.arctan2(xg @ pt.tangent2[p], xg @ pt.tangent1[p])
    step = np.deg2rad(dmg.config.angle_step)
    gap = np.linalg.norm(pt.centers[p] - pt.centers[goal.patch])
    return float(gap + dmg.config.rotation_weight * abs(_wrap(k * step - theta)))


def plan(dmg: DMGraph, initial: Grasp, desired: Grasp) -> DMGPath:
    """Plan from ``initial`` to ``desired`` on ``dmg`` (deterministic)."""
    import networkx as nx

    t0 = time.perf_counter()
    start = snap_grasp(dmg, initial)
    goal = snap_grasp(dmg, desired, principal=start.principal)
    G = dmg.graph
    reached = True
    try:
        cost, path = nx.single_source_dijkstra(G, start.state, goal.state, weight="weight")
    except nx.NetworkXNoPath:
        reached = False
        dist, paths = nx.single_source_dijkstra(G, start.state, weight="weight")
        best = min(sorted(dist), key=lambda s: (_miss(dmg, s, goal), dist[s]))
        cost, path = dist[best], paths[best]
    end_patch, end_k = dmg.unstate(path[-1])
    step = np.deg2rad(dmg.config.angle_step)
    if reached and abs(_wrap(goal.theta - end_k * step)) <= step / 2 + 1e-9:
        theta_end = goal.theta  # continuous rotation inside the final node
    else:
        theta_end = end_k * step
    prims = _primitives(dmg, path, start.theta, theta_end)
    final = _final_grasp(dmg, end_patch, theta_end, start.principal)
    return DMGPath(
        start=start,
        goal=goal,
        states=tuple(int(s) for s in path),
        primitives=prims,
        final=final,
        cost=float(cost),
        reached_goal=reached,
        plan_time_s=time.perf_counter() - t0,
    )
