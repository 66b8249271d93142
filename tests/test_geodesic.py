"""Geodesic and Euclidean contact distances on a box against unfolded-face answers.

Box [-a, a]^3 with a = 5 cm, triangulated on a regular grid (all the points
used are mesh vertices). A shortest surface path between points on two
faces crosses the shared edge; unfolding the faces into a plane turns it
into a straight segment:

* adjacent faces, A = (x1, y1, a) on top, B = (a, y2, z2) on the +x side:
  d = sqrt(((a - x1) + (a - z2))^2 + (y1 - y2)^2)
* opposite faces, A = (x, 0, a) and C = (x, 0, -a) near the +x side:
  d = (a - x) + 2a + (a - x) over the +x face (every other unfolding is longer).
"""

import numpy as np
import pytest
import trimesh
from scipy.spatial.distance import pdist

from benchharness.metrics.contact import (
    ObjectSurface,
    contact_region_error,
    euclidean_max_min,
    object_surface,
)

A = 0.05
HEAT_REL_TOL = 0.03  # heat method on a ~4k-vertex mesh: observed 0.4-1.2 %


def grid_box(a=A, n=20):
    """Box with each face a regular n x n grid of split squares (vertex spacing 2a/n)."""
    u = np.linspace(-a, a, n + 1)
    uu, vv = (g.ravel() for g in np.meshgrid(u, u, indexing="ij"))
    k = np.arange(n + 1)
    i, j = (g.ravel() for g in np.meshgrid(k[:-1], k[:-1], indexing="ij"))
    q00, q10, q01, q11 = (
        i * (n + 1) + j,
        (i + 1) * (n + 1) + j,
        i * (n + 1) + j + 1,
        (i + 1) * (n + 1) + j + 1,
    )
    tri = np.vstack([np.column_stack([q00, q10, q11]), np.column_stack([q00, q11, q01])])
    verts, faces = [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            p = np.zeros((len(uu), 3))
            p[:, axis] = sign * a
            p[:, (axis + 1) % 3], p[:, (axis + 2) % 3] = uu, vv
            f = tri if sign > 0 else tri[:, ::-1]
            faces.append(f + sum(len(x) for x in verts))
            verts.append(p)
    return trimesh.Trimesh(np.vstack(verts), np.vstack(faces), process=True)


@pytest.fixture(scope="module")
def box():
    return ObjectSurface(grid_box())


def vid(surface, p):
    i = int(surface.min_vertex(np.asarray(p, float))[0])
    assert np.allclose(surface.vertices[i], p), "test point must be a mesh vertex"
    return i


CASES = [
    # (A, B, analytic geodesic)
    ((0.0, -0.025, A), (A, 0.025, -0.025), np.hypot((A - 0.0) + (A + 0.025), 0.05)),
    ((0.025, 0.0, A), (A, 0.0, 0.0), (A - 0.025) + (A - 0.0)),
    ((0.025, 0.0, A), (0.025, 0.0, -A), (A - 0.025) + 2 * A + (A - 0.025)),
]


@pytest.mark.parametrize("p, q, expected", CASES)
def test_exact_geodesic_matches_unfolding(box, p, q, expected):
    d = box.geodesic_to_set([vid(box, p)], [vid(box, q)], "exact")[0]
    assert d == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("p, q, expected", CASES)
def test_heat_geodesic_within_tolerance(box, p, q, expected):
    d = box.geodesic_to_set([vid(box, p)], [vid(box, q)], "heat")[0]
    assert d == pytest.approx(expected, rel=HEAT_REL_TOL)


def test_multisource_gives_distance_to_nearest_source(box):
    top = vid(box, (0.025, 0.0, A))
    side = vid(box, (A, 0.0, 0.025))
    target = vid(box, (A, 0.0, 0.0))
    for method in ("exact", "heat"):
        d = box.geodesic_to_set([top, side], [target], method)[0]
        assert d == pytest.approx(0.025, rel=HEAT_REL_TOL if method == "heat" else 1e-9)
        assert box.geodesic_to_set([target], [target], method)[0] == pytest.approx(0.0, abs=1e-12)


def test_euclidean_metric():
    d, k = euclidean_max_min([[0, 0, 0], [3, 4, 0], [1, 0, 0]], [[0, 0, 0], [1, 0, 0]])
    assert (d, k) == (pytest.approx(np.hypot(2, 4)), 1)


def test_g_min_is_closest_vertex_pair(box):
    assert box.g_min == pytest.approx(pdist(box.vertices).min())


def test_algorithm1_with_vertex_indices_and_points(box):
    v = box.vertices
    desired = np.flatnonzero(np.isclose(v[:, 2], A) & (v[:, 0] <= 0))  # left half of the top face
    reached = np.array([[A, 0.0, 0.0], [A, 0.0, -0.025]])  # two points on the +x face
    # farthest reached point (A, 0, -0.025): nearest desired vertex is (0, 0, A)
    exp_euc = np.hypot(A, A + 0.025)
    exp_geo = A + (A + 0.025)
    res = contact_region_error(box, desired, reached, method="exact")
    assert res.euc == pytest.approx(exp_euc)
    assert res.geo == pytest.approx(exp_geo)
    assert np.allclose(v[res.worst_geo], [A, 0, -0.025])
    assert res.g_min == pytest.approx(box.g_min)
    heat = contact_region_error(box, desired, reached, method="heat")
    assert heat.geo == pytest.approx(exp_geo, rel=HEAT_REL_TOL)
    assert heat.euc == res.euc


def test_algorithm1_with_region_mesh_and_link_mesh(box):
    m = box.mesh
    centroids = m.triangles_center
    region_faces = np.flatnonzero(np.isclose(centroids[:, 2], A) & (centroids[:, 0] < 0))
    region = m.submesh([region_faces], append=True)
    # a 1 cm fingertip cube pressed 0.5 mm into the +x face around (A, 0, 0)
    tip = trimesh.creation.box(extents=(0.01, 0.01, 0.01))
    tip.apply_translation([A + 0.005 - 0.0005, 0.0, 0.0])
    res = contact_region_error(box, region, [tip], method="exact", contact_tol=1e-3)
    v = box.vertices
    assert np.all(np.isclose(v[res.desired_vertices, 2], A))
    assert np.all(v[res.desired_vertices, 0] <= 1e-12)
    touched = v[res.reached_vertices]
    assert np.allclose(touched[:, 0], A)
    assert np.all(np.abs(touched[:, 1:]) <= 0.005 + 1e-9)  # inside the fingertip footprint
    # worst touched vertex is the bottom edge of the footprint, z = -0.005
    assert res.geo == pytest.approx(A + (A + 0.005))


def test_surface_cache_is_keyed_by_content():
    m1, m2 = grid_box(n=4), grid_box(n=4)
    assert object_surface(m1) is object_surface(m2)
    assert object_surface(grid_box(n=2)) is not object_surface(m1)


def test_no_contact_raises(box):
    far = trimesh.creation.box(extents=(0.01,) * 3)
    far.apply_translation([1.0, 0, 0])
    with pytest.raises(ValueError, match="no object vertex"):
        contact_region_error(box, np.array([0, 1]), [far])
