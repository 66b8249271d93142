"""Kinematic trajectory optimisation for in-grasp manipulation (Level I).

Decision variables: the used fingers' joints at T waypoints after the fixed
initial grasp. The object is not simulated: it is a frame rigidly attached
to a carrier frame computed from the fingertips (the fingertip triangle, or
the reference fingertip as in the original; the pose at the initial grasp
fixes the offset), so the object pose at every waypoint is forward
kinematics. Variants differ in how the fingertips are kept on the object
(see ``docs/ingrasp.md``):

* ``relaxed-rigidity``: each fingertip's position in the object frame may
  change only at a cost (rolling is free), goal = object pose;
* ``relaxed-position``: the same fingertip cost, goal = object position;
* ``relaxed-position-orientation``: as relaxed-rigidity plus, as a separate
  term, the fingertip's orientation relative to the object;
* ``ik-rigid``: the object follows a path interpolated from the initial to
  the goal pose and every fingertip (reference included) must keep its
  initial pose in the object frame (heavily weighted, i.e. constraints) --
  over-constrained with 4-joint fingers;
* ``point-contact``: as ik-rigid but only the fingertip positions are held
  (point contact with friction: orientation free); the object pose is
  recovered afterwards by a least-squares fit of the contacts.

Every variant's cost is a weighted sum of squared residuals, solved as the
nonlinear least-squares problem it is: trust-region reflective
(``scipy.optimize.least_squares``) with the exact Jacobian by forward-mode
autodiff through the fingertip FK, joint limits as bounds, from an
IK-interpolated initial trajectory (:func:`warm_start`). Per-step velocity
limits are penalty residuals during the optimisation; both limits are then
enforced exactly by projecting the trajectory (clamping waypoint by
waypoint), so the returned trajectory always satisfies them. L-BFGS and an
in-house Levenberg-Marquardt remain as opt-in solvers (``IngraspConfig.solver``).

Why the warm start (measured, docs/ingrasp.md "Solver"): from ``q0`` repeated
only the last waypoint feels the goal, and the motion has to be pushed back
through the chain of per-step velocity limits one (penalty) hinge at a time;
no solver we tried (L-BFGS, LM, trust region) converged from there within
150 iterations, while from the IK-interpolated trajectory all reach the goal
in about ten Gauss-Newton iterations.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import torch

from .collision import CollisionScene
from .config import OBJECT_PATH, RELAXED, VARIANTS, IngraspConfig
from .hand import DTYPE, FINGERS, HandKinematics
from .problem import InGraspProblem
from .rotations import interpolate_poses, inverse, pose_vector, rot_residual

__all__ = ["PlanResult", "plan", "object_poses", "project_trajectory", "fit_object_pose"]


@dataclass(frozen=True)
class PlanResult:
    """A planned trajectory and what it implies for the object."""

    variant: str
    fingers: tuple[str, ...]
    q: np.ndarray  #: (T + 1, 4 k) joints of the used fingers, row 0 = initial grasp
    q_hand: np.ndarray  #: (T + 1, 16) whole hand (unused fingers hold the initial grasp)
    object_final: np.ndarray  #: 4x4 planned object pose in the palm frame at the last waypoint
    goal: np.ndarray  #: 4x4 desired object pose in the palm frame
    reached: (
        np.ndarray
    )  #: (7,) planned pose ``[x, y, z, qx, qy, qz, qw]`` in the dataset's convention
    plan_time_s: float  #: wall time of the optimisation (set-up of the hand model excluded)
    converged: bool  #: stopped on the tolerances, not on the iteration budget
    iterations: int
    cost: float  #: final cost (before projection)
    pos_error: float  #: m, planned vs goal object position
    rot_error: float  #: rad, planned vs goal object orientation
    projection_change: float  #: rad, largest joint change made by the final limit projection
    #: m, with a collision scene: the most any hand shape comes nearer the object than allowed
    #: over the returned trajectory (0: none does; None: planned without a scene)
    collision_shortfall: float | None = None


def carrier_frames(tips: torch.Tensor, object_frame: str) -> torch.Tensor:
    """The frame the object is attached to, from fingertip poses (B, k, 4, 4) -> (B, 4, 4).

    ``reference-finger``: the first fingertip's frame. ``fingertips``: the
    triangle of the first three fingertip positions (origin at the centroid,
    x along tip 0 -> tip 1, z along the triangle normal), which moves with
    all three fingers, so the object has as many degrees of freedom as a
    rigid body instead of the reference finger's four.
    """
    if object_frame == "reference-finger":
        return tips[:, 0]
    if tips.shape[1] < 3:
        raise ValueError("object_frame='fingertips' needs at least three fingers")
    p = tips[:, :3, :3, 3]
    x = p[:, 1] - p[:, 0]
    x = x / x.norm(dim=-1, keepdim=True)
    z = torch.linalg.cross(x, p[:, 2] - p[:, 0])
    z = z / z.norm(dim=-1, keepdim=True)
    y = torch.linalg.cross(z, x)
    top = torch.cat([torch.stack([x, y, z], dim=-1), p.mean(dim=1)[..., None]], dim=-1)
    return torch.cat([top, tips[:, 0, 3:4, :]], dim=-2)


def object_poses(
    hand: HandKinematics,
    problem: InGraspProblem,
    q: torch.Tensor,
    object_frame: str = "reference-finger",
) -> torch.Tensor:
    """Object frame implied by the fingertips for joint rows ``q`` (B, 4 k) -> (B, 4, 4)."""
    q0 = torch.as_tensor(problem.q0, dtype=DTYPE)[None]
    c0 = carrier_frames(hand.tip_poses(q0, problem.fingers), object_frame)[0]
    attach = inverse(c0) @ torch.as_tensor(problem.object_initial, dtype=DTYPE)
    return carrier_frames(hand.tip_poses(q, problem.fingers), object_frame) @ attach


def tip_rotation_deg(hand: HandKinematics, fingers: tuple[str, ...], q: np.ndarray) -> np.ndarray:
    """How far each fingertip turns against the object over a plan (deg, one per finger).

    The object is taken to move with the fingertip triangle (the ``"fingertips"`` carrier, as the
    relaxed variants plan it): the angle is that of the fingertip's rotation relative to the
    carrier frame between the first and the last row of ``q`` (T + 1, 4 k). A rigid fingertip
    sphere of radius r whose centre the plan holds on the object can only turn that much by
    rolling (its centre then moves r x angle over the object) or by sliding: the relaxed
    variants leave this angle free (docs/ingrasp.md, "Execution drops").
    """
    x = torch.as_tensor(hand.tip_poses_np(np.asarray(q, float)[[0, -1]], fingers), dtype=DTYPE)
    rel = inverse(carrier_frames(x, "fingertips"))[:, None] @ x  # (2, k, 4, 4)
    r = (rel[0, :, :3, :3].transpose(-1, -2) @ rel[1, :, :3, :3]).numpy()
    cos = (np.trace(r, axis1=-2, axis2=-1) - 1.0) / 2.0
    w = np.stack([r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]], -1)
    return np.degrees(np.arctan2(np.linalg.norm(w, axis=-1) / 2.0, cos))  # exact near 0 and pi


def project_trajectory(
    q: np.ndarray, q0: np.ndarray, lower: np.ndarray, upper: np.ndarray, max_step: float
) -> np.ndarray:
    """Nearest-by-clamping trajectory within joint limits and the per-step bound (rows after ``q0``).

    Clamping waypoint by waypoint is always feasible because each clamped
    waypoint is itself within the limits.
    """
    out = np.empty_like(q)
    prev = np.asarray(q0, float)
    for t in range(q.shape[0]):
        lo = np.maximum(lower, prev - max_step)
        hi = np.minimum(upper, prev + max_step)
        out[t] = np.clip(q[t], lo, hi)
        prev = out[t]
    return out


def fit_object_pose(points_obj: np.ndarray, points_palm: np.ndarray) -> np.ndarray:
    """Rigid transform (4x4) best mapping object-frame contacts onto palm-frame fingertips (Kabsch)."""
    a, b = np.asarray(points_obj, float), np.asarray(points_palm, float)
    ca, cb = a.mean(0), b.mean(0)
    u, _, vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = r, cb - r @ ca
    return m


class _Cost:
    """The variant's cost as a function of the waypoint block (T, 4 k)."""

    def __init__(
        self,
        hand: HandKinematics,
        problem: InGraspProblem,
        variant: str,
        cfg: IngraspConfig,
        scene: CollisionScene | None = None,
    ) -> None:
        self.hand, self.p, self.variant, self.cfg = hand, problem, variant, cfg
        self.scene = scene if cfg.w_collision > 0 else None
        t = lambda a: torch.as_tensor(np.asarray(a, float), dtype=DTYPE)  # noqa: E731
        self.q0 = t(problem.q0)
        lo, hi = hand.limits(problem.fingers)
        self.lo, self.hi = t(lo + cfg.limit_margin), t(hi - cfg.limit_margin)
        self.goal = t(problem.goal)
        x0 = hand.tip_poses(self.q0[None], problem.fingers)[0]  # (k, 4, 4)
        self.x_o0 = t(problem.object_initial)
        self.attach = (
            inverse(carrier_frames(x0[None], cfg.object_frame)[0]) @ self.x_o0
        )  # object in its carrier frame
        rel = inverse(self.x_o0)[None] @ x0  # fingertips in the object frame (k, 4, 4)
        self.tip_in_obj = rel
        if variant in OBJECT_PATH:
            s = np.arange(1, cfg.waypoints + 1) / cfg.waypoints
            path = interpolate_poses(problem.object_initial, problem.goal, s)  # (T, 4, 4)
            self.path = t(path)  # (T, 4, 4) the object's pose at each waypoint
            self.targets = self.path[:, None] @ rel[None]  # (T, k, 4, 4)

    def rigidity_residuals(
        self, x: torch.Tensor, x_o: torch.Tensor, first: int = 0
    ) -> list[torch.Tensor]:
        """Relaxed-rigidity residuals: each fingertip's pose in the object frame against its initial one.

        ``x`` (T, k, 4, 4) fingertip poses, ``x_o`` (T, 4, 4) object poses, both in
        the palm frame. Position residuals (m) for every finger from ``first``
        on, weighted ``w_rigid_pos``; for relaxed-position-orientation also the
        fingertip's orientation relative to the object (``w_rigid_rot``). Zero
        for any trajectory that moves fingertips and object as one rigid body.
        """
        cfg = self.cfg
        in_obj = inverse(x_o)[:, None] @ x[:, first:]  # fingertips in the object frame now
        ref = self.tip_in_obj[None, first:]
        out = [(cfg.w_rigid_pos**0.5) * (in_obj[..., :3, 3] - ref[..., :3, 3]).reshape(-1)]
        if self.variant == "relaxed-position-orientation":
            r = rot_residual(ref[..., :3, :3], in_obj[..., :3, :3])
            out.append((cfg.w_rigid_rot**0.5) * r.reshape(-1))
        return out

    def residuals(self, q: torch.Tensor, active: torch.Tensor | None = None) -> torch.Tensor:
        """All weighted residuals as one vector; the cost is its squared norm (a least-squares problem).

        ``active``: the collision term's nearest surface samples (:meth:`residuals_at`).
        """
        cfg, v = self.cfg, self.variant
        sq = lambda w, r: (w**0.5) * r.reshape(-1)  # noqa: E731
        x = self.hand.tip_poses(q, self.p.fingers)  # (T, k, 4, 4)
        parts = []
        x_o = self.object_poses(x)
        if v in RELAXED:
            # the carrier finger (reference-finger model) is the object's frame: it cannot slip
            first = 1 if cfg.object_frame == "reference-finger" else 0
            parts.extend(self.rigidity_residuals(x, x_o, first))
            # the object pose cost at every waypoint (not only the last): each waypoint is pulled
            # towards the goal as far as the velocity limit lets it
            xs = x_o if cfg.goal_every_waypoint else x_o[-1:]
            parts.append(sq(cfg.w_goal_pos, xs[:, :3, 3] - self.goal[None, :3, 3]))
            if v != "relaxed-position":  # relaxed-position: the object's position is the goal
                parts.append(
                    sq(cfg.w_goal_rot, rot_residual(self.goal[None, :3, :3], xs[:, :3, :3]))
                )
        else:
            parts.append(sq(cfg.w_contact_pos, x[..., :3, 3] - self.targets[..., :3, 3]))
            if v == "ik-rigid":
                parts.append(
                    sq(cfg.w_contact_rot, rot_residual(self.targets[..., :3, :3], x[..., :3, :3]))
                )
        if self.scene is not None:
            links = self.scene.hand_links(self.hand, q)
            parts.append(self.scene.residuals(links, x_o, cfg.w_collision, active))
        steps = torch.diff(torch.cat([self.q0[None], q]), dim=0)
        parts.append(sq(cfg.w_smooth, steps))
        parts.append(sq(cfg.w_limits, torch.relu(q - self.hi) + torch.relu(self.lo - q)))
        parts.append(sq(cfg.w_limits, torch.relu(steps.abs() - cfg.max_step)))
        return torch.cat(parts)

    def __call__(self, q: torch.Tensor) -> torch.Tensor:
        return (self.residuals(q) ** 2).sum()

    def residuals_at(self, q: torch.Tensor):
        """:meth:`residuals` specialised at the plain point ``q`` (T, 4 k): the collision term
        measures only each shape's nearest surface sample there (same value and derivative at
        ``q``, :meth:`.collision.CollisionScene.distances`)."""
        if self.scene is None:
            return self.residuals
        with torch.no_grad():
            x_o = self.object_poses(self.hand.tip_poses(q, self.p.fingers))
            active = self.scene.nearest(self.scene.hand_links(self.hand, q), x_o)
        return lambda y: self.residuals(y, active)

    def object_poses(self, x: torch.Tensor) -> torch.Tensor:
        """The object's planned pose at each waypoint (T, 4, 4) from fingertip poses ``x``: carried
        by the fingertips (relaxed variants) or on the interpolated path (object-path variants)."""
        if self.variant in RELAXED:
            return carrier_frames(x, self.cfg.object_frame) @ self.attach
        return self.path

    def collision_shortfall(self, q: np.ndarray) -> float | None:
        """The most any hand shape comes nearer the object than allowed along ``q`` (T, 4 k), m."""
        if self.scene is None:
            return None
        return float(self.collision_shortfalls(q).max())

    def collision_shortfalls(
        self, q: np.ndarray | torch.Tensor, object_poses: torch.Tensor | None = None
    ) -> torch.Tensor:
        """How much nearer than allowed each hand shape comes to the object at each row of ``q``
        (T, 4 k) -> (T, shapes), m, 0 where it keeps its distance; the object where the plan
        carries it, or at ``object_poses`` (T, 4, 4). Needs a scene."""
        assert self.scene is not None and self.scene.allowed is not None
        with torch.no_grad():
            qt = torch.as_tensor(np.asarray(q, float), dtype=DTYPE)
            if object_poses is None:
                object_poses = self.object_poses(self.hand.tip_poses(qt, self.p.fingers))
            d = self.scene.distances(self.scene.hand_links(self.hand, qt), object_poses)
            return torch.clamp(self.scene.allowed[None] - d, min=0.0)


