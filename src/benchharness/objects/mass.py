"""Mass properties of a collision model made of backend primitive shapes.

A backend spreads a body's mass uniformly over its shapes' volume unless it
is given a centre of mass and inertia. The two engines disagree on how they
do that for overlapping or mesh shapes, so we compute the properties once,
here, and pass them explicitly: uniform density ``mass / total volume``,
each shape's own properties from the one set of primitive formulas
(:mod:`benchharness.inertia`, through the backends' shape mapping
:func:`~benchharness.backends._urdf.shape_volume_com_inertia`): closed forms
for boxes, spheres and cylinders, trimesh's exact polyhedral integrals for
convex mesh pieces.

Shapes are assumed not to overlap (our collision models are built that way:
ring-plane hull pieces, studs *on* the brick, wings *beside* the fuselage);
overlap would be counted twice.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import trimesh

from ..backends._urdf import shape_volume_com_inertia
from ..backends.interface import Shape
from ..inertia import parallel_axis

__all__ = ["MassProperties", "shape_volume", "mass_properties"]


@dataclass(frozen=True)
class MassProperties:
    """Mass (kg), centre of mass and inertia tensor about it, in the body frame."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray  #: 3x3 about ``com``, body-frame axes (kg m^2)
    volume: float  #: total collision volume (m^3); density = mass / volume

    @property
    def density(self) -> float:
        return self.mass / self.volume

    def principal(self) -> tuple[np.ndarray, np.ndarray]:
        """Principal moments (ascending) and axes (columns), body frame."""
        w, v = np.linalg.eigh(self.inertia)
        return w, v

    @property
    def off_diagonal_ratio(self) -> float:
        """Largest product of inertia relative to the largest moment.

        The backends take a *diagonal* inertia in the body frame; where this
        ratio is not small the diagonal alone misstates the rotational
        dynamics (see docs/objects.md).
        """
        off = self.inertia - np.diag(np.diag(self.inertia))
        return float(np.abs(off).max() / np.abs(np.diag(self.inertia)).max())


def shape_volume(shape: Shape) -> float:
    return shape_volume_com_inertia(shape)[0]


def mass_properties(shapes: Sequence[Shape], mass: float) -> MassProperties:
    """Properties of ``shapes`` filled uniformly with total ``mass``."""
    if not shapes:
        raise ValueError("a collision model needs at least one shape")
    parts = []
    for s in shapes:
        v, c, i_unit = shape_volume_com_inertia(s)
        rot = s.pose.rotation.as_matrix()
        parts.append((v, s.pose.apply(c), rot @ i_unit @ rot.T))
    vol = sum(p[0] for p in parts)
    rho = mass / vol
    com = sum(p[0] * p[1] for p in parts) / vol
    inertia = np.zeros((3, 3))
    for v, c, i_unit in parts:
        d = c - com
        inertia += rho * (i_unit + parallel_axis(v, d))
    return MassProperties(
        mass=float(mass), com=np.asarray(com, float), inertia=inertia, volume=float(vol)
    )


def solid_mass_properties(mesh: trimesh.Trimesh, mass: float) -> MassProperties:
    """Properties of the solid a closed surface bounds, filled uniformly with ``mass``.

    For the watertight YCB scans: the scan's own volume, not a collision
    model's (convex hulls and V-HACD pieces are larger, and V-HACD pieces
    may overlap, which :func:`mass_properties` would count twice).
    """
    if not mesh.is_watertight or mesh.volume <= 0:
        raise ValueError("solid mass properties need a closed, outward-oriented surface")
    m = mesh.copy()
    m.density = 1.0
    vol = float(m.volume)
    return MassProperties(
        mass=float(mass),
        com=np.asarray(m.center_mass, float),
        inertia=np.asarray(m.moment_inertia, float) * (mass / vol),
        volume=vol,
    )
