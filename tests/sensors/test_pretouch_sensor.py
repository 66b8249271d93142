"""The ToF pre-touch sensor on both engines: noise statistics, range limits, batching, scans."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from sensor_rig import BACKENDS, new_backend

from benchharness.backends import Box, Sphere
from benchharness.geometry import Pose
from benchharness.sensors import Emitter, PreTouchSensor, ToFConfig, free_body_mover, scan

pytestmark = pytest.mark.sim

WALL_X = 0.2  #: the wall's -x face


@pytest.fixture(params=BACKENDS)
def backend(request):
    b = new_backend(request.param)
    yield b
    b.close()


def _wall(b):
    """A large fixed slab whose -x face is the plane x = WALL_X."""
    return b.add_body(
        [Box((0.01, 0.3, 0.3))], Pose([WALL_X + 0.01, 0.0, 0.3]), 1.0, fixed=True, name="wall"
    )


def _grid_emitters(n_side: int = 20) -> list[Emitter]:
    """n_side² parallel emitters on a 2 mm grid, all looking along link +x."""
    ys, zs = np.meshgrid(np.arange(n_side) * 0.002, np.arange(n_side) * 0.002)
    return [
        Emitter((0.0, float(y), float(z)), (1.0, 0.0, 0.0)) for y, z in zip(ys.ravel(), zs.ravel())
    ]


def _sensor_at(b, x: float, emitters, cfg=None):
    body = b.add_body([Sphere(0.004)], Pose([x, -0.02, 0.28]), 0.01, name="tof")
    return body, PreTouchSensor(b, body, None, emitters, cfg)


def test_noise_statistics_match_config(backend):
    _wall(backend)
    cfg = ToFConfig(noise_std=0.002, noise_std_per_m=0.01)
    _, sensor = _sensor_at(backend, WALL_X - 0.05, _grid_emitters(), cfg)
    rng = np.random.default_rng(21)
    err = np.concatenate([sensor.read(rng).distance - 0.05 for _ in range(5)])  # 2000 readings
    want = cfg.std_at(0.05)  # 2.5 mm
    assert err.size == 2000 and np.isfinite(err).all()
    assert err.std() == pytest.approx(want, rel=0.06)
    assert abs(err.mean()) < 4 * want / np.sqrt(err.size) + 2e-5
    # the noiseless range is the geometry (PyBullet's margin allows 1 mm at normal incidence)
    r = sensor.read(rng)
    assert np.allclose(r.true_distance, 0.05, atol=1e-3)


def test_seeded_readings_are_reproducible(backend):
    _wall(backend)
    _, sensor = _sensor_at(backend, WALL_X - 0.05, _grid_emitters(4))
    a = sensor.read(np.random.default_rng(3)).distance
    b = sensor.read(np.random.default_rng(3)).distance
    c = sensor.read(np.random.default_rng(4)).distance
    assert np.array_equal(a, b) and not np.array_equal(a, c)


@pytest.mark.parametrize("gap, expect", [(0.003, "nan"), (0.05, "finite"), (0.12, "inf")])
def test_range_limits(backend, gap, expect):
    wall = _wall(backend)
    body, sensor = _sensor_at(backend, WALL_X - gap, _grid_emitters(3))
    r = sensor.read(np.random.default_rng(0))
    assert len(r) == 9 and r.origins.shape == (9, 3) and r.directions.shape == (9, 3)
    if expect == "nan":  # inside the 5 mm dead zone: a return, but no valid range
        assert np.isnan(r.distance).all() and (r.body == wall).all()
    elif expect == "finite":
        assert r.valid.all() and (r.body == wall).all()
        assert np.allclose(r.distance, gap, atol=6 * ToFConfig().std_at(gap))
    else:  # beyond 100 mm: nothing
        assert (
            np.isinf(r.distance).all() and (r.body == -1).all() and np.isinf(r.true_distance).all()
        )


def test_own_body_is_ignored_and_other_bodies_are_reported(backend):
    wall = _wall(backend)
    # the emitter sits inside its own 4 mm sphere: the ray must not stop there
    body, sensor = _sensor_at(backend, WALL_X - 0.04, [Emitter((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))])
    r = sensor.read(np.random.default_rng(0))
    assert r.body[0] == wall and r.true_distance[0] == pytest.approx(0.04, abs=1e-3)
    blocker = backend.add_body(
        [Box((0.002, 0.01, 0.01))], Pose([WALL_X - 0.02, -0.02, 0.28]), 0.01, fixed=True
    )
    r = sensor.read(np.random.default_rng(0))
    assert r.body[0] == blocker and r.true_distance[0] == pytest.approx(0.018, abs=1e-3)


def test_a_sensor_on_one_link_sees_the_rest_of_its_robot(backend):
    """A ToF window in one pad looking across the gap: with only its own link ignored it ranges the other pad."""
    from pathlib import Path

    urdf = Path(__file__).resolve().parents[1] / "backends" / "assets" / "gripper.urdf"
    grip = backend.load_urdf(urdf, Pose(), fixed_base=True, name="gripper")
    q = 0.04  # each pad's inner face at q - 9 mm from the centre plane (the rig's URDF)
    backend.set_joint_positions(grip, [0.2, q, q], joints=["lift", "left_finger", "right_finger"])
    backend.step(
        1
    )  # PhysX's scene queries see a joint teleport only after a step (docs/backends.md)
    across = [Emitter((0.0, 0.0, 0.0), (0.0, -1.0, 0.0))]  # from pad_l's centre towards pad_r
    whole = PreTouchSensor(backend, grip, "pad_l", across)
    assert not np.isfinite(
        whole.read(np.random.default_rng(0)).true_distance[0]
    )  # the robot is transparent
    own = PreTouchSensor(
        backend, grip, "pad_l", across, ignore_bodies=(), ignore_links=((grip, "pad_l"),)
    )
    r = own.read(np.random.default_rng(0))
    assert r.body[0] == grip
    assert r.true_distance[0] == pytest.approx(
        0.002 + 2 * (q - 0.009), abs=1e-3
    )  # half pad + the gap


def test_emitters_follow_the_link_pose_and_belief(backend):
    _wall(backend)
    body, sensor = _sensor_at(backend, WALL_X - 0.05, [Emitter((0.01, 0.0, 0.0), (1.0, 0.0, 0.0))])
    # turn the sensor 30° about z: the ray meets the wall at a slant
    p = backend.get_pose(body).p
    backend.set_pose(body, Pose.from_rotation(p, Rotation.from_euler("z", 30, degrees=True)))
    r = sensor.read(np.random.default_rng(0))
    origin = p + Rotation.from_euler("z", 30, degrees=True).apply([0.01, 0, 0])
    assert np.allclose(r.origins[0], origin, atol=1e-6)
    assert r.true_distance[0] == pytest.approx(
        (WALL_X - origin[0]) / np.cos(np.deg2rad(30)), abs=1.2e-3
    )
    # a believed pose changes the reported rays, never the ranges
    belief = Pose(p + [0.0, 0.005, 0.0])
    r2 = sensor.read(np.random.default_rng(0), believed_link_pose=belief)
    assert np.array_equal(r2.distance, r.distance)
    assert np.allclose(r2.origins[0], belief.apply([0.01, 0, 0])) and np.allclose(
        r2.directions[0], [1, 0, 0]
    )


def test_scan_collects_one_reading_per_step(backend):
    _wall(backend)
    emitters = [
        Emitter((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
        Emitter((0.0, 0.0, 0.01), (1.0, 0.0, 0.0)),
    ]
    body, sensor = _sensor_at(backend, WALL_X - 0.05, emitters)
    xs = WALL_X - np.array([0.004, 0.03, 0.06, 0.09, 0.15])
    path = [Pose([x, 0.0, 0.3]) for x in xs]
    s = scan(sensor, path, free_body_mover(backend, body), np.random.default_rng(1))
    assert len(s) == 10 and s.origins.shape == (10, 3) and s.distance.shape == (10,)
    assert all(lp.allclose(cmd, atol_p=1e-6, atol_q=1e-6) for lp, cmd in zip(s.link_poses, path))
    gaps = np.repeat(WALL_X - xs, 2)
    assert np.isnan(s.distance[:2]).all()  # 4 mm: dead zone
    assert np.allclose(s.distance[2:8], gaps[2:8], atol=0.008)
    assert np.isinf(s.distance[8:]).all()  # 150 mm: out of range
    # a belief that offsets the link by 1 cm shows in the reported origins only
    shift = Pose([0.0, 0.01, 0.0])
    s2 = scan(
        sensor,
        path,
        free_body_mover(backend, body),
        np.random.default_rng(1),
        belief=lambda cmd, actual: shift * actual,
    )
    assert np.allclose(s2.origins - s.origins, [0.0, 0.01, 0.0])
    assert np.array_equal(s2.distance, s.distance, equal_nan=True)


def test_config_validation():
    with pytest.raises(ValueError):
        ToFConfig(min_range=0.1, max_range=0.05)
    with pytest.raises(ValueError):
        ToFConfig(noise_std=-0.001)
    with pytest.raises(ValueError):
        Emitter((0, 0, 0), (0, 0, 0))


def test_all_emitters_go_in_one_ray_cast(backend, monkeypatch):
    _wall(backend)
    _, sensor = _sensor_at(backend, WALL_X - 0.05, _grid_emitters(10))
    calls = []
    real = backend.ray_cast

    def spy(origins, directions, max_distance, **kw):
        calls.append(len(origins))
        return real(origins, directions, max_distance, **kw)

    monkeypatch.setattr(backend, "ray_cast", spy)
    r = sensor.read(np.random.default_rng(0))
    assert calls == [100] and len(r) == 100
