"""Kinematics from URDF text: batched FK, Jacobians, IK (NumPy, with pytorch-kinematics for large batches).

Everything is float64 (millimetre tolerances over a metre of arm leave
float32 little headroom) and deterministic: random IK restarts come from a
generator the caller passes (a :class:`~.uniform_stream.UniformStream`, or a
``torch.Generator``) or seeds explicitly, never from global random state.

Frames: a :class:`KinematicChain` works in its ``root_link`` frame. Callers
that need world poses compose with the root link's world pose (from the
backend, or from :class:`KinematicTree`).

Speed: pytorch-kinematics costs ~2 ms per solver iteration for a few
targets (dozens of small torch ops per FK), so a motion's single IK call
from the current configuration used to take ~200-300 ms. Each chain is
therefore also a NumPy model (:class:`_SerialModel`, ~0.1 ms per FK +
Jacobian): small FK/Jacobian batches, the seeded attempt (seed alone, early
stopping) and IK passes of up to 256 rows run the same damped-least-squares
iteration in NumPy (:meth:`KinematicChain._dls`, tested against
``PseudoInverseIK``); large batches (e.g. 1,000 targets x 4 restarts) go to
pytorch-kinematics' batched solver.

Start-up: the NumPy model is read from the URDF as pytorch-kinematics reads
it (:mod:`.urdf_chain`, equal to it bit for bit on the shipped robots) and
the restarts are drawn from torch's generator stream reproduced in NumPy
(:mod:`.uniform_stream`), so torch and pytorch-kinematics are imported only
when a large batch, :class:`KinematicTree` or a ``torch.Generator`` needs
them — never in a Rubik's trial, which saves each run command ~2.5 CPU-s
(issue 12).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .uniform_stream import UniformStream
from .urdf_chain import read_serial_chain

if TYPE_CHECKING:
    import torch

__all__ = [
    "IKConfig",
    "IKResult",
    "KinematicChain",
    "KinematicTree",
    "UniformStream",
    "pose_error",
    "row_norm",
]

_NUMPY_FK_MAX_BATCH = 32  #: above this, pytorch-kinematics' batched FK is as fast as the NumPy loop
#: IK passes with at most this many rows (targets x restarts) run in NumPy (:meth:`KinematicChain._dls`),
#: larger ones through pytorch-kinematics' batched solver
_NUMPY_IK_MAX_ROWS = 256
_NEXT = np.array([1, 2, 0])  #: index i+1 (mod 3) of each vector component i
_AFTER = np.array([2, 0, 1])  #: index i+2 (mod 3)

try:  # the LAPACK gufunc behind np.linalg.solve (see _solve)
    from numpy.linalg import _umath_linalg

    _SOLVE = _umath_linalg.solve
except (ImportError, AttributeError):  # pragma: no cover - another NumPy layout: the public call
    _SOLVE = None


def __getattr__(name: str) -> Any:
    """``DTYPE`` (torch.float64) on first use, so that importing this module does not import torch."""
    if name == "DTYPE":
        import torch

        return torch.float64
    raise AttributeError(name)


def _pk() -> Any:
    """pytorch-kinematics (and torch), imported on first need."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import pytorch_kinematics as pk
    return pk


def restart_stream(generator: Any, seed: int) -> Any:
    """The generator restarts are drawn from: the caller's, else a :class:`UniformStream` at ``seed``.

    Built only where restarts are drawn (a seeded IK call that converges draws none).
    """
    return generator if generator is not None else UniformStream(seed)


