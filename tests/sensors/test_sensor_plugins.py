"""The built-in sensors come through the plugin registry, and importing them stays light."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from benchharness.cube_physics import CubeConfig
from benchharness.geometry import Pose
from benchharness.plugin import get_manager
from benchharness.sensors import CubeFilterConfig, HeadCamera, HeadCameraConfig


def test_builtin_sensors_are_registered():
    m = get_manager()
    names = m.names("sensor")
    assert {"head-camera", "pretouch-tof", "cube-kf"} <= set(names)
    for name in ("head-camera", "pretouch-tof", "cube-kf"):
        item = m.get("sensor", name)
        assert item.distribution == "benchharness" and item.summary and item.meta.get("config")


def test_head_camera_factory_takes_config_fields_or_a_config():
    m = get_manager()
    cam = m.create("sensor", "head-camera", yaw_std_deg=5.0)
    assert isinstance(cam, HeadCamera) and cam.config.yaw_std_deg == 5.0
    cfg = HeadCameraConfig(pos_std_xy=0.001)
    assert m.create("sensor", "head-camera", config=cfg).config is cfg
    with pytest.raises(TypeError):
        m.create("sensor", "head-camera", config=cfg, yaw_std_deg=1.0)
    with pytest.raises(TypeError):
        m.create("sensor", "head-camera", colour="red")


def test_cube_kf_factory():
    pytest.importorskip("filterpy")
    m = get_manager()
    kf = m.create("sensor", "cube-kf", gate_sigma=4.0)
    assert kf.config.gate_sigma == 4.0
    est = HeadCamera().estimate(Pose(), np.random.default_rng(0))
    kf2 = m.create("sensor", "cube-kf", initial=est)
    assert kf2.estimate.n_measurements == 1


@pytest.mark.sim
@pytest.mark.parametrize("backend_name", ["pybullet", "sapien"])
def test_pretouch_factory(backend_name):
    from sensor_rig import new_backend

    from benchharness.backends import Sphere
    from benchharness.sensors import Emitter

    b = new_backend(backend_name)
    try:
        body = b.add_body([Sphere(0.004)], Pose([0, 0, 0.5]), 0.01)
        s = get_manager().create(
            "sensor",
            "pretouch-tof",
            backend=b,
            body=body,
            emitters=[Emitter((0, 0, 0), (0, 0, -1))],
            max_range=0.6,
        )
        r = s.read(np.random.default_rng(0))
        assert s.config.max_range == 0.6 and np.isinf(
            r.distance[0]
        )  # nothing below but empty space
        b.add_ground(0.0)
        assert s.read(np.random.default_rng(0)).distance[0] == pytest.approx(0.5, abs=0.01)
    finally:
        b.close()


def test_filter_edge_matches_the_physical_cube():
    assert CubeFilterConfig().edge == CubeConfig().edge


def test_importing_sensors_pulls_in_no_engine_and_no_filterpy():
    code = (
        "import sys, benchharness.sensors\n"
        "heavy = sorted({m.split('.')[0] for m in sys.modules} & {'pybullet', 'sapien', 'torch', 'filterpy'})\n"
        "print(','.join(heavy))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert out == ""
