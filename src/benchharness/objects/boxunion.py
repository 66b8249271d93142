"""Surfaces of unions of axis-aligned boxes, meshed on a shared rectilinear grid.

The boxes (cracker, gelatin, potted meat can), the Lego Duplo brick (body plus
studs) and the airplane toy (fuselage, wings, tail, landing gear) are unions
of axis-aligned boxes. Their union is exact on the grid whose lines are all
the boxes' faces: each grid cell is either inside or outside, and the surface
is the set of cell faces between an inside and an outside cell.

Every grid interval is then split into ``ceil(length / h)`` equal parts, the
*same* split wherever the interval appears, so neighbouring faces share their
edge vertices exactly: the mesh is watertight and conforming without vertex
merging by tolerance, and triangles are right triangles whose legs are at
most ``h`` and at least about ``h / 2`` (no slivers unless a box is thinner
than ``h / 2``, which none of ours is).

Unions whose cells touch only along an edge would be non-manifold; the
object definitions avoid that and the tests check watertightness.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

__all__ = ["AABox", "mesh_box_union"]


@dataclass(frozen=True)
class AABox:
    """An axis-aligned box by its corners (metres)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    @classmethod
    def centred(
        cls, size: tuple[float, float, float], centre: tuple[float, float, float] = (0.0, 0.0, 0.0)
    ) -> AABox:
        s = np.asarray(size, float) / 2
        c = np.asarray(centre, float)
        return cls(tuple(c - s), tuple(c + s))

    @property
    def size(self) -> np.ndarray:
        return np.asarray(self.hi) - np.asarray(self.lo)

    @property
    def centre(self) -> np.ndarray:
        return (np.asarray(self.hi) + np.asarray(self.lo)) / 2

    @property
    def volume(self) -> float:
        return float(np.prod(self.size))


def _axis_points(bounds: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Fine coordinates along one axis and, per coarse line, its index among them."""
    fine = [bounds[0]]
    coarse_idx = [0]
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        n = max(1, int(np.ceil((hi - lo) / h - 1e-9)))
        fine += list(lo + (hi - lo) * np.arange(1, n + 1) / n)
        fine[-1] = hi
        coarse_idx.append(len(fine) - 1)
    return np.asarray(fine), np.asarray(coarse_idx)


def mesh_box_union(boxes: list[AABox], h: float) -> trimesh.Trimesh:
    """Watertight surface of the union of ``boxes`` with legs of at most ``h``."""
    lo = np.array([b.lo for b in boxes])
    hi = np.array([b.hi for b in boxes])
    coarse = [np.unique(np.round(np.concatenate([lo[:, d], hi[:, d]]), 12)) for d in range(3)]
    fine_idx = [_axis_points(c, h) for c in coarse]
    fine = [f for f, _ in fine_idx]
    cidx = [i for _, i in fine_idx]

    centres = [(c[:-1] + c[1:]) / 2 for c in coarse]
    cx, cy, cz = np.meshgrid(*centres, indexing="ij")
    pts = np.stack([cx, cy, cz], axis=-1)
    inside = np.zeros(cx.shape, dtype=bool)
    for b in boxes:
        inside |= np.all((pts > np.asarray(b.lo)) & (pts < np.asarray(b.hi)), axis=-1)
    padded = np.pad(inside, 1)

    vid: dict[tuple[int, int, int], int] = {}
    verts: list[tuple[float, float, float]] = []

    def vertex(i: int, j: int, k: int) -> int:
        key = (i, j, k)
        v = vid.get(key)
        if v is None:
            v = len(verts)
            vid[key] = v
            verts.append((fine[0][i], fine[1][j], fine[2][k]))
        return v

    faces: list[tuple[int, int, int]] = []
    for d in range(3):
        d1, d2 = (d + 1) % 3, (d + 2) % 3
        shape = inside.shape
        for c in range(shape[d] + 1):  # coarse plane index along d
            # cells on the low (c-1) and high (c) side of this plane
            sl_lo = [slice(1, s + 1) for s in shape]
            sl_hi = [slice(1, s + 1) for s in shape]
            sl_lo[d] = c
            sl_hi[d] = c + 1
            a = padded[tuple(sl_lo)]
            b = padded[tuple(sl_hi)]
            if d1 > d2:  # remaining axes come out ascending; we want (d1, d2) order
                a, b = a.T, b.T
            diff = a != b
            if not diff.any():
                continue
            # a (low side) inside -> outward normal is +d
            for u, v in zip(*np.nonzero(diff)):
                plus = bool(a[u, v])
                iu0, iu1 = cidx[d1][u], cidx[d1][u + 1]
                iv0, iv1 = cidx[d2][v], cidx[d2][v + 1]
                plane = cidx[d][c]
                for p in range(iu0, iu1):
                    for q in range(iv0, iv1):
                        corners = []
                        for pp, qq in ((p, q), (p + 1, q), (p + 1, q + 1), (p, q + 1)):
                            ijk = [0, 0, 0]
                            ijk[d], ijk[d1], ijk[d2] = plane, pp, qq
                            corners.append(vertex(*ijk))
                        c0, c1, c2, c3 = corners
                        # (d1, d2, d) is right-handed: counter-clockwise in (d1, d2) faces +d
                        if plus:
                            faces += [(c0, c1, c2), (c0, c2, c3)]
                        else:
                            faces += [(c0, c2, c1), (c0, c3, c2)]
    return trimesh.Trimesh(np.asarray(verts), np.asarray(faces, dtype=np.int64), process=False)
