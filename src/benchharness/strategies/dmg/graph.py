"""Construction of the Dexterous Manipulation Graph (the paper's "DMG time").

A *state* is (patch, angle index): the principal finger on a patch, the
gripper turned about the patch normal by ``k * angle_step``. A state is
admissible when

1. the line along the normal exits the object at an opposite contact (ray
   cast along ``-normal``) within the gripper's opening range, with that
   contact's normal inside the friction cone around the closing direction
   (an antipodal pair), and
2. at that angle the gripper does not collide with the object: sample points
   along both fingers (``finger_clearance`` outside the surface, from the
   contacts to the palm) and across the palm (at ``finger_length`` and
   ``finger_length + palm_depth`` towards ``-x``) must all be outside the
   object. In effect the object must end within a finger length of the
   contact in the palm's direction, so the admissible angles on a face are
   those that point the palm over a nearby edge.

The DMG's *nodes* are the maximal runs of consecutive admissible angles of a
patch (one patch can give several nodes, e.g. near a corner). Edges of the
state graph: *rotation* edges between neighbouring angles of one patch (cost
``rotation_weight * angle_step``) and *translation* edges between adjacent
patches whose normals differ by less than ``translation_normal_angle``, for
angles admissible on both sides once the tangent frames are aligned (cost:
distance between patch centres), provided the secondary finger's contact
moves continuously too. Inside/outside is looked up in a filled voxel grid of
the mesh (``occupancy_pitch``), which is why the samples keep a clearance.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .config import DMGConfig
from .patches import Patches, discretise_surface

__all__ = ["DMGNode", "DMGraph", "build_graph", "Occupancy"]


@dataclass(frozen=True)
class DMGNode:
    """A DMG node: one patch and a run of consecutive admissible angle indices."""

    patch: int
    angle_indices: tuple[int, ...]


class Occupancy:
    """Inside/outside lookups on a filled voxel grid of a watertight mesh.

    Built once per graph; a lookup is an array index, so the ~10^6 gripper
    samples of a large object cost well under a second.
    """

    def __init__(self, mesh, pitch: float):
        vox = mesh.voxelized(pitch).fill()
        self.filled = np.asarray(vox.matrix, bool)
        self.pitch = float(pitch)
        # centre of voxel (0, 0, 0): voxel grids are axis-aligned with uniform pitch
        self.origin = np.asarray(vox.transform, float)[:3, 3]

    def inside(self, points: np.ndarray) -> np.ndarray:
        idx = np.round((np.asarray(points, float) - self.origin) / self.pitch).astype(np.int64)
        shape = np.array(self.filled.shape)
        ok = np.all((idx >= 0) & (idx < shape), axis=-1)
        out = np.zeros(idx.shape[:-1], bool)
        i = idx[ok]
        out[ok] = self.filled[i[..., 0], i[..., 1], i[..., 2]]
        return out


@dataclass
class DMGraph:
    """The graph of one object and everything needed to read a plan off it.

    ``opposite[p]`` is the secondary finger's contact when the principal is on
    patch ``p`` (NaN if none), ``width[p]`` the opening there; ``feasible[p]``
    says the pair is within the opening range and antipodal; ``admissible``
    is ``(n_patches, n_angles)``. ``graph`` is the state graph (networkx,
    node id ``patch * n_angles + k``, edge attributes ``weight`` and
    ``kind`` in {"rotate", "translate"}). ``shift[(a, b)]`` is the angle-index
    offset from patch ``a``'s frame to ``b``'s for a translation between them.
    ``build_time_s`` is the wall time of :func:`build_graph`.
    """

    config: DMGConfig
    patches: Patches
    opposite: np.ndarray
    opposite_normals: np.ndarray
    width: np.ndarray
    feasible: np.ndarray
    admissible: np.ndarray
    nodes: list[DMGNode]
    graph: object = field(repr=False)
    shift: dict[tuple[int, int], int] = field(repr=False)
    build_time_s: float = 0.0
    mesh: object = field(default=None, repr=False)

    @property
    def n_angles(self) -> int:
        return self.config.n_angles

    def state(self, patch: int, k: int) -> int:
        return int(patch) * self.n_angles + int(k) % self.n_angles

    def unstate(self, s: int) -> tuple[int, int]:
        return divmod(int(s), self.n_angles)

    def admissible_angles(self, patch: int) -> np.ndarray:
        """Admissible gripper angles (deg) at a patch, in the patch's tangent frame."""
        return np.flatnonzero(self.admissible[patch]) * self.config.angle_step

    def gripper_axes(self, patch: int, theta: float) -> np.ndarray:
        """Gripper rotation matrix (columns x, y, z) at ``patch``, angle ``theta`` (rad)."""
        p = self.patches
        n = p.normals[patch]
        x = np.cos(theta) * p.tangent1[patch] + np.sin(theta) * p.tangent2[patch]
        z = -n
        return np.column_stack([x, np.cross(z, x), z])


