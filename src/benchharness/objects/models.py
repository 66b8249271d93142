"""An object's surface mesh and collision model: the real YCB scan, a generated model, or the user's mesh.

``load_object("potted meat can")`` gives the vendored YCB scan (see
:mod:`.ycb`) in the frame the published data uses (``spec.scan.frame``),
with its convex hull or its vendored V-HACD pieces for collision.
``load_object(name, model="generated")`` (or any ``resolution=``) builds
both representations from the published dimensions instead (see
:mod:`.catalog`); ``load_object(name, mesh_path=...)`` uses the user's mesh
in its own frame. The published mass is kept in every case.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
import trimesh
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from ..backends.interface import Box, Cylinder, MeshShape, Shape, Sphere
from ..geometry import Pose
from .boxunion import mesh_box_union
from .catalog import CATALOG
from .mass import MassProperties, mass_properties, solid_mass_properties
from .spec import BoxGeometry, ObjectSpec, SweepGeometry
from .swept import mesh_sweep, pieces_as_meshes

__all__ = [
    "DEFAULT_RESOLUTION",
    "ObjectModel",
    "MeshStats",
    "UnknownObjectError",
    "get_spec",
    "load_object",
    "mesh_stats",
    "object_names",
]

#: Target edge length (m) of generated meshes. 3 mm gives edges of about
#: 2.5-5 mm (the zipper diagonals are the long ones): fine enough that
#: vertex snapping in Algorithm 1 moves a point by well under a fingertip's
#: contact patch, coarse enough that the heat-method solve stays fast.
DEFAULT_RESOLUTION = 3e-3

CollisionMode = Literal["hull", "decompose"]
ModelKind = Literal["ycb", "generated"]


class UnknownObjectError(LookupError):
    """An object name matched none of the benchmark's objects."""


@dataclass(frozen=True)
class MeshStats:
    """Triangle-quality figures of a surface mesh (lengths in metres, angles in degrees)."""

    n_vertices: int
    n_faces: int
    edge_min: float
    edge_mean: float
    edge_max: float
    min_angle_deg: float
    g_min: float  #: distance between the two closest vertices: the paper's G_min
    watertight: bool


def mesh_stats(mesh: trimesh.Trimesh) -> MeshStats:
    lengths = mesh.edges_unique_length
    d, _ = cKDTree(mesh.vertices).query(mesh.vertices, k=2)
    return MeshStats(
        n_vertices=len(mesh.vertices),
        n_faces=len(mesh.faces),
        edge_min=float(lengths.min()),
        edge_mean=float(lengths.mean()),
        edge_max=float(lengths.max()),
        min_angle_deg=float(np.degrees(mesh.face_angles.min())),
        g_min=float(d[:, 1].min()),
        watertight=bool(mesh.is_watertight),
    )


@dataclass(frozen=True)
class ObjectModel:
    """An object ready for the metric module and for a backend.

    ``surface`` is in the object frame (metres); ``collision`` are backend
    shapes with poses in the same frame; ``mass`` carries the published mass
    spread uniformly over the collision volume. ``source`` is ``"ycb"``
    (the vendored scan), ``"generated"`` or the path of a user-supplied mesh.
    ``frame_offset`` is the translation (m) applied to the mesh file's
    coordinates to get the object frame (non-zero for a scan used centred on
    its bounding box); ``resolution`` is the generated models' edge length.
    """

    spec: ObjectSpec
    surface: trimesh.Trimesh
    collision: tuple[Shape, ...]
    mass: MassProperties
    source: str
    resolution: float | None
    frame_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def g_min(self) -> float:
        """The paper's G_min: Euclidean distance between the two closest vertices (m)."""
        return mesh_stats(self.surface).g_min

    def stats(self) -> MeshStats:
        return mesh_stats(self.surface)

    def body_kwargs(self) -> dict:
        """Arguments for :meth:`Backend.add_body` (add ``pose``).

        ``inertia_diag`` is the diagonal of the body-frame inertia tensor
        about the centre of mass; see ``mass.off_diagonal_ratio`` for what
        that drops (zero for the symmetric objects, a few per cent for the
        bent fork and spatula).
        """
        return dict(
            shapes=list(self.collision),
            mass=self.mass.mass,
            com=self.mass.com.tolist(),
            inertia_diag=np.diag(self.mass.inertia).tolist(),
            name=self.spec.ycb_name,
        )


