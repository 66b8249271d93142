"""The shipped collision-only URDFs: generated from cited figures, physically consistent."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.paths import robots_dir
from benchharness.robots.descriptions import write_all
from benchharness.robots.urdf_builder import Geom, composite_inertia, shape_inertia

NAMES = ("pr2", "herb", "allegro")
#: movable joints of each URDF (the PR2 has 19 driven ones and 4 four-bar fingertip joints that follow)
DOF = {"pr2": 23, "herb": 30, "allegro": 16}


def _root(name):
    return ET.parse(robots_dir() / name / f"{name}.urdf").getroot()


def test_shipped_files_match_generators(tmp_path):
    for p in write_all(tmp_path):
        shipped = robots_dir() / p.parent.name / p.name
        assert shipped.read_text() == p.read_text(), (
            f"{shipped} is stale: run python -m benchharness.robots.descriptions"
        )


@pytest.mark.parametrize("name", NAMES)
def test_collision_only_primitives_no_mimic(name):
    root = _root(name)
    assert root.find(".//visual") is None
    assert root.find(".//mimic") is None
    assert root.find(".//mesh") is None
    movable = [j for j in root.findall("joint") if j.get("type") != "fixed"]
    assert len(movable) == DOF[name]
    for j in movable:
        lim = j.find("limit")
        if j.get("type") != "continuous":  # a continuous joint has no position limits
            assert float(lim.get("lower")) < float(lim.get("upper"))
        assert float(lim.get("velocity")) > 0 and float(lim.get("effort")) > 0


@pytest.mark.parametrize("name", NAMES)
def test_inertias_are_physical(name):
    """Every link has mass and a positive-definite inertia satisfying the triangle inequality."""
    for link in _root(name).findall("link"):
        inertial = link.find("inertial")
        assert inertial is not None, link.get("name")
        assert float(inertial.find("mass").get("value")) > 0
        i = inertial.find("inertia")
        d = np.array([float(i.get(k)) for k in ("ixx", "iyy", "izz")])
        assert np.all(d > 0)
        assert (
            d[0] + d[1] >= d[2] * (1 - 1e-9)
            and d[1] + d[2] >= d[0] * (1 - 1e-9)
            and d[0] + d[2] >= d[1] * (1 - 1e-9)
        )


@pytest.mark.parametrize("name", NAMES)
def test_every_link_and_joint_cites_a_source(name):
    lines = (robots_dir() / name / f"{name}.urdf").read_text().splitlines()
    for k, line in enumerate(lines):
        if line.startswith("  <link ") or line.startswith("  <joint "):
            assert lines[k - 1].strip().startswith("<!--"), (
                f"{name}.urdf line {k + 1} has no source comment"
            )


def test_composite_inertia_matches_a_known_solid():
    """Two half boxes side by side have the inertia of the whole box (parallel-axis theorem)."""
    whole = shape_inertia(Geom("box", (0.2, 0.1, 0.05)), 2.0)
    halves = [
        Geom("box", (0.1, 0.1, 0.05), (-0.05, 0, 0)),
        Geom("box", (0.1, 0.1, 0.05), (0.05, 0, 0)),
    ]
    com, inertia = composite_inertia(halves, 2.0)
    np.testing.assert_allclose(com, 0, atol=1e-15)
    np.testing.assert_allclose(inertia, whole, rtol=1e-12)
    # a rotated cylinder: the tensor rotates with it
    g = Geom("cylinder", (0.03, 0.2), rpy=(np.pi / 2, 0, 0))
    r = Rotation.from_euler("xyz", g.rpy).as_matrix()
    base = shape_inertia(Geom("cylinder", (0.03, 0.2)), 1.0)
    np.testing.assert_allclose(shape_inertia(g, 1.0), r @ base @ r.T, atol=1e-15)


def test_pr2_published_figures():
    root = _root("pr2")
    j = {x.get("name"): x for x in root.findall("joint")}
    assert j["l_elbow_flex_joint"].find("origin").get("xyz") == "0.4 0 0"
    assert j["l_wrist_flex_joint"].find("origin").get("xyz") == "0.321 0 0"
    assert j["l_shoulder_pan_joint"].find("origin").get("xyz") == "0 0.188 0"
    lim = j["l_shoulder_lift_joint"].find("limit")
    assert (float(lim.get("lower")), float(lim.get("upper"))) == (-0.5236, 1.3963)
    # the gripper opens to 90 mm: two fingers of travel t, each pad 1 mm off the joint value
    f = j["l_gripper_l_finger_joint"].find("limit")
    assert 2 * float(f.get("upper")) + 2 * 0.001 == pytest.approx(0.09)
    # forearm and wrist roll are continuous, as in pr2_description (no position limits)
    for side in "lr":
        for name in ("forearm_roll", "wrist_roll"):
            joint = j[f"{side}_{name}_joint"]
            assert joint.get("type") == "continuous"
            assert (
                joint.find("limit").get("lower") is None
                and joint.find("limit").get("upper") is None
            )


def test_allegro_published_figures():
    root = _root("allegro")
    j = {x.get("name"): x for x in root.findall("joint")}
    assert j["joint_0"].find("origin").get("xyz") == "0 0.0435 -0.001542"
    assert j["joint_2"].find("origin").get("xyz") == "0 0 0.054"
    lim = j["joint_12"].find("limit")
    assert (float(lim.get("lower")), float(lim.get("upper"))) == (0.263, 1.396)
    tips = [lk for lk in root.findall("link") if lk.get("name").endswith("_tip")]
    assert len(tips) == 4 and all(t.find(".//sphere") is not None for t in tips)
