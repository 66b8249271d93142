"""Scenes for the sensor tests: a 5.7 cm box on the ground and a free-floating ToF sensor.

Only the Backend interface is used, so every registered backend runs them.
The sensor body is a small sphere that is teleported along a path
(:func:`benchharness.sensors.free_body_mover`); nothing is stepped, so the
cube stays exactly where it was put and the truth is known.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from benchharness.backends import Backend, Box, PhysicsConfig, Sphere
from benchharness.geometry import Pose
from benchharness.plugin import get_manager
from benchharness.sensors import (
    CAMERA_AXES,
    Emitter,
    HeadCamera,
    PoseEstimate,
    PreTouchSensor,
    cube_yaw,
    face_sweep,
    free_body_mover,
    scan,
    yaw_error,
)

BACKENDS = ("pybullet", "sapien")
HALF = 0.0285  #: 5.7 cm cube
CUBE_CENTRE = np.array([0.30, 0.10, HALF])

#: A fingertip-like sensor: three forward emitters in a vertical column (the
#: sweep's face rays) and one tip emitter looking down from above the cube
#: (the top face, which pins z). Link frame: x towards the face.
FINGER_EMITTERS = (
    Emitter((0.0, 0.0, -0.012), (1.0, 0.0, 0.0), "front-low"),
    Emitter((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), "front-mid"),
    Emitter((0.0, 0.0, 0.012), (1.0, 0.0, 0.0), "front-high"),
    Emitter((0.045, 0.0, 0.05), (0.0, 0.0, -1.0), "tip-down"),
)


def new_backend(name: str) -> Backend:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return get_manager().create("backend", name, config=PhysicsConfig())


@dataclass
class CubeRig:
    backend: Backend
    ground: int
    cube: int
    sensor_body: int
    sensor: PreTouchSensor

    @property
    def truth(self) -> Pose:
        return self.backend.get_pose(self.cube)


def cube_rig(
    backend: Backend, yaw_deg: float = 10.0, emitters=FINGER_EMITTERS, tof=None
) -> CubeRig:
    g = backend.add_ground(0.0)
    pose = Pose.from_rotation(CUBE_CENTRE, Rotation.from_euler("z", yaw_deg, degrees=True))
    cube = backend.add_body([Box((HALF,) * 3)], pose, 0.094, name="cube")
    sb = backend.add_body([Sphere(0.004)], Pose([0.0, 0.0, 0.6]), 0.01, name="tof-sensor")
    sensor = PreTouchSensor(backend, sb, None, emitters, tof)
    return CubeRig(backend, g, cube, sb, sensor)


def offset_prior(
    truth: Pose, rng: np.random.Generator, pos_err: float = 0.008, yaw_err_deg: float = 5.0
) -> PoseEstimate:
    """A head-camera estimate forced to be ``pos_err`` m and ``yaw_err_deg`` off (direction from ``rng``).

    Its covariance is the camera's shape, scaled so the forced error is ~1.5σ
    (a bad but believable shot): isotropic position std ``pos_err / (1.5 √3)``
    and yaw std ``yaw_err / 1.5``.
    """
    u = rng.standard_normal(3)
    u /= np.linalg.norm(u)
    yaw = cube_yaw(truth.rotation) + np.deg2rad(yaw_err_deg) * rng.choice([-1.0, 1.0])
    pose = Pose.from_rotation(truth.p + pos_err * u, Rotation.from_euler("z", yaw))
    std = np.sqrt(np.diag(HeadCamera().covariance))
    std[:3] = pos_err / (1.5 * np.sqrt(3.0))
    std[5] = np.deg2rad(yaw_err_deg) / 1.5
    return PoseEstimate(
        pose, np.diag(std**2), n_measurements=1, axes=CAMERA_AXES, source="head-camera"
    )


def two_face_scan(rig: CubeRig, prior: PoseEstimate, rng: np.random.Generator, faces=("-x", "-y")):
    """Sweep the sensor across two adjacent vertical faces, planned from the prior."""
    path = []
    for f in faces:
        path += face_sweep(prior.pose.p, prior.yaw, f, half_edge=HALF)
    return scan(rig.sensor, path, free_body_mover(rig.backend, rig.sensor_body), rng)


def errors(estimate: PoseEstimate, truth: Pose) -> tuple[float, float, np.ndarray]:
    """(position error m, |yaw error| rad, error vector over x, y, z, yaw)."""
    e_yaw = yaw_error(estimate.yaw, cube_yaw(truth.rotation))
    e = np.r_[estimate.pose.p - truth.p, e_yaw]
    return float(np.linalg.norm(e[:3])), abs(e_yaw), e
