"""Rotation helpers for costs (torch, differentiable) and results (numpy).

The cost uses ``vee(skew(R))`` = ``sin(angle) * axis`` instead of the exact
log map: it is smooth everywhere (no arccos at the identity, where the
optimiser spends its time) and equals the angle to first order; the
benchmark's task rotations stay below 90 deg, where it is monotonic.
"""

from __future__ import annotations

import numpy as np
import torch
from scipy.spatial.transform import Rotation

__all__ = ["rot_residual", "pose_matrix", "pose_vector", "interpolate_poses", "inverse"]


def rot_residual(ra: torch.Tensor, rb: torch.Tensor) -> torch.Tensor:
    """``sin(angle) * axis`` of ``ra^T rb`` (..., 3): zero iff the rotations agree (for angles < 180 deg)."""
    m = ra.transpose(-1, -2) @ rb
    return 0.5 * torch.stack(
        (m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1]),
        dim=-1,
    )


def inverse(t: torch.Tensor) -> torch.Tensor:
    """Inverse of rigid transforms (..., 4, 4)."""
    r = t[..., :3, :3].transpose(-1, -2)
    top = torch.cat([r, -(r @ t[..., :3, 3:4])], dim=-1)
    return torch.cat(
        [top, t[..., 3:4, :]], dim=-2
    )  # functional (no in-place writes): forward-mode AD


def pose_matrix(pose7) -> np.ndarray:
    """``[x, y, z, qx, qy, qz, qw]`` -> 4x4 (the quaternion is normalised)."""
    p = np.asarray(pose7, float)
    m = np.eye(4)
    m[:3, :3] = Rotation.from_quat(p[3:7] / np.linalg.norm(p[3:7])).as_matrix()
    m[:3, 3] = p[:3]
    return m


def pose_vector(m: np.ndarray) -> np.ndarray:
    """4x4 -> ``[x, y, z, qx, qy, qz, qw]`` with ``qw >= 0``."""
    q = Rotation.from_matrix(np.asarray(m)[:3, :3]).as_quat()
    if q[3] < 0:
        q = -q
    return np.concatenate([np.asarray(m)[:3, 3], q])


def interpolate_poses(a: np.ndarray, b: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Poses from ``a`` to ``b`` (4x4) at fractions ``s`` (n,): linear position, slerp rotation."""
    from scipy.spatial.transform import Slerp

    rots = Rotation.from_matrix(np.stack([a[:3, :3], b[:3, :3]]))
    out = np.tile(np.eye(4), (len(s), 1, 1))
    out[:, :3, :3] = Slerp([0.0, 1.0], rots)(np.clip(s, 0.0, 1.0)).as_matrix()
    out[:, :3, 3] = a[:3, 3] + np.asarray(s)[:, None] * (b[:3, 3] - a[:3, 3])
    return out
