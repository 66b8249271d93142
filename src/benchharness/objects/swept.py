"""Solids whose cross-sections ``x = const`` are ellipses, meshed as stacks of rings.

Most of the in-hand objects are, to the accuracy we can source, bodies of
revolution (apple, orange, tuna can, screwdriver) or flattened tubes along a
gently bent centre line (banana, fork, spatula). One generator covers them
all, so there is a single place where triangle quality is decided.

Why rings and not marching cubes or booleans: Algorithm 1 snaps points to mesh
vertices and runs geodesics over the triangles, so we want every triangle
close to equilateral with edges near a target length ``h``. Rings placed
about ``h`` apart, each with about ``perimeter / h`` points spaced by arc
length, and stitched by a "zipper" that always advances the ring whose next
point comes first, give exactly that, close the surface exactly (watertight
by construction, no vertex merging), and cost no dependency beyond numpy.

A profile is a list of :class:`Segment` s along ``x``; at a segment boundary
the half-widths may jump (the screwdriver's handle-to-shaft step): the
generator then inserts rings *in the plane* of the boundary, which meshes the
flat annulus of the step. Where both half-widths reach zero (a pole) the
stack closes on a point; otherwise it is closed by a flat cap of inset
rings finished by a strip across the remaining thickness.

The cross-section in the plane ``x`` is the ellipse centred at
``(x, 0, centre_z(x))`` with half-axes ``a(x)`` along ``y`` and ``b(x)`` along
``z``: a *sheared* sweep, not one perpendicular to a bent centre line. Its
volume is therefore exactly ``∫ π a b dx`` whatever the bend, which is what
the tests check the mesh against.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import trimesh

__all__ = ["Segment", "SweepProfile", "SweptMesh", "mesh_sweep", "ellipse_perimeter"]

Fn = Callable[[np.ndarray], np.ndarray]


def _zero(x: np.ndarray) -> np.ndarray:
    return np.zeros_like(np.asarray(x, dtype=float))


@dataclass(frozen=True)
class Segment:
    """Half-widths ``a`` (along y) and ``b`` (along z) on ``x0 <= x <= x1``."""

    x0: float
    x1: float
    a: Fn
    b: Fn


@dataclass(frozen=True)
class SweepProfile:
    """An elliptical-section sweep along ``x`` (metres).

    ``breaks`` are x positions where collision pieces must split (a step in
    the radius, a change of part); pieces are otherwise at most
    ``max_piece_length`` long so that each convex hull hugs the surface.
    """

    segments: tuple[Segment, ...]
    centre_z: Fn = _zero
    breaks: tuple[float, ...] = ()
    max_piece_length: float = 0.03

    @property
    def x_range(self) -> tuple[float, float]:
        return self.segments[0].x0, self.segments[-1].x1

    def volume(self, n: int = 200001) -> float:
        """``∫ π a b dx`` by the trapezoid rule on a fine grid (the analytic target)."""
        total = 0.0
        for seg in self.segments:
            x = np.linspace(seg.x0, seg.x1, n)
            y = np.pi * seg.a(x) * seg.b(x)
            total += float(np.sum((y[1:] + y[:-1]) * np.diff(x)) / 2.0)
        return total


@dataclass
class SweptMesh:
    """The surface plus, per ring, its x position and vertex index range."""

    mesh: trimesh.Trimesh
    ring_x: np.ndarray
    ring_slices: list[
        slice
    ]  #: vertices of main ring k (cap rings lie inside the end rings, so hulls ignore them)
    cap_slices: tuple[slice | None, slice | None] = field(default=(None, None))


def ellipse_perimeter(a: float, b: float) -> float:
    """Ramanujan's second approximation (relative error < 1e-9 for our aspect ratios)."""
    if a + b <= 0.0:
        return 0.0
    h = ((a - b) / (a + b)) ** 2
    return float(np.pi * (a + b) * (1 + 3 * h / (10 + np.sqrt(4 - 3 * h))))


def _ellipse_angles(a: float, b: float, n: int) -> np.ndarray:
    """Parameter angles of ``n`` points equally spaced in arc length, the first at theta = 0."""
    if n == 1:
        return np.zeros(1)
    t = np.linspace(0.0, 2 * np.pi, 721)
    ds = np.hypot(a * np.sin(t), b * np.cos(t))
    s = np.concatenate([[0.0], np.cumsum((ds[1:] + ds[:-1]) / 2 * np.diff(t))])
    if s[-1] <= 0:
        return np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.interp(np.arange(n) / n * s[-1], s, t)