def _lbfgs(
    cost: _Cost, init: torch.Tensor, cfg: IngraspConfig
) -> tuple[torch.Tensor, bool, int, float]:
    """Minimise the cost from ``init`` with L-BFGS (strong-Wolfe line search).

    Runs in calls of ``inner_iterations`` and stops when a call lowered the
    cost by less than ``ftol`` (relative) or the gradient is below ``gtol``
    (converged), or when ``max_iterations`` are spent (not converged: the
    budget is set for planning time, and the goal error is usually settled
    long before the slip/smoothness trade-off is).
    """
    z = init.clone().requires_grad_(True)
    opt = torch.optim.LBFGS(
        [z],
        lr=1.0,
        max_iter=cfg.inner_iterations,
        history_size=20,
        line_search_fn="strong_wolfe",
        tolerance_grad=cfg.gtol,
        tolerance_change=1e-14,
    )

    def closure():
        opt.zero_grad()
        c = cost(z)
        c.backward()
        return c

    converged, prev, iters = False, None, 0
    while iters < cfg.max_iterations:
        opt.step(closure)
        iters = int(opt.state[z].get("n_iter", iters + cfg.inner_iterations))
        with torch.no_grad():
            cur = float(cost(z))
        if z.grad is not None and float(z.grad.abs().max()) <= cfg.gtol:
            converged = True
            break
        if prev is not None and prev - cur <= cfg.ftol * max(1.0, abs(cur)):
            converged = True
            break
        prev = cur
    with torch.no_grad():
        final = float(cost(z))
    return z.detach(), converged, iters, final


