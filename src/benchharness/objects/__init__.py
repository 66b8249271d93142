"""The YCB objects of the in-hand manipulation benchmark.

The real YCB meshes are not downloadable here, so each of the twelve objects
is generated from its published dimensions and mass as two simplified
models: a surface mesh (watertight, near-uniform triangles, for the contact
metrics of Algorithm 1) and a collision model of backend primitives (for
simulation). A user with the real meshes passes ``mesh_path=`` and gets
those instead, with the published mass. Contact regions ``C_i``/``C_d`` are
defined on the surface mesh as geodesic or Euclidean discs.

>>> from benchharness.objects import load_object, contact_region
>>> can = load_object("potted meat can")
>>> can.surface.is_watertight, round(can.mass.mass, 3)
(True, 0.37)
>>> region = contact_region(can.surface, [0.025, 0.0, 0.0], radius=0.015)

See docs/objects.md for the object table, frames and sources.
"""

from .catalog import CATALOG
from .mass import MassProperties, mass_properties
from .models import (
    DEFAULT_RESOLUTION,
    MeshStats,
    ObjectModel,
    UnknownObjectError,
    get_spec,
    load_object,
    mesh_stats,
    object_names,
)
from .regions import ContactRegion, contact_region, vertex_distances
from .spec import Citation, ObjectSpec

__all__ = [
    "CATALOG",
    "Citation",
    "ContactRegion",
    "DEFAULT_RESOLUTION",
    "MassProperties",
    "MeshStats",
    "ObjectModel",
    "ObjectSpec",
    "UnknownObjectError",
    "contact_region",
    "get_spec",
    "load_object",
    "mass_properties",
    "mesh_stats",
    "object_names",
    "vertex_distances",
]