def _uniform(generator: Any, n: int, dof: int) -> np.ndarray:
    """``n`` x ``dof`` uniforms from a :class:`UniformStream` or a ``torch.Generator``."""
    if isinstance(generator, UniformStream):
        return generator.rand(n, dof)
    import torch

    return torch.rand(n, dof, generator=generator, dtype=torch.float64).numpy()


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
    """Settings of the damped-least-squares IK (pytorch-kinematics ``PseudoInverseIK``, or its NumPy twin).

    The defaults reach 0.1 mm / 0.06 deg on the shipped arms for >99 % of
    reachable targets; the tolerances are convergence thresholds, the
    returned errors are what was actually reached.
    """

    num_retries: int = (
        4  #: restarts per target in the first pass: the seed (if given) plus random configurations
    )
    retry_num_retries: int = (
        24  #: restarts in a second pass over only the targets the first pass missed
    )
    max_iterations: int = 80  #: DLS iterations per restart in the first pass
    retry_max_iterations: int = 80  #: DLS iterations in the second pass
    pos_tolerance: float = 1e-4  #: m, a restart counts as converged below this ...
    rot_tolerance: float = 1e-3  #: rad, ... and this
    lr: float = 0.8  #: step scale; below 1 damps overshoot near limits
    lm_damping: float = 0.05  #: Levenberg-Marquardt damping (error-proportional)
    #: With a ``seed_q``, first run the seed alone (early stopping, NumPy) and keep its solution where
    #: it converges; only the targets it misses get the random restarts. The seed's own solution is the
    #: one a motion from the seed wants (no elbow or wrist flip), and this makes such a call cost a few ms.
    seed_first: bool = True
    #: clamped DLS iterations that polish a converged solution (as pytorch-kinematics' limit refinement)
    refine_iterations: int = 10


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


def _quat_wxyz(r: np.ndarray) -> np.ndarray:
    """Unit quaternions (w, x, y, z), w >= 0, of rotation matrices (B, 3, 3) (Shepperd's method)."""
    m00, m11, m22 = r[:, 0, 0], r[:, 1, 1], r[:, 2, 2]
    tr = m00 + m11 + m22
    cand = np.stack([tr, m00, m11, m22], axis=1)
    k = np.argmax(cand, axis=1)
    q = np.empty((r.shape[0], 4))
    for case in range(4):
        sel = k == case
        if not sel.any():
            continue
        a = r[sel]
        if case == 0:
            t = np.sqrt(1.0 + tr[sel]) * 2.0
            q[sel] = np.stack(
                [
                    0.25 * t,
                    (a[:, 2, 1] - a[:, 1, 2]) / t,
                    (a[:, 0, 2] - a[:, 2, 0]) / t,
                    (a[:, 1, 0] - a[:, 0, 1]) / t,
                ],
                axis=1,
            )
        elif case == 1:
            t = np.sqrt(1.0 + a[:, 0, 0] - a[:, 1, 1] - a[:, 2, 2]) * 2.0
            q[sel] = np.stack(
                [
                    (a[:, 2, 1] - a[:, 1, 2]) / t,
                    0.25 * t,
                    (a[:, 0, 1] + a[:, 1, 0]) / t,
                    (a[:, 0, 2] + a[:, 2, 0]) / t,
                ],
                axis=1,
            )
        elif case == 2:
            t = np.sqrt(1.0 + a[:, 1, 1] - a[:, 0, 0] - a[:, 2, 2]) * 2.0
            q[sel] = np.stack(
                [
                    (a[:, 0, 2] - a[:, 2, 0]) / t,
                    (a[:, 0, 1] + a[:, 1, 0]) / t,
                    0.25 * t,
                    (a[:, 1, 2] + a[:, 2, 1]) / t,
                ],
                axis=1,
            )
        else:
            t = np.sqrt(1.0 + a[:, 2, 2] - a[:, 0, 0] - a[:, 1, 1]) * 2.0
            q[sel] = np.stack(
                [
                    (a[:, 1, 0] - a[:, 0, 1]) / t,
                    (a[:, 0, 2] + a[:, 2, 0]) / t,
                    (a[:, 1, 2] + a[:, 2, 1]) / t,
                    0.25 * t,
                ],
                axis=1,
            )
    q *= np.where(q[:, :1] < 0, -1.0, 1.0)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.solve(a, b)`` for float64 stacks (B, n, n), (B, n, 1): the same LAPACK ``gesv`` call.

    Why: the public wrapper's checks and error-state switch cost ~4 of its ~6 us, and a Rubik's
    trial solves ~40,000 of these 6 x 6 systems in its IK (issue 12). The error state only turns
    a singular matrix into ``LinAlgError``; the DLS system ``J J^T + (1e-9 + mu) I`` is positive
    definite, so it cannot be singular for finite input (non-finite input gives NaN either way).
    """
    if _SOLVE is None:  # pragma: no cover
        return np.linalg.solve(a, b)
    return _SOLVE(a, b, signature="dd->d")


def row_norm(a: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(a, axis=1)`` for a real (B, n) array: the same reduction, bit for bit, without
    its dispatch (for the small arrays of per-step and per-iteration checks)."""
    return np.sqrt(np.add.reduce(a * a, axis=1))