def _levenberg_marquardt(
    cost: _Cost, init: torch.Tensor, cfg: IngraspConfig
) -> tuple[torch.Tensor, bool, int, float]:
    """Minimise the sum of squared residuals from ``init`` with Levenberg-Marquardt.

    The cost is a least-squares problem (:meth:`_Cost.residuals`); its
    Jacobian comes from forward-mode autodiff (``torch.func.jacfwd``) through
    the fingertip FK. Gauss-Newton steps are insensitive to how stiff the
    weights make the problem (rigidity summed over every waypoint against one
    goal term), where a gradient method needs thousands of iterations.
    Converged: a step lowered the cost by less than ``ftol`` (relative), or the
    gradient is below ``gtol``; not converged: ``max_iterations`` spent or the
    damping ran away.
    """
    z = init.clone()
    n = z.numel()

    def res(y: torch.Tensor) -> torch.Tensor:
        return cost.residuals(y.reshape(z.shape))

    r = res(z.reshape(-1))
    f = float(r @ r)
    lam, converged, it = 1.0e-3, False, 0
    eye = torch.eye(n, dtype=DTYPE)
    while it < cfg.max_iterations:
        it += 1
        jac = torch.func.jacfwd(res)(z.reshape(-1))  # (m, n)
        g = jac.T @ r
        if float(g.abs().max()) <= cfg.gtol:
            converged = True
            break
        h = jac.T @ jac
        d = torch.diagonal(h).clamp_min(1.0e-12)
        accepted = False
        while lam < 1.0e12:
            step = torch.linalg.solve(h + lam * torch.diag(d) + 1.0e-12 * eye, -g)
            z_new = z + step.reshape(z.shape)
            r_new = res(z_new.reshape(-1))
            f_new = float(r_new @ r_new)
            if f_new < f:
                accepted = True
                break
            lam *= 4.0
        if not accepted:  # no descent left at any damping: a (numerical) minimum
            converged = True
            break
        decrease = f - f_new
        z, r, f = z_new, r_new, f_new
        lam = max(lam / 3.0, 1.0e-9)
        if decrease <= cfg.ftol * max(1.0, f):
            converged = True
            break
    return z.detach(), converged, it, f


