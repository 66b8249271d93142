"""The YCB objects of the in-hand manipulation benchmark.

Each of the twelve objects is, by default, its real YCB scan (vendored, see
:mod:`.ycb`) in the frame the published data uses, with its convex hull or
V-HACD pieces for collision and the published mass. ``model="generated"``
gives the simplified models generated from the published dimensions (a
watertight surface with near-uniform triangles and a collision model of
backend primitives); ``mesh_path=`` substitutes any mesh. Contact regions
``C_i``/``C_d`` are defined on the surface mesh as geodesic or Euclidean
discs.

>>> from benchharness.objects import load_object, contact_region
>>> can = load_object("potted meat can")
>>> can.source, len(can.surface.faces), round(can.mass.mass, 3)
('ycb', 16384, 0.37)
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
