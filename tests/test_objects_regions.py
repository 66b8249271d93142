"""Contact regions against analytic discs and caps.

Tolerances: on a flat face a region of radius r has area pi r^2 within 5 %
(Euclidean, exact distances; the error is the ragged one-triangle boundary)
and within 10 % with the heat-method geodesic (which under-measures distance
on our meshes by a few per cent, so its discs come out slightly large).
On a sphere of radius R, a geodesic disc of radius r has area
2 pi R^2 (1 - cos(r / R)) and a Euclidean (chord) disc of radius c has area
pi c^2 exactly; same tolerances.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchharness.objects import contact_region, load_object, vertex_distances


@pytest.fixture(scope="module")
def box():
    return load_object(
        "cracker box", model="generated"
    ).surface  # 158 x 210 mm faces at x = +-30 mm


@pytest.fixture(scope="module")
def orange():
    return load_object("orange", model="generated").surface


@pytest.mark.parametrize("metric, tol", [("euclidean", 0.05), ("geodesic", 0.10)])
@pytest.mark.parametrize("radius", [0.015, 0.03])
def test_disc_on_a_flat_face_has_area_pi_r2(box, metric, tol, radius):
    reg = contact_region(
        box, [0.08, 0.01, -0.02], radius, metric
    )  # projects onto the x = +30 mm face
    assert np.allclose(reg.centre, [0.03, 0.01, -0.02])
    assert reg.area == pytest.approx(np.pi * radius**2, rel=tol)
    v = box.vertices[reg.vertices]
    assert np.allclose(v[:, 0], 0.03)  # stayed on that face
    assert np.all(np.linalg.norm(v - reg.centre, axis=1) <= radius * 1.1 + 1e-9)
    assert reg.mesh.faces.shape[0] == reg.faces.size
    assert reg.centre_vertex in set(reg.vertices.tolist())


def test_euclidean_disc_jumps_a_thin_object_geodesic_does_not():
    # gelatin box: 28 mm thick; a 30 mm disc centred on a big face
    box = load_object("gelatin box", model="generated").surface
    p = [0.05, 0.0, 0.0]  # projects to the x = +14 mm face centre
    e = contact_region(box, p, 0.03, "euclidean")
    g = contact_region(box, p, 0.03, "geodesic")
    back_e = np.isclose(box.vertices[e.vertices, 0], -0.014).sum()
    back_g = np.isclose(box.vertices[g.vertices, 0], -0.014).sum()
    assert back_e > 0 and back_g == 0
    # along the surface is never shorter than through space (up to heat-method error)
    # (from the same source: geodesics start at the snapped vertex)
    d_g, _, v = vertex_distances(box, p, "geodesic")
    d_e = np.linalg.norm(box.vertices - box.vertices[v], axis=1)
    assert np.all(d_g >= 0.95 * d_e - 1e-3)


@pytest.mark.parametrize("r_geo", [0.02, 0.04])
def test_geodesic_cap_on_a_sphere(orange, r_geo):
    big_r = 0.0365
    reg = contact_region(orange, [0.0, 0.0, 0.1], r_geo, "geodesic")
    want = 2 * np.pi * big_r**2 * (1 - np.cos(r_geo / big_r))
    assert reg.area == pytest.approx(want, rel=0.10)


def test_euclidean_cap_on_a_sphere_is_pi_c2(orange):
    c = 0.03
    reg = contact_region(orange, [0.1, 0.0, 0.0], c, "euclidean")
    assert reg.area == pytest.approx(np.pi * c**2, rel=0.05)


def test_exact_geodesic_agrees_on_a_flat_face(box):
    pytest.importorskip("pygeodesic")
    small = load_object(
        "gelatin box", model="generated"
    ).surface  # 85 x 73 mm face at x = +14 mm; small and fast
    reg = contact_region(small, [0.02, 0.0, 0.0], 0.02, "geodesic_exact")
    assert reg.area == pytest.approx(np.pi * 0.02**2, rel=0.05)


def test_bad_arguments(box):
    with pytest.raises(ValueError):
        contact_region(box, [0, 0, 0.2], 0.0)
    with pytest.raises(ValueError):
        contact_region(box, [0, 0, 0.2], 0.01, "manhattan")  # type: ignore[arg-type]