def _opposite_contacts(mesh, patches: Patches, min_depth: float = 5e-4):
    """First exit of the ray from each patch centre along ``-normal``."""
    n = len(patches)
    start = 1e-4
    origins = patches.centers + start * patches.normals
    dirs = -patches.normals
    loc, iray, itri = mesh.ray.intersects_location(origins, dirs, multiple_hits=True)
    opposite = np.full((n, 3), np.nan)
    onormal = np.full((n, 3), np.nan)
    width = np.full(n, np.nan)
    if len(loc):
        d = np.einsum("ij,ij->i", loc - origins[iray], dirs[iray]) - start
        keep = d > min_depth
        loc, iray, itri, d = loc[keep], iray[keep], itri[keep], d[keep]
        order = np.lexsort((d, iray))
        loc, iray, itri, d = loc[order], iray[order], itri[order], d[order]
        first = np.unique(iray, return_index=True)[1]
        r = iray[first]
        opposite[r] = loc[first]
        onormal[r] = mesh.face_normals[itri[first]]
        width[r] = d[first]
    return opposite, onormal, width


def _collision_free(cfg: DMGConfig, occ: Occupancy, p, n, q, t1, t2) -> np.ndarray:
    """``(len(p), n_angles)``: gripper at each angle free of the object."""
    g = cfg.gripper
    th = cfg.angles
    m = g.samples_per_finger
    s = np.linspace(0.0, g.finger_length, m)
    # palm direction a = -x for every patch and angle: (P, K, 3)
    x = np.cos(th)[None, :, None] * t1[:, None, :] + np.sin(th)[None, :, None] * t2[:, None, :]
    a = -x
    f1 = p + g.finger_clearance * n
    f2 = q - g.finger_clearance * n
    u = np.linspace(0.0, 1.0, m)
    samples = [
        f1[:, None, None, :] + s[None, None, :, None] * a[:, :, None, :],
        f2[:, None, None, :] + s[None, None, :, None] * a[:, :, None, :],
    ]
    for depth in (g.finger_length, g.finger_length + g.palm_depth):
        base = f1[:, None, :] + depth * a  # (P, K, 3)
        across = (f2 - f1)[:, None, None, :] * u[None, None, :, None]
        samples.append(base[:, :, None, :] + across)
    pts = np.concatenate(samples, axis=2)
    return ~np.any(occ.inside(pts), axis=2)


def _runs(row: np.ndarray) -> list[tuple[int, ...]]:
    """Maximal circular runs of True in a boolean row."""
    k = len(row)
    idx = np.flatnonzero(row)
    if len(idx) == 0:
        return []
    if len(idx) == k:
        return [tuple(range(k))]
    start = int(np.flatnonzero(~row)[0]) + 1  # begin right after a gap
    runs, cur = [], []
    for j in range(k):
        i = (start + j) % k
        if row[i]:
            cur.append(i)
        elif cur:
            runs.append(tuple(cur))
            cur = []
    if cur:
        runs.append(tuple(cur))
    return sorted(runs)


