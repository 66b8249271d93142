"""The head camera's one-shot cube pose estimate.

Both PR2 baselines start from the head camera: it sees the cube on the table
once, and everything afterwards is either dead reckoning or pre-touch
re-localisation. We do not render and fit a box: the camera is modelled by
its outcome, the true pose plus Gaussian noise of documented size
(:class:`~benchharness.sensors.config.HeadCameraConfig`), so the estimate's
error statistics are exactly the configured ones on every backend, with or
without a renderer.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ..backends.interface import Backend, BodyId
from ..geometry import Pose
from .config import HeadCameraConfig
from .pose_estimate import CAMERA_AXES, PoseEstimate

__all__ = ["HeadCamera"]


class HeadCamera:
    """Noisy pose of a body, with the covariance a consumer should assume.

    Randomness comes only from the ``numpy.random.Generator`` passed to each
    call, so a trial seeded once replays exactly.
    """

    name = "head-camera"

    def __init__(self, config: HeadCameraConfig | None = None) -> None:
        self.config = config or HeadCameraConfig()

    @property
    def covariance(self) -> np.ndarray:
        """6×6 covariance over (x, y, z, roll, pitch, yaw), m and rad."""
        c = self.config
        tilt = np.deg2rad(c.tilt_std_deg)
        std = np.array(
            [c.pos_std_xy, c.pos_std_xy, c.pos_std_z, tilt, tilt, np.deg2rad(c.yaw_std_deg)]
        )
        return np.diag(std**2)

    def estimate(
        self, true_pose: Pose, rng: np.random.Generator, *, time: float = 0.0
    ) -> PoseEstimate:
        """An estimate of ``true_pose``: position plus noise, orientation perturbed in the world frame."""
        if not isinstance(rng, np.random.Generator):
            raise TypeError("rng must be a numpy.random.Generator (seed it explicitly)")
        cov = self.covariance
        noise = rng.standard_normal(6) * np.sqrt(np.diag(cov))
        p = true_pose.p + noise[:3]
        rot = Rotation.from_euler("xyz", noise[3:]) * true_pose.rotation
        return PoseEstimate(
            Pose.from_rotation(p, rot),
            cov,
            n_measurements=1,
            time=float(time),
            axes=CAMERA_AXES,
            source=self.name,
        )

    def observe(self, backend: Backend, body: BodyId, rng: np.random.Generator) -> PoseEstimate:
        """Estimate the pose of ``body`` as the camera would see it now."""
        return self.estimate(backend.get_pose(body), rng, time=backend.time)
