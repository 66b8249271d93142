"""Analytic ray–box intersection: the measurement model of a ToF range on the cube.

The estimator must predict, for its current pose estimate, the range a ToF
ray would read. The cube's outer surface is a box, so the prediction is the
classic slab intersection, evaluated here in closed form for a batch of rays
(no engine involved, so the filter runs anywhere and the model can be tested
against the engines' own ray casts).

The Jacobian with respect to the filter state (x, y, z, yaw) is analytic: a
hit on the face with outward unit normal ``n`` (world) at point ``p`` of a
box centred at ``c`` has range ``t = (h - n·(o - c)) / (n·d)``, so

* ``dt/dc = n / (n·d)``;
* yaw turns ``n`` about world z (``dn/dψ = ẑ × n``) and
  ``dt/dψ = -((ẑ × n)·(p - c)) / (n·d)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["RayBoxHits", "ray_box", "ray_box_jacobian"]

_TINY = 1e-12


@dataclass(frozen=True)
class RayBoxHits:
    """Where a batch of rays enters a box (one row per ray)."""

    hit: np.ndarray  #: (n,) bool; False for a miss or an origin inside the box
    distance: np.ndarray  #: (n,) range to the entry point (m); inf where not hit
    point: np.ndarray  #: (n, 3) world entry point; NaN where not hit
    normal: np.ndarray  #: (n, 3) world outward normal of the face entered; NaN where not hit
    face_axis: np.ndarray  #: (n,) box-frame axis (0, 1, 2) of the face entered; -1 where not hit
    edge_distance: (
        np.ndarray
    )  #: (n,) distance (m) from the entry point to the face's nearest edge; NaN where not hit


def _as_rows(a: np.ndarray, name: str) -> np.ndarray:
    r = np.atleast_2d(np.asarray(a, dtype=float))
    if r.ndim != 2 or r.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), got {np.shape(a)}")
    return r


def ray_box(
    origins: np.ndarray,
    directions: np.ndarray,
    center: np.ndarray,
    rotation: np.ndarray,
    half_extents: np.ndarray | float,
) -> RayBoxHits:
    """Entry of rays ``o + t d`` (t ≥ 0) into a box.

    ``rotation`` is the box's 3×3 rotation matrix (body → world), ``center``
    its centre (world), ``half_extents`` a scalar or 3 half widths. Directions
    need not be unit; ranges are in units of the normalised direction.
    """
    o = _as_rows(origins, "origins")
    d = _as_rows(directions, "directions")
    if o.shape != d.shape:
        raise ValueError(f"origins {o.shape} and directions {d.shape} differ in shape")
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    c = np.asarray(center, dtype=float).reshape(3)
    rot = np.asarray(rotation, dtype=float).reshape(3, 3)
    h = np.broadcast_to(np.asarray(half_extents, dtype=float), (3,))

    ob = (o - c) @ rot  # box frame: R^T (o - c), row-wise
    db = d @ rot
    db_safe = np.where(np.abs(db) < _TINY, np.where(db < 0, -_TINY, _TINY), db)
    t1 = (-h - ob) / db_safe
    t2 = (h - ob) / db_safe
    t_lo = np.minimum(t1, t2)
    t_hi = np.maximum(t1, t2)
    # a ray parallel to a slab and outside it never enters
    outside_parallel = (np.abs(db) < _TINY) & (np.abs(ob) > h)
    t_lo = np.where(outside_parallel, np.inf, t_lo)
    t_near = t_lo.max(axis=1)
    t_far = t_hi.min(axis=1)
    hit = np.isfinite(t_near) & (t_near >= 0.0) & (t_near <= t_far)

    n = o.shape[0]
    dist = np.full(n, np.inf)
    point = np.full((n, 3), np.nan)
    normal = np.full((n, 3), np.nan)
    axis = np.full(n, -1, dtype=int)
    edge = np.full(n, np.nan)
    if np.any(hit):
        idx = np.nonzero(hit)[0]
        t = t_near[idx]
        k = t_lo[idx].argmax(axis=1)
        dist[idx] = t
        point[idx] = o[idx] + d[idx] * t[:, None]
        axis[idx] = k
        pb = ob[idx] + db[idx] * t[:, None]
        sign = -np.sign(db[idx, k])  # the ray enters against the outward normal
        nb = np.zeros((idx.size, 3))
        nb[np.arange(idx.size), k] = sign
        normal[idx] = nb @ rot.T
        slack = h[None, :] - np.abs(pb)
        slack[np.arange(idx.size), k] = np.inf
        edge[idx] = np.clip(slack.min(axis=1), 0.0, None)
    return RayBoxHits(hit, dist, point, normal, axis, edge)


def ray_box_jacobian(
    directions: np.ndarray,
    center: np.ndarray,
    hits: RayBoxHits,
) -> np.ndarray:
    """d(range)/d(x, y, z, yaw) for each hit ray, shape (n, 4); NaN rows where not hit.

    Yaw is a rotation of the box about world z through its centre.
    """
    d = _as_rows(directions, "directions")
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    c = np.asarray(center, dtype=float).reshape(3)
    n = hits.normal
    nd = np.einsum("ij,ij->i", n, d)
    jac = np.full((d.shape[0], 4), np.nan)
    ok = hits.hit & (np.abs(nd) > _TINY)
    z_cross_n = np.stack([-n[:, 1], n[:, 0], np.zeros(len(n))], axis=1)
    jac[ok, :3] = n[ok] / nd[ok, None]
    jac[ok, 3] = -np.einsum("ij,ij->i", z_cross_n[ok], hits.point[ok] - c) / nd[ok]
    return jac
