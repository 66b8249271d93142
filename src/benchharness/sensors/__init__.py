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
* :mod:`.sweep` — :func:`find_edges`, face edges where a swept beam's range steps;
* :mod:`.pose6` — :class:`CubePose6Filter`, the 6-DOF iterated EKF over face
  ranges and swept edges (filterpy imported when one is built);
* :mod:`.yaw` — the cube's yaw modulo its 90° symmetry.

Nothing here imports a physics engine; sensors act through the Backend interface.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .camera import HeadCamera
from .config import CubeFilterConfig, HeadCameraConfig, SweepConfig, ToFConfig
from .pose6 import POSE6_AXES, CubePose6Filter, Update6Report
from .pose_estimate import CAMERA_AXES, FILTER_AXES, PoseEstimate
from .pretouch import Emitter, PreTouchSensor, Scan, ToFReading, free_body_mover, scan
from .raybox import RayBoxHits, ray_box, ray_box_jacobian
from .scan_path import VERTICAL_FACES, face_sweep
from .sweep import EdgeObservation, find_edges
from .yaw import cube_tilt, cube_yaw, wrap_quarter, yaw_error

if TYPE_CHECKING:
    from .cube_filter import CubePoseFilter, UpdateReport

__all__ = [
    "CAMERA_AXES",
    "CubeFilterConfig",
    "CubePose6Filter",
    "CubePoseFilter",
    "EdgeObservation",
    "Emitter",
    "FILTER_AXES",
    "HeadCamera",
    "HeadCameraConfig",
    "POSE6_AXES",
    "PoseEstimate",
    "PreTouchSensor",
    "RayBoxHits",
    "Scan",
    "SweepConfig",
    "ToFConfig",
    "ToFReading",
    "Update6Report",
    "UpdateReport",
    "VERTICAL_FACES",
    "cube_tilt",
    "cube_yaw",
    "face_sweep",
    "find_edges",
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
