"""Poses and rotations: the one convention used everywhere in benchharness.

Convention (converted only at the backend boundary and at file import):

* positions are metres, as a length-3 float array;
* orientations are unit quaternions in **scalar-last** order ``(x, y, z, w)``,
  the order of :mod:`scipy.spatial.transform` and of PyBullet, so the common
  paths need no conversion; SAPIEN's ``(w, x, y, z)`` is converted inside its
  backend;
* a :class:`Pose` maps points from its child frame into its parent frame:
  ``parent_p = pose.apply(child_p)``;
* Euler angles in the published in-hand data are extrinsic roll-pitch-yaw
  about fixed x, y, z (the ROS/``tf`` RPY convention), converted with
  :func:`pose_from_xyz_rpy`.

Rotation arithmetic is delegated to :class:`scipy.spatial.transform.Rotation`;
nothing here re-implements quaternion algebra.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = [
    "QUAT_NORM_TOL",
    "Pose",
    "pose_from_xyz_rpy",
    "quat_xyzw_to_wxyz",
    "quat_wxyz_to_xyzw",
]


#: Largest accepted ``| ||q|| - 1 |`` of a recorded quaternion scored as given
#: (in-hand result files, the metrics with ``normalize=False``). Rounding each
#: of the four components to three decimals, as the published YuMi data are
#: (norms 0.9995-1.0001), moves the norm by at most ``||dq|| <= 2 * 5e-4 =
#: 1e-3``; the tolerance is twice that.
QUAT_NORM_TOL = 2e-3


def _vec3(v: Iterable[float]) -> np.ndarray:
    a = np.asarray(v, dtype=float).reshape(-1)
    if a.shape != (3,):
        raise ValueError(f"expected a 3-vector, got shape {a.shape}")
    return a


def _unit_quat(q: Iterable[float]) -> np.ndarray:
    a = np.asarray(q, dtype=float).reshape(-1)
    if a.shape != (4,):
        raise ValueError(f"expected a quaternion (x, y, z, w), got shape {a.shape}")
    n = np.linalg.norm(a)
    if not np.isfinite(n) or n < 1e-12:
        raise ValueError(f"quaternion {a.tolist()} has no direction")
    return a / n


@dataclass(frozen=True)
class Pose:
    """A rigid transform: position ``p`` (m) and unit quaternion ``q`` (x, y, z, w)."""

    p: np.ndarray = field(default_factory=lambda: np.zeros(3))
    q: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))

    def __post_init__(self) -> None:
        object.__setattr__(self, "p", _vec3(self.p))
        object.__setattr__(self, "q", _unit_quat(self.q))

    @classmethod
    def identity(cls) -> Pose:
        return cls()

    @classmethod
    def from_rotation(cls, p: Iterable[float], rot: Rotation) -> Pose:
        return cls(np.asarray(p, dtype=float), rot.as_quat())

    @classmethod
    def from_matrix(cls, m: np.ndarray) -> Pose:
        m = np.asarray(m, dtype=float)
        if m.shape != (4, 4):
            raise ValueError(f"expected a 4x4 homogeneous matrix, got {m.shape}")
        return cls(m[:3, 3], Rotation.from_matrix(m[:3, :3]).as_quat())

    @functools.cached_property
    def rotation(self) -> Rotation:
        """The orientation as a scipy ``Rotation``, built once per pose: composing, inverting and
        applying a pose all need it, and building it from ``q`` was 47,000 calls (~10 % of a Rubik's
        trial's CPU outside the engine, SAPIEN Rubiks-1-5, cProfile). The same ``Rotation`` either way,
        so results are unchanged bit for bit; a pose is frozen, so the cache cannot go stale."""
        return Rotation.from_quat(self.q)

    def as_matrix(self) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = self.rotation.as_matrix()
        m[:3, 3] = self.p
        return m

    def __mul__(self, other: Pose) -> Pose:
        """Compose: ``(a * b).apply(x) == a.apply(b.apply(x))``."""
        r = self.rotation * other.rotation
        return Pose(self.p + self.rotation.apply(other.p), r.as_quat())

    def inv(self) -> Pose:
        r_inv = self.rotation.inv()
        return Pose(-r_inv.apply(self.p), r_inv.as_quat())

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Map points (shape (3,) or (n, 3)) from the child into the parent frame."""
        return self.rotation.apply(np.asarray(points, dtype=float)) + self.p

    def as_xyz_rpy(self) -> np.ndarray:
        return np.concatenate([self.p, self.rotation.as_euler("xyz")])

    def as_array(self) -> np.ndarray:
        """``[x, y, z, qx, qy, qz, qw]``, the layout used in result files."""
        return np.concatenate([self.p, self.q])

    @classmethod
    def from_array(cls, a: Iterable[float]) -> Pose:
        a = np.asarray(a, dtype=float).reshape(-1)
        if a.shape != (7,):
            raise ValueError(f"expected [x, y, z, qx, qy, qz, qw], got {a.shape[0]} numbers")
        return cls(a[:3], a[3:])

    def allclose(self, other: Pose, atol_p: float = 1e-9, atol_q: float = 1e-9) -> bool:
        """Equal as transforms: q and -q are the same rotation."""
        dq = min(np.linalg.norm(self.q - other.q), np.linalg.norm(self.q + other.q))
        return bool(np.linalg.norm(self.p - other.p) <= atol_p and dq <= atol_q)


def pose_from_xyz_rpy(values: Iterable[float]) -> Pose:
    """Pose from ``x, y, z, roll, pitch, yaw`` (metres, radians, extrinsic xyz).

    This is how the in-hand benchmark's spreadsheets store palm poses.
    """
    v = np.asarray(values, dtype=float).reshape(-1)
    if v.shape != (6,):
        raise ValueError(f"expected x,y,z,roll,pitch,yaw: got {v.shape[0]} numbers")
    return Pose(v[:3], Rotation.from_euler("xyz", v[3:]).as_quat())


def quat_xyzw_to_wxyz(q: Iterable[float]) -> np.ndarray:
    a = np.asarray(q, dtype=float)
    return a[..., [3, 0, 1, 2]]


def quat_wxyz_to_xyzw(q: Iterable[float]) -> np.ndarray:
    a = np.asarray(q, dtype=float)
    return a[..., [1, 2, 3, 0]]
