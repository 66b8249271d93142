"""The vendored YCB scans: default models, frames fixed by the published data, G_min vs Table III.

Oracles: the authors' published DMG contacts (tasks/inhand/level3_dmg_tasks.csv,
converted from DMG.ods) must lie on the scan in the frame the spec records,
and the paper's Table III G_min (Cruciani et al., RA-L 2020, Sec. IV-B,
Table III: 0.013 / 0.057 / 0.034 / 0.004 cm) is a property of the mesh.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from benchharness.backends.interface import MeshShape
from benchharness.inhand.fileformat import read_tasks
from benchharness.objects import CATALOG, load_object
from benchharness.objects.ycb import MESH_DIR, drop_stray_pieces, read_parts, read_scan, scan_offset
from benchharness.paths import tasks_dir

#: Table III, G_min (cm), as printed
TABLE_III_GMIN_CM = {
    "gelatin box": 0.013,
    "cracker box": 0.057,
    "spatula": 0.034,
    "potted meat can": 0.004,
}

#: the published contacts lie this close to the scan in the recorded frame (m):
#: the largest measured distance is 4.42 mm (cracker box, a printed label's
#: thickness and the scan's rounding of the box edges)
CONTACT_TOL = 0.0045
#: ... and at least this far in the other frame (the data fixes the frame)
OTHER_FRAME_MIN = 0.010


def _dmg_contacts() -> dict[str, np.ndarray]:
    ts = read_tasks(tasks_dir() / "inhand" / "level3_dmg_tasks.csv")
    out = {}
    for i, obj in enumerate(ts.object):
        pts = [np.asarray(ts.contacts[s][i], float) for s in ("initial", "desired")]
        out[str(obj)] = np.concatenate(pts)
    return out


def test_every_object_has_a_vendored_scan_of_16k_triangles():
    total = 0
    for spec in CATALOG:
        assert len(read_scan(spec.scan.file).faces) == 16384, spec.name  # as shipped
        m = load_object(spec.name)
        assert m.source == "ycb" and m.resolution is None
        # the model drops the gelatin box's and tuna can's four stray two-triangle pieces
        strays = 8 if spec.name in ("gelatin box", "tuna fish can") else 0
        assert len(m.surface.faces) == 16384 - strays, spec.name
        total += (MESH_DIR / f"{spec.scan.file}.npz").stat().st_size
    assert total < 3e6  # the repository stays small: about 1.9 MB for the twelve


def test_stray_pieces_are_slivers_inside_the_object_and_the_rest_is_closed():
    """The pieces ``drop_stray_pieces`` removes enclose nothing and carry no surface: each is a
    triangle and its reverse (two faces, three vertices) of under 0.002 mm2, lying on the closed
    surface that remains; without them both scans are closed (trimesh: watertight)."""
    for spec in CATALOG:
        raw = read_scan(spec.scan.file)
        pieces = raw.split(only_watertight=False)
        stray = [p for p in pieces if len(p.faces) < 4]
        main = max(pieces, key=lambda p: len(p.faces))
        kept = read_scan(spec.scan.file)
        assert drop_stray_pieces(kept) == sum(len(p.faces) for p in stray), spec.name
        assert len(kept.faces) == len(main.faces) and kept.is_watertight, spec.name
        for p in stray:
            assert len(p.faces) == 2 and len(p.vertices) == 3 and p.area < 2e-9, spec.name
            _, d, _ = trimesh.proximity.closest_point(main, p.vertices)
            assert d.max() < 5e-5, spec.name  # on the surface that remains (within 0.05 mm)
        assert len(stray) == (4 if spec.name in ("gelatin box", "tuna fish can") else 0)


def test_default_is_the_scan_and_generated_stays_an_option():
    scan = load_object("spatula")
    gen = load_object("spatula", model="generated")
    assert gen.source == "generated" and gen.resolution == pytest.approx(0.003)
    assert load_object("spatula", resolution=0.004).source == "generated"
    assert len(scan.surface.vertices) != len(gen.surface.vertices)
    with pytest.raises(ValueError, match="resolution"):
        load_object("spatula", model="ycb", resolution=0.003)
    with pytest.raises(ValueError, match="model"):
        load_object("spatula", model="scan")  # type: ignore[arg-type]


@pytest.mark.parametrize("name", sorted(TABLE_III_GMIN_CM))
def test_published_dmg_contacts_lie_on_the_scan_in_the_recorded_frame(name):
    pts = _dmg_contacts()[name]
    model = load_object(name)
    _, d, _ = trimesh.proximity.closest_point(model.surface, pts)
    assert d.max() < CONTACT_TOL, (name, np.round(d * 1e3, 2))
    # the other frame puts them well off the surface: the data, not a default, picks the frame
    other = "ycb" if model.spec.scan.frame == "bbox_centre" else "bbox_centre"
    moved = model.surface.copy()
    moved.apply_translation(scan_offset(model.spec.scan.file, other) - model.frame_offset)
    _, d_other, _ = trimesh.proximity.closest_point(moved, pts)
    assert d_other.max() > OTHER_FRAME_MIN, (name, np.round(d_other * 1e3, 2))


def test_frame_offset_is_the_bounding_box_centre_where_recorded():
    box = load_object("cracker box")
    assert box.spec.scan.frame == "bbox_centre"
    assert np.allclose(box.surface.bounds.mean(axis=0), 0.0, atol=1e-9)
    spatula = load_object("spatula")
    assert spatula.spec.scan.frame == "ycb" and spatula.frame_offset == (0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    "name",
    [
        "cracker box",
        "spatula",
        "potted meat can",
        "gelatin box",
    ],
)
def test_g_min_on_the_scans_against_table_iii(name):
    """Ours vs the paper's G_min: within 2x, and the printed value is ours cut to 3 decimals.

    Cut, not rounded: the gelatin box's is 0.01352 cm, printed 0.013 (rounding would give 0.014);
    the other three are the same either way. Before the scan's stray slivers were dropped, their
    vertices (0.0065 cm apart) set the gelatin box's at half the printed value."""
    ours_cm = load_object(name).g_min * 100
    paper = TABLE_III_GMIN_CM[name]
    assert paper / 2 <= ours_cm <= paper * 2, (name, ours_cm)
    assert math.floor(ours_cm * 1000) / 1000 == pytest.approx(paper, abs=1e-12), (name, ours_cm)


