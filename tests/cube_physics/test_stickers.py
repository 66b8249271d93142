"""The rendered cube shows its logical state: every facelet in its colour, rigid or mid-twist.

A camera looks straight at each face in turn; each facelet's centre is
projected into the image and the pixel there must have that facelet's
colour (brightness-normalised, so the renderer's shading does not matter).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchharness.backends import Backend, CameraSpec
from benchharness.cube.facelets import FACES, SOLVED_STRING, to_array
from benchharness.cube.moves import apply
from benchharness.cube_physics import PhysicalCube
from benchharness.cube_physics.config import CubeConfig
from benchharness.cube_physics.model import (
    FACE_BODY_AXES,
    FACELET_BODY_NORMALS,
    FACELET_BODY_POSITIONS,
    STICKER_RGBA,
    articulated_urdf,
    stickers,
)
from benchharness.geometry import Pose
from benchharness.plugin import get_manager

CENTRE = np.array([0.0, 0.0, 0.5])
SCRAMBLE = "R U F' L2 D B'"


def _backend() -> Backend:
    b = get_manager().create("backend", "pybullet")
    if not b.capabilities.camera:  # pragma: no cover - the built-in PyBullet renders
        pytest.skip("no camera")
    return b


def _camera(normal: np.ndarray) -> CameraSpec:
    up = (0.0, 1.0, 0.0) if abs(normal[2]) > 0.5 else (0.0, 0.0, 1.0)
    eye = CENTRE + 0.25 * normal
    return CameraSpec(tuple(eye), tuple(CENTRE), up, width=96, height=96, fov_deg=30.0)


def _project(cam: CameraSpec, p: np.ndarray) -> tuple[int, int]:
    eye = np.asarray(cam.eye)
    f = np.asarray(cam.target) - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, cam.up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    d = p - eye
    s = (cam.height / 2) / math.tan(math.radians(cam.fov_deg) / 2)
    x = cam.width / 2 + s * (d @ r) / (d @ f)
    y = cam.height / 2 - s * (d @ u) / (d @ f)
    return int(round(y)), int(round(x))


def _classify(px: np.ndarray) -> str | None:
    """The sticker colour (face letter) nearest a pixel after dividing out its brightness."""
    v = px.astype(float)
    if v.max() < 30:
        return None  # black plastic
    v /= v.max()
    refs = {f: np.array(c[:3]) / max(c[:3]) for f, c in STICKER_RGBA.items()}
    return min(refs, key=lambda f: float(np.linalg.norm(refs[f] - v)))


def _seen(b: Backend) -> str:
    """The colour of all 54 facelets as rendered, as a state string (cube at the identity pose)."""
    out = ["?"] * 54
    for face in FACES:
        n = FACE_BODY_AXES[face].astype(float)
        cam = _camera(n)
        img = b.render(cam)
        for i in np.flatnonzero(np.all(FACELET_BODY_NORMALS == n, axis=1)):
            y, x = _project(cam, CENTRE + FACELET_BODY_POSITIONS[i] * 0.057)
            out[i] = _classify(img[y, x]) or "."
    return "".join(out)


@pytest.mark.parametrize("twist_axis", [None, "x", "z"])
def test_rendered_cube_shows_its_state(twist_axis):
    state = apply(to_array(SOLVED_STRING), SCRAMBLE)
    expected = "".join(FACES[int(c)] for c in state)
    b = _backend()
    try:
        cube = PhysicalCube(b, Pose(CENTRE), state=state)
        if twist_axis is not None:  # the three slabs carry the same stickers
            cube.begin_twist(twist_axis)
        assert _seen(b) == expected
        counts = {f: expected.count(f) for f in FACES}
        assert all(counts.values())  # the scramble shows all six colours on the faces
    finally:
        b.close()


def test_a_twist_turns_the_stickers_with_the_layer():
    """After U the rendered cube is the logical state, which differs from before."""
    b = _backend()
    try:
        cube = PhysicalCube(b, Pose(CENTRE))
        cube.begin_twist("z")
        b.set_joint_positions(cube.body, [0.0, -math.pi / 2])  # slab 2 (U) a quarter clockwise
        out = cube.end_twist()
        assert out.moves == "U"
        assert _seen(b) == cube.state_string != SOLVED_STRING
    finally:
        b.close()


def test_stickers_ride_on_their_slab():
    cfg = CubeConfig()
    st = stickers(cfg, to_array(SOLVED_STRING), "z")
    assert sorted(s.slab for s in st).count(2) == 9 + 12  # the U face and a ring of 12
    urdf = articulated_urdf(cfg, "z", to_array(SOLVED_STRING))
    assert urdf.count("<visual>") == 54 + 3
    assert "<visual>" not in articulated_urdf(cfg, "z")  # no state, no visuals
