"""Where an engine puts an object's collision surface, against the object model's own pieces.

An in-hand fingertip's force is the hand's stiffness times how far its target lies inside the surface
it meets (~650 N/m at an Allegro fingertip: 1 mm is 0.65 N of a 3 N squeeze), so each engine must put
the surface where :attr:`ObjectModel.collision` says (docs/backends.md, "Object surfaces"). The answer
is independent of the engines: trimesh's exact signed distance to each convex piece. Used by
``bench/bench_object_surfaces.py`` (every scan, both engines) and ``tests/backends/test_object_surfaces.py``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..backends.interface import Backend, BodyId, Sphere
from ..geometry import Pose

__all__ = ["overlapping_spheres", "contact_separations"]


def overlapping_spheres(
    model: Any, n: int, radius: float, overlap: float, seed: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """Up to ``n`` centres of spheres of ``radius`` overlapping the model's surface by ``overlap`` (m),
    and their exact separations (about ``-overlap``).

    Points are sampled on the pieces' faces (``6 n``, seeded) and kept where the sphere overlaps the
    union of the pieces by ``overlap`` to within 0.1 mm: a point on a face inside another piece is not
    on the surface. The exact separation is the least over the convex pieces, as each engine reports
    one contact per piece.
    """
    import trimesh

    pieces = [trimesh.Trimesh(s.vertices, s.faces).convex_hull for s in model.collision]
    union: Any = trimesh.util.concatenate(pieces) if len(pieces) > 1 else pieces[0]
    pts, fi = trimesh.sample.sample_surface(union, 6 * n, seed=seed)
    centres = pts + union.face_normals[fi] * (radius - overlap)
    exact = np.min([-trimesh.proximity.signed_distance(p, centres) for p in pieces], axis=0)
    exact = exact - radius
    keep = np.flatnonzero(np.abs(exact + overlap) < 1e-4)[:n]
    return centres[keep], exact[keep]


def contact_separations(
    backend: Backend, obj: BodyId, centres: np.ndarray, radius: float
) -> np.ndarray:
    """The separation (m) the engine reports between body ``obj`` and a fixed sphere at each centre,
    after one step; ``inf`` where it made no contact.

    ``obj`` must be free to move (a fixed-fixed pair makes no contacts in either engine); give the
    backend no gravity so one step moves nothing that matters.
    """
    tips = {
        backend.add_body([Sphere(radius)], Pose(c), 0.0, fixed=True): i
        for i, c in enumerate(centres)
    }
    backend.step(1)
    sep = np.full(len(centres), np.inf)
    for ct in backend.contacts(obj, None):
        i = tips.get(ct.body_b)
        if i is not None:
            sep[i] = min(sep[i], float(ct.distance))
    return sep
