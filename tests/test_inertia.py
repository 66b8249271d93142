"""The primitive mass properties (``benchharness.inertia``) against an independent oracle.

The oracle is trimesh's polyhedral integration over a mesh of the same
solid (``Trimesh.moment_inertia`` at unit density, scaled to the mass), not
a closed form, so a wrong factor or a radius taken for a diameter in the one
shared formula fails here. The box mesh is exact; the cylinder and sphere
meshes are fine tessellations, whose volume and moments approach the
solid's from below within the stated tolerances.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from benchharness.backends._urdf import shape_volume_com_inertia
from benchharness.backends.interface import Box, Cylinder, MeshShape, Sphere
from benchharness.inertia import (
    box_inertia,
    box_volume,
    convex_hull_properties,
    cylinder_inertia,
    cylinder_volume,
    parallel_axis,
    sphere_inertia,
    sphere_volume,
)

MASS = 0.37  # kg, not 1: a mass mistaken for a density or a volume must show


def _oracle(mesh: trimesh.Trimesh, mass: float) -> tuple[float, np.ndarray]:
    """Volume and inertia tensor about the centroid of ``mesh`` filled uniformly with ``mass``."""
    mesh.density = 1.0
    return float(mesh.volume), np.asarray(mesh.moment_inertia) * (mass / mesh.volume)


@pytest.mark.parametrize("size", [(0.2, 0.1, 0.05), (0.057, 0.057, 0.019), (0.3, 0.01, 0.07)])
def test_box_matches_trimesh(size):
    vol, tensor = _oracle(trimesh.creation.box(extents=size), MASS)
    assert box_volume(size) == pytest.approx(vol, rel=1e-12)
    np.testing.assert_allclose(np.diag(box_inertia(MASS, size)), tensor, rtol=1e-10, atol=1e-15)


@pytest.mark.parametrize("radius,length", [(0.03, 0.2), (0.05, 0.02), (0.0425, 0.033)])
def test_cylinder_matches_trimesh(radius, length):
    # 2048 sections: the polygon's area is short of the circle's by ~(2 pi / n)^2 / 6 ~ 2e-6
    mesh = trimesh.creation.cylinder(radius=radius, height=length, sections=2048)
    vol, tensor = _oracle(mesh, MASS)
    assert cylinder_volume(radius, length) == pytest.approx(vol, rel=1e-5)
    np.testing.assert_allclose(
        np.diag(cylinder_inertia(MASS, radius, length)), tensor, rtol=1e-5, atol=1e-12
    )


@pytest.mark.parametrize("radius", [0.01, 0.037, 0.1])
def test_sphere_matches_trimesh(radius):
    # an icosphere of 5 subdivisions (20 480 faces) is within ~1e-3 of the ball
    vol, tensor = _oracle(trimesh.creation.icosphere(subdivisions=5, radius=radius), MASS)
    assert sphere_volume(radius) == pytest.approx(vol, rel=2e-3)
    np.testing.assert_allclose(np.diag(sphere_inertia(MASS, radius)), tensor, rtol=3e-3, atol=1e-15)


def test_convex_hull_matches_trimesh_of_a_rotated_offset_box():
    rot = trimesh.transformations.rotation_matrix(0.7, [1.0, 2.0, 0.5])
    rot[:3, 3] = (0.1, -0.02, 0.3)
    box = trimesh.creation.box(extents=(0.2, 0.1, 0.05), transform=rot)
    vol, com, unit = convex_hull_properties(box.vertices)
    o_vol, o_tensor = _oracle(box.copy(), vol)  # unit density: mass = volume
    assert vol == pytest.approx(0.2 * 0.1 * 0.05, rel=1e-12) and vol == pytest.approx(o_vol)
    np.testing.assert_allclose(com, (0.1, -0.02, 0.3), atol=1e-12)
    np.testing.assert_allclose(unit, o_tensor, rtol=1e-10, atol=1e-15)


@pytest.mark.parametrize(
    "shape,size",
    [
        (Box((0.1, 0.05, 0.025)), (0.2, 0.1, 0.05)),
        (Cylinder(0.03, 0.1), (0.03, 0.2)),
        (Sphere(0.037), (0.037,)),
    ],
)
def test_backend_shapes_use_the_primitives(shape, size):
    """The collision shapes' unit-density figures are the primitives' with mass = volume.

    Exact equality: the backends, the object models and the URDF builder
    must compute the very same numbers, not merely close ones.
    """
    v, com, tensor = shape_volume_com_inertia(shape)
    vol, moments = {
        Box: lambda: (box_volume(size), box_inertia(box_volume(size), size)),
        Cylinder: lambda: (cylinder_volume(*size), cylinder_inertia(cylinder_volume(*size), *size)),
        Sphere: lambda: (sphere_volume(*size), sphere_inertia(sphere_volume(*size), *size)),
    }[type(shape)]()
    assert v == vol and np.array_equal(com, np.zeros(3))
    assert np.array_equal(tensor, np.diag(moments))


def test_mesh_shape_uses_the_hull():
    box = trimesh.creation.box(extents=(0.2, 0.1, 0.05))
    v, _, tensor = shape_volume_com_inertia(MeshShape(box.vertices, box.faces))
    assert v == pytest.approx(0.001, rel=1e-12)
    np.testing.assert_allclose(np.diag(tensor), box_inertia(v, (0.2, 0.1, 0.05)), rtol=1e-10)


def test_parallel_axis_moves_a_box_inertia_to_a_point_off_its_centre():
    """box_inertia + parallel_axis vs trimesh's inertia of the offset box about the origin."""
    size, d = (0.2, 0.1, 0.05), np.array([0.03, -0.12, 0.07])
    mesh = trimesh.creation.box(extents=size)
    mesh.apply_translation(d)
    mesh.density = 1.0
    about_origin = mesh.moment_inertia_frame(np.eye(4)) * (MASS / mesh.volume)
    ours = np.diag(box_inertia(MASS, size)) + parallel_axis(MASS, d)
    np.testing.assert_allclose(ours, about_origin, rtol=1e-12, atol=1e-15)
