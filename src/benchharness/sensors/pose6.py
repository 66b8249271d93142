"""A 6-DOF cube pose filter: face ranges and swept edges fused into position and all three rotations.

**State.** An error state ``x = (δp, δθ)`` about a nominal pose (the robot's
belief when the filter starts): ``δp`` the centre's offset (world, m), ``δθ``
a small rotation vector (world, rad) applied about the centre, so that the
estimated pose is ``(p0 + δp, Rot(δθ) · R0)``. Covariance axes
:data:`POSE6_AXES`. Rotations are kept as a vector about the belief, never as
Euler angles, so no axis is special and a cube in any of its 24 orientations
is handled alike (the box's symmetry only matters if the belief is 45° off).

**Observations**, each with its model ``h(x)`` and analytic Jacobian:

* a **range** ``z`` along a world ray ``o + t d`` (a face reading): ``h`` is
  the ray's entry distance into the estimated box (:func:`.raybox.ray_box`);
  on the face with outward normal ``n`` at point ``q``,
  ``∂h/∂δp = n / (n·d)`` and ``∂h/∂δθ = −(n × (q − c)) / (n·d)``. One range
  fixes the face along its normal; several across the face fix its two tilts;
* an **edge** (:class:`.sweep.EdgeObservation`): the transition point ``q``
  lies on the plane of the face adjacent to the ranged one across that edge,
  outward normal ``m``: ``h = m·(q − c) − edge/2``, measured as 0, with
  ``∂h/∂δp = −m`` and ``∂h/∂δθ = m × (q − c)``; its variance is
  ``(m·u)² σ_along² + (m·d)² σ_range²`` (``u`` the sweep direction). An edge
  fixes the cube across the beam; two points on one edge fix the rotation
  about the face normal. ``m`` is chosen on the estimated box: the border of
  the ranged face nearest the transition point (:func:`edge_model`), used
  only when the beam crossed it the right way (out when leaving, in when
  entering) by at least half its motion.

The rotation columns above are for a small turn on the left of the current
estimate; the filter multiplies them by the SO(3) left Jacobian of ``δθ``
(:func:`left_jacobian`) so that they are derivatives in the state itself.

**Update** (:meth:`CubePose6Filter.update`): an iterated EKF over the whole
batch — Gauss–Newton on the MAP objective, relinearised at each iterate,
with the same gates as :class:`.cube_filter.CubePoseFilter` (no return,
predicted miss or near an edge or grazing, innovation beyond ``gate_sigma``);
the inliers, linearised at the last iterate, then go through filterpy's EKF
update in one batch (every vector a column). filterpy is imported when the
filter is built.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from ..geometry import Pose
from .config import CubeFilterConfig, ToFConfig
from .pose_estimate import PoseEstimate
from .raybox import ray_box
from .sweep import EdgeObservation

__all__ = [
    "POSE6_AXES",
    "CubePose6Filter",
    "Update6Report",
    "compose",
    "edge_model",
    "left_jacobian",
    "range_model",
]

#: Covariance axes of the 6-DOF filter: centre offset (m) and rotation vector about the belief (rad).
POSE6_AXES: tuple[str, ...] = ("x", "y", "z", "rx", "ry", "rz")
_DIM = 6


def compose(nominal: Pose, x: np.ndarray) -> Pose:
    """The pose ``nominal ⊕ x``: centre moved by ``x[:3]``, turned by ``x[3:]`` (world) about it."""
    x = np.asarray(x, dtype=float).reshape(_DIM)
    return Pose.from_rotation(nominal.p + x[:3], Rotation.from_rotvec(x[3:]) * nominal.rotation)


def left_jacobian(phi: np.ndarray) -> np.ndarray:
    """SO(3) left Jacobian: ``Rot(φ + ε) ≈ Rot(J_l(φ) ε) Rot(φ)``.

    The models' rotation columns are derivatives with respect to a small turn
    applied on the left of the current estimate; times ``J_l(δθ)`` they become
    derivatives with respect to the state's rotation vector itself.
    """
    phi = np.asarray(phi, dtype=float).reshape(3)
    th = float(np.linalg.norm(phi))
    k = np.array([[0.0, -phi[2], phi[1]], [phi[2], 0.0, -phi[0]], [-phi[1], phi[0], 0.0]])
    if th < 1e-6:
        return np.eye(3) + 0.5 * k
    return np.eye(3) + (1 - math.cos(th)) / th**2 * k + (th - math.sin(th)) / th**3 * (k @ k)


def range_model(
    pose: Pose, half: float, origins: np.ndarray, directions: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Predicted ranges of rays into the box at ``pose`` and d(range)/d(δp, δθ) (n, 6).

    Returns (hit, range, jacobian, cos_incidence, edge_distance); rows not hit are NaN in the Jacobian.
    """
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    c = pose.p
    hits = ray_box(origins, d, c, pose.rotation.as_matrix(), half)
    n = hits.normal
    nd = np.einsum("ij,ij->i", np.where(hits.hit[:, None], n, 0.0), d)
    jac = np.full((len(d), _DIM), np.nan)
    ok = hits.hit & (np.abs(nd) > 1e-12)
    jac[ok, :3] = n[ok] / nd[ok, None]
    jac[ok, 3:] = -np.cross(n[ok], hits.point[ok] - c) / nd[ok, None]
    return hits.hit, hits.distance, jac, -nd, hits.edge_distance