# ---------------------------------------------------------------------------- registry


def _key(name: str) -> str:
    return re.sub(r"[^a-z0-9]", "", name.lower())


@functools.lru_cache(maxsize=1)
def _index() -> dict[str, ObjectSpec]:
    out: dict[str, ObjectSpec] = {}
    for spec in CATALOG:
        for n in spec.all_names:
            k = _key(n)
            if k in out and out[k] is not spec:
                raise RuntimeError(f"object name {n!r} is ambiguous")
            out[k] = spec
    return out


def object_names() -> list[str]:
    """The names as spelled in the published data, in catalog order."""
    return [s.name for s in CATALOG]


def get_spec(name: str) -> ObjectSpec:
    """Look an object up by its published name, YCB name or alias.

    Case, spaces, hyphens and underscores are ignored, so "Lego Duplo",
    "lego_duplo", "073_lego_duplo" and "Phillips-head screwdriver" /
    "phillips head screwdriver" all work.
    """
    spec = _index().get(_key(name))
    if spec is None:
        raise UnknownObjectError(
            f"unknown object {name!r}; valid names: " + ", ".join(repr(n) for n in object_names())
        )
    return spec


# ---------------------------------------------------------------------------- generation

_Z_FROM_X = Rotation.from_euler("y", -90, degrees=True)  # maps +x to +z


def _build_sweep(geom: SweepGeometry, h: float) -> tuple[trimesh.Trimesh, list[Shape]]:
    swept = mesh_sweep(geom.profile, h)
    mesh = swept.mesh
    hulls = pieces_as_meshes(swept, geom.profile) if geom.collision == "hull_pieces" else []
    rot = _Z_FROM_X.as_matrix() if geom.axis == "z" else np.eye(3)
    centre = (mesh.bounds[0] + mesh.bounds[1]) / 2
    tf = np.eye(4)
    tf[:3, :3] = rot
    tf[:3, 3] = -rot @ centre
    mesh.apply_transform(tf)
    if geom.collision == "sphere":
        r = float(geom.profile.segments[0].a(np.array([0.0]))[0])
        shapes: list[Shape] = [Sphere(radius=r)]
    elif geom.collision == "cylinder":
        seg = geom.profile.segments[0]
        r = float(seg.a(np.array([seg.x0]))[0])
        if geom.axis != "z":
            raise ValueError("a cylinder collision model needs axis='z'")
        shapes = [Cylinder(radius=r, half_length=(seg.x1 - seg.x0) / 2)]
    else:
        shapes = []
        for hull in hulls:
            hull.apply_transform(tf)
            shapes.append(
                MeshShape(vertices=np.asarray(hull.vertices), faces=np.asarray(hull.faces))
            )
    return mesh, shapes


def _build_boxes(geom: BoxGeometry, h: float) -> tuple[trimesh.Trimesh, list[Shape]]:
    mesh = mesh_box_union(list(geom.boxes), h)
    shapes: list[Shape] = [
        Box(half_extents=tuple(float(v) for v in b.size / 2), pose=Pose(b.centre))
        for b in geom.boxes
    ]
    return mesh, shapes


@functools.lru_cache(maxsize=64)
def _generated(name: str, resolution: float) -> ObjectModel:
    spec = get_spec(name)
    if isinstance(spec.geometry, SweepGeometry):
        mesh, shapes = _build_sweep(spec.geometry, resolution)
    else:
        mesh, shapes = _build_boxes(spec.geometry, resolution)
    mesh.metadata["name"] = spec.name
    return ObjectModel(
        spec=spec,
        surface=mesh,
        collision=tuple(shapes),
        mass=mass_properties(shapes, spec.mass_kg),
        source="generated",
        resolution=resolution,
    )


