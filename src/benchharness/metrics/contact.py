"""Contact-region error of the in-hand benchmark (paper III-A, Algorithm 1).

Given the object mesh ``O``, the desired contact region ``C_d`` and what the
robot touched, Algorithm 1 snaps both to object vertices and reports the
largest distance ``max_d`` from a touched vertex to its nearest desired
vertex, measured either in space (``G_euc``, eq. 4) or along the surface
(``G_geo``, eq. 5). ``G_min``, the distance between the two closest object
vertices, says how fine that snapping is.

How the two helper functions of Algorithm 1 are realised here:

``intersect(M, O)``
    The points of mesh ``M`` (a desired-region mesh or a robot link mesh,
    both in the object frame) that lie within ``contact_tol`` of the object
    surface, by :func:`trimesh.proximity.closest_point`. ``M`` is first
    subdivided (deterministically) until no edge is longer than the object's
    mean edge length, so a coarse link mesh touching the object between its
    own vertices is still seen. A desired region cut from ``O`` lies on it
    (distance ~0); a fingertip resting on or slightly penetrating the object
    contributes its points near the surface.
``min-vertex(p, O)``
    The object vertex nearest to ``p`` (KD-tree over the object vertices).

The desired region can also be given directly as object vertex indices or as
points, and the robot contact as points (e.g. estimated contact locations
from a real robot's log); points go through ``min-vertex`` only.

Geodesic distances
    ``method="heat"`` (default): the heat method (Crane et al., paper ref.
    [48]) through potpourri3d. One multi-source solve from ``V_c`` gives,
    for every vertex, the distance to the *nearest* desired vertex -- the
    inner minimum of Algorithm 1 in one go. The solve is seeded from the
    boundary ring of ``V_c`` (see :meth:`ObjectSurface.region_boundary`);
    reached vertices inside ``V_c`` get 0. The solver's factorisation
    dominates the cost, so it is built once per mesh and cached
    (:class:`ObjectSurface`). Approximate: about 1 % mean error on meshes of
    a few thousand vertices, worse near sharp creases, see
    ``docs/benchmarks/geodesic.md``. ``method="exact"``: the exact
    polyhedral geodesics of pygeodesic (MMP algorithm), also one multi-source
    propagation; slower, optional dependency ``benchharness[exact]``.

Everything is in the units of the mesh (metres for YCB meshes).
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal, Union

import numpy as np
from scipy.spatial import cKDTree

if TYPE_CHECKING:  # trimesh is imported where it is used: a Rubik's run never needs it (0.2 s)
    import trimesh

__all__ = [
    "ContactError",
    "ObjectSurface",
    "object_surface",
    "contact_region_error",
    "euclidean_max_min",
    "DEFAULT_CONTACT_TOL",
]

#: Distance (m) from the object surface within which a mesh point counts as
#: touching it: about a fingertip pad's compliance and a YCB mesh's accuracy.
DEFAULT_CONTACT_TOL = 2e-3

GeodesicMethod = Literal["heat", "exact"]
#: A region or robot contact: a mesh, several meshes (robot links), object
#: vertex indices (integer 1-D array), or points ((n, 3) float array).
ContactSpec = Union[
    "trimesh.Trimesh", Sequence["trimesh.Trimesh"], np.ndarray, Sequence[Sequence[float]]
]


@dataclass(frozen=True)
class ContactError:
    """Result of Algorithm 1 for one trial.

    ``euc``/``geo`` are ``max_d`` with ``G_euc``/``G_geo``; ``worst_euc`` and
    ``worst_geo`` the object vertices of ``P_r`` attaining them.
    ``desired_vertices`` is ``V_c`` and ``reached_vertices`` is ``P_r`` (both
    unique, sorted object vertex indices). ``geo`` is NaN when the desired
    and reached vertices lie on disconnected parts of the mesh.
    """

    euc: float
    geo: float
    g_min: float
    desired_vertices: np.ndarray = field(repr=False)
    reached_vertices: np.ndarray = field(repr=False)
    worst_euc: int
    worst_geo: int
    method: str


class ObjectSurface:
    """An object mesh with the per-mesh state Algorithm 1 reuses across trials.

    Build one per object (or use :func:`object_surface`, which caches by mesh
    content) and score every trial on it: the KD-tree, ``G_min`` and above all
    the heat-method factorisation are computed once, lazily.
    """

    def __init__(self, mesh: trimesh.Trimesh):
        import trimesh

        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            raise TypeError("ObjectSurface needs a non-empty trimesh.Trimesh")
        self.mesh = mesh
        self.vertices = np.asarray(mesh.vertices, dtype=np.float64)
        self.faces = np.asarray(mesh.faces, dtype=np.int64)
        self._tree: cKDTree | None = None
        self._heat = None
        self._exact = None
        self._g_min: float | None = None

    @property
    def tree(self) -> cKDTree:
        if self._tree is None:
            self._tree = cKDTree(self.vertices)
        return self._tree

    @property
    def g_min(self) -> float:
        """Euclidean distance between the two closest distinct vertices."""
        if self._g_min is None:
            d, _ = self.tree.query(self.vertices, k=2)
            d = d[:, 1]
            # Coincident (unmerged) vertices would make G_min 0, which says
            # nothing about resolution: they are skipped.
            d = d[d > 0]
            self._g_min = float(d.min()) if len(d) else float("nan")
        return self._g_min

    @property
    def mean_edge(self) -> float:
        return float(self.mesh.edges_unique_length.mean())

    def min_vertex(self, points: np.ndarray) -> np.ndarray:
        """``min-vertex``: nearest object vertex of each point."""
        pts = np.asarray(points, dtype=float).reshape(-1, 3)
        if len(pts) == 0:
            return np.zeros(0, dtype=np.int64)
        _, idx = self.tree.query(pts)
        return np.asarray(idx, dtype=np.int64)

    def intersect(
        self, part: trimesh.Trimesh, contact_tol: float = DEFAULT_CONTACT_TOL
    ) -> np.ndarray:
        """``intersect``: points of ``part`` within ``contact_tol`` of the surface."""
        import trimesh.proximity
        import trimesh.remesh

        v, f = np.asarray(part.vertices, float), np.asarray(part.faces, np.int64)
        if len(f):
            v, f = trimesh.remesh.subdivide_to_size(v, f, max_edge=self.mean_edge, max_iter=12)
            pts = np.vstack([v, v[f].mean(axis=1)])
        else:
            pts = v
        _, dist, _ = trimesh.proximity.closest_point(self.mesh, pts)
        return pts[dist <= contact_tol]

    def heat_solver(self):
        if self._heat is None:
            import potpourri3d as pp3d

            self._heat = pp3d.MeshHeatMethodDistanceSolver(self.vertices, self.faces)
        return self._heat

    def exact_solver(self):
        if self._exact is None:
            try:
                from pygeodesic import geodesic
            except ImportError as e:  # pragma: no cover - optional dependency
                raise ImportError(
                    "method='exact' needs pygeodesic: pip install 'benchharness[exact]'"
                ) from e
            self._exact = geodesic.PyGeodesicAlgorithmExact(self.vertices, self.faces)
        return self._exact

    def region_boundary(self, vertices: np.ndarray) -> np.ndarray:
        """Vertices of the set with a mesh neighbour outside it.

        The heat method recovers distance only up to a constant, which
        potpourri3d fixes from the values at the sources; over an *area* of
        sources those values spread by about the region's radius (several mm
        on a 5 cm face), biasing every distance. Seeding from the region's
        boundary ring -- through which any path from outside must pass --
        removes most of that bias (6.8 % -> 1.1 % error in the box test).
        Falls back to the whole set when it has no boundary.
        """
        inside = np.zeros(len(self.vertices), dtype=bool)
        inside[vertices] = True
        e = self.mesh.edges_unique
        cross = inside[e[:, 0]] != inside[e[:, 1]]
        ring = np.unique(e[cross].ravel())
        ring = ring[inside[ring]]
        return ring if len(ring) else np.asarray(vertices)

    def geodesic_to_set(
        self, sources: np.ndarray, targets: np.ndarray, method: GeodesicMethod = "heat"
    ) -> np.ndarray:
        """Distance along the surface from each target vertex to the nearest source vertex."""
        sources = np.unique(np.asarray(sources, dtype=np.int64))
        targets = np.asarray(targets, dtype=np.int64)
        if len(sources) == 0 or len(targets) == 0:
            return np.full(len(targets), np.nan)
        if method == "heat":
            d = self.heat_solver().compute_distance_multisource(
                self.region_boundary(sources).tolist()
            )
            out = np.asarray(d, dtype=float)[targets]
            out[np.isin(targets, sources)] = 0.0
            return out
        if method == "exact":
            d, _ = self.exact_solver().geodesicDistances(
                sources.astype(np.int32), targets.astype(np.int32)
            )
            d = np.asarray(d, dtype=float)
            d[~np.isfinite(d) | (d > 1e30)] = np.nan  # unreachable: other component
            return d
        raise ValueError(f"unknown geodesic method {method!r} (heat or exact)")

    def vertices_of(
        self, spec: ContactSpec, contact_tol: float = DEFAULT_CONTACT_TOL
    ) -> np.ndarray:
        """Object vertices for a region / contact given in any accepted form."""
        import trimesh

        if isinstance(spec, trimesh.Trimesh):
            return np.unique(self.min_vertex(self.intersect(spec, contact_tol)))
        if (
            isinstance(spec, (list, tuple))
            and spec
            and all(isinstance(m, trimesh.Trimesh) for m in spec)
        ):
            parts = [self.min_vertex(self.intersect(m, contact_tol)) for m in spec]
            return np.unique(np.concatenate(parts))
        arr = np.asarray(spec)
        if arr.ndim == 1 and np.issubdtype(arr.dtype, np.integer):
            if len(arr) and (arr.min() < 0 or arr.max() >= len(self.vertices)):
                raise ValueError(f"vertex index out of range 0..{len(self.vertices) - 1}")
            return np.unique(arr.astype(np.int64))
        if arr.size == 0:
            return np.zeros(0, dtype=np.int64)
        try:
            arr = arr.astype(float)
        except (TypeError, ValueError):
            raise ValueError("contact points: not numbers") from None
        if arr.ndim == 1 and arr.shape == (3,):
            arr = arr[None]
        if arr.ndim != 2 or arr.shape[1] != 3:
            raise ValueError(f"contact points: expected shape (n, 3), got {arr.shape}")
        if np.isinf(arr).any():
            raise ValueError("contact points: an infinite coordinate")
        # NaN rows are "no point" (fixed-width logs pad with them).
        arr = arr[np.all(np.isfinite(arr), axis=1)]
        return np.unique(self.min_vertex(arr))


_CACHE: OrderedDict[str, ObjectSurface] = OrderedDict()
_CACHE_SIZE = 16


def _digest(mesh: trimesh.Trimesh) -> str:
    h = hashlib.sha1()
    h.update(np.ascontiguousarray(mesh.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype=np.int64).tobytes())
    return h.hexdigest()


def object_surface(mesh: trimesh.Trimesh | ObjectSurface) -> ObjectSurface:
    """The cached :class:`ObjectSurface` of a mesh (keyed by its content).

    Keyed by content rather than identity so that reloading the same file for
    each trial still reuses the factorisation; a small LRU bounds memory.
    """
    if isinstance(mesh, ObjectSurface):
        return mesh
    key = _digest(mesh)
    surf = _CACHE.get(key)
    if surf is None:
        surf = ObjectSurface(mesh)
        _CACHE[key] = surf
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)
    else:
        _CACHE.move_to_end(key)
    return surf


def euclidean_max_min(reached_points: np.ndarray, desired_points: np.ndarray) -> tuple[float, int]:
    """``max over r of min over d ||r - d||`` and the index of the worst ``r``."""
    r = np.asarray(reached_points, float).reshape(-1, 3)
    d = np.asarray(desired_points, float).reshape(-1, 3)
    if len(r) == 0 or len(d) == 0:
        return float("nan"), -1
    dist, _ = cKDTree(d).query(r)
    k = int(np.argmax(dist))
    return float(dist[k]), k


def contact_region_error(
    mesh: trimesh.Trimesh | ObjectSurface,
    desired: ContactSpec,
    reached: ContactSpec,
    *,
    method: GeodesicMethod = "heat",
    contact_tol: float = DEFAULT_CONTACT_TOL,
) -> ContactError:
    """Algorithm 1: Euclidean and geodesic contact-region error.

    ``desired`` (``C_d``) and ``reached`` (the robot links ``L_i`` or contact
    points ``P_r``) are each a mesh, a list of meshes, an integer array of
    object vertex indices, or an ``(n, 3)`` array of points, all in the object
    frame. Raises ``ValueError`` if either side touches no vertex (nothing to
    measure: e.g. a link farther than ``contact_tol`` from the object), and
    ``ValueError`` naming the argument for a negative or non-finite
    ``contact_tol``, an unknown ``method``, points not shaped ``(n, 3)``, an
    infinite coordinate or a vertex index out of range. NaN point rows are
    skipped (padding of fixed-width logs).
    """
    if method not in ("heat", "exact"):
        raise ValueError(f"method: unknown geodesic method {method!r} (heat or exact)")
    if not (
        isinstance(contact_tol, (int, float)) and np.isfinite(contact_tol) and contact_tol >= 0
    ):
        raise ValueError(f"contact_tol: {contact_tol!r} is not a non-negative distance")
    surf = object_surface(mesh)
    try:
        v_c = surf.vertices_of(desired, contact_tol)
    except ValueError as exc:
        raise ValueError(f"desired: {exc}") from None
    try:
        p_r = surf.vertices_of(reached, contact_tol)
    except ValueError as exc:
        raise ValueError(f"reached: {exc}") from None
    if len(v_c) == 0:
        raise ValueError(
            "the desired contact region maps to no object vertex (intersect() found nothing)"
        )
    if len(p_r) == 0:
        raise ValueError(
            "the robot contact maps to no object vertex (nothing within contact_tol of the object)"
        )
    euc, k_e = euclidean_max_min(surf.vertices[p_r], surf.vertices[v_c])
    geo_d = surf.geodesic_to_set(v_c, p_r, method)
    if np.all(np.isnan(geo_d)):
        geo, k_g = float("nan"), -1
    else:
        k_g = int(np.nanargmax(geo_d))
        geo = float(geo_d[k_g])
    return ContactError(
        euc=euc,
        geo=geo,
        g_min=surf.g_min,
        desired_vertices=v_c,
        reached_vertices=p_r,
        worst_euc=int(p_r[k_e]),
        worst_geo=int(p_r[k_g]) if k_g >= 0 else -1,
        method=method,
    )
