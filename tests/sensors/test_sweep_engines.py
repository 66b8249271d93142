"""Sweeps on both engines: a ToF beam swept across a real box's edges finds them within the sensor
noise, and the 6-DOF filter fuses the sweeps into a pose nearer the truth (the engine's body pose).

The sensor is a free body teleported along each sweep (nothing is stepped), reading at the PR2's
default spacing; the filter sees only the believed rays and measured ranges.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from sensor_rig import BACKENDS, HALF, new_backend

pytest.importorskip("filterpy")

from benchharness.backends import Box, Sphere
from benchharness.geometry import Pose
from benchharness.sensors import (
    POSE6_AXES,
    CubePose6Filter,
    Emitter,
    PoseEstimate,
    PreTouchSensor,
    SweepConfig,
    find_edges,
    free_body_mover,
    scan,
)
from benchharness.sensors.pose6 import compose, edge_model

pytestmark = pytest.mark.sim

PRIOR_STD = np.array([0.006, 0.006, 0.006, *np.radians([2.0, 2.0, 3.0])])
#: a cube held in the air, tilted a little about every axis (nothing is stepped: it stays there)
TRUTH = Pose.from_rotation([0.4, 0.1, 0.5], Rotation.from_rotvec([0.02, -0.03, 0.04]))


def _sweep_paths(belief: Pose, sw: SweepConfig) -> list[list[Pose]]:
    """The PR2's three sweeps across the belief's -x face, the beam along +x (link x)."""
    base = belief.p + np.array([-(HALF + sw.standoff), 0.0, 0.0])
    far, low, vo = HALF + sw.overshoot, HALF - sw.face_depth, sw.vertical_offset
    lines = [((-far, 0.0), (far, 0.0)), ((vo, low), (vo, far)), ((-vo, far), (-vo, low))]
    paths = []
    for (s0, v0), (s1, v1) in lines:
        a, b = base + [0.0, s0, v0], base + [0.0, s1, v1]
        n = int(np.linalg.norm(b - a) / sw.spacing) + 1
        paths.append([Pose(a + (b - a) * f) for f in np.linspace(0.0, 1.0, n)])
    return paths


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_sweeps_find_the_edges_and_the_filter_fuses_them(backend_name):
    b = new_backend(backend_name)
    try:
        cube = b.add_body([Box((HALF,) * 3)], TRUTH, 0.094, fixed=True, name="cube")
        probe = b.add_body([Sphere(0.004)], Pose([0.0, 0.0, 1.0]), 0.01, name="probe")
        sensor = PreTouchSensor(b, probe, None, [Emitter((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))])
        truth = b.get_pose(cube)
        sw = SweepConfig()
        rng = np.random.default_rng(7)
        belief = compose(truth, -np.array([0.004, -0.003, 0.002, 0.02, -0.015, 0.03]))
        o_all, d_all, z_all, edges = [], [], [], []
        for path in _sweep_paths(belief, sw):
            s = scan(sensor, path, free_body_mover(b, probe), rng)
            edges += find_edges(s.origins, s.directions, s.distance, config=sw, tof=sensor.config)
            o_all.append(s.origins)
            d_all.append(s.directions)
            z_all.append(s.distance)
        # both side edges and the top edge twice, each on the true box within its own noise
        assert len(edges) == 4
        for e in edges:
            h, _, var = edge_model(truth, HALF, e)
            assert abs(h) < 4 * np.sqrt(var), (h, np.sqrt(var))
        kf = CubePose6Filter(PoseEstimate(belief, np.diag(PRIOR_STD**2), axes=POSE6_AXES))
        rep = kf.update(np.concatenate(o_all), np.concatenate(d_all), np.concatenate(z_all), edges)
        assert rep.n_edges_used == 4 and rep.n_rays_used > 100
        err0 = np.r_[belief.p - truth.p, (belief.rotation * truth.rotation.inv()).as_rotvec()]
        post = kf.pose
        err1 = np.r_[post.p - truth.p, (post.rotation * truth.rotation.inv()).as_rotvec()]
        std = np.sqrt(np.diag(kf.P))
        assert np.all(np.abs(err1) < np.abs(err0)), (err0, err1)
        assert np.all(np.abs(err1) < 4 * std), (err1, std)
        assert np.all(np.abs(err1[:3]) < 0.0015)  # every position axis to about a millimetre
    finally:
        b.close()