def edge_model(
    pose: Pose, half: float, edge: EdgeObservation
) -> tuple[float, np.ndarray, float] | None:
    """``h(x)`` (m), its Jacobian (6,) and its variance (m²) for one edge at the box ``pose``.

    The edge is the ranged face's border nearest the transition point on the
    box at ``pose`` (the point lies on the face, within a few mm of the edge it
    crossed; the two other borders it could be taken for are a face-width
    away), with ``m`` the adjacent face's outward normal there. Not the border
    the step points at: the step is the emitter's motion between two readings,
    and at a sweep's start the arm may still be moving from the previous
    sweep's end (measured, PyBullet Rubiks-1-100 sensor-aided: a down-sweep's
    step 0.79 along the face's horizontal axis as its beam came onto the top
    edge; taken for a side edge it moved the belief 17 mm sideways and the
    next grip jammed).

    None when the edge cannot be associated: the step crosses that border
    the wrong way for an entry or exit, or nearly along it (the motion across
    it, ``|m·u|``, under 0.5), so the transition says little across it.
    """
    rot = pose.rotation.as_matrix()
    d = edge.direction
    u = edge.step
    v = edge.point - pose.p
    k_face = int(np.argmax(np.abs(rot.T @ d)))  # the face the beam ranged
    others = [j for j in range(3) if j != k_face]
    j = max(others, key=lambda i: abs(float(rot[:, i] @ v)))
    m = rot[:, j] * float(np.sign(rot[:, j] @ v))  # outward, across the nearest border
    if float(m @ u) * (-1.0 if edge.entering else 1.0) < 0.5:
        return None
    h = float(m @ v) - half
    jac = np.concatenate([-m, np.cross(m, v)])
    var = float(m @ u) ** 2 * edge.std_along**2 + float(m @ d) ** 2 * edge.std_range**2
    return h, jac, var


@dataclass(frozen=True)
class Update6Report:
    """What one batch did: every range and every edge lands in exactly one count of its kind."""

    n_rays: int
    n_rays_used: int
    n_no_return: int
    n_predicted_miss: int
    n_rays_gated: int
    n_edges: int
    n_edges_used: int
    n_edges_unassociated: int
    n_edges_gated: int
    nis: float  #: normalised innovation squared of the fused batch
    fused_rays: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    fused_edges: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))


