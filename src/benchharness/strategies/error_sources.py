"""The Rubik's baselines' injected error sources, shared by every robot's strategy.

Why one class: the paper's error sources (arm calibration, actuator
tracking, camera noise) are properties of the benchmark set-up, not of one
robot, and strategies on different robots are only comparable when they draw
the same errors from the same named parameters.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

__all__ = ["ErrorConfig"]


@dataclass(frozen=True)
class ErrorConfig:
    """Injected errors, all drawn from the trial's ``ctx.rng``.

    * **Arm calibration**: each arm has a fixed offset between where it is
      told to go and where it goes (drawn once per trial).
    * **Actuator tracking**: every arm motion adds an independent error.
    * **Camera noise**: the head camera's one-shot estimate of the cube on the
      table (``benchharness.sensors.HeadCamera`` defaults when that package
      is importable: 4 mm xy, 2 mm z, 3° yaw, 1° tilt; else the figures below).
    """

    #: std of each arm's fixed calibration offset, per world axis (m). 1.5 mm: a few-mm calibrated arm.
    calib_pos_std: float = 0.0015
    #: std of each arm's fixed calibration rotation, per world axis (deg).
    calib_rot_std_deg: float = 0.5
    #: std of the per-motion tracking error of a commanded tool pose, per world axis (m).
    #: 1 mm: a PR2 arm's repeatability under its PD control is of that order.
    tracking_std: float = 0.001
    #: fallback camera noise when benchharness.sensors is absent: position std (m), yaw std (deg)
    camera_pos_std: float = 0.003
    camera_yaw_std_deg: float = 2.0
    #: use the head camera at all (False = the initial estimate is the true pose)
    camera: bool = True

    def zero(self) -> ErrorConfig:
        """Every error off (the ``-exact`` diagnostics)."""
        return ErrorConfig(**{f.name: (False if f.name == "camera" else 0.0) for f in fields(self)})

    @property
    def is_zero(self) -> bool:
        return not self.camera and all(
            getattr(self, f.name) == 0.0 for f in fields(self) if f.name != "camera"
        )
