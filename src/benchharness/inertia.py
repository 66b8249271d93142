"""Mass properties of the primitive solids: one function per primitive, used everywhere.

Boxes, cylinders and spheres are the shapes of every collision model here
(the robots' URDFs, the YCB object models, the Rubik's cube and its slabs)
and convex hulls the pieces of the mesh models. The backends, the object
models, the URDF builder and the cube model each used to carry their own
copy of these formulas; a slip in one (a radius for a diameter, a missing
factor) would have given two engines or two robots different dynamics
without any test noticing. They live here once, checked against trimesh's
polyhedral integrals (``tests/test_inertia.py``).

Conventions: SI units; solids are uniform and centred at the origin of
their own frame; a cylinder's axis is its local z. The moments are the
principal moments about the centre, along the local axes, for a solid of
``mass`` kg (pass the volume as ``mass`` for the unit-density figures). The
arithmetic is kept in the order the generated URDFs were written with, so
they stay byte-identical.

numpy only at import (trimesh loads inside :func:`convex_hull_properties`),
so the core stays light.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = [
    "box_volume",
    "box_inertia",
    "cylinder_volume",
    "cylinder_inertia",
    "sphere_volume",
    "sphere_inertia",
    "convex_hull_properties",
    "parallel_axis",
]


def box_volume(size: Sequence[float] | np.ndarray) -> float:
    """Volume (m^3) of a box with full side lengths ``size`` (x, y, z)."""
    a, b, c = (float(s) for s in size)
    return a * b * c


def box_inertia(mass: float, size: Sequence[float] | np.ndarray) -> np.ndarray:
    """Principal moments (kg m^2) of a uniform box with full side lengths ``size``: m (b^2 + c^2) / 12, ..."""
    a, b, c = (float(s) for s in size)
    return mass / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])


def cylinder_volume(radius: float, length: float) -> float:
    """Volume (m^3) of a solid cylinder of ``radius`` and full ``length``."""
    r, h = float(radius), float(length)
    return math.pi * r * r * h


def cylinder_inertia(mass: float, radius: float, length: float) -> np.ndarray:
    """Principal moments (kg m^2) of a uniform solid cylinder along z: m (3 r^2 + h^2) / 12 across, m r^2 / 2 along."""
    r, h = float(radius), float(length)
    across = mass * (3 * r * r + h * h) / 12.0
    return np.array([across, across, 0.5 * mass * r * r])


def sphere_volume(radius: float) -> float:
    """Volume (m^3) of a solid sphere of ``radius``."""
    return 4.0 / 3.0 * math.pi * float(radius) ** 3


def sphere_inertia(mass: float, radius: float) -> np.ndarray:
    """Principal moments (kg m^2) of a uniform solid sphere: 2 m r^2 / 5 on every axis."""
    r = float(radius)
    return np.full(3, 0.4 * mass * r * r)


def convex_hull_properties(vertices) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume (m^3), centroid and unit-density inertia tensor about it of the convex hull of ``vertices``.

    trimesh's exact polyhedral integrals; the mesh pieces of the collision
    models are convex, so their hull is the piece itself.
    """
    import trimesh

    hull = trimesh.convex.convex_hull(np.asarray(vertices, dtype=float))
    hull.density = 1.0
    return (
        float(hull.volume),
        np.asarray(hull.center_mass, dtype=float),
        np.asarray(hull.moment_inertia, dtype=float),
    )


def parallel_axis(mass: float, offset: Sequence[float] | np.ndarray) -> np.ndarray:
    """The parallel-axis (Steiner) term ``m (|d|^2 I - d d^T)``: add it to a part's inertia about its
    own centre to get its inertia about a point ``offset`` away (a composite body's centre).

    One place for the composite bodies of the object models, the URDF builder and the backends'
    multi-shape links, which each wrote it out before.
    """
    d = np.asarray(offset, dtype=float)
    return mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
