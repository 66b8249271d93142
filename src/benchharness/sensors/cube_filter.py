"""Extended Kalman filter over the cube's planar pose, fed by pre-touch ranges.

State ``x = (x, y, z, yaw)``: the cube centre (world, m) and its yaw about
world z (rad, wrapped to (−45°, 45°] by the cube's symmetry). Roll and pitch
are taken as zero: the cube rests on the table or is held level between
parallel pads, and a 90° flip is a symmetry of the box.

* **Predict** from the cube's *commanded* displacement — what dead reckoning
  trusts — adding process noise that grows with the size of the motion
  (:class:`~benchharness.sensors.config.CubeFilterConfig`). Predict-only is
  dead reckoning with an honest covariance.
* **Update** with ToF ranges: each reading is a range along a known world ray;
  the predicted range is the analytic ray–box entry distance of the current
  estimate (:mod:`.raybox`), with an analytic Jacobian. A batch (one scan) is
  fused as an *iterated* EKF update: relinearised at each iterate, because a
  prior several millimetres and degrees off puts the first linearisation on
  the wrong side of edges. A plain sequential EKF, tried first, let rays near
  a corner pull some runs tens of degrees off.
* **Gating** uses only what a real robot has: a reading with no return, one
  the estimate predicts would miss the cube (or meet it near an edge or at
  grazing incidence), and one whose innovation exceeds ``gate_sigma``
  standard deviations (a hit on the table, the other gripper, a face the
  estimate puts elsewhere) are not fused. The body each ray really hit is
  never consulted.

filterpy 2.0.0 silently broadcasts a 1-D measurement against its (m, 1)
prediction into an (m, m) residual; every vector handed to it here is a
column, and :meth:`CubePoseFilter._check_shapes` guards the state after each
step.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..geometry import Pose
from .config import CubeFilterConfig, ToFConfig
from .pose_estimate import FILTER_AXES, PoseEstimate
from .pretouch import Scan, ToFReading
from .raybox import ray_box, ray_box_jacobian
from .yaw import cube_tilt, cube_yaw, level_rotation, wrap_quarter

__all__ = ["CubePoseFilter", "UpdateReport"]

_DIM = 4


def _state_diff(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a - b`` with the yaw difference taken modulo the cube's 90° symmetry."""
    diff = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    diff[3] = wrap_quarter(diff[3])
    return diff


@dataclass(frozen=True)
class UpdateReport:
    """What one batch of ranges did to the filter; every ray lands in exactly one count."""

    n_rays: int
    n_used: int  #: fused
    n_no_return: int  #: NaN (too close) or inf (nothing in range)
    n_predicted_miss: int  #: returned, but the estimate's box is off the ray, or the hit is near an edge or grazing
    n_gated: int  #: innovation beyond the gate
    nis: float  #: normalised innovation squared of the fused batch (χ² with n_used dof if consistent)
    fused: np.ndarray = field(
        default_factory=lambda: np.zeros(0, dtype=bool)
    )  #: (n_rays,) which rays were fused


