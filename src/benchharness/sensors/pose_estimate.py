"""The record every pose estimator hands out: a mean pose *with* its covariance.

Strategies decide whether to trust an estimate (regrasp now, or scan again)
from its covariance, and the results store keeps both, so the record carries
them together with how much evidence went in and when.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..geometry import Pose
from .yaw import cube_yaw

__all__ = ["CAMERA_AXES", "FILTER_AXES", "PoseEstimate"]

#: Covariance axes of a full 6-DOF estimate (the head camera): metres and
#: radians, rotations as a small world-frame roll-pitch-yaw perturbation.
CAMERA_AXES: tuple[str, ...] = ("x", "y", "z", "roll", "pitch", "yaw")
#: Covariance axes of the cube filter's planar state.
FILTER_AXES: tuple[str, ...] = ("x", "y", "z", "yaw")


@dataclass(frozen=True)
class PoseEstimate:
    """A cube pose estimate.

    ``covariance`` is square over ``axes`` (metres, radians). ``yaw`` is
    the cube's yaw modulo 90°, in (−45°, 45°].
    """

    pose: Pose
    covariance: np.ndarray
    n_measurements: int = (
        0  #: measurements fused so far (camera: 1; filter: accepted ranges + priors)
    )
    time: float = 0.0  #: simulated seconds at which the estimate holds
    axes: tuple[str, ...] = field(default=FILTER_AXES)
    source: str = ""  #: what produced it ("head-camera", "cube-kf", ...)

    def __post_init__(self) -> None:
        cov = np.array(self.covariance, dtype=float)
        k = len(self.axes)
        if cov.shape != (k, k):
            raise ValueError(
                f"covariance must be {k}x{k} over axes {self.axes}, got shape {cov.shape}"
            )
        if not np.all(np.isfinite(cov)):
            raise ValueError("covariance must be finite")
        cov = 0.5 * (cov + cov.T)
        cov.setflags(write=False)
        object.__setattr__(self, "covariance", cov)

    @property
    def yaw(self) -> float:
        """The cube's yaw (rad) modulo its 90° symmetry."""
        return cube_yaw(self.pose.rotation)

    def std(self, axis: str) -> float:
        """Standard deviation along one named axis (m or rad)."""
        i = self.axes.index(axis)
        return float(np.sqrt(self.covariance[i, i]))

    def marginal(self, axes: tuple[str, ...]) -> np.ndarray:
        """The covariance block over ``axes`` (all of them must be in :attr:`axes`)."""
        idx = [self.axes.index(a) for a in axes]
        return self.covariance[np.ix_(idx, idx)].copy()

    @property
    def position_std(self) -> np.ndarray:
        """Per-axis position std (m), (3,)."""
        return np.sqrt(np.diag(self.marginal(("x", "y", "z"))))