def _jacobian(fun, x: torch.Tensor) -> torch.Tensor:
    """Exact Jacobian of ``fun`` at ``x`` by forward-mode autodiff through the fingertip FK."""
    return torch.func.jacfwd(fun)(x)


def _least_squares(
    fun, x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, cfg: IngraspConfig, at=None
) -> tuple[np.ndarray, bool, int, float]:
    """Bounded nonlinear least squares (``scipy.optimize.least_squares``, trust-region reflective).

    ``fun`` maps a flat torch vector to the residual vector; the Jacobian is
    exact (:func:`_jacobian`). Variables are scaled by the Jacobian's column
    norms (``x_scale="jac"``), so metres and radians need no hand scaling;
    ``lower``/``upper`` are hard bounds the iterates never leave. ``at`` (optional): maps a
    plain point to the residual function to use there (an active set chosen at that point).
    Converged: scipy stopped on ``ftol``/``xtol``/``gtol``, not ``max_iterations``.
    """
    from scipy.optimize import least_squares

    def at_x(x: torch.Tensor):
        return fun if at is None else at(x)

    def f(x: np.ndarray) -> np.ndarray:
        xt = torch.as_tensor(x, dtype=DTYPE)
        with torch.no_grad():
            return at_x(xt)(xt).numpy()

    def j(x: np.ndarray) -> np.ndarray:
        xt = torch.as_tensor(x, dtype=DTYPE)
        return _jacobian(at_x(xt), xt).detach().numpy()

    x0 = np.clip(x0, lower, upper)
    out = least_squares(
        f,
        x0,
        jac=j,
        bounds=(lower, upper),
        method="trf",
        x_scale="jac",
        ftol=cfg.ftol,
        xtol=cfg.xtol,
        gtol=cfg.gtol,
        max_nfev=cfg.max_iterations,
        # the dense sub-solver takes an SVD of the Jacobian every iteration, which multi-threaded
        # OpenBLAS on a loaded machine made cost ~1 s (measured); lsmr only multiplies by it
        tr_solver="lsmr",
    )
    return out.x, bool(out.status > 0), int(out.nfev), float(2.0 * out.cost)