class CubePoseFilter:
    """Tracks one cube: initialise from the head camera, predict from motion, update from ToF.

    The filter is deterministic; all randomness lives in the sensors.
    """

    name = "cube-kf"

    def __init__(
        self,
        config: CubeFilterConfig | None = None,
        tof: ToFConfig | None = None,
        *,
        initial: PoseEstimate | None = None,
    ) -> None:
        self.config = config or CubeFilterConfig()
        #: The range noise model used for R; it should match the sensors' ToFConfig.
        self.tof = tof or ToFConfig()
        # imported here: filterpy's package import pulls in scipy.stats etc. (~0.2 s at start-up)
        from filterpy.kalman import ExtendedKalmanFilter

        self._kf = ExtendedKalmanFilter(dim_x=_DIM, dim_z=1)
        self._kf.B = np.eye(_DIM)
        self._n = 0
        self._time = 0.0
        self._initialised = False
        if initial is not None:
            self.initialize(initial)

    # -- state ---------------------------------------------------------------
    @property
    def half(self) -> float:
        return 0.5 * self.config.edge

    @property
    def x(self) -> np.ndarray:
        """Copy of the state (x, y, z, yaw), shape (4,)."""
        return self._kf.x[:, 0].copy()

    @property
    def P(self) -> np.ndarray:
        """Copy of the 4×4 state covariance."""
        return self._kf.P.copy()

    @property
    def estimate(self) -> PoseEstimate:
        self._require_init()
        x = self.x
        pose = Pose.from_rotation(x[:3], level_rotation(x[3]))
        return PoseEstimate(
            pose,
            self.P,
            n_measurements=self._n,
            time=self._time,
            axes=FILTER_AXES,
            source=self.name,
        )

    def initialize(self, prior: PoseEstimate) -> None:
        """Start from a prior (usually the head camera's): its x, y, z and yaw marginal."""
        missing = [a for a in FILTER_AXES if a not in prior.axes]
        if missing:
            raise ValueError(f"prior lacks covariance axes {missing}")
        x0 = np.array([*prior.pose.p, cube_yaw(prior.pose.rotation)], dtype=float).reshape(_DIM, 1)
        self._kf.x = x0
        self._kf.P = prior.marginal(FILTER_AXES)
        self._n = int(prior.n_measurements)
        self._time = float(prior.time)
        self._initialised = True
        self._check_shapes()

    def _require_init(self) -> None:
        if not self._initialised:
            raise RuntimeError("CubePoseFilter is not initialised: call initialize(prior) first")

    def _check_shapes(self) -> None:
        kf = self._kf
        if kf.x.shape != (_DIM, 1) or kf.P.shape != (_DIM, _DIM):
            raise AssertionError(f"filter state mis-shaped: x {kf.x.shape}, P {kf.P.shape}")
        if not (np.all(np.isfinite(kf.x)) and np.all(np.isfinite(kf.P))):
            raise AssertionError("filter state is not finite")

    def _set_time(self, time: float | None) -> None:
        if time is not None:
            self._time = float(time)

    # -- predict ---------------------------------------------------------------
    def process_noise(self, translation: float, rotation: float) -> np.ndarray:
        """Q (4×4) for a commanded motion of ``translation`` m and ``rotation`` rad."""
        c = self.config
        s_p = math.hypot(c.process_pos_std, c.process_pos_std_per_m * abs(translation))
        s_y = math.hypot(
            math.radians(c.process_yaw_std_deg), c.process_yaw_std_per_deg * abs(rotation)
        )
        return np.diag([s_p**2, s_p**2, s_p**2, s_y**2])

    def predict(
        self,
        delta_p: Sequence[float] = (0.0, 0.0, 0.0),
        delta_yaw: float = 0.0,
        *,
        rotation_magnitude: float | None = None,
        time: float | None = None,
    ) -> None:
        """Move the estimate by the cube's commanded displacement (world frame).

        ``delta_yaw`` turns the cube about its own vertical axis.
        ``rotation_magnitude`` (rad) sizes the process noise when the commanded
        rotation is larger than its effect on yaw (a 90° flip is invisible in
        yaw, not in slip); it defaults to ``|delta_yaw|``.
        """
        self._require_init()
        dp = np.asarray(delta_p, dtype=float).reshape(3)
        u = np.array([*dp, float(delta_yaw)]).reshape(_DIM, 1)
        rot = (
            abs(float(delta_yaw)) if rotation_magnitude is None else abs(float(rotation_magnitude))
        )
        self._kf.Q = self.process_noise(float(np.linalg.norm(dp)), rot)
        self._kf.predict(u=u)
        self._kf.x[3, 0] = wrap_quarter(self._kf.x[3, 0])
        self._set_time(time)
        self._check_shapes()

    def predict_carried(self, before: Pose, after: Pose, *, time: float | None = None) -> float:
        """The cube is carried rigidly by a link commanded from ``before`` to ``after``.

        Returns the tilt (rad) the motion would give the estimated box, which
        the planar state drops: zero for turns about the vertical and for 90°
        flips of a box square to the flip axis, as in the Rubik's regrasps.
        """
        self._require_init()
        delta = after * before.inv()
        x = self.x
        old = Pose.from_rotation(x[:3], level_rotation(x[3]))
        new = delta * old
        d_yaw = wrap_quarter(cube_yaw(new.rotation) - x[3])
        self.predict(
            new.p - old.p, d_yaw, rotation_magnitude=float(delta.rotation.magnitude()), time=time
        )
        return cube_tilt(new.rotation)

    # -- update ----------------------------------------------------------------
    def _scalar_update(self, z: float, h: np.ndarray, hx: float, r: float) -> None:
        self._kf.update(
            np.array([[z]]),
            HJacobian=lambda _x: h.reshape(1, _DIM),
            Hx=lambda _x: np.array([[hx]]),
            R=np.array([[r]]),
        )
        self._kf.x[3, 0] = wrap_quarter(self._kf.x[3, 0])
        self._check_shapes()

    def _predict_ranges(self, x: np.ndarray, o: np.ndarray, d: np.ndarray):
        pred = ray_box(o, d, x[:3], level_rotation(x[3]).as_matrix(), self.half)
        return pred, ray_box_jacobian(d, x[:3], pred)

    def update_ranges(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        distances: np.ndarray,
        *,
        time: float | None = None,
    ) -> UpdateReport:
        """Fuse ranges measured along world rays (origins, directions: (n, 3); distances (n,)).

        An iterated EKF update over the whole batch: the measurement model is
        relinearised at each iterate (Gauss–Newton on the MAP objective) and
        the inlier set re-chosen, first with the prior's covariance (loose:
        it must admit readings while the estimate is still mm off) and then
        with the latest posterior (tight: once the box is in place, a ray that
        grazed the wrong face stands out). The final step feeds the inliers,
        linearised at the last iterate, through filterpy's EKF update.
        """
        self._require_init()
        o = np.atleast_2d(np.asarray(origins, dtype=float))
        d = np.atleast_2d(np.asarray(directions, dtype=float))
        z = np.asarray(distances, dtype=float).reshape(-1)
        if o.shape != d.shape or o.shape != (z.size, 3):
            raise ValueError(
                f"origins {o.shape}, directions {d.shape} and distances {z.shape} disagree"
            )
        d = d / np.linalg.norm(d, axis=1, keepdims=True)
        cfg = self.config
        gate2 = cfg.gate_sigma**2
        cos_max = math.cos(math.radians(cfg.max_incidence_deg))
        returned = np.isfinite(z)
        z_ok = np.where(returned, z, 0.0)
        r_diag = np.where(returned, self.tof.noise_std + self.tof.noise_std_per_m * z_ok, 1.0) ** 2
        x0 = self._kf.x[:, 0].copy()
        p0 = self._kf.P.copy()
        # a floor of (0.1 µm)² keeps a zero-variance prior invertible
        p0_inv = np.linalg.inv(p0 + 1e-14 * np.eye(_DIM))
        p_gate = p0
        xi = x0.copy()
        x_lin = x0.copy()  # where the fused rows were linearised
        inl = np.zeros(z.size, dtype=bool)
        predicted = np.zeros(z.size, dtype=bool)
        h_in = np.zeros((0, _DIM))
        pred_in = np.zeros(0)
        for _ in range(self.config.max_iterations):
            pred, jac = self._predict_ranges(xi, o, d)
            cos_inc = -np.einsum("ij,ij->i", np.where(pred.hit[:, None], pred.normal, 0.0), d)
            predicted = (
                returned & pred.hit & (pred.edge_distance >= cfg.edge_margin) & (cos_inc >= cos_max)
            )
            resid = np.where(predicted, z - np.where(predicted, pred.distance, 0.0), np.inf)
            jac_safe = np.where(predicted[:, None], jac, 0.0)
            s_gate = np.einsum("ij,jk,ik->i", jac_safe, p_gate, jac_safe) + r_diag
            new_inl = predicted & (resid**2 <= gate2 * s_gate)
            if not np.any(new_inl):
                inl = new_inl
                break
            h_in = jac[new_inl]
            pred_in = pred.distance[new_inl]
            x_lin = xi
            # Gauss-Newton step of the MAP objective, in information form (4x4
            # inverses only): the model linearised at xi, evaluated at x0.
            w = 1.0 / r_diag[new_inl]
            p_post = np.linalg.inv(p0_inv + h_in.T @ (w[:, None] * h_in))
            innov = z[new_inl] - (pred_in + h_in @ _state_diff(x0, xi))
            x_new = x0 + p_post @ (h_in.T @ (w * innov))
            x_new[3] = wrap_quarter(x_new[3])
            step = np.abs(_state_diff(x_new, xi))
            same = np.array_equal(new_inl, inl)
            inl = new_inl
            p_gate = p_post
            xi = x_new
            if same and step[:3].max() < 1e-7 and step[3] < 1e-6:
                break
        n_used = int(inl.sum())
        nis = 0.0
        # The fused rows go through filterpy as scalar updates of the model
        # linearised at x_lin: for a linear model with independent noise this
        # is exactly the batch update, and each z is a (1, 1) column.
        for j, i in enumerate(np.flatnonzero(inl)):
            h_j = h_in[j]
            hx = float(pred_in[j] + h_j @ _state_diff(self._kf.x[:, 0], x_lin))
            s_j = float(h_j @ self._kf.P @ h_j) + r_diag[i]
            nis += (z[i] - hx) ** 2 / s_j
            self._scalar_update(float(z[i]), h_j, hx, float(r_diag[i]))
        self._n += n_used
        self._set_time(time)
        n_no = int((~returned).sum())
        n_miss = int((returned & ~predicted).sum())
        return UpdateReport(
            int(z.size), n_used, n_no, n_miss, int(z.size) - n_used - n_no - n_miss, nis, inl.copy()
        )

    def update_reading(self, reading: ToFReading | Scan) -> UpdateReport:
        """Fuse a :class:`ToFReading` or a whole :class:`Scan` (its believed rays)."""
        return self.update_ranges(
            reading.origins, reading.directions, reading.distance, time=reading.time
        )

    def update_support(
        self, height: float, std: float = 0.0005, *, time: float | None = None
    ) -> None:
        """The cube rests on a horizontal surface at ``height`` (m): its centre is ``edge/2`` above.

        ``std`` (m) is how well the surface height is known (0.5 mm: a fitted
        table plane). Use it only while the cube is known to rest there.
        """
        self._require_init()
        h = np.array([0.0, 0.0, 1.0, 0.0])
        self._scalar_update(float(height) + self.half, h, float(self._kf.x[2, 0]), float(std) ** 2)
        self._n += 1
        self._set_time(time)
