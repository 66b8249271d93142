"""Each engine puts a YCB object's collision surface where the object model says it is.

An in-hand fingertip's force is the hand's stiffness times how far its target lies inside the surface
it meets, so a surface 1 mm off is ~0.65 N of a 3 N squeeze. Three engine defaults had moved it
(bench/bench_object_surfaces.py, docs/backends.md "Object surfaces"): PyBullet kept only 16 of a
32-piece scan's convex pieces (``createCollisionShapeArray``'s limit, silently) and grew every hull by
a 1 mm margin; PhysX simplified hulls in metres (vertices within 0.7 mm of a face dropped, and a hull
over 255 vertices reduced), leaving the surface up to 1.2 mm (single hull) to 7.8 mm (pieces) inside.

The independent answer is trimesh's exact signed distance of a 12 mm sphere (the Allegro fingertip) to
the model's own convex pieces; each engine reports the separation of that contact.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchharness.backends.interface import BackendError, Box, MeshShape, PhysicsConfig
from benchharness.geometry import Pose
from benchharness.objects.surface_check import contact_separations, overlapping_spheres
from benchharness.plugin import get_manager

pytestmark = pytest.mark.sim
trimesh = pytest.importorskip("trimesh")

TIP = 0.012
OVERLAP = 0.001
#: worst contact separation error allowed (m): PyBullet keeps a 0.1 mm margin (its ray casts miss thin
#: hulls without one); PhysX cooks to ~0.05 mm
TOLERANCE = {"pybullet": 0.00015, "sapien": 0.0002}


@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
@pytest.mark.parametrize(
    "name",
    [
        "apple",  # one hull of 4374 vertices (PhysX keeps 255 of one hull)
        "airplane_toy",  # 32 convex pieces (PyBullet's compound kept 16)
        "tuna_fish_can",  # the hull whose rim PhysX's metre-cooked hull cut (a fingertip sank 2.3 mm)
    ],
)
def test_fingertip_contacts_meet_the_model_surface(backend, name):
    from benchharness.objects import load_object

    model = load_object(name)
    centres, exact = overlapping_spheres(model, 40, TIP, OVERLAP)
    assert len(centres) >= 30
    be = get_manager().create("backend", backend, config=PhysicsConfig(gravity=(0.0, 0.0, 0.0)))
    try:
        obj = be.add_body(pose=Pose(), **model.body_kwargs())  # free: fixed pairs make no contacts
        sep = contact_separations(be, obj, centres, TIP)
    finally:
        be.close()
    assert np.all(np.isfinite(sep)), (
        f"{np.sum(~np.isfinite(sep))} overlapping fingertips made no contact"
    )
    err = np.abs(sep - exact)
    assert np.max(err) < TOLERANCE[backend], (np.median(err), np.max(err))


def test_pybullet_keeps_every_convex_piece_of_a_scan():
    """A column cast down through each of the 32 pieces' centres hits the body (16 missed before)."""
    from benchharness.objects import load_object

    model = load_object("airplane_toy")
    assert len(model.collision) > 16
    be = get_manager().create("backend", "pybullet")
    try:
        be.add_body(pose=Pose(), fixed=True, **model.body_kwargs())
        centres = np.array([np.asarray(s.vertices).mean(axis=0) for s in model.collision])
        tops = centres + np.array([0.0, 0.0, 0.3])
        # each column crosses its own piece (trimesh says so, per piece) and must hit the body
        for top, s in zip(tops, model.collision):
            piece = trimesh.Trimesh(s.vertices, s.faces).convex_hull
            assert len(piece.ray.intersects_location([top], [[0, 0, -1.0]])[0]) > 0
        hits = be.ray_cast(tops, np.tile([0.0, 0.0, -1.0], (len(tops), 1)), 0.6)
    finally:
        be.close()
    assert hits.hit.all(), np.flatnonzero(~hits.hit)


def test_a_body_the_engine_refuses_leaves_no_hull_file(tmp_path, monkeypatch):
    """A mesh body whose creation fails after its hull was written to disk removes that file."""
    import tempfile

    import pybullet

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    be = get_manager().create("backend", "pybullet")
    cube = MeshShape(
        vertices=np.array([[x, y, z] for x in (0, 0.01) for y in (0, 0.01) for z in (0, 0.01)]),
        faces=np.zeros((0, 3), dtype=int),
    )

    def refuse(*args, **kwargs):
        assert list(tmp_path.glob("bh_hull_*")), "the hull is written before the body is made"
        raise pybullet.error("refused")

    monkeypatch.setattr(pybullet, "createMultiBody", refuse)
    try:
        with pytest.raises(pybullet.error, match="refused"):
            be.add_body([cube], Pose(), 0.1)
        assert not [p.name for p in tmp_path.glob("bh_hull_*")]
    finally:
        be.close()


def test_pybullet_refuses_a_mixed_compound_it_would_truncate(tmp_path, monkeypatch):
    """Refused with a clear error before any hull file is written (until 2026-12-05 its mesh's hull
    was written first and left in the temporary directory, one per test-suite run)."""
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    be = get_manager().create("backend", "pybullet")
    cube = MeshShape(
        vertices=np.array([[x, y, z] for x in (0, 0.01) for y in (0, 0.01) for z in (0, 0.01)]),
        faces=np.zeros((0, 3), dtype=int),
    )
    shapes = [Box((0.005, 0.005, 0.005), Pose([0.02 * i, 0.0, 0.0])) for i in range(16)] + [cube]
    try:
        with pytest.raises(BackendError, match="17 collision shapes"):
            be.add_body(shapes, Pose(), 0.1)
        assert not [p.name for p in tmp_path.glob("bh_hull_*")]
    finally:
        be.close()