def warm_start(hand: HandKinematics, cost: _Cost, cfg: IngraspConfig) -> torch.Tensor:
    """IK-interpolated initial trajectory (T, 4 k).

    The last waypoint is :func:`rigid_goal_joints`; the waypoints between
    interpolate the joints linearly from ``q0`` and are then clamped onto the
    per-step bound. When the goal is reachable by rigid motion this starts
    every variant near a trajectory that keeps the grasp, instead of at ``q0``
    repeated, from which only the last waypoint feels the goal. With a
    collision scene the path stops where the hand would first meet the object
    (:func:`_free_fraction`).
    """
    q0n = cost.q0.numpy()
    q_goal = rigid_goal_joints(hand, cost, cfg)
    if cost.scene is not None:
        q_goal = q0n + _free_fraction(cost, q0n, q_goal, cfg) * (q_goal - q0n)
    s = np.arange(1, cfg.waypoints + 1)[:, None] / cfg.waypoints
    path = q0n[None] + s * (q_goal - q0n)[None]
    lo, hi = cost.lo.numpy(), cost.hi.numpy()
    return torch.as_tensor(project_trajectory(path, q0n, lo, hi, cfg.max_step), dtype=DTYPE)


def rigid_goal_joints(hand: HandKinematics, cost: _Cost, cfg: IngraspConfig) -> np.ndarray:
    """Inverse kinematics of the fingertip *positions* the initial grasp would have if carried
    rigidly to the goal (bounded least squares within the joint limits, a tiny pull to ``q0``
    choosing among the redundant solutions) -> (4 k,)."""
    targets = (cost.goal[None] @ cost.tip_in_obj)[:, :3, 3]  # (k, 3)
    q0 = cost.q0
    reg = cfg.w_smooth**0.5 / cfg.w_goal_pos**0.5  # smoothness against goal, in metres

    def res(q: torch.Tensor) -> torch.Tensor:
        tips = hand.tip_poses(q[None], cost.p.fingers)[0, :, :3, 3]
        return torch.cat([(tips - targets).reshape(-1), reg * (q - q0)])

    q_goal, _, _, _ = _least_squares(res, q0.numpy(), cost.lo.numpy(), cost.hi.numpy(), cfg)
    return q_goal


