"""Typed parameters of the sensors and the cube pose filter, each with its default and why.

Every error magnitude the Rubik's baselines depend on (docs/strategies.md,
"Error sources") is a named field here, so a sweep can vary
it and a report can print it. Units are SI (metres, radians) unless a name
says ``_deg``; docs/sensors.md explains each figure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["CubeFilterConfig", "HeadCameraConfig", "SweepConfig", "ToFConfig"]


def _check_nonneg(owner: str, **values: float) -> None:
    for name, value in values.items():
        if not (math.isfinite(value) and value >= 0):
            raise ValueError(f"{owner}.{name} must be finite and >= 0, got {value!r}")


def _check_pos(owner: str, **values: float) -> None:
    for name, value in values.items():
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{owner}.{name} must be finite and > 0, got {value!r}")


@dataclass(frozen=True)
class HeadCameraConfig:
    """Noise of the head camera's one-shot cube pose estimate.

    The PR2 baseline localises the cube once with its head-mounted Kinect-class
    RGB-D camera, about 1 m away. At 1 m such a sensor's depth noise is
    ~1.5–3 mm (Khoshelham & Elberink 2012), and the head-to-arm extrinsic
    calibration adds a few mm more, so a box fit to the cube's point cloud is
    good to a few mm and a few degrees. Noise is Gaussian, independent per
    axis, and applied in the world frame (rotations as a small extrinsic
    roll-pitch-yaw perturbation of the true orientation).
    """

    #: Position std along world x and y (m). 4 mm: depth noise plus extrinsic
    #: calibration at ~1 m; with ``pos_std_z`` it gives ~6 mm RMS, so a bare
    #: camera estimate sits well inside the 9.5 mm (half-cubie) grasp tolerance
    #: once and drifts out of it under dead reckoning, as in the paper.
    pos_std_xy: float = 0.004
    #: Position std along world z (m). Smaller than x/y: the table plane the
    #: cube rests on is fitted from many points, pinning height to ~2 mm.
    pos_std_z: float = 0.002
    #: Yaw std (deg). 3°: the cube's vertical edges span only ~20 pixels at
    #: 1 m, so face orientation is resolved to a few degrees.
    yaw_std_deg: float = 3.0
    #: Roll and pitch std (deg). 1°: the supporting plane fixes the tilt.
    tilt_std_deg: float = 1.0

    def __post_init__(self) -> None:
        _check_nonneg(
            "HeadCameraConfig",
            pos_std_xy=self.pos_std_xy,
            pos_std_z=self.pos_std_z,
            yaw_std_deg=self.yaw_std_deg,
            tilt_std_deg=self.tilt_std_deg,
        )


@dataclass(frozen=True)
class ToFConfig:
    """One optical time-of-flight pre-touch emitter (every emitter of a sensor shares it).

    Figures are those of an ST VL6180X-class proximity sensor, the kind Yang
    et al. built into the PR2 fingertips: a single-zone ToF ranger rated for
    0–100 mm, unreliable in its first few millimetres, with a few mm of range
    noise on matte targets. The beam is modelled as a single ray along the
    emitter axis (the real ~25° cone reports roughly the nearest surface near
    the axis; a ray is the model the estimator can invert).
    """

    #: Shortest reported range (m). Below ~5 mm the VL6180X's cover-glass
    #: crosstalk dominates; such readings come back invalid (NaN).
    min_range: float = 0.005
    #: Longest reported range (m). The VL6180X's rated range is 100 mm; beyond
    #: it there is no return (inf).
    max_range: float = 0.100
    #: Range noise std (m) independent of range. 1.5 mm: the datasheet's
    #: ±~3 mm ranging accuracy on 17–88 % reflectance targets read as ±2σ.
    noise_std: float = 0.0015
    #: Extra range noise std per metre of range (fraction of range). 0.01 (1 %)
    #: models the weaker return at the far end: +1 mm at 100 mm.
    noise_std_per_m: float = 0.01

    def __post_init__(self) -> None:
        _check_nonneg(
            "ToFConfig",
            min_range=self.min_range,
            noise_std=self.noise_std,
            noise_std_per_m=self.noise_std_per_m,
        )
        _check_pos("ToFConfig", max_range=self.max_range)
        if self.min_range >= self.max_range:
            raise ValueError(
                f"ToFConfig.min_range ({self.min_range}) must be below max_range ({self.max_range})"
            )

    def std_at(self, distance: float) -> float:
        """Range noise std (m) at ``distance`` (m)."""
        return self.noise_std + self.noise_std_per_m * float(distance)


@dataclass(frozen=True)
class CubeFilterConfig:
    """The Kalman filter that tracks the cube's planar pose (x, y, z, yaw).

    Process noise is what dead reckoning leaves out: each commanded motion of
    the cube (a regrasp, a hand-off, a carry) lands it slightly off, by an
    amount that grows with the motion. The measurement model is the ToF range
    along a known world ray to the estimated box (:mod:`.raybox`).
    """

    #: Cube edge (m); 57 mm is the standard 3×3 (``CubeConfig.edge``).
    edge: float = 0.057
    #: Position std (m, per axis) added by every predict, however small the
    #: motion. 1 mm: the slip of one regrasp of a 94 g cube between 20 N pads.
    #: With the per-metre term, ~20 dead-reckoned moves reach 9.5 mm (1σ·√n),
    #: inside the 10–50 move range where the paper's dead reckoning failed.
    process_pos_std: float = 0.001
    #: Position std per metre of commanded translation (per axis). 0.02: 2 mm
    #: for a 10 cm hand-off, the arm's tracking error over such a move.
    process_pos_std_per_m: float = 0.02
    #: Yaw std (deg) added by every predict. 0.5°: regrasp slip in yaw.
    process_yaw_std_deg: float = 0.5
    #: Yaw std per degree of commanded yaw. 0.02: ~1.8° for a 90° wrist turn.
    process_yaw_std_per_deg: float = 0.02
    #: Mahalanobis gate on a single range innovation (in σ). A reading whose
    #: innovation exceeds it — a hit on another body, a ray that grazed an
    #: edge the estimate puts elsewhere — is dropped. 3σ keeps 99.7 % of good
    #: readings; a fixed gate is robust where a χ² test per batch is not.
    gate_sigma: float = 3.0
    #: Predicted hits closer than this (m) to a box edge are skipped: there the
    #: range is discontinuous in the pose and a linearisation is meaningless.
    edge_margin: float = 0.002
    #: Predicted hits at a larger angle (deg) between ray and face normal are
    #: skipped. Near grazing, the range changes by 1/cos(angle) per mm of pose
    #: error, so one grazing ray can drag the estimate; a real ToF return is
    #: weak there too, and PyBullet's ray cast (which sees boxes through a
    #: ~1 mm collision margin) is off by up to a centimetre.
    max_incidence_deg: float = 60.0
    #: Relinearisations of one batch update (iterated EKF). A prior 8 mm / 5°
    #: off converges in 3–5; the cap only bounds a pathological batch.
    max_iterations: int = 10

    def __post_init__(self) -> None:
        _check_pos("CubeFilterConfig", edge=self.edge, gate_sigma=self.gate_sigma)
        if not 0.0 < self.max_incidence_deg < 90.0:
            raise ValueError(
                f"CubeFilterConfig.max_incidence_deg must be in (0, 90), got {self.max_incidence_deg!r}"
            )
        if int(self.max_iterations) != self.max_iterations or self.max_iterations < 1:
            raise ValueError(
                f"CubeFilterConfig.max_iterations must be a positive integer, got {self.max_iterations!r}"
            )
        _check_nonneg(
            "CubeFilterConfig",
            process_pos_std=self.process_pos_std,
            process_pos_std_per_m=self.process_pos_std_per_m,
            process_yaw_std_deg=self.process_yaw_std_deg,
            process_yaw_std_per_deg=self.process_yaw_std_per_deg,
            edge_margin=self.edge_margin,
        )


@dataclass(frozen=True)
class SweepConfig:
    """How a fingertip ToF sweep is run and read (:mod:`.sweep`, the PR2's sensor-aided grasps).

    The sensor moves at a constant speed and ranges at a fixed rate, so the
    spacing of the readings along the sweep (speed / rate) bounds how well an
    edge is placed; the beam's footprint adds its own blur.
    """

    #: Ranging rate (Hz). 50 Hz: the VL6180X's single-shot ranging takes ~10-15 ms
    #: (its datasheet's typical convergence time plus readout), so ~50-60 Hz is its
    #: continuous-mode ceiling.
    rate_hz: float = 50.0
    #: Fingertip speed along a sweep (m/s). 40 mm/s puts readings 0.8 mm apart at
    #: 50 Hz: an edge quantised to 0.23 mm (std), under the beam's 0.5 mm and the
    #: range noise; twice as slow halved the edge std's quantisation part only and
    #: doubled the sweeps' ~3.4 s per grasp.
    speed: float = 0.04
    #: Gap (m) from the believed face to the emitter window while sweeping: 30 mm is
    #: mid-window for a 5-100 mm ranger, so a centimetre of pose error either way
    #: stays in range.
    standoff: float = 0.03
    #: How far (m) a sweep runs past each believed edge: 12 mm covers the ~6 mm
    #: dead-reckoning error with margin, and leaves ``min_run`` readings past the edge.
    overshoot: float = 0.012
    #: How far (m) a vertical sweep reaches down the face from the top edge: 15 mm
    #: of face readings (19 at the default spacing) to range and to fit the slope.
    face_depth: float = 0.015
    #: Lateral offset (m) of the two vertical sweeps from the face centre (either
    #: side): their top-edge heights 24 mm apart give the rotation about the work axis.
    vertical_offset: float = 0.012
    #: Range step (m) that separates the face from what lies beyond its edge. 10 mm:
    #: ~7 sigma of the range noise, and nothing but an edge steps that far on a flat face.
    jump: float = 0.010
    #: Readings (on the face, and past the edge) that make a face and an edge: 3
    #: rejects a single outlier and keeps 2.4 mm of travel at the default spacing.
    min_run: int = 3
    #: Shortest run (m of sensor travel) that counts as a face: 4 mm (5 readings at the default
    #: spacing). Near an edge of a cube turned a few degrees the beam can graze the adjacent face for a
    #: few readings, whose ranges then climb steeply; such a run must not make a second "edge".
    min_face_length: float = 0.004
    #: Steepest range slope (m of range per m of travel, fitted over a run) of a face: tan 60 degrees,
    #: the filter's default ``max_incidence_deg``; a grazing face is steeper.
    max_face_slope: float = 1.732
    #: Std (m) the beam's footprint adds to an edge's position. 0.5 mm: the model's
    #: beam is a ray (the real ~25 degree cone's return is dominated by its axis on a
    #: matte face), and a cone reports an edge somewhat early by an amount that varies
    #: with reflectance; 0.5 mm is a guess of that spread, not a datasheet figure.
    edge_std: float = 0.0005

    def __post_init__(self) -> None:
        _check_pos(
            "SweepConfig",
            rate_hz=self.rate_hz,
            speed=self.speed,
            standoff=self.standoff,
            jump=self.jump,
            max_face_slope=self.max_face_slope,
        )
        _check_nonneg(
            "SweepConfig",
            min_face_length=self.min_face_length,
            overshoot=self.overshoot,
            face_depth=self.face_depth,
            vertical_offset=self.vertical_offset,
            edge_std=self.edge_std,
        )
        if int(self.min_run) != self.min_run or self.min_run < 1:
            raise ValueError(
                f"SweepConfig.min_run must be a positive integer, got {self.min_run!r}"
            )

    @property
    def spacing(self) -> float:
        """Distance (m) between readings along a sweep."""
        return self.speed / self.rate_hz
