"""Where to put our object model so the published grasp touches it (set-up of a simulated trial).

The dataset's object frames are not our mesh frames and its hand is not
ours (``docs/ingrasp.md``): placing our YCB model at ``H_i`` puts the
fingertips of the published grasp centimetres inside or outside the
surface. A simulated set-up therefore needs its own answer to "where does
the human put the object": we solve for the object pose in the palm frame
that makes every used fingertip sphere *touch* the surface at the initial
grasp ``q_0`` (signed distance of the sphere centre = its radius) while no
other part of the hand (palm, phalanges, the unused fingers) penetrates the
object.

The solve is a small nonlinear least-squares problem per candidate
orientation (the 24 axis-aligned orientations of the object, or one for a
sphere), each allowed to rotate away from the candidate at a small cost, from
three starts (the fingertip centroid and 3 cm either side of the fingertip
plane); the lowest-cost result wins, ties broken by the object's centre of
mass nearest the fingertip centroid (a short lever arm for gravity).
Distances to the surface are measured to the tangent plane of the nearest
mesh vertex (KD-tree), which is exact on flat faces and within about a
tenth of a millimetre on our 3 mm meshes' curved faces; penetration of the
hand's collision boxes is measured on the mesh vertices.

Deterministic: no randomness; results are cached per (task, object) in the
process.
"""

from __future__ import annotations

import itertools
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import torch
from scipy.optimize import least_squares
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from .hand import DTYPE, FINGERS, TIP_LINKS, HandKinematics, default_urdf

__all__ = ["InGraspPlacement", "HandGeometry", "hand_geometry", "place_object"]


@dataclass(frozen=True)
class InGraspPlacement:
    """The object's pose in the palm frame at the initial grasp and how well it fits."""

    pose: np.ndarray  #: 4x4, object (mesh / body) frame in the palm frame
    tip_gaps: (
        np.ndarray
    )  #: (k,) m, surface distance minus sphere radius per used fingertip (0 = touching)
    penetration: float  #: m, deepest object vertex inside any other hand part (0 = clear)
    cost: float  #: final least-squares cost
    rotation_change_deg: float  #: how far the pose turned away from its axis-aligned candidate
    #: (k,) deg, per used fingertip: angle between the squeeze direction (towards the fingertip
    #: centroid) and the surface's inward normal at the contact (<= the friction cone's half
    #: angle: the grip presses the object instead of sliding along it)
    grip_angles_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def max_gap(self) -> float:
        return float(np.max(np.abs(self.tip_gaps)))


@dataclass(frozen=True)
class HandGeometry:
    """The hand's collision shapes per link (from the URDF): boxes (centre pose, half extents) and spheres."""

    boxes: dict[
        str, list[tuple[np.ndarray, np.ndarray]]
    ]  #: link -> [(4x4 in link frame, half extents)]
    spheres: dict[str, list[tuple[np.ndarray, float]]]  #: link -> [(centre in link frame, radius)]