class CubePose6Filter:
    """A cube's full pose (position and small rotation about the belief) with its 6×6 covariance.

    Deterministic; the randomness lives in the sensors.
    """

    name = "cube-kf6"

    def __init__(
        self,
        prior: PoseEstimate,
        config: CubeFilterConfig | None = None,
        tof: ToFConfig | None = None,
    ) -> None:
        if tuple(prior.axes) != POSE6_AXES:
            raise ValueError(f"the prior's axes must be {POSE6_AXES}, got {prior.axes}")
        self.config = config or CubeFilterConfig()
        self.tof = tof or ToFConfig()
        from filterpy.kalman import ExtendedKalmanFilter

        self._kf = ExtendedKalmanFilter(dim_x=_DIM, dim_z=1)
        self._kf.x = np.zeros((_DIM, 1))
        self._kf.P = np.array(prior.covariance, dtype=float)
        self.nominal = prior.pose
        self._n = int(prior.n_measurements)
        self._time = float(prior.time)

    @property
    def half(self) -> float:
        return 0.5 * self.config.edge

    @property
    def x(self) -> np.ndarray:
        return self._kf.x[:, 0].copy()

    @property
    def P(self) -> np.ndarray:
        return self._kf.P.copy()

    @property
    def pose(self) -> Pose:
        return compose(self.nominal, self.x)

    @property
    def estimate(self) -> PoseEstimate:
        return PoseEstimate(
            self.pose, self.P, n_measurements=self._n, time=self._time, axes=POSE6_AXES,
            source=self.name,
        )  # fmt: skip

    def _rows(
        self,
        xi: np.ndarray,
        o: np.ndarray,
        d: np.ndarray,
        z: np.ndarray,
        edges: Sequence[EdgeObservation],
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """At iterate ``xi``: measured, predicted, Jacobian, variance, usable (predicted) per row."""
        cfg = self.config
        pose = compose(self.nominal, xi)
        returned = np.isfinite(z)
        hit, rng, jac_r, cos_inc, edge_d = range_model(pose, self.half, o, d)
        cos_max = math.cos(math.radians(cfg.max_incidence_deg))
        ok_r = returned & hit & (np.nan_to_num(edge_d) >= cfg.edge_margin) & (cos_inc >= cos_max)
        z_ok = np.where(returned, z, 0.0)
        var_r = (self.tof.noise_std + self.tof.noise_std_per_m * z_ok) ** 2
        meas = [z_ok]
        pred = [np.where(ok_r, rng, 0.0)]
        jac = [np.where(ok_r[:, None], jac_r, 0.0)]
        var = [var_r]
        ok = [ok_r]
        pe = np.zeros(len(edges))
        je = np.zeros((len(edges), _DIM))
        ve = np.ones(len(edges))
        oke = np.zeros(len(edges), dtype=bool)
        for i, e in enumerate(edges):
            res = edge_model(pose, self.half, e)
            if res is not None:
                pe[i], je[i], ve[i] = res
                oke[i] = True
        meas.append(np.zeros(len(edges)))
        pred.append(pe)
        jac.append(je)
        var.append(ve)
        ok.append(oke)
        jac_all = np.concatenate(jac, axis=0).reshape(-1, _DIM)
        jac_all[:, 3:] = jac_all[:, 3:] @ left_jacobian(xi[3:])
        return (
            np.concatenate(meas),
            np.concatenate(pred),
            jac_all,
            np.concatenate(var),
            np.concatenate(ok),
            returned,
        )

    def update(
        self,
        origins: np.ndarray | None = None,
        directions: np.ndarray | None = None,
        distances: np.ndarray | None = None,
        edges: Sequence[EdgeObservation] = (),
        *,
        time: float | None = None,
    ) -> Update6Report:
        """Fuse ranges along world rays (origins, directions (n, 3), distances (n,)) and swept edges."""
        o = np.zeros((0, 3)) if origins is None else np.asarray(origins, dtype=float).reshape(-1, 3)
        d = (
            np.zeros((0, 3))
            if directions is None
            else np.asarray(directions, dtype=float).reshape(-1, 3)
        )
        z = np.zeros(0) if distances is None else np.asarray(distances, dtype=float).reshape(-1)
        if not (len(o) == len(d) == len(z)):
            raise ValueError("origins, directions and distances must have one row per ray")
        if len(d):
            d = d / np.linalg.norm(d, axis=1, keepdims=True)
        edges = list(edges)
        n_r = len(z)
        gate2 = self.config.gate_sigma**2
        x0 = self._kf.x[:, 0].copy()
        p0 = self._kf.P.copy()
        p0_inv = np.linalg.inv(p0 + 1e-14 * np.eye(_DIM))
        p_gate = p0
        xi = x0.copy()
        x_lin = x0.copy()
        inl = np.zeros(n_r + len(edges), dtype=bool)
        usable = inl.copy()
        returned = np.isfinite(z)
        h_in = np.zeros((0, _DIM))
        pred_in = np.zeros(0)
        var_all = np.ones(n_r + len(edges))
        meas = np.zeros(n_r + len(edges))
        for _ in range(self.config.max_iterations):
            meas, pred, jac, var_all, usable, returned = self._rows(xi, o, d, z, edges)
            resid = np.where(usable, meas - pred, np.inf)
            s_gate = np.einsum("ij,jk,ik->i", jac, p_gate, jac) + var_all
            new_inl = usable & (resid**2 <= gate2 * s_gate)
            if not np.any(new_inl):
                inl = new_inl
                break
            h_in = jac[new_inl]
            pred_in = pred[new_inl]
            x_lin = xi
            w = 1.0 / var_all[new_inl]
            p_post = np.linalg.inv(p0_inv + h_in.T @ (w[:, None] * h_in))
            innov = meas[new_inl] - (pred_in + h_in @ (x0 - xi))
            x_new = x0 + p_post @ (h_in.T @ (w * innov))
            step = np.abs(x_new - xi)
            same = np.array_equal(new_inl, inl)
            inl = new_inl
            p_gate = p_post
            xi = x_new
            if same and step[:3].max() < 1e-7 and step[3:].max() < 1e-7:
                break
        nis = 0.0
        if np.any(inl):
            zc = meas[inl].reshape(-1, 1)
            r = np.diag(var_all[inl])
            h = h_in
            p_lin = pred_in

            def hx(x: np.ndarray) -> np.ndarray:
                return (p_lin + h @ (x[:, 0] - x_lin)).reshape(-1, 1)

            innov0 = zc - hx(self._kf.x)
            s = h @ self._kf.P @ h.T + r
            nis = float(innov0[:, 0] @ np.linalg.solve(s, innov0[:, 0]))
            self._kf.dim_z = int(inl.sum())
            self._kf.update(zc, HJacobian=lambda _x: h, Hx=hx, R=r)
            if self._kf.x.shape != (_DIM, 1) or self._kf.P.shape != (_DIM, _DIM):
                raise AssertionError(
                    f"filter state mis-shaped: x {self._kf.x.shape}, P {self._kf.P.shape}"
                )
        self._n += int(inl.sum())
        if time is not None:
            self._time = float(time)
        r_inl, e_inl = inl[:n_r], inl[n_r:]
        r_use, e_use = usable[:n_r], usable[n_r:]
        n_no = int((~returned).sum())
        n_miss = int((returned & ~r_use).sum())
        return Update6Report(
            n_rays=n_r,
            n_rays_used=int(r_inl.sum()),
            n_no_return=n_no,
            n_predicted_miss=n_miss,
            n_rays_gated=n_r - int(r_inl.sum()) - n_no - n_miss,
            n_edges=len(edges),
            n_edges_used=int(e_inl.sum()),
            n_edges_unassociated=int((~e_use).sum()),
            n_edges_gated=int((e_use & ~e_inl).sum()),
            nis=nis,
            fused_rays=r_inl.copy(),
            fused_edges=e_inl.copy(),
        )