def _dense_samples(profile: SweepProfile, n_per_segment: int = 4001) -> np.ndarray:
    """Rows ``(x, a, b, zc)``, clustered near segment ends where poles curve fastest."""
    rows = []
    for seg in profile.segments:
        u = np.linspace(0.0, 1.0, n_per_segment)
        x = seg.x0 + (seg.x1 - seg.x0) * (1 - np.cos(np.pi * u)) / 2
        a = np.clip(seg.a(x), 0.0, None)
        b = np.clip(seg.b(x), 0.0, None)
        rows.append(np.column_stack([x, a, b, profile.centre_z(x)]))
    return np.vstack(rows)


def _ring_positions(samples: np.ndarray, h: float) -> np.ndarray:
    """Pick rows so that consecutive rings are about ``h`` apart in 3-D."""
    th = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    x, a, b, zc = samples.T
    pts = np.stack(
        [
            np.repeat(x[:, None], th.size, 1),
            a[:, None] * np.cos(th),
            zc[:, None] + b[:, None] * np.sin(th),
        ],
        axis=-1,
    )
    step = np.linalg.norm(np.diff(pts, axis=0), axis=-1).max(axis=1)
    dist = np.concatenate([[0.0], np.cumsum(step)])
    dist = dist + np.arange(dist.size) * 1e-15  # strictly increasing for interp
    # an even number of intervals puts a ring in the middle of symmetric shapes
    # (the equator of a sphere), so their bounding boxes are exact too
    n = max(2, 2 * int(np.ceil(dist[-1] / (2 * h) - 1e-9)))
    targets = np.linspace(0.0, dist[-1], n + 1)
    return np.column_stack([np.interp(targets, dist, col) for col in samples.T])


def _zip(
    ia: np.ndarray, fa: np.ndarray, ib: np.ndarray, fb: np.ndarray
) -> list[tuple[int, int, int]]:
    """Triangulate the band between two closed rings by advancing the earlier next point."""
    faces: list[tuple[int, int, int]] = []
    na, nb = len(ia), len(ib)
    i = j = 0
    while i < na or j < nb:
        fa_next = fa[i + 1] if i + 1 < na else 1.0
        fb_next = fb[j + 1] if j + 1 < nb else 1.0
        if j >= nb or (i < na and fa_next <= fb_next):
            tri = (ia[i % na], ia[(i + 1) % na], ib[j % nb])
            i += 1
        else:
            tri = (ia[i % na], ib[(j + 1) % nb], ib[j % nb])
            j += 1
        if len({int(v) for v in tri}) == 3:
            faces.append(tuple(int(v) for v in tri))
    return faces


def _zip_open(
    upper: np.ndarray, lower: np.ndarray, y_of_ring: np.ndarray
) -> list[tuple[int, int, int]]:
    """Triangulate between two polylines sharing both end points, paired by y."""
    base = int(upper[0])
    fu = -y_of_ring[upper - base]
    fl = -y_of_ring[lower - base]
    faces: list[tuple[int, int, int]] = []
    i = j = 0
    mu, ml = len(upper) - 1, len(lower) - 1
    while i < mu or j < ml:
        if j >= ml or (i < mu and fu[i + 1] <= fl[j + 1]):
            tri = (upper[i], upper[i + 1], lower[j])
            i += 1
        else:
            tri = (upper[i], lower[j + 1], lower[j])
            j += 1
        if len({int(v) for v in tri}) == 3:
            faces.append(tuple(int(v) for v in tri))
    return faces


