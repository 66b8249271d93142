"""Generated YCB object models against analytic shapes and the published figures.

Tolerances (stated here once, used below):

* volume and area of a generated sphere / cylinder mesh: within 1 % of the
  analytic solid (a polyhedron inscribed in a smooth surface with ~3 mm
  edges loses about 0.3 % of volume); boxes: exact (1e-9 relative);
* elliptical sweeps: mesh volume within 3 % of ``∫ π a b dx``, except the
  fork, 7 %: its 3 mm-thin sections are 12- to 16-gons with ~3 mm sides,
  whose area is 93-96 % of the ellipse's (checked separately below);
* bounding-box extents: within 0.1 mm of the published dimension on every
  axis the published dimensions fix (the generators hit them exactly by
  construction; 0.1 mm leaves room for float round-off only);
* triangle quality at the default resolution: smallest angle >= 12 degrees,
  at least 99 % of triangles with smallest angle >= 20 degrees, mean edge
  2-5 mm.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from benchharness.backends.interface import Box, Cylinder, MeshShape, Sphere
from benchharness.geometry import Pose
from benchharness.objects import (
    CATALOG,
    DEFAULT_RESOLUTION,
    UnknownObjectError,
    get_spec,
    load_object,
    mass_properties,
    object_names,
)
from benchharness.objects.spec import BoxGeometry, SweepGeometry

#: Object names exactly as they appear in the published data (hand_poses.ods,
#: relaxed-rigidity-dataset.ods, DMG.ods).
PUBLISHED_NAMES = [
    "Lego Duplo",
    "Phillips-head screwdriver",
    "airplane toy",
    "apple",
    "banana",
    "cracker box",
    "fork",
    "gelatin box",
    "orange",
    "potted meat can",
    "spatula",
    "tuna fish can",
]

ALL = [s.name for s in CATALOG]


@pytest.fixture(scope="module", params=ALL)
def model(request):
    return load_object(request.param, model="generated")


# ---------------------------------------------------------------------------- catalogue


def test_catalog_covers_the_published_objects_once():
    assert sorted(object_names()) == sorted(PUBLISHED_NAMES)
    assert len({s.ycb_id for s in CATALOG}) == 12


def test_every_spec_cites_its_figures_and_states_its_simplification():
    for s in CATALOG:
        assert s.dimension_source.text and s.mass_source.text, s.name
        assert len(s.simplification) > 20, s.name
        assert 0.005 < s.mass_kg < 1.0, s.name


# ---------------------------------------------------------------------------- lookup


@pytest.mark.parametrize(
    "query, expected",
    [
        ("Lego Duplo", "Lego Duplo"),
        ("lego_duplo", "Lego Duplo"),
        ("  LEGO-duplo ", "Lego Duplo"),
        ("Phillips-head screwdriver", "Phillips-head screwdriver"),
        ("phillips head screwdriver", "Phillips-head screwdriver"),
        ("043_phillips_screwdriver", "Phillips-head screwdriver"),
        ("potted meat can", "potted meat can"),
        ("Potted_Meat_Can", "potted meat can"),
        ("010_potted_meat_can", "potted meat can"),
        ("airplane toy", "airplane toy"),
        ("toy airplane", "airplane toy"),
        ("tuna fish can", "tuna fish can"),
    ],
)
def test_lookup_ignores_case_spacing_and_punctuation(query, expected):
    assert get_spec(query).name == expected


def test_unknown_name_lists_the_valid_ones():
    with pytest.raises(UnknownObjectError) as err:
        get_spec("mustard bottle")
    msg = str(err.value)
    assert "mustard bottle" in msg
    for name in PUBLISHED_NAMES:
        assert repr(name) in msg
    with pytest.raises(LookupError):  # a LookupError, catchable as such
        load_object("mug", model="generated")


# ---------------------------------------------------------------------------- meshes vs analytic shapes


def test_sphere_mesh_volume_and_area():
    r = 0.0375
    m = load_object("apple", model="generated").surface
    assert m.volume == pytest.approx(4 / 3 * np.pi * r**3, rel=0.01)
    assert m.area == pytest.approx(4 * np.pi * r**2, rel=0.01)
    assert m.volume < 4 / 3 * np.pi * r**3  # inscribed: vertices on the sphere
    assert np.allclose(np.linalg.norm(m.vertices, axis=1), r, atol=1e-9)


def test_cylinder_mesh_volume_and_area():
    r, length = 0.0425, 0.033
    m = load_object("tuna fish can", model="generated").surface
    assert m.volume == pytest.approx(np.pi * r**2 * length, rel=0.01)
    assert m.area == pytest.approx(2 * np.pi * r**2 + 2 * np.pi * r * length, rel=0.01)


@pytest.mark.parametrize(
    "name, size",
    [
        ("cracker box", (0.06, 0.158, 0.21)),
        ("gelatin box", (0.028, 0.085, 0.073)),
        ("potted meat can", (0.05, 0.097, 0.082)),
    ],
)
def test_box_mesh_volume_and_area_are_exact(name, size):
    a, b, c = size
    m = load_object(name, model="generated").surface
    assert m.volume == pytest.approx(a * b * c, rel=1e-9)
    assert m.area == pytest.approx(2 * (a * b + b * c + a * c), rel=1e-9)


def test_box_union_volume_is_the_sum_of_its_boxes():
    for spec in CATALOG:
        if isinstance(spec.geometry, BoxGeometry):
            m = load_object(spec.name, model="generated").surface
            assert m.volume == pytest.approx(
                sum(b.volume for b in spec.geometry.boxes), rel=1e-9
            ), spec.name


def test_sweep_mesh_volume_matches_its_profile_integral():
    for spec in CATALOG:
        if isinstance(spec.geometry, SweepGeometry):
            m = load_object(spec.name, model="generated").surface
            tol = 0.07 if spec.name == "fork" else 0.03
            assert m.volume == pytest.approx(spec.geometry.profile.volume(), rel=tol), spec.name
            assert m.volume < spec.geometry.profile.volume()  # inscribed polygons: never larger


def test_finer_resolution_converges_to_the_sphere():
    r = 0.0365
    coarse = load_object("orange", resolution=0.005).surface
    fine = load_object("orange", resolution=0.0015).surface
    exact = 4 / 3 * np.pi * r**3
    assert len(fine.vertices) > 5 * len(coarse.vertices)
    assert abs(fine.volume - exact) < abs(coarse.volume - exact) / 5


# ---------------------------------------------------------------------------- per-object properties


def test_mesh_is_watertight_and_outward(model):
    m = model.surface
    assert m.is_watertight and m.is_winding_consistent
    assert m.volume > 0


def test_triangles_have_no_slivers(model):
    st = model.stats()
    angles = np.degrees(model.surface.face_angles.min(axis=1))
    assert st.min_angle_deg >= 12.0, model.name
    assert np.mean(angles >= 20.0) >= 0.99, model.name
    assert 0.002 <= st.edge_mean <= 0.005, model.name
    assert 0 < st.g_min <= st.edge_min + 1e-12


def test_bounding_box_matches_published_dimensions(model):
    extents = (model.surface.bounds[1] - model.surface.bounds[0]) * 1e3
    for axis, want in enumerate(model.spec.bbox_mm):
        if want is not None:
            assert extents[axis] == pytest.approx(want, abs=0.1), (model.name, axis)
    # origin at the bounding-box centre
    assert np.allclose(model.surface.bounds.sum(axis=0) / 2, 0.0, atol=1e-9)


def test_collision_model_carries_the_published_mass(model):
    assert model.mass.mass == pytest.approx(model.spec.mass_kg, rel=1e-12)
    assert model.mass.volume == pytest.approx(model.surface.volume, rel=0.06), model.name
    # the collision model's centre of mass lies inside the surface's bounding box, near its centroid
    assert np.linalg.norm(model.mass.com - model.surface.center_mass) < 0.003, model.name
    w, _ = model.mass.principal()
    assert np.all(w > 0) and w[0] + w[1] >= w[2] * (1 - 1e-9)  # triangle inequality of a real body
    kw = model.body_kwargs()
    assert kw["mass"] == model.spec.mass_kg and len(kw["shapes"]) == len(model.collision)


# ---------------------------------------------------------------------------- mass properties, closed forms


def test_sphere_mass_properties():
    m = load_object("orange", model="generated")
    (s,) = m.collision
    assert isinstance(s, Sphere) and s.radius == pytest.approx(0.0365)
    assert np.allclose(m.mass.com, 0.0)
    assert np.allclose(m.mass.inertia, np.eye(3) * 0.4 * 0.047 * 0.0365**2, rtol=1e-12)


def test_box_mass_properties():
    m = load_object("cracker box", model="generated")
    (s,) = m.collision
    assert isinstance(s, Box)
    a, b, c = 0.06, 0.158, 0.21
    want = 0.411 / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    assert np.allclose(m.mass.com, 0.0) and np.allclose(m.mass.inertia, want, rtol=1e-12)


def test_cylinder_mass_properties():
    m = load_object("tuna fish can", model="generated")
    (s,) = m.collision
    assert isinstance(s, Cylinder)
    mass, r, length = 0.171, 0.0425, 0.033
    ixx = mass * (3 * r * r + length * length) / 12
    assert np.allclose(m.mass.inertia, np.diag([ixx, ixx, mass * r * r / 2]), rtol=1e-12)


def test_composition_uses_poses_and_parallel_axes():
    # two 1 x 1 x 1 boxes side by side along x are one 2 x 1 x 1 box, here offset and rotated
    off = np.array([0.3, -0.2, 0.5])
    two = [
        Box((0.5, 0.5, 0.5), Pose(off + [-0.5, 0, 0])),
        Box((0.5, 0.5, 0.5), Pose(off + [0.5, 0, 0])),
    ]
    one = [Box((1.0, 0.5, 0.5), Pose(off))]
    a, b = mass_properties(two, 2.0), mass_properties(one, 2.0)
    assert np.allclose(a.com, off) and np.allclose(a.inertia, b.inertia)
    assert np.allclose(b.inertia, 2.0 / 12 * np.diag([2.0, 5.0, 5.0]))
    # a convex mesh piece agrees with the primitive it triangulates
    box = trimesh.creation.box(extents=(2.0, 1.0, 1.0))
    c = mass_properties([MeshShape(box.vertices + off, box.faces)], 2.0)
    assert np.allclose(c.com, off) and np.allclose(c.inertia, b.inertia)
    # a rotated cylinder: axis along x after a quarter turn about y
    rot = Pose.from_rotation(
        [0, 0, 0],
        __import__("scipy.spatial.transform", fromlist=["Rotation"]).Rotation.from_euler(
            "y", 90, degrees=True
        ),
    )
    cyl = mass_properties([Cylinder(0.1, 0.5, rot)], 1.0)
    assert cyl.inertia[0, 0] == pytest.approx(0.1**2 / 2) and cyl.inertia[2, 2] == pytest.approx(
        (3 * 0.01 + 1.0) / 12
    )


# ---------------------------------------------------------------------------- substitution by a real mesh


def test_user_mesh_replaces_surface_and_collision_keeping_the_mass(tmp_path):
    size = np.array([0.05, 0.08, 0.12])
    shift = np.array([0.01, 0.02, 0.06])  # real YCB meshes are not centred; the frame is kept
    user = trimesh.creation.box(extents=size)
    user.apply_translation(shift)
    path = tmp_path / "my_cracker_box.stl"
    user.export(path)

    m = load_object("Cracker Box", mesh_path=path)
    assert m.source == str(path) and m.resolution is None
    assert m.spec.name == "cracker box"
    assert np.allclose(np.sort(m.surface.vertices, axis=0), np.sort(user.vertices, axis=0))
    assert len(m.collision) == 1 and isinstance(m.collision[0], MeshShape)
    assert m.mass.mass == pytest.approx(0.411)
    assert np.allclose(m.mass.com, shift)
    a, b, c = size
    assert np.allclose(
        m.mass.inertia, 0.411 / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    )


def test_user_mesh_collision_hull_of_a_nonconvex_mesh(tmp_path):
    # an L made of two boxes: the hull is bigger than the mesh, and says so in its volume
    a = trimesh.creation.box(extents=(0.1, 0.02, 0.02))
    b = trimesh.creation.box(extents=(0.02, 0.1, 0.02))
    b.apply_translation([-0.04, 0.04, 0.0])
    path = tmp_path / "ell.obj"
    trimesh.util.concatenate([a, b]).export(path)
    m = load_object("fork", mesh_path=path)
    assert m.mass.volume > 1.5 * (0.1 * 0.02 * 0.02 + 0.02 * 0.08 * 0.02)
    with pytest.raises(ValueError):
        load_object("fork", mesh_path=path, collision="bogus")  # type: ignore[arg-type]
    pytest.importorskip("vhacdx")
    parts = load_object("fork", mesh_path=path, collision="decompose")
    assert len(parts.collision) >= 2 and parts.mass.mass == pytest.approx(0.034)
    assert parts.mass.volume < m.mass.volume  # pieces hug the L better than one hull


def test_generated_models_are_cached_but_returned_as_copies():
    a = load_object("banana", model="generated")
    a.surface.vertices += 1.0
    b = load_object("banana", resolution=DEFAULT_RESOLUTION)
    assert np.abs(b.surface.bounds).max() < 0.2
