"""The analytic ray–box model and the cube's yaw symmetry, against hand-worked answers.

No engine: these run in the simulator-free environment too.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.sensors import (
    cube_tilt,
    cube_yaw,
    ray_box,
    ray_box_jacobian,
    wrap_quarter,
    yaw_error,
)

H = 0.0285


def test_axis_aligned_hits_by_hand():
    c = np.array([0.3, 0.1, H])
    o = np.array([[0.3 - 0.1, 0.1, H], [0.3, 0.1, 0.5], [0.3 + 0.01, 0.1 + 0.02, 0.2]])
    d = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 0, -2.0]])  # last one not normalised
    r = ray_box(o, d, c, np.eye(3), H)
    assert r.hit.all()
    assert r.distance == pytest.approx([0.1 - H, 0.5 - 2 * H, 0.2 - 2 * H])
    assert np.allclose(r.normal, [[-1, 0, 0], [0, 0, 1], [0, 0, 1]])
    assert list(r.face_axis) == [0, 2, 2]
    assert r.edge_distance == pytest.approx([H, H, H - 0.02])
    assert np.allclose(r.point[0], [0.3 - H, 0.1, H])


def test_misses_inside_and_parallel():
    c = np.zeros(3)
    o = np.array(
        [
            [-0.1, 0.05, 0.0],  # passes beside the box
            [0.0, 0.0, 0.0],  # starts inside: a ToF window is never inside the cube
            [-0.1, H + 1e-4, 0.0],  # parallel to the +y face, just outside it
            [0.1, 0.0, 0.0],  # points away
        ]
    )
    d = np.array([[1.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0]])
    r = ray_box(o, d, c, np.eye(3), H)
    assert not r.hit.any()
    assert np.isinf(r.distance).all() and np.isnan(r.point).all() and (r.face_axis == -1).all()


def test_rotated_box_by_hand():
    """A box turned 45° about z: a ray along +x meets the vertical edge at x = -H·√2."""
    rot = Rotation.from_euler("z", 45, degrees=True).as_matrix()
    r = ray_box([[-1.0, 0.0, 0.0]], [[1.0, 0.0, 0.0]], np.zeros(3), rot, H)
    assert r.hit[0] and r.distance[0] == pytest.approx(1.0 - H * math.sqrt(2))
    assert r.edge_distance[0] == pytest.approx(0.0, abs=1e-12)


def test_jacobian_matches_finite_differences():
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(200):
        x = np.r_[rng.uniform(-0.01, 0.01, 3), rng.uniform(-0.7, 0.7)]
        target = x[:3] + rng.uniform(-0.02, 0.02, 3)
        d = rng.standard_normal(3)
        d /= np.linalg.norm(d)
        o = target - 0.08 * d

        def rng_at(s, o=o, d=d):
            return ray_box(o, d, s[:3], Rotation.from_euler("z", s[3]).as_matrix(), H)

        hit = rng_at(x)
        if not hit.hit[0] or hit.edge_distance[0] < 1e-3 or abs(hit.normal[0] @ d) < 0.3:
            continue
        jac = ray_box_jacobian(d, x[:3], hit)[0]
        for k in range(4):
            eps = 1e-7
            dx = np.zeros(4)
            dx[k] = eps
            fd = (rng_at(x + dx).distance[0] - rng_at(x - dx).distance[0]) / (2 * eps)
            assert jac[k] == pytest.approx(fd, rel=1e-4, abs=1e-6)
        checked += 1
    assert checked > 50


def test_wrap_quarter():
    deg = np.array([-45.0, 45.0, 46.0, -46.0, 90.0, 135.0, 44.9, -180.0])
    want = np.array([45.0, 45.0, -44.0, 44.0, 0.0, 45.0, 44.9, 0.0])
    assert np.allclose(np.rad2deg(wrap_quarter(np.deg2rad(deg))), want)
    assert math.degrees(yaw_error(math.radians(44), math.radians(-46))) == pytest.approx(
        0.0, abs=1e-9
    )


def _cube_symmetries() -> list[Rotation]:
    mats = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1, -1), repeat=3):
            m = np.zeros((3, 3))
            for i, (p, s) in enumerate(zip(perm, signs)):
                m[i, p] = s
            if np.linalg.det(m) > 0:
                mats.append(Rotation.from_matrix(m))
    assert len(mats) == 24
    return mats


@pytest.mark.parametrize("yaw_deg", [0.0, 10.0, -30.0, 44.0, 60.0])
def test_cube_yaw_is_the_same_for_all_24_body_frames(yaw_deg):
    level = Rotation.from_euler("z", yaw_deg, degrees=True)
    want = math.radians(yaw_deg)
    for s in _cube_symmetries():
        r = level * s
        assert yaw_error(cube_yaw(r), want) == pytest.approx(0.0, abs=1e-9)
        assert cube_tilt(r) == pytest.approx(0.0, abs=1e-6)
    tilted = Rotation.from_euler("x", 5, degrees=True) * level
    assert math.degrees(cube_tilt(tilted)) == pytest.approx(5.0, abs=1e-6)