def _from_mesh(spec: ObjectSpec, path: Path, collision: CollisionMode) -> ObjectModel:
    loaded = trimesh.load(str(path), force="mesh", process=True)
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise ValueError(f"{path}: no triangle mesh found")
    surface = loaded
    surface.merge_vertices()
    if collision == "hull":
        hulls = [surface.convex_hull]
    elif collision == "decompose":
        # trimesh delegates to V-HACD (the optional ``vhacdx`` package)
        parts = surface.convex_decomposition()
        parts = parts if isinstance(parts, list) else [parts]
        hulls = [p if isinstance(p, trimesh.Trimesh) else trimesh.Trimesh(**p) for p in parts]
    else:
        raise ValueError(f"collision must be 'hull' or 'decompose', not {collision!r}")
    shapes: list[Shape] = [
        MeshShape(vertices=np.asarray(h.vertices), faces=np.asarray(h.faces)) for h in hulls
    ]
    return ObjectModel(
        spec=spec,
        surface=surface,
        collision=tuple(shapes),
        mass=mass_properties(shapes, spec.mass_kg),
        source=str(path),
        resolution=None,
    )


@functools.lru_cache(maxsize=16)
def _scanned(name: str) -> ObjectModel:
    from .ycb import drop_stray_pieces, read_parts, read_scan, scan_offset

    spec = get_spec(name)
    offset = scan_offset(spec.scan.file, spec.scan.frame)
    surface = read_scan(spec.scan.file)
    drop_stray_pieces(surface)  # the gelatin box's and tuna can's four stray slivers each
    surface.apply_translation(offset)
    surface.metadata["name"] = spec.name
    if spec.scan.collision == "hull":
        pieces = [(np.asarray(surface.convex_hull.vertices), np.asarray(surface.convex_hull.faces))]
    else:
        pieces = [(v + offset, f) for v, f in read_parts(spec.scan.file)]
    shapes: list[Shape] = [MeshShape(vertices=v, faces=f) for v, f in pieces]
    # the scan's own solid (all twelve are closed once the strays are dropped); a surface that
    # is not (a future scan) spreads the mass over its collision pieces instead
    closed = surface.is_watertight and surface.volume > 0
    return ObjectModel(
        spec=spec,
        surface=surface,
        collision=tuple(shapes),
        mass=(
            solid_mass_properties(surface, spec.mass_kg)
            if closed
            else mass_properties(shapes, spec.mass_kg)
        ),
        source="ycb",
        resolution=None,
        frame_offset=(float(offset[0]), float(offset[1]), float(offset[2])),
    )


def load_object(
    name: str,
    *,
    model: ModelKind | None = None,
    resolution: float | None = None,
    mesh_path: str | Path | None = None,
    collision: CollisionMode = "hull",
) -> ObjectModel:
    """The model of a benchmark object.

    ``model="ycb"`` (the default): the real YCB scan (vendored, 16 384
    triangles), in the frame of the published data (``spec.scan.frame``),
    colliding as its convex hull or its vendored V-HACD pieces
    (``spec.scan.collision``). ``model="generated"``: built from the
    published dimensions with target edge length ``resolution`` (m, default
    :data:`DEFAULT_RESOLUTION`); passing ``resolution`` alone implies it,
    since only generated meshes have one. ``mesh_path``: the user's mesh
    (any format trimesh reads, in metres, in its own frame) as the surface,
    colliding as its convex hull (``collision="hull"``) or a V-HACD
    decomposition (``collision="decompose"``, needs ``vhacdx``). The
    published mass is kept in every case.

    Models are cached per (name, kind, resolution); the returned mesh is a
    copy, so callers may modify it.
    """
    spec = get_spec(name)
    if mesh_path is not None:
        if model is not None or resolution is not None:
            raise ValueError("mesh_path replaces the model: pass neither model= nor resolution=")
        return _from_mesh(spec, Path(mesh_path), collision)
    kind = model if model is not None else ("generated" if resolution is not None else "ycb")
    if kind == "ycb":
        if resolution is not None:
            raise ValueError("resolution applies to model='generated'; the YCB scan has its own")
        cached = _scanned(spec.name)
    elif kind == "generated":
        res = DEFAULT_RESOLUTION if resolution is None else float(resolution)
        if res <= 0:
            raise ValueError("resolution must be a positive length in metres")
        cached = _generated(spec.name, res)
    else:
        raise ValueError(f"model must be 'ycb' or 'generated', not {model!r}")
    return ObjectModel(
        spec=cached.spec,
        surface=cached.surface.copy(),
        collision=cached.collision,
        mass=cached.mass,
        source=cached.source,
        resolution=cached.resolution,
        frame_offset=cached.frame_offset,
    )