def _free_fraction(cost: _Cost, q0: np.ndarray, q_goal: np.ndarray, cfg: IngraspConfig) -> float:
    """How far (0..1) along the straight joint path ``q0`` -> ``q_goal`` the hand stays off the
    object (no shape nearer than allowed by more than a tenth of the margin), checked at 40 steps.

    The warm start stops there: a trajectory started inside the object is pushed out of a link
    through its nearest face, which can be the far one, and the solver settles with the object
    deep in the hand (measured on apple-06: 10.8 mm, from a warm start 10.7 mm deep).
    """
    s = np.linspace(0.0, 1.0, 41)[1:]
    path = q0[None] + s[:, None] * (q_goal - q0)[None]
    obj = None  # relaxed variants: the object where the fingertips carry it
    if cost.variant not in RELAXED:  # object-path variants: along their own path, by fraction
        obj = torch.as_tensor(interpolate_poses(cost.p.object_initial, cost.p.goal, s), dtype=DTYPE)
    short = cost.collision_shortfalls(path, obj).amax(-1)
    bad = np.flatnonzero(short.numpy() > 0.1 * cfg.collision_margin)
    return 1.0 if bad.size == 0 else float(s[bad[0]] - s[0])


def _trust_region(
    cost: _Cost, init: torch.Tensor, cfg: IngraspConfig
) -> tuple[torch.Tensor, bool, int, float]:
    """Minimise the sum of squared residuals with joint limits as bounds (:func:`_least_squares`)."""
    lo = cost.lo[None].expand_as(init).reshape(-1).numpy()
    hi = cost.hi[None].expand_as(init).reshape(-1).numpy()
    shape = init.shape

    def at(y: torch.Tensor):
        fun = cost.residuals_at(y.reshape(shape))
        return lambda z: fun(z.reshape(shape))

    x, converged, n, f = _least_squares(
        lambda y: cost.residuals(y.reshape(shape)), init.reshape(-1).numpy(), lo, hi, cfg, at
    )
    return torch.as_tensor(x, dtype=DTYPE).reshape(init.shape), converged, n, f


