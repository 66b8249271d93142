"""Sensors and the cube pose estimator (see docs/sensors.md).

* :mod:`.config` — :class:`HeadCameraConfig`, :class:`ToFConfig`,
  :class:`CubeFilterConfig`: every noise figure with its default and why;
* :mod:`.camera` — :class:`HeadCamera`, the one-shot initial estimate;
* :mod:`.pretouch` — :class:`PreTouchSensor` (ToF emitters on a link, batched
  ray casts) and :func:`scan` (readings along a path);
* :mod:`.scan_path` — :func:`face_sweep`, scan paths planned from an estimate;
* :mod:`.raybox` — analytic ray–box ranges and their Jacobian;
* :mod:`.pose_estimate` — :class:`PoseEstimate`, mean pose plus covariance;
* :mod:`.cube_filter` — :class:`CubePoseFilter`, the EKF (needs filterpy, which
  is imported only when the filter is first used);
* :mod:`.yaw` — the cube's yaw modulo its 90° symmetry.

Nothing here imports a physics engine; sensors act through the Backend interface.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .camera import HeadCamera
from .config import CubeFilterConfig, HeadCameraConfig, ToFConfig
from .pose_estimate import CAMERA_AXES, FILTER_AXES, PoseEstimate
from .pretouch import Emitter, PreTouchSensor, Scan, ToFReading, free_body_mover, scan
from .raybox import RayBoxHits, ray_box, ray_box_jacobian
from .scan_path import VERTICAL_FACES, face_sweep
from .yaw import cube_tilt, cube_yaw, wrap_quarter, yaw_error

if TYPE_CHECKING:
    from .cube_filter import CubePoseFilter, UpdateReport

__all__ = [
    "CAMERA_AXES",
    "CubeFilterConfig",
    "CubePoseFilter",
    "Emitter",
    "FILTER_AXES",
    "HeadCamera",
    "HeadCameraConfig",
    "PoseEstimate",
    "PreTouchSensor",
    "RayBoxHits",
    "Scan",
    "ToFConfig",
    "ToFReading",
    "UpdateReport",
    "VERTICAL_FACES",
    "cube_tilt",
    "cube_yaw",
    "face_sweep",
    "free_body_mover",
    "ray_box",
    "ray_box_jacobian",
    "scan",
    "wrap_quarter",
    "yaw_error",
]


def __getattr__(name: str) -> Any:
    if name in ("CubePoseFilter", "UpdateReport"):
        from . import cube_filter

        return getattr(cube_filter, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
