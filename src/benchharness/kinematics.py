"""Kinematics from URDF text with pytorch-kinematics: batched FK, Jacobians, IK.

Everything here is CPU torch in float64 (millimetre tolerances over a metre
of arm leave float32 little headroom) and deterministic: random IK restarts
come from a :class:`torch.Generator` the caller passes or seeds explicitly,
never from global random state.

Frames: a :class:`KinematicChain` works in its ``root_link`` frame. Callers
that need world poses compose with the root link's world pose (from the
backend, or from :class:`KinematicTree`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
import torch

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import pytorch_kinematics as pk

__all__ = ["IKConfig", "IKResult", "KinematicChain", "KinematicTree", "pose_error"]

DTYPE = torch.float64


def _read(urdf: str | Path) -> str:
    """URDF text from a path or from the text itself."""
    if isinstance(urdf, Path) or (isinstance(urdf, str) and not urdf.lstrip().startswith("<")):
        return Path(urdf).read_text()
    return urdf


def _quiet_build(fn, *args):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*args)


@dataclass(frozen=True)
class IKConfig:
    """Settings of the damped-least-squares IK (pytorch-kinematics ``PseudoInverseIK``).

    The defaults reach 0.1 mm / 0.06 deg on the shipped arms for >99 % of
    reachable targets; the tolerances are convergence thresholds, the
    returned errors are what was actually reached.
    """

    num_retries: int = 4  #: restarts per target in the first pass: the seed (if given) plus random configurations
    retry_num_retries: int = 24  #: restarts in a second pass over only the targets the first pass missed
    max_iterations: int = 80  #: DLS iterations per restart in the first pass
    retry_max_iterations: int = 80  #: DLS iterations in the second pass
    pos_tolerance: float = 1e-4  #: m, a restart counts as converged below this ...
    rot_tolerance: float = 1e-3  #: rad, ... and this
    lr: float = 0.8  #: step scale; below 1 damps overshoot near limits
    lm_damping: float = 0.05  #: Levenberg-Marquardt damping (error-proportional)


@dataclass(frozen=True)
class IKResult:
    """One solution per target (rows), the best restart of each."""

    q: np.ndarray  #: (B, dof) joint positions, within limits
    success: np.ndarray  #: (B,) converged to the tolerances
    pos_error: np.ndarray  #: (B,) m
    rot_error: np.ndarray  #: (B,) rad


def pose_error(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position (m) and rotation-angle (rad) differences of batches of 4x4 transforms."""
    a = np.asarray(a).reshape(-1, 4, 4)
    b = np.asarray(b).reshape(-1, 4, 4)
    dp = np.linalg.norm(a[:, :3, 3] - b[:, :3, 3], axis=1)
    rel = np.einsum("bji,bjk->bik", a[:, :3, :3], b[:, :3, :3])
    cos = np.clip((np.trace(rel, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    return dp, np.arccos(cos)


class KinematicChain:
    """A serial chain ``root_link`` -> ``tip_link`` of a URDF (e.g. one arm, one finger)."""

    def __init__(self, urdf: str | Path, root_link: str, tip_link: str) -> None:
        text = _read(urdf)
        self.root_link = root_link
        self.tip_link = tip_link
        self.chain = _quiet_build(pk.build_serial_chain_from_urdf, text.encode(), tip_link, root_link).to(dtype=DTYPE)
        self.joint_names: list[str] = list(self.chain.get_joint_parameter_names(exclude_fixed=True))
        low, high = self.chain.get_joint_limits()
        self.lower = np.asarray(low, dtype=float)
        self.upper = np.asarray(high, dtype=float)
        # Continuous joints (e.g. a full pr2_description's forearm/wrist roll) are searched over
        # [-pi, pi]: every angle is reachable there, and IK needs finite bounds to sample and clamp.
        unbounded = ~(np.isfinite(self.lower) & np.isfinite(self.upper)) | (self.lower >= self.upper)
        if unbounded.any():
            self.lower[unbounded], self.upper[unbounded] = -np.pi, np.pi
            self.chain.low = torch.as_tensor(self.lower, dtype=DTYPE)
            self.chain.high = torch.as_tensor(self.upper, dtype=DTYPE)

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    def _q(self, q: np.ndarray | Sequence[float] | torch.Tensor) -> torch.Tensor:
        t = torch.as_tensor(np.asarray(q, dtype=float), dtype=DTYPE)
        return t.reshape(-1, self.dof)

    def fk(self, q) -> np.ndarray:
        """Tip transforms in the root frame, (B, 4, 4), for joint vectors (B, dof) or (dof,)."""
        m = self.chain.forward_kinematics(self._q(q)).get_matrix()
        return m.detach().numpy()

    def jacobian(self, q) -> np.ndarray:
        """Geometric Jacobians (B, 6, dof) of the tip origin, rows (v, omega) in the root frame."""
        return self.chain.jacobian(self._q(q)).detach().numpy()

    def sample(self, n: int, generator: torch.Generator, margin: float = 0.0) -> np.ndarray:
        """``n`` joint vectors uniform within limits shrunk by ``margin`` on each side."""
        lo = torch.as_tensor(self.lower + margin, dtype=DTYPE)
        hi = torch.as_tensor(self.upper - margin, dtype=DTYPE)
        u = torch.rand(n, self.dof, generator=generator, dtype=DTYPE)
        return (lo + u * (hi - lo)).numpy()

    def ik(
        self,
        targets: np.ndarray,
        *,
        seed_q: np.ndarray | Sequence[float] | None = None,
        generator: torch.Generator | None = None,
        seed: int = 0,
        config: IKConfig = IKConfig(),
    ) -> IKResult:
        """Joint positions within limits that put the tip at ``targets`` ((B, 4, 4), root frame).

        ``seed_q`` ((dof,) or (B, dof)) is tried first and, among converged
        restarts, the solution nearest to it is returned, so that a motion
        from the current configuration does not flip elbow or wrist. The
        other restarts are drawn from ``generator`` (or a generator seeded
        with ``seed``). Two passes: a few restarts for all targets, many for
        the few that missed — most targets converge from the first restarts.
        """
        tgt = np.asarray(targets, dtype=float).reshape(-1, 4, 4)
        gen = generator if generator is not None else torch.Generator().manual_seed(seed)
        ref = None if seed_q is None else np.broadcast_to(np.asarray(seed_q, dtype=float).reshape(-1, self.dof), (tgt.shape[0], self.dof))
        res = self._ik_pass(tgt, ref, gen, config, config.num_retries, config.max_iterations)
        miss = np.flatnonzero(~res.success)
        if miss.size and config.retry_num_retries > 0:
            again = self._ik_pass(tgt[miss], None if ref is None else ref[miss], gen, config,
                                  config.retry_num_retries, config.retry_max_iterations)
            better = again.pos_error + 0.1 * again.rot_error < res.pos_error[miss] + 0.1 * res.rot_error[miss]
            better |= again.success
            rows = miss[better]
            q, ok, dp, dr = res.q.copy(), res.success.copy(), res.pos_error.copy(), res.rot_error.copy()
            q[rows], ok[rows], dp[rows], dr[rows] = (again.q[better], again.success[better],
                                                     again.pos_error[better], again.rot_error[better])
            res = IKResult(q, ok, dp, dr)
        return res

    def _ik_pass(
        self,
        targets: np.ndarray,
        seed_q: np.ndarray | None,
        gen: torch.Generator,
        config: IKConfig,
        r: int,
        iterations: int,
    ) -> IKResult:
        tgt = torch.as_tensor(targets, dtype=DTYPE)
        b = tgt.shape[0]
        init = torch.as_tensor(self.sample(b * r, gen), dtype=DTYPE).reshape(b, r, self.dof)
        ref = None
        if seed_q is not None:
            ref = torch.as_tensor(np.array(seed_q, dtype=float), dtype=DTYPE).reshape(-1, self.dof).expand(b, self.dof)
            init[:, 0, :] = torch.clamp(ref, torch.as_tensor(self.lower), torch.as_tensor(self.upper))
        solver = pk.PseudoInverseIK(
            self.chain,
            retry_configs=init[0],
            max_iterations=iterations,
            pos_tolerance=config.pos_tolerance,
            rot_tolerance=config.rot_tolerance,
            lr=config.lr,
            lm_damping=config.lm_damping,
            early_stopping_any_converged=ref is None,
            early_stopping_no_improvement=None,
            clamp_to_limits=True,
            enforce_joint_limits=True,
        )
        # The constructor takes one (R, dof) block shared by all targets; a (B, R, dof) block set
        # afterwards gives every target its own restarts (solve() reshapes it to (B*R, dof)).
        solver.initial_config = init
        sol = solver.solve(pk.Transform3d(matrix=tgt, dtype=DTYPE))
        q = sol.solutions  # (B, R, dof)
        err = sol.err_pos + sol.err_rot * 0.1
        conv = sol.converged
        score = torch.where(conv, torch.zeros_like(err), err + 1.0)
        if ref is not None:
            dist = (q - ref[:, None, :]).norm(dim=-1)
            score = score + torch.where(conv, dist * 1e-3, torch.zeros_like(dist))
        best = score.argmin(dim=1)
        idx = torch.arange(b)
        qb = q[idx, best].clamp(torch.as_tensor(self.lower), torch.as_tensor(self.upper))
        reached = self.fk(qb.numpy())
        dp, dr = pose_error(reached, tgt.numpy())
        ok = (dp <= max(config.pos_tolerance, 1e-9) * 1.0001) & (dr <= config.rot_tolerance * 1.0001)
        return IKResult(q=qb.numpy(), success=ok, pos_error=dp, rot_error=dr)


class KinematicTree:
    """FK of every link of a URDF at once (the whole robot), for checks and rendering.

    Joint values not given are zero; poses are in the URDF root link's frame.
    """

    def __init__(self, urdf: str | Path) -> None:
        text = _read(urdf)
        self.chain = _quiet_build(pk.build_chain_from_urdf, text.encode()).to(dtype=DTYPE)
        self.joint_names: list[str] = list(self.chain.get_joint_parameter_names(exclude_fixed=True))

    def fk(self, q: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        vec = torch.zeros(1, len(self.joint_names), dtype=DTYPE)
        for name, v in (q or {}).items():
            vec[0, self.joint_names.index(name)] = float(v)
        out = self.chain.forward_kinematics(vec)
        return {k: v.get_matrix()[0].detach().numpy() for k, v in out.items()}