def test_mass_is_published_and_fills_the_scan():
    for spec in CATALOG:
        m = load_object(spec.name)
        assert m.mass.mass == pytest.approx(spec.mass_kg, rel=1e-12)
        w, _ = m.mass.principal()
        assert np.all(w > 0) and w[0] + w[1] >= w[2] * (1 - 1e-9), spec.name
        # every scan is closed (the strays dropped): the mass fills its own solid
        assert m.surface.is_watertight, spec.name
        assert m.mass.volume == pytest.approx(m.surface.volume, rel=1e-9)
        assert np.allclose(m.mass.com, m.surface.center_mass, atol=1e-9)


def test_collision_pieces_hug_the_scan():
    for spec in CATALOG:
        m = load_object(spec.name)
        assert all(isinstance(s, MeshShape) for s in m.collision)
        if spec.scan.collision == "hull":
            assert len(m.collision) == 1
            continue
        assert len(read_parts(spec.scan.file)) == len(m.collision) > 1
        lo, hi = m.surface.bounds
        pieces = np.concatenate([np.asarray(s.vertices) for s in m.collision])
        # V-HACD's pieces stay within 3 mm of the scan's bounding box ...
        assert np.all(pieces > lo - 0.003) and np.all(pieces < hi + 0.003), spec.name
        # ... and fill less than one convex hull would (the reason to decompose)
        vol = sum(trimesh.convex.convex_hull(np.asarray(s.vertices)).volume for s in m.collision)
        assert vol < m.surface.convex_hull.volume, spec.name


def test_scans_are_cached_and_returned_as_copies():
    a = load_object("banana")
    a.surface.vertices += 1.0
    assert np.abs(load_object("banana").surface.bounds).max() < 0.2


# ---------------------------------------------------------------------------- Level I grasps

#: a grasp is valid when every used fingertip touches the scan (gap under 0.1 mm; measured
#: at most 0.035 mm) and no other hand part enters it by more than 1 mm (measured 0.75 mm
#: for orange-06, 0.84 mm for phillips_head_screwdriver-06, 0 for the rest) ...
MAX_GAP, MAX_PENETRATION = 1e-4, 1e-3
#: ... except the airplane's two grasps: 6.51 mm (airplane_toy-01) and 5.78 mm (-06) of
#: penetration by the palm or a phalanx at the best placement (docs/objects.md, "Frames")
AIRPLANE = ("airplane_toy-01", "airplane_toy-06")


def _level1_grasps():
    from benchharness.strategies.ingrasp.tasks import distinct_initial_grasps

    return distinct_initial_grasps()


def _check_grasp(task_id: str):
    pytest.importorskip("pytorch_kinematics")
    from benchharness.strategies.ingrasp.hand import HandKinematics
    from benchharness.strategies.ingrasp.placement import object_surface_arrays, place_object

    (t,) = [g for g in _level1_grasps() if g.task_id == task_id]
    v, n, c, sym = object_surface_arrays(load_object(t.object))
    p = place_object(HandKinematics(), t.q0_published, t.fingers, v, n, c, symmetric=sym)
    assert p.max_gap < MAX_GAP, (task_id, p.tip_gaps)  # every used fingertip touches the scan
    assert p.penetration < MAX_PENETRATION, (task_id, p.penetration)


def test_level1_has_20_distinct_initial_grasps():
    pytest.importorskip("pytorch_kinematics")
    grasps = _level1_grasps()
    assert len(grasps) == 20 and len({g.object for g in grasps}) == 10


@pytest.mark.parametrize("task_id", ["spatula-01", "lego_duplo-06"])
def test_a_level1_initial_grasp_is_a_grasp_of_the_scan(task_id):
    _check_grasp(task_id)


@pytest.mark.slow
def test_every_level1_initial_grasp_but_the_airplanes_is_a_grasp_of_the_scan():
    for g in _level1_grasps():
        if g.task_id not in AIRPLANE:
            _check_grasp(g.task_id)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="the hand enters the airplane scan by 5.8-6.5 mm")
@pytest.mark.parametrize("task_id", AIRPLANE)
def test_airplane_level1_grasps(task_id):
    _check_grasp(task_id)