def _rotvec_between(target: np.ndarray, current: np.ndarray) -> np.ndarray:
    """Rotation vectors (B, 3), base frame, of ``target @ current.T``: the shortest rotation current -> target.

    ``angle = atan2(|v|, (tr - 1) / 2)`` with ``v`` the axial vector of the
    antisymmetric part is accurate from 0 to near pi; within 1e-3 rad of pi
    the axis comes from the quaternion instead.
    """
    r = target @ current.transpose(0, 2, 1)
    # (r21 - r12, r02 - r20, r10 - r01): component i = r[i+2, i+1] - r[i+1, i+2]
    v = 0.5 * (r[:, _AFTER, _NEXT] - r[:, _NEXT, _AFTER])
    n = row_norm(v)
    angle = np.arctan2(n, 0.5 * (r.trace(axis1=1, axis2=2) - 1.0))  # the trace: r00 + r11, + r22
    out = v * (angle / np.maximum(n, 1e-300))[:, None]  # n = 0 only at angle 0 (angle pi: below)
    flip = angle > np.pi - 1e-3
    if flip.any():
        qf = _quat_wxyz(r[flip])
        nf = np.linalg.norm(qf[:, 1:], axis=1)
        out[flip] = qf[:, 1:] * (2.0 * np.arctan2(nf, qf[:, 0]) / nf)[:, None]
    return out


