"""Built-in sensors and pose estimators, registered like any third-party sensor.

Each factory takes its config either whole (``config=...``) or as that
config's field names as keywords (``create("sensor", "head-camera",
yaw_std_deg=5.0)``), so a sweep can vary one figure without building
dataclasses. The filter's factory imports filterpy only when called.
"""

from __future__ import annotations

from dataclasses import fields
from typing import Any

from benchharness.plugin import Registration, hookimpl


def _config(cls: type, config: Any, kwargs: dict[str, Any]) -> Any:
    names = {f.name for f in fields(cls)}
    own = {k: kwargs.pop(k) for k in list(kwargs) if k in names}
    if config is not None and own:
        raise TypeError(
            f"pass either config= or {cls.__name__} fields ({', '.join(sorted(own))}), not both"
        )
    return config if config is not None else cls(**own)


def _head_camera(*, config=None, **kwargs):
    from benchharness.sensors import HeadCamera, HeadCameraConfig

    cfg = _config(HeadCameraConfig, config, kwargs)
    if kwargs:
        raise TypeError(f"head-camera got unexpected arguments: {', '.join(sorted(kwargs))}")
    return HeadCamera(cfg)


def _pretouch(*, backend, body, link=None, emitters, config=None, ignore_bodies=None, **kwargs):
    from benchharness.sensors import PreTouchSensor, ToFConfig

    cfg = _config(ToFConfig, config, kwargs)
    if kwargs:
        raise TypeError(f"pretouch-tof got unexpected arguments: {', '.join(sorted(kwargs))}")
    return PreTouchSensor(backend, body, link, emitters, cfg, ignore_bodies=ignore_bodies)


def _cube_kf(*, config=None, tof=None, initial=None, **kwargs):
    from benchharness.sensors.config import CubeFilterConfig
    from benchharness.sensors.cube_filter import CubePoseFilter

    cfg = _config(CubeFilterConfig, config, kwargs)
    if kwargs:
        raise TypeError(f"cube-kf got unexpected arguments: {', '.join(sorted(kwargs))}")
    return CubePoseFilter(cfg, tof, initial=initial)


@hookimpl
def benchharness_sensors() -> list[Registration]:
    return [
        Registration(
            "head-camera",
            _head_camera,
            "Head RGB-D camera: one-shot cube pose, Gaussian noise (4 mm xy, 2 mm z, 3° yaw)",
            meta={
                "config": "benchharness.sensors.HeadCameraConfig",
                "output": "PoseEstimate (6x6 covariance)",
            },
        ),
        Registration(
            "pretouch-tof",
            _pretouch,
            "Optical time-of-flight pre-touch emitters on a link (VL6180X-class: 5-100 mm, 1.5 mm noise)",
            meta={
                "config": "benchharness.sensors.ToFConfig",
                "needs": ["backend", "body", "link", "emitters"],
                "output": "ToFReading",
            },
        ),
        Registration(
            "cube-kf",
            _cube_kf,
            "Iterated EKF over the cube's x, y, z, yaw (mod 90°): predict from commanded motion, update from ToF",
            meta={
                "config": "benchharness.sensors.CubeFilterConfig",
                "state": ["x", "y", "z", "yaw"],
                "requires": "filterpy",
            },
        ),
    ]