def _frame_shift(pt: Patches, a: int, b: int, step: float) -> int:
    """Angle-index offset carrying a gripper direction from patch a's frame to b's."""
    na, nb = pt.normals[a], pt.normals[b]
    v = pt.tangent1[a]
    axis = np.cross(na, nb)
    sn, cs = np.linalg.norm(axis), float(na @ nb)
    if sn > 1e-12:  # minimal rotation taking na to nb (Rodrigues)
        k = axis / sn
        ang = np.arctan2(sn, cs)
        v = v * np.cos(ang) + np.cross(k, v) * np.sin(ang) + k * (k @ v) * (1 - np.cos(ang))
    theta = np.arctan2(v @ pt.tangent2[b], v @ pt.tangent1[b])
    return int(np.round(theta / step))


def build_graph(mesh, config: DMGConfig | None = None) -> DMGraph:
    """Build the DMG of a watertight ``trimesh.Trimesh`` (units: metres)."""
    import networkx as nx

    cfg = config or DMGConfig()
    g = cfg.gripper
    t0 = time.perf_counter()
    pt = discretise_surface(mesh, cfg.patch_size, cfg.patch_normal_angle)
    opposite, onormal, width = _opposite_contacts(mesh, pt)
    with np.errstate(invalid="ignore"):
        antipodal = np.einsum("ij,ij->i", onormal, -pt.normals) >= np.cos(
            g.friction_cone_half_angle
        )
        feasible = (
            np.isfinite(width)
            & (width >= g.min_opening)
            & (width <= g.max_opening + g.opening_tolerance)
            & antipodal
        )
    K = cfg.n_angles
    admissible = np.zeros((len(pt), K), bool)
    fi = np.flatnonzero(feasible)
    if len(fi):
        occ = Occupancy(mesh, cfg.occupancy_pitch)
        for chunk in np.array_split(fi, max(1, len(fi) // 256)):
            admissible[chunk] = _collision_free(
                cfg,
                occ,
                pt.centers[chunk],
                pt.normals[chunk],
                opposite[chunk],
                pt.tangent1[chunk],
                pt.tangent2[chunk],
            )
    nodes = [DMGNode(int(p), run) for p in range(len(pt)) for run in _runs(admissible[p])]

    G = nx.Graph()
    ids = np.flatnonzero(admissible.reshape(-1))
    G.add_nodes_from(int(i) for i in ids)
    step = np.deg2rad(cfg.angle_step)
    w_rot = cfg.rotation_weight * step
    for p in fi:
        row = admissible[p]
        for k in np.flatnonzero(row & np.roll(row, -1)):
            if K > 1:
                G.add_edge(int(p * K + k), int(p * K + (k + 1) % K), weight=w_rot, kind="rotate")
    cos_tr = np.cos(np.deg2rad(cfg.translation_normal_angle))
    shift: dict[tuple[int, int], int] = {}
    for a, b in pt.adjacency:
        if not (feasible[a] and feasible[b]) or pt.normals[a] @ pt.normals[b] < cos_tr:
            continue
        d = float(np.linalg.norm(pt.centers[a] - pt.centers[b]))
        jump = float(np.linalg.norm(opposite[a] - opposite[b]))
        if jump > cfg.secondary_jump_factor * d + cfg.patch_size:
            continue
        sh = _frame_shift(pt, a, b, step)
        shift[(int(a), int(b))] = sh
        shift[(int(b), int(a))] = -sh
        for k in np.flatnonzero(admissible[a]):
            kb = (k + sh) % K
            if admissible[b, kb]:
                G.add_edge(int(a * K + k), int(b * K + kb), weight=d, kind="translate")
    build_time = time.perf_counter() - t0
    return DMGraph(
        config=cfg,
        patches=pt,
        opposite=opposite,
        opposite_normals=onormal,
        width=width,
        feasible=feasible,
        admissible=admissible,
        nodes=nodes,
        graph=G,
        shift=shift,
        build_time_s=build_time,
        mesh=mesh,
    )