def mesh_sweep(profile: SweepProfile, h: float, pole_tol: float = 1e-7) -> SweptMesh:
    """Mesh ``profile`` with target edge length ``h`` (metres)."""
    rings = _ring_positions(_dense_samples(profile), h)
    verts: list[np.ndarray] = []
    fracs: list[np.ndarray] = []
    idx: list[np.ndarray] = []
    slices: list[slice] = []
    count = 0

    def add_ring(x: float, a: float, b: float, zc: float, n: int | None = None) -> int:
        nonlocal count
        if a < pole_tol and b < pole_tol:
            n = 1
        elif n is None:
            # a multiple of 4, so the points at theta = 0, pi/2, pi, 3pi/2 (the
            # y and z extremes) are always vertices and bounding boxes are exact
            # (at least 12 on a real section, or a thin fork handle becomes a
            # diamond; 6 on the small rings next to a pole, where more would
            # crowd and 4 would make slivers)
            perimeter = ellipse_perimeter(a, b)
            n = max(12, 4 * int(round(perimeter / (4 * h)))) if perimeter >= 4 * h else 6
        th = _ellipse_angles(a, b, n)
        p = np.column_stack([np.full(n, x), a * np.cos(th), zc + b * np.sin(th)])
        verts.append(p)
        fracs.append(np.arange(n) / n)
        idx.append(np.arange(count, count + n))
        slices.append(slice(count, count + n))
        count += n
        return len(idx) - 1

    for x, a, b, zc in rings:
        add_ring(x, a, b, zc)
    ring_x = rings[:, 0].copy()
    n_main = len(idx)

    faces: list[tuple[int, int, int]] = []
    for k in range(n_main - 1):
        faces += _zip(idx[k], fracs[k], idx[k + 1], fracs[k + 1])

    caps: list[slice | None] = [None, None]
    for end, k in ((0, 0), (1, n_main - 1)):
        x, a, b, zc = rings[k]
        if len(idx[k]) == 1:
            continue
        # Flat cap: rings inset by h (not scaled: scaling a thin ellipse makes
        # gaps across its thickness far thinner than h) while both half-axes
        # leave room, then the last ring's upper half is zipped to its lower
        # half, strips as wide as what is left of the thickness.
        start = count
        prev = k
        ac, bc = a, b
        while min(ac, bc) > 1.5 * h:
            ac, bc = ac - h, bc - h
            cur = add_ring(x, ac, bc, zc)
            faces += _zip(idx[prev], fracs[prev], idx[cur], fracs[cur])
            prev = cur
        if ac < 2.5 * bc:  # roundish: a fan to the centre is best
            cur = add_ring(x, 0.0, 0.0, zc)
            faces += _zip(idx[prev], fracs[prev], idx[cur], fracs[cur])
        else:
            n = len(idx[prev])
            upper = idx[prev][: n // 2 + 1]
            lower = idx[prev][np.r_[0, np.arange(n - 1, n // 2 - 1, -1)]]
            faces += _zip_open(upper, lower, verts[prev][:, 1])
        caps[end] = slice(start, count) if count > start else None

    mesh = trimesh.Trimesh(np.vstack(verts), np.asarray(faces, dtype=np.int64), process=False)
    mesh.fix_normals()
    return SweptMesh(
        mesh=mesh, ring_x=ring_x, ring_slices=slices[:n_main], cap_slices=(caps[0], caps[1])
    )


def piece_vertex_sets(swept: SweptMesh, profile: SweepProfile) -> list[np.ndarray]:
    """Vertex index sets whose convex hulls tile the solid (collision pieces).

    Pieces meet in ring planes ``x = const``, so their hulls do not overlap
    beyond the (small) bulge of a hull over a bent stretch. At a break where
    the section steps (several rings in one plane) the left piece ends on the
    first ring of that plane and the right piece starts on the last one.
    """
    xs = swept.ring_x
    n = len(xs)
    tol = 1e-9
    cut_pairs: list[tuple[int, int]] = []  # (last ring of left piece, first ring of right piece)
    for xb in profile.breaks:
        same = np.flatnonzero(np.abs(xs - xb) < 1e-6)
        if same.size:
            cut_pairs.append((int(same[0]), int(same[-1])))
        else:
            k = int(np.argmin(np.abs(xs - xb)))
            cut_pairs.append((k, k))
    cut_pairs.sort()
    bounds: list[tuple[int, int]] = []
    start = 0
    for left_end, right_start in cut_pairs + [(n - 1, n)]:
        # split [start, left_end] further so no piece is longer than max_piece_length
        length = xs[left_end] - xs[start]
        m = max(1, int(np.ceil(length / profile.max_piece_length - tol)))
        targets = xs[start] + np.arange(1, m) * length / m
        inner = sorted(
            {int(np.argmin(np.abs(xs[start : left_end + 1] - t))) + start for t in targets}
        )
        edges = [start] + [k for k in inner if start < k < left_end] + [left_end]
        bounds += list(zip(edges[:-1], edges[1:]))
        start = right_start
    sets = []
    for k0, k1 in bounds:
        if k1 <= k0:
            continue
        sl = [
            np.arange(swept.ring_slices[k].start, swept.ring_slices[k].stop)
            for k in range(k0, k1 + 1)
        ]
        sets.append(np.concatenate(sl))
    return sets


def pieces_as_meshes(swept: SweptMesh, profile: SweepProfile) -> list[trimesh.Trimesh]:
    """Convex hulls of :func:`piece_vertex_sets` (skipping degenerate ones)."""
    out = []
    for ids in piece_vertex_sets(swept, profile):
        pts = swept.mesh.vertices[ids]
        if len(pts) < 4:
            continue
        hull = trimesh.convex.convex_hull(pts)
        if hull.volume > 0:
            out.append(hull)
    return out