class _SerialModel:
    """NumPy FK and geometric Jacobian of a serial chain (small batches, NumPy IK).

    Built from the chain's static frame offsets, joint axes and types, read
    from the URDF as pytorch-kinematics reads them (:meth:`from_urdf`); or
    taken from a pytorch-kinematics chain's own arrays (:meth:`from_pk`,
    which the tests compare it with, bit for bit). Consecutive fixed frames are
    pre-multiplied, so one FK is ``dof + 1`` batched 4x4 products.
    """

    def __init__(
        self,
        static: Sequence[np.ndarray],
        kinds: Sequence[int],
        joint_index: Sequence[int],
        axes: Sequence[np.ndarray],
    ) -> None:
        """Frames root -> tip: ``static[f]`` their fixed offsets, ``kinds[f]`` 0 fixed / 1 revolute /
        2 prismatic, ``joint_index[f]`` the index into q of a movable one, ``axes[k]`` joint k's axis."""
        pre = np.eye(4)
        self.pre: list[np.ndarray] = []  #: fixed transform before movable joint k
        self.joint: list[int] = []  #: index into q of movable joint k
        self.prismatic: list[bool] = []
        self.axis: list[np.ndarray] = []
        for f in range(len(static)):
            pre = pre @ static[f]
            if kinds[f] == 0:
                continue
            self.pre.append(pre)
            self.joint.append(int(joint_index[f]))
            self.prismatic.append(bool(kinds[f] == 2))
            ax = np.asarray(axes[int(joint_index[f])])
            self.axis.append(ax / np.linalg.norm(ax))
            pre = np.eye(4)
        self.post = pre  #: fixed transform after the last movable joint (to the tip)
        if not self.pre:
            raise ValueError("no movable joint")
        self._pre = np.stack(self.pre)  # (K, 4, 4)
        self._axes = np.stack(self.axis)  # (K, 3)
        self._pris = np.array(self.prismatic, dtype=float)  # (K,)
        rev = (1.0 - self._pris)[:, None, None]
        self._eye3 = np.eye(3)
        self._skew = rev * np.stack(
            [np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]]) for x, y, z in self.axis]
        )
        self._skew2 = self._skew @ self._skew
        self._pris_mask = np.array(self.prismatic, dtype=bool)[None, :, None]  # (1, K, 1)
        self._any_prismatic = bool(self._pris_mask.any())
        self._joint_idx = np.array(self.joint, dtype=np.intp)
        self._identity_order = self.joint == list(range(len(self.joint)))
        self._jt: dict[int, np.ndarray] = {}  #: per batch size, the joint-transform buffer

    @classmethod
    def from_urdf(cls, spec) -> _SerialModel:
        """From a :class:`~.urdf_chain.SerialChainSpec`: the root frame (identity), then a frame per joint."""
        static = [np.eye(4)] + [j.offset for j in spec.joints]
        kinds = [0] + [j.kind for j in spec.joints]
        index, k = [0], 0
        for j in spec.joints:
            index.append(k if j.kind else 0)
            k += bool(j.kind)
        return cls(static, kinds, index, [j.axis for j in spec.movable])

    @classmethod
    def from_pk(cls, chain) -> _SerialModel:
        """From a pytorch-kinematics serial chain's own arrays."""
        static = chain._static_offsets.detach().cpu().numpy()
        jtype = chain.joint_type_indices.detach().cpu().numpy()
        jidx = chain.joint_indices.detach().cpu().numpy()
        parent = chain._direct_parent_idx.detach().cpu().numpy()
        axes = chain.axes.detach().cpu().numpy()
        order = [int(f) for level in chain._bfs_levels for f in level.reshape(-1).tolist()]
        for a, b in zip(order, order[1:]):
            if parent[b] != a:
                raise ValueError("not a serial chain")
        if int(chain._serial_eef_frame_idx) != order[-1]:
            raise ValueError("end effector is not the last frame")
        return cls(
            [static[f] for f in order],
            [int(jtype[f]) for f in order],
            [int(jidx[f]) for f in order],
            list(axes),
        )

    def fk_jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tip transforms (B, 4, 4) and geometric Jacobians (B, 6, dof), root frame, rows (v, omega).

        Written for few targets (the seeded IK's usual B = 1), where NumPy's
        per-call overhead dominates: every joint's local transform
        ``pre_k @ joint_k(q)`` is built in one vectorised pass (Rodrigues'
        formula; prismatic joints translate along their axis), leaving one
        4x4 product per joint in the loop.
        """
        b = q.shape[0]
        local = self._local(q)  # (B, K, 4, 4)
        frames = np.empty_like(local)
        t = local[:, 0]
        frames[:, 0] = t
        for k in range(1, local.shape[1]):  # each product straight into its frame: the same GEMM
            t = np.matmul(t, local[:, k], out=frames[:, k])
        tip = t @ self.post
        rot = frames[:, :, :3, :3]
        # many restarts: einsum is ~2x faster on a contiguous copy (same bits); few: the copy costs
        if b > 8:
            rot = np.ascontiguousarray(rot)
        z = np.einsum("bkij,kj->bki", rot, self._axes)  # (B, K, 3) world axes
        d = tip[:, None, :3, 3] - frames[:, :, :3, 3]
        # z x d, component i = z[i+1] d[i+2] - z[i+2] d[i+1]: the same products and differences as
        # written out per component, in 5 array operations instead of 16 (np.cross: ~80 us)
        jv = z[..., _NEXT] * d[..., _AFTER] - z[..., _AFTER] * d[..., _NEXT]
        if self._any_prismatic:
            jv = np.where(self._pris_mask, z, jv)
        jw = z if not self._any_prismatic else np.where(self._pris_mask, 0.0, z)
        if self._identity_order:
            return tip, np.concatenate([jv, jw], axis=2).transpose(0, 2, 1)
        jac = np.zeros((b, 6, q.shape[1]))
        jac[:, :3, self._joint_idx] = jv.transpose(0, 2, 1)
        jac[:, 3:, self._joint_idx] = jw.transpose(0, 2, 1)
        return tip, jac

    def _local(self, q: np.ndarray) -> np.ndarray:
        """Every movable joint's transform from the previous one, ``pre_k @ joint_k(q)``, (B, K, 4, 4)."""
        b = q.shape[0]
        x = q if self._identity_order else q[:, self._joint_idx]  # (B, K)
        s = np.sin(x)[:, :, None, None]
        c = 1.0 - np.cos(x)[:, :, None, None]
        jt = self._jt.get(b)
        if jt is None:  # rows 0-2 are rewritten on every call, row 3 stays (0, 0, 0, 1)
            jt = np.zeros((b, len(self.joint), 4, 4))
            jt[:, :, 3, 3] = 1.0
            if b <= _NUMPY_FK_MAX_BATCH:
                self._jt[b] = jt
        np.add(self._eye3 + s * self._skew, c * self._skew2, out=jt[:, :, :3, :3])
        if self._any_prismatic:  # otherwise the translations stay the buffer's zeros
            jt[:, :, :3, 3] = (x * self._pris)[:, :, None] * self._axes
        return self._pre @ jt

    def joint_origins(self, q: np.ndarray) -> np.ndarray:
        """Origins of the movable joints' frames in the root frame, (B, K, 3), in chain order."""
        local = self._local(q)
        out = np.empty((q.shape[0], len(self.joint), 3))
        t = local[:, 0]
        out[:, 0] = t[:, :3, 3]
        for k in range(1, local.shape[1]):
            t = t @ local[:, k]
            out[:, k] = t[:, :3, 3]
        return out


class KinematicChain:
    """A serial chain ``root_link`` -> ``tip_link`` of a URDF (e.g. one arm, one finger)."""

    def __init__(
        self,
        urdf: str | Path,
        root_link: str,
        tip_link: str,
        limits: Mapping[str, tuple[float, float]] | None = None,
    ) -> None:
        """``limits``: joint -> (lower, upper) replacing the URDF's, e.g. a robot's soft limits.

        Every search, sample and clamp of the chain (NumPy and pytorch-kinematics
        solver alike) then stays inside them.
        """
        text = _read(urdf)
        self.root_link = root_link
        self.tip_link = tip_link
        self._text = text
        self._pk_chain: Any = None
        spec = read_serial_chain(text, root_link, tip_link)  # ValueError naming a link off the path
        self.joint_names: list[str] = [j.name for j in spec.movable]
        self.lower = np.array([j.lower for j in spec.movable], dtype=float)
        self.upper = np.array([j.upper for j in spec.movable], dtype=float)
        for name, (lo, hi) in (limits or {}).items():
            k = self.joint_names.index(name)
            if not lo < hi:
                raise ValueError(f"joint {name}: limits {lo}..{hi} are empty")
            self.lower[k], self.upper[k] = lo, hi
        # Continuous joints (e.g. a full pr2_description's forearm/wrist roll) are searched over
        # [-pi, pi]: every angle is reachable there, and IK needs finite bounds to sample and clamp.
        unbounded = ~(np.isfinite(self.lower) & np.isfinite(self.upper)) | (
            self.lower >= self.upper
        )
        if unbounded.any():
            self.lower[unbounded], self.upper[unbounded] = -np.pi, np.pi
        self._np = _SerialModel.from_urdf(spec)

    @property
    def chain(self) -> Any:
        """The pytorch-kinematics serial chain (built on first use: large batches, tests).

        Its limits are this chain's (soft limits, continuous joints in [-pi, pi]).
        """
        if self._pk_chain is None:
            import torch

            pk = _pk()
            c = _quiet_build(
                pk.build_serial_chain_from_urdf, self._text.encode(), self.tip_link, self.root_link
            ).to(dtype=torch.float64)
            c.low = torch.as_tensor(self.lower, dtype=torch.float64)
            c.high = torch.as_tensor(self.upper, dtype=torch.float64)
            self._pk_chain = c
        return self._pk_chain

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    def _q(self, q: np.ndarray | Sequence[float] | torch.Tensor) -> torch.Tensor:
        import torch

        t = torch.as_tensor(np.asarray(q, dtype=float), dtype=torch.float64)
        return t.reshape(-1, self.dof)

    def fk(self, q) -> np.ndarray:
        """Tip transforms in the root frame, (B, 4, 4), for joint vectors (B, dof) or (dof,).

        Small batches go through the NumPy model (~0.1 ms instead of ~1.5 ms
        for one configuration; identical to pytorch-kinematics within 1e-12),
        large ones through pytorch-kinematics.
        """
        qa = np.asarray(q, dtype=float).reshape(-1, self.dof)
        if qa.shape[0] <= _NUMPY_FK_MAX_BATCH:
            return self._np.fk_jacobian(qa)[0]
        return self._fk_pk(qa)

    def joint_origins(self, q) -> np.ndarray:
        """Origins of the movable joints (B, K, 3) in the root frame."""
        return self._np.joint_origins(np.asarray(q, dtype=float).reshape(-1, self.dof))

    def _fk_pk(self, q) -> np.ndarray:
        m = self.chain.forward_kinematics(self._q(q)).get_matrix()
        return m.detach().numpy()

    def jacobian(self, q) -> np.ndarray:
        """Geometric Jacobians (B, 6, dof) of the tip origin, rows (v, omega) in the root frame.

        Small batches use the NumPy model, as :meth:`fk` does.
        """
        qa = np.asarray(q, dtype=float).reshape(-1, self.dof)
        if qa.shape[0] <= _NUMPY_FK_MAX_BATCH:
            return self._np.fk_jacobian(qa)[1]
        return self.chain.jacobian(self._q(qa)).detach().numpy()

    def sample(
        self, n: int, generator: UniformStream | torch.Generator, margin: float = 0.0
    ) -> np.ndarray:
        """``n`` joint vectors uniform within limits shrunk by ``margin`` on each side."""
        lo = self.lower + margin
        hi = self.upper - margin
        return lo + _uniform(generator, n, self.dof) * (hi - lo)

    def ik(
        self,
        targets: np.ndarray,
        *,
        seed_q: np.ndarray | Sequence[float] | None = None,
        generator: UniformStream | torch.Generator | None = None,
        seed: int = 0,
        config: IKConfig = IKConfig(),
    ) -> IKResult:
        """Joint positions within limits that put the tip at ``targets`` ((B, 4, 4), root frame).

        ``seed_q`` ((dof,) or (B, dof)) is tried first: with
        ``config.seed_first`` (the default) a target whose seeded descent
        converges gets that solution, the one continuous with the seed, so
        that a motion from the current configuration does not flip elbow or
        wrist (and costs a few ms). Targets it misses, and every target when
        no seed is given, get restarts drawn from ``generator`` (or a
        generator seeded with ``seed``); among converged restarts the one
        nearest to the seed wins. Two passes: a few restarts for all targets,
        many for the few that missed — most targets converge from the first
        restarts. Deterministic for a given seed/generator state.
        """
        tgt = np.asarray(targets, dtype=float).reshape(-1, 4, 4)
        ref = (
            None
            if seed_q is None
            else np.broadcast_to(
                np.asarray(seed_q, dtype=float).reshape(-1, self.dof), (tgt.shape[0], self.dof)
            )
        )
        if ref is not None and config.seed_first:
            first = self._ik_seeded(tgt, ref, config)
            miss = np.flatnonzero(~first.success)
            if miss.size == 0:
                return first
            rest = self._ik_restarts(tgt[miss], ref[miss], restart_stream(generator, seed), config)
            better = rest.success | (
                rest.pos_error + 0.1 * rest.rot_error
                < first.pos_error[miss] + 0.1 * first.rot_error[miss]
            )
            rows = miss[better]
            q, ok, dp, dr = (
                first.q.copy(),
                first.success.copy(),
                first.pos_error.copy(),
                first.rot_error.copy(),
            )
            q[rows], ok[rows], dp[rows], dr[rows] = (
                rest.q[better],
                rest.success[better],
                rest.pos_error[better],
                rest.rot_error[better],
            )
            return IKResult(q, ok, dp, dr)
        return self._ik_restarts(tgt, ref, restart_stream(generator, seed), config)

    def _ik_seeded(self, tgt: np.ndarray, ref: np.ndarray, config: IKConfig) -> IKResult:
        """Damped least squares from the seed alone, per target, stopping at convergence (NumPy)."""
        q, _, _, _ = self._dls(
            tgt,
            np.clip(np.asarray(ref, dtype=float), self.lower, self.upper)[:, None, :],
            config,
            config.max_iterations,
            stop_when_any=True,
        )
        q = q[:, 0]
        dp, dr = pose_error(
            self.fk(q) if q.shape[0] <= _NUMPY_FK_MAX_BATCH else self._np.fk_jacobian(q)[0], tgt
        )
        ok = (dp <= max(config.pos_tolerance, 1e-9) * 1.0001) & (
            dr <= config.rot_tolerance * 1.0001
        )
        return IKResult(q=q, success=ok, pos_error=dp, rot_error=dr)

    def _dls(
        self,
        tgt: np.ndarray,
        init: np.ndarray,
        config: IKConfig,
        iterations: int,
        *,
        stop_when_any: bool,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """pytorch-kinematics' ``PseudoInverseIK.solve`` in NumPy, for B targets x R restarts ``init``.

        The same iteration: error ``dx`` = position difference and rotation
        vector; ``dq = J^T (J J^T + (1e-9 + lm_damping |dx|^2) I)^-1 dx``;
        ``q += lr dq`` clamped to the limits; a restart's solution is the
        first iterate within the tolerances (sticky convergence), else its
        last. Restarts stop once converged (their solution no longer
        changes), a target's restarts all stop once any converged when
        ``stop_when_any``. Then, as its joint-limit enforcement does,
        ``refine_iterations`` clamped steps polish every solution and
        convergence is re-evaluated on the result.

        Why NumPy: pytorch-kinematics costs ~2 ms per iteration for a few
        rows (dozens of small torch ops), this ~0.1-0.3 ms. Returns q
        (B, R, dof), position and rotation errors and convergence (B, R).
        """
        model = self._np
        b, r, dof = init.shape
        lo, hi = self.lower, self.upper
        q = init.reshape(b * r, dof).copy()
        tpos = np.repeat(tgt[:, :3, 3], r, axis=0)
        trot = np.repeat(tgt[:, :3, :3], r, axis=0)
        eye6 = np.eye(6)
        pos_tol, rot_tol = config.pos_tolerance, config.rot_tolerance

        def error(qq: np.ndarray, rows: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
            """Pose errors (position, rotation vector) and Jacobians of ``qq``, rows ``rows`` (None: all)."""
            tip, jac = model.fk_jacobian(qq)
            tp, tr = (tpos, trot) if rows is None else (tpos[rows], trot[rows])
            dx = np.concatenate([tp - tip[:, :3, 3], _rotvec_between(tr, tip[:, :3, :3])], axis=1)
            return dx, jac

        def step(qq: np.ndarray, dx: np.ndarray, jac: np.ndarray) -> np.ndarray:
            mu = config.lm_damping * np.add.reduce(dx * dx, axis=1)
            jt = jac.transpose(0, 2, 1)
            a = jac @ jt + (1e-9 + mu)[:, None, None] * eye6
            dq = (jt @ _solve(a, dx[:, :, None]))[:, :, 0]
            # np.clip's value, without its dispatch (clip is max, then min; NaN propagates in both)
            return np.minimum(np.maximum(qq + config.lr * dq, lo), hi)

        full = b * r
        active = np.ones(full, dtype=bool)
        sol = q.copy()
        idx = np.arange(full)  # the active rows
        for it in range(iterations + 1):  # the last pass only tests the last step
            qa = q[idx]
            dx, jac = error(qa, None if idx.size == full else idx)
            conv = (row_norm(dx[:, :3]) < pos_tol) & (row_norm(dx[:, 3:]) < rot_tol)
            if not conv.any():  # the usual pass: every active row steps on (no index bookkeeping)
                if it == iterations:
                    sol[idx] = qa
                    break
                q[idx] = step(qa, dx, jac)
                continue
            sol[idx] = qa  # converged rows keep this; the others are overwritten while they run
            active[idx[conv]] = False
            if stop_when_any:
                done = np.zeros(b, dtype=bool)
                done[idx[conv] // r] = True
                active &= ~np.repeat(done, r)
            keep = active[idx]
            if not keep.any() or it == iterations:
                break
            q[idx[keep]] = step(qa[keep], dx[keep], jac[keep])
            idx = np.flatnonzero(active)
        q = sol
        for _ in range(config.refine_iterations):
            dx, jac = error(q, None)
            q = step(q, dx, jac)
        dx, _ = error(q, None)
        ep, er = row_norm(dx[:, :3]), row_norm(dx[:, 3:])
        conv = (ep < pos_tol) & (er < rot_tol)
        return q.reshape(b, r, dof), ep.reshape(b, r), er.reshape(b, r), conv.reshape(b, r)

    def _ik_restarts(
        self,
        tgt: np.ndarray,
        ref: np.ndarray | None,
        gen: UniformStream | torch.Generator,
        config: IKConfig,
    ) -> IKResult:
        """The batched pytorch-kinematics solver: seed (if any) + random restarts, two passes."""
        res = self._ik_pass(tgt, ref, gen, config, config.num_retries, config.max_iterations)
        miss = np.flatnonzero(~res.success)
        if miss.size and config.retry_num_retries > 0:
            again = self._ik_pass(
                tgt[miss],
                None if ref is None else ref[miss],
                gen,
                config,
                config.retry_num_retries,
                config.retry_max_iterations,
            )
            better = (
                again.pos_error + 0.1 * again.rot_error
                < res.pos_error[miss] + 0.1 * res.rot_error[miss]
            )
            better |= again.success
            rows = miss[better]
            q, ok, dp, dr = (
                res.q.copy(),
                res.success.copy(),
                res.pos_error.copy(),
                res.rot_error.copy(),
            )
            q[rows], ok[rows], dp[rows], dr[rows] = (
                again.q[better],
                again.success[better],
                again.pos_error[better],
                again.rot_error[better],
            )
            res = IKResult(q, ok, dp, dr)
        return res

    def _ik_pass(
        self,
        targets: np.ndarray,
        seed_q: np.ndarray | None,
        gen: UniformStream | torch.Generator,
        config: IKConfig,
        r: int,
        iterations: int,
    ) -> IKResult:
        b = targets.shape[0]
        init = self.sample(b * r, gen).reshape(b, r, self.dof)
        ref = None
        if seed_q is not None:
            ref = np.broadcast_to(
                np.array(seed_q, dtype=float).reshape(-1, self.dof), (b, self.dof)
            )
            init[:, 0, :] = np.clip(ref, self.lower, self.upper)
        if b * r <= _NUMPY_IK_MAX_ROWS:
            q, ep, er, conv = self._dls(
                targets, init, config, iterations, stop_when_any=ref is None
            )
            err = ep + 0.1 * er
        else:
            q, err, conv = self._pk_solve(targets, init, config, iterations, ref is None)
        score = np.where(conv, 0.0, err + 1.0)
        if ref is not None:
            dist = np.sqrt(np.sum((q - ref[:, None, :]) ** 2, axis=-1))
            score = score + np.where(conv, dist * 1e-3, 0.0)
        best = score.argmin(axis=1)
        qb = np.clip(q[np.arange(b), best], self.lower, self.upper)
        reached = self.fk(qb)
        dp, dr = pose_error(reached, targets)
        ok = (dp <= max(config.pos_tolerance, 1e-9) * 1.0001) & (
            dr <= config.rot_tolerance * 1.0001
        )
        return IKResult(q=qb, success=ok, pos_error=dp, rot_error=dr)

    def _pk_solve(
        self,
        targets: np.ndarray,
        init: np.ndarray,
        config: IKConfig,
        iterations: int,
        any_converged: bool,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """pytorch-kinematics' batched ``PseudoInverseIK`` (large batches): q (B, R, dof), error, converged."""
        import torch

        pk = _pk()
        tinit = torch.as_tensor(init, dtype=torch.float64)
        solver = pk.PseudoInverseIK(
            self.chain,
            retry_configs=tinit[0],
            max_iterations=iterations,
            pos_tolerance=config.pos_tolerance,
            rot_tolerance=config.rot_tolerance,
            lr=config.lr,
            lm_damping=config.lm_damping,
            early_stopping_any_converged=any_converged,
            early_stopping_no_improvement=None,
            clamp_to_limits=True,
            enforce_joint_limits=True,
        )
        # The constructor takes one (R, dof) block shared by all targets; a (B, R, dof) block set
        # afterwards gives every target its own restarts (solve() reshapes it to (B*R, dof)).
        solver.initial_config = tinit
        tgt = torch.as_tensor(targets, dtype=torch.float64)
        sol = solver.solve(pk.Transform3d(matrix=tgt, dtype=torch.float64))
        err = sol.err_pos + sol.err_rot * 0.1
        return sol.solutions.numpy(), err.numpy(), sol.converged.numpy()


class KinematicTree:
    """FK of every link of a URDF at once (the whole robot), for checks and rendering.

    Joint values not given are zero; poses are in the URDF root link's frame.
    """

    def __init__(self, urdf: str | Path) -> None:
        import torch

        text = _read(urdf)
        self.chain = _quiet_build(_pk().build_chain_from_urdf, text.encode()).to(
            dtype=torch.float64
        )
        self.joint_names: list[str] = list(self.chain.get_joint_parameter_names(exclude_fixed=True))

    def fk(self, q: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        import torch

        vec = torch.zeros(1, len(self.joint_names), dtype=torch.float64)
        for name, v in (q or {}).items():
            vec[0, self.joint_names.index(name)] = float(v)
        out = self.chain.forward_kinematics(vec)
        return {k: v.get_matrix()[0].detach().numpy() for k, v in out.items()}
