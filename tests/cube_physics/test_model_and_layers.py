"""Physics-free parts of the cube mechanism, checked against the cube core and analytic answers."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.cube import SOLVED, apply, reorient
from benchharness.cube_physics import CubeConfig, intended_twist, layer_moves, snap_angle
from benchharness.cube_physics.model import (
    AXES,
    AXIS_FACES,
    AXIS_SLICES,
    FACE_BODY_AXES,
    FACELET_BODY_NORMALS,
    FACELET_BODY_POSITIONS,
    articulated_urdf,
    rigid_inertia,
    slab_geometry,
)

SCRAMBLE = "R U2 F' L D B2 R' U' F2 D' L2 B"


def geometric_layer_turn(state: np.ndarray, axis: str, slab: int, quarter_turns: int) -> np.ndarray:
    """Oracle: rotate the stickers of one slab about +axis in the body frame and re-read positions."""
    a = AXES.index(axis)
    pos = FACELET_BODY_POSITIONS * 6.0  # integer sticker coordinates, -3..3
    layer = (np.sign(pos[:, a]) * (np.abs(pos[:, a]) > 1.5)).astype(int) + 1  # ±2/±3 -> slab 0/2
    rot = Rotation.from_rotvec(np.eye(3)[a] * quarter_turns * np.pi / 2).as_matrix()
    lookup = {tuple(np.rint(p).astype(int)): i for i, p in enumerate(pos)}
    new = state.copy()
    for i in np.flatnonzero(layer == slab):
        new[lookup[tuple(np.rint(rot @ pos[i]).astype(int))]] = state[i]
    return new


def test_face_axes_are_a_right_handed_frame_with_u_up():
    assert FACE_BODY_AXES["U"].tolist() == [0, 0, 1]
    assert FACE_BODY_AXES["R"].tolist() == [1, 0, 0]
    assert FACE_BODY_AXES["F"].tolist() == [0, -1, 0]
    for a, b in ("UD", "RL", "FB"):
        assert (FACE_BODY_AXES[a] == -FACE_BODY_AXES[b]).all()
    # the core's frame (x R, y U, z F) is right-handed, so R x U = F must hold here too
    assert (
        np.cross(FACE_BODY_AXES["R"], FACE_BODY_AXES["U"]).tolist() == FACE_BODY_AXES["F"].tolist()
    )


def test_facelets_lie_on_their_faces_and_follow_the_kociemba_net():
    pos, nrm = FACELET_BODY_POSITIONS, FACELET_BODY_NORMALS
    assert np.allclose(np.einsum("ij,ij->i", pos, nrm), 0.5)  # on the surface of a unit cube
    name = lambda f, k: "URFDLB".index(f) * 9 + k - 1  # noqa: E731
    # U1 is the back-left corner of U (touching L and B), U9 front-right (touching F and R)
    assert np.allclose(pos[name("U", 1)], [-1 / 3, 1 / 3, 0.5])
    assert np.allclose(pos[name("U", 9)], [1 / 3, -1 / 3, 0.5])
    # F1 is top-left seen from the front; D1 touches F and L
    assert np.allclose(pos[name("F", 1)], [-1 / 3, -0.5, 1 / 3])
    assert np.allclose(pos[name("D", 1)], [-1 / 3, -1 / 3, -0.5])
    # R1 touches U and F; B1 touches U and R (seen from behind)
    assert np.allclose(pos[name("R", 1)], [0.5, -1 / 3, 1 / 3])
    assert np.allclose(pos[name("B", 1)], [1 / 3, 0.5, 1 / 3])


@pytest.mark.parametrize("axis", AXES)
@pytest.mark.parametrize("slab", [0, 2])
@pytest.mark.parametrize("k", [1, 2, 3, -1])
def test_layer_moves_match_rotating_the_stickers(axis, slab, k):
    start = apply(SOLVED, SCRAMBLE)
    q0, q2 = (k, 0) if slab == 0 else (0, k)
    got = apply(start, layer_moves(axis, q0, q2))
    assert np.array_equal(got, geometric_layer_turn(start, axis, slab, k))


@pytest.mark.parametrize("axis", AXES)
def test_middle_turning_against_both_outer_layers_is_the_slice_move_up_to_a_rotation(axis):
    start = apply(SOLVED, SCRAMBLE)
    slice_move = AXIS_SLICES[axis]
    for suffix, k in (("", 1), ("2", 2), ("'", 3)):
        # the slice turns the middle +k quarters about +axis: relative to it the outers turn -k
        body = apply(start, layer_moves(axis, -k, -k))
        assert np.array_equal(body, reorient(apply(start, slice_move + suffix)))


def test_layer_move_notation():
    assert layer_moves("z", 0, -1) == "U"
    assert layer_moves("z", 0, 1) == "U'"
    assert layer_moves("z", 1, 0) == "D"
    assert layer_moves("z", 2, -2) == "D2 U2"
    assert layer_moves("x", 0, 4) == ""
    assert layer_moves("y", -1, 0) == "F'"


@pytest.mark.parametrize("move", ["U", "U'", "U2", "D", "R", "L'", "F2", "B", "M", "E'", "S2"])
def test_intended_twist_quarter_turns_reproduce_the_move(move):
    it = intended_twist(move)
    start = apply(SOLVED, SCRAMBLE)
    got = apply(start, layer_moves(it.axis, *it.quarter_turns))
    assert np.array_equal(got, reorient(apply(start, move)))
    assert it.axis == next(a for a in AXES if move[0] in AXIS_FACES[a] + (AXIS_SLICES[a],))


def test_whole_cube_rotation_is_not_a_twist():
    with pytest.raises(ValueError, match="whole-cube rotation"):
        intended_twist("y")


@pytest.mark.parametrize(
    "angle,k,residual,within",
    [
        (89.9, 1, -0.1, True),
        (-90.4, -1, -0.4, True),
        (31.0, 0, 31.0, False),
        (104.0, 1, 14.0, True),
        (-181.0, -2, -1.0, True),
        (44.0, 0, 44.0, False),
        (46.0, 1, -44.0, False),
        (0.0, 0, 0.0, True),
    ],
)
def test_snap_angle(angle, k, residual, within):
    s = snap_angle(angle, 15.0)
    assert (s.quarter_turns, s.within) == (k, within)
    assert s.residual_deg == pytest.approx(residual)


@pytest.mark.parametrize("axis", AXES)
def test_urdf_slabs_tile_the_cube_with_consistent_mass_and_inertia(axis):
    cfg = CubeConfig()
    root = ET.fromstring(articulated_urdf(cfg, axis))
    masses = {
        l.get("name"): float(l.find("inertial/mass").get("value")) for l in root.findall("link")
    }
    assert sum(masses.values()) == pytest.approx(0.094)
    assert all(m == pytest.approx(0.094 / 3) for m in masses.values())
    joints = root.findall("joint")
    assert [j.get("name") for j in joints] == ["layer_0", "layer_2"]
    assert all(j.find("parent").get("link") == "slab_1" for j in joints)
    a = AXES.index(axis)
    for j in joints:
        assert j.get("type") == "continuous"
        assert np.allclose([float(v) for v in j.find("axis").get("xyz").split()], np.eye(3)[a])
    # parallel-axis theorem: the three slabs about the cube's centre = the rigid cube
    total = np.zeros(3)
    for s in slab_geometry(cfg, axis):
        d = s.centre
        total += s.inertia + s.mass * (np.dot(d, d) - d * d)
    assert np.allclose(total, rigid_inertia(cfg), rtol=1e-12)
    assert np.allclose(rigid_inertia(cfg), 0.094 * 0.057**2 / 6)
    # slabs cover [-edge/2, edge/2] along the axis without overlap
    spans = sorted(
        (s.centre[a] - s.size[a] / 2, s.centre[a] + s.size[a] / 2) for s in slab_geometry(cfg, axis)
    )
    assert spans[0][0] == pytest.approx(-0.0285) and spans[-1][1] == pytest.approx(0.0285)
    assert spans[0][1] == pytest.approx(spans[1][0]) and spans[1][1] == pytest.approx(spans[2][0])


def test_config_validation_and_derived_figures():
    cfg = CubeConfig()
    assert cfg.joint_frictions(2) == pytest.approx((0.01, 0.03))
    assert cfg.joint_frictions(0) == pytest.approx((0.03, 0.01))
    assert cfg.joint_frictions(None) == (0.02, 0.02)
    k, d = cfg.drive_gains(0.02)
    assert k == pytest.approx(0.03 / np.radians(8.0))
    assert d == pytest.approx(0.03 / 0.5)
    with pytest.raises(ValueError):
        CubeConfig(snap_tolerance_deg=50)
    with pytest.raises(ValueError):
        CubeConfig(mass=0)
    with pytest.raises(ValueError):
        CubeConfig(drag_bias=1.0)