def _origin(el: ET.Element | None) -> np.ndarray:
    m = np.eye(4)
    if el is None:
        return m
    xyz = [float(v) for v in el.get("xyz", "0 0 0").split()]
    rpy = [float(v) for v in el.get("rpy", "0 0 0").split()]
    m[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
    m[:3, 3] = xyz
    return m


@lru_cache(maxsize=4)
def hand_geometry(urdf: str | None = None) -> HandGeometry:
    """Collision boxes and spheres of every link of the Allegro URDF (primitive shapes only)."""
    root = ET.parse(str(urdf or default_urdf())).getroot()
    boxes: dict[str, list] = {}
    spheres: dict[str, list] = {}
    for link in root.findall("link"):
        name = link.get("name")
        for col in link.findall("collision"):
            o = _origin(col.find("origin"))
            g = col.find("geometry")
            if g is None:
                continue
            if g.find("box") is not None:
                size = np.array([float(v) for v in g.find("box").get("size").split()])
                boxes.setdefault(name, []).append((o, size / 2.0))
            elif g.find("sphere") is not None:
                spheres.setdefault(name, []).append(
                    (o[:3, 3], float(g.find("sphere").get("radius")))
                )
            else:
                raise ValueError(
                    f"link {name}: only box and sphere collision shapes are supported here"
                )
    return HandGeometry(boxes, spheres)


def link_frames(hand: HandKinematics, q16: np.ndarray) -> dict[str, np.ndarray]:
    """Every link frame of the hand in the palm frame at ``q16`` (4x4 each)."""
    out = {"palm_link": np.eye(4)}
    with torch.no_grad():
        for i, f in enumerate(FINGERS):
            q = torch.as_tensor(np.asarray(q16, float)[4 * i : 4 * i + 4][None], dtype=DTYPE)
            for name, tf in hand.chains[f].forward_kinematics(q, end_only=False).items():
                out[name] = tf.get_matrix()[0].numpy()
    return out


def _rotations(symmetric: bool) -> list[np.ndarray]:
    """The 24 proper axis-aligned rotations (one for a sphere), in a fixed order."""
    if symmetric:
        return [np.eye(3)]
    out = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            m = np.zeros((3, 3))
            for r, (c, s) in enumerate(zip(perm, signs)):
                m[r, c] = s
            if np.linalg.det(m) > 0:
                out.append(m)
    return out


def place_object(
    hand: HandKinematics,
    q16: np.ndarray,
    fingers: tuple[str, ...],
    vertices: np.ndarray,
    normals: np.ndarray,
    com: np.ndarray,
    *,
    symmetric: bool = False,
    clearance: float = 0.001,
    w_rot: float = 0.003,
    w_com: float = 0.02,
    max_vertices: int = 400,
    refine: int = 4,
    grip_cone_deg: float | None = None,
    fit_tol: float = 0.0005,
) -> InGraspPlacement:
    """Solve the object pose in the palm frame so ``fingers``' tips touch the surface at ``q16``.

    ``vertices``/``normals``: the object's surface mesh in its body frame
    (outward normals); ``com``: its centre of mass (body frame). ``clearance``:
    margin (m) kept between the object and every other hand part. ``w_rot``:
    cost per radian of turning away from an axis-aligned candidate; ``w_com``:
    cost per metre of centre of mass away from the fingertip centroid (both
    tie-breakers: the fingertip gaps weigh 1 per metre). ``max_vertices``:
    mesh vertices (every n-th) used for penetration while solving (all are
    used for the reported figure); ``refine``: candidates solved with
    penetration after the contacts-only first pass.

    ``grip_cone_deg`` (None: off): the friction cone's half angle. With it the
    placement is chosen like a person setting the object into the grasp: of
    the candidate poses whose fingertips touch (gaps and penetration within
    ``fit_tol``), the one whose squeeze directions (each fingertip towards the
    fingertip centroid, the direction the grip pushes) lie best inside the
    friction cones around the surface normals (least summed excess angle),
    then the best fit. Without it a pose may touch all fingertips on faces
    the squeeze only slides along, and the grip ejects the object as soon as
    it is released (docs/ingrasp.md, "Set-up drops").
    """
    geo = hand_geometry(hand.urdf_path)  # the collision shapes of the same description
    frames = link_frames(hand, q16)
    tips_used = {TIP_LINKS[f] for f in fingers}
    tip_c, tip_r = [], []
    for f in fingers:
        ((c, r),) = geo.spheres[TIP_LINKS[f]]
        tip_c.append((frames[TIP_LINKS[f]] @ np.append(c, 1.0))[:3])
        tip_r.append(r)
    tip_c, tip_r = np.array(tip_c), np.array(tip_r)
    # obstacles: every other shape, as (world<-box 4x4, half extents) and (centre, radius)
    obst_boxes = [(frames[l] @ o, h) for l, lst in geo.boxes.items() for o, h in lst if l in frames]
    obst_sph = [
        ((frames[l] @ np.append(c, 1.0))[:3], r)
        for l, lst in geo.spheres.items()
        for c, r in lst
        if l in frames and l not in tips_used
    ]
    inv_boxes = [(np.linalg.inv(m), h) for m, h in obst_boxes]
    tree = cKDTree(vertices)
    centroid = tip_c.mean(axis=0)
    sq_dir = centroid - tip_c
    sq_dir = sq_dir / np.maximum(np.linalg.norm(sq_dir, axis=1, keepdims=True), 1e-12)
    nrm = np.cross(tip_c[1] - tip_c[0], tip_c[-1] - tip_c[0])
    nrm = nrm / max(np.linalg.norm(nrm), 1e-12)

    def pose_of(x: np.ndarray, r0: np.ndarray) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = r0 @ Rotation.from_rotvec(x[3:]).as_matrix()
        m[:3, 3] = x[:3]
        return m

    def gaps(m: np.ndarray) -> np.ndarray:
        local = (tip_c - m[:3, 3]) @ m[:3, :3]  # tip centres in the object frame
        _, idx = tree.query(local)
        return np.einsum("ij,ij->i", local - vertices[idx], normals[idx]) - tip_r

    def grip_angles(m: np.ndarray) -> np.ndarray:
        local = (tip_c - m[:3, 3]) @ m[:3, :3]
        _, idx = tree.query(local)
        inward = -(normals[idx] @ m[:3, :3].T)
        inward = inward / np.maximum(np.linalg.norm(inward, axis=1, keepdims=True), 1e-12)
        return np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", inward, sq_dir), -1.0, 1.0)))

    def grip_excess(m: np.ndarray) -> float:
        if grip_cone_deg is None:
            return 0.0
        return float(np.sum(np.maximum(grip_angles(m) - grip_cone_deg, 0.0)))

    stride = max(1, len(vertices) // max_vertices)
    sub = vertices[::stride]

    def penetration(m: np.ndarray, pts: np.ndarray = sub) -> np.ndarray:
        v = pts @ m[:3, :3].T + m[:3, 3]
        pen = []
        for inv, h in inv_boxes:
            loc = v @ inv[:3, :3].T + inv[:3, 3]
            depth = np.min(h + clearance - np.abs(loc), axis=1)  # > 0 inside the (grown) box
            pen.append(np.max(depth, initial=0.0))
        for c, r in obst_sph:
            pen.append(max(0.0, float(r + clearance - np.min(np.linalg.norm(v - c, axis=1)))))
        return np.maximum(np.array(pen), 0.0)

    def residuals(x: np.ndarray, r0: np.ndarray, with_pen: bool) -> np.ndarray:
        m = pose_of(x, r0)
        com_w = m[:3, :3] @ com + m[:3, 3]
        parts = [gaps(m), w_rot * x[3:], w_com * (com_w - centroid)]
        if with_pen:
            parts.append(3.0 * penetration(m))
        return np.concatenate(parts)

    scale = np.array([0.01, 0.01, 0.01, 0.1, 0.1, 0.1])
    # stage 1: every candidate, fingertip contacts only (cheap); rank with the penetration at the result
    ranked = []
    for i, r0 in enumerate(_rotations(symmetric)):
        for j, off in enumerate((0.0, 0.03, -0.03)):
            x0 = np.concatenate([centroid + off * nrm - r0 @ com, np.zeros(3)])
            sol = least_squares(
                residuals,
                x0,
                args=(r0, False),
                method="trf",
                diff_step=1e-4,
                max_nfev=100,
                x_scale=scale,
            )
            m1 = pose_of(sol.x, r0)
            score = 2.0 * sol.cost + float(np.sum((3.0 * penetration(m1)) ** 2))
            ranked.append((round(score, 10), i, j, sol.x, r0, m1))
    ranked.sort(key=lambda e: e[:3])

    def refine_one(x1: np.ndarray, r0: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
        sol = least_squares(
            residuals,
            x1,
            args=(r0, True),
            method="trf",
            diff_step=1e-4,
            max_nfev=200,
            x_scale=scale,
        )
        return float(2.0 * sol.cost), sol.x, pose_of(sol.x, r0)

    def fits(m2: np.ndarray) -> bool:
        return (
            float(np.max(np.abs(gaps(m2)))) <= fit_tol
            and float(np.max(penetration(m2, vertices) - clearance, initial=0.0)) <= fit_tol
        )

    # stage 2: the best few, with the hand's other parts kept out of the object; the first of the
    # least (cost, turn away from the candidate's axes)
    def fit_key(e: tuple[float, np.ndarray, np.ndarray]) -> tuple:
        return (round(e[0], 10), float(np.linalg.norm(e[1][3:])))

    cost, x, m = min((refine_one(x1, r0) for _, _, _, x1, r0, _ in ranked[:refine]), key=fit_key)
    if grip_cone_deg is not None and grip_excess(m) > 0.0:
        # the best fit does not grip: also refine the touching candidates that grip best
        # (penetration is only fixed in stage 2) and take the touching pose that grips best
        touching = [e for e in ranked if float(np.max(np.abs(gaps(e[5])))) <= fit_tol]
        touching.sort(key=lambda e: (round(grip_excess(e[5]), 6), e[0], e[1], e[2]))
        pool = [(cost, x, m)]
        pool += [refine_one(x1, r0) for _, _, _, x1, r0, _ in touching[: 2 * refine]]

        def grip_key(e: tuple[float, np.ndarray, np.ndarray]) -> tuple:
            ok = fits(e[2])
            # none fits: the best fit, as without the cone
            return (not ok, round(grip_excess(e[2]), 6) if ok else 0.0, *fit_key(e))

        cost, x, m = min(pool, key=grip_key)
    return InGraspPlacement(
        m,
        gaps(m),
        float(np.max(penetration(m, vertices) - clearance, initial=0.0).clip(min=0.0)),
        cost,
        float(np.degrees(np.linalg.norm(x[3:]))),
        grip_angles(m),
    )


def object_surface_arrays(model) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """(vertices, outward vertex normals, centre of mass, is-a-sphere) of an :class:`ObjectModel`."""
    mesh = model.surface
    com = np.asarray(model.body_kwargs().get("com") or np.zeros(3), float)
    ext = np.asarray(mesh.extents, float)
    symmetric = bool(
        np.ptp(ext) < 1e-6 and abs(mesh.volume - np.pi * ext[0] ** 3 / 6.0) < 0.02 * mesh.volume
    )
    return np.asarray(mesh.vertices, float), np.asarray(mesh.vertex_normals, float), com, symmetric