def plan(
    hand: HandKinematics,
    problem: InGraspProblem,
    variant: str = "relaxed-rigidity",
    config: IngraspConfig = IngraspConfig(),  # noqa: B008 - frozen dataclass, immutable
    scene: CollisionScene | None = None,
) -> PlanResult:
    """Optimise a joint trajectory for ``problem`` with ``variant``; deterministic for a given ``config.seed``.

    ``scene``: the object's surface where the set-up puts it (:func:`.collision.collision_scene`);
    with it (and ``config.w_collision > 0``) the hand's other parts are kept off the object.
    Without it the plan is purely kinematic, as offline planning from the dataset alone must be.
    """
    if variant not in VARIANTS:
        raise ValueError(f"unknown variant {variant!r}; one of {', '.join(VARIANTS)}")
    threads = torch.get_num_threads()
    # the tensors are tiny: intra-op threads only add synchronisation, which on a loaded machine
    # made plans 3-6x slower (2 threads vs 1, same result; docs/ingrasp.md "Solver")
    torch.set_num_threads(1)
    try:
        return _plan(hand, problem, variant, config, scene)
    finally:
        torch.set_num_threads(threads)


def _plan(
    hand: HandKinematics,
    problem: InGraspProblem,
    variant: str,
    config: IngraspConfig,
    scene: CollisionScene | None,
) -> PlanResult:
    cfg = config
    start = time.perf_counter()
    cost_fn = _Cost(hand, problem, variant, cfg, scene)
    gen = torch.Generator().manual_seed(cfg.seed)
    if cfg.init == "ik":
        init = warm_start(hand, cost_fn, cfg)
    else:
        init = cost_fn.q0[None].repeat(cfg.waypoints, 1)
    init = init + cfg.init_noise * torch.randn(init.shape, generator=gen, dtype=DTYPE)
    solve = {"trf": _trust_region, "lm": _levenberg_marquardt, "lbfgs": _lbfgs}[cfg.solver]
    z, converged, iters, final_cost = solve(cost_fn, init, cfg)
    q_opt = z.detach().numpy()
    lo, hi = hand.limits(problem.fingers)
    q_proj = project_trajectory(
        q_opt, problem.q0, lo + cfg.limit_margin, hi - cfg.limit_margin, cfg.max_step
    )
    q_all = np.vstack([problem.q0[None], q_proj])
    obj = _planned_object(hand, problem, variant, q_all[-1], cfg.object_frame)
    elapsed = time.perf_counter() - start
    q_hand = np.tile(problem.q_rest, (q_all.shape[0], 1))
    for i, f in enumerate(problem.fingers):
        j = FINGERS.index(f)
        q_hand[:, 4 * j : 4 * j + 4] = q_all[:, 4 * i : 4 * i + 4]
    dp = float(np.linalg.norm(obj[:3, 3] - problem.goal[:3, 3]))
    rel = problem.goal[:3, :3].T @ obj[:3, :3]
    dr = float(np.arccos(np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0)))
    return PlanResult(
        variant,
        problem.fingers,
        q_all,
        q_hand,
        obj,
        problem.goal.copy(),
        pose_vector(obj),
        elapsed,
        converged,
        iters,
        final_cost,
        dp,
        dr,
        float(np.abs(q_proj - q_opt).max()),
        cost_fn.collision_shortfall(q_proj),
    )


def _planned_object(
    hand: HandKinematics,
    problem: InGraspProblem,
    variant: str,
    q_last: np.ndarray,
    object_frame: str,
) -> np.ndarray:
    """Object pose the plan implies: reference-finger attachment, or a contact fit for point-contact."""
    if variant == "point-contact":
        x0 = hand.tip_poses_np(problem.q0[None], problem.fingers)[0]
        c_obj = (np.linalg.inv(problem.object_initial)[None] @ x0)[:, :3, 3]
        x = hand.tip_poses_np(q_last[None], problem.fingers)[0]
        return fit_object_pose(c_obj, x[:, :3, 3])
    with torch.no_grad():
        return object_poses(
            hand, problem, torch.as_tensor(q_last[None], dtype=DTYPE), object_frame
        )[0].numpy()
