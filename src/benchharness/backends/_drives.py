"""Argument handling shared by the backends' joint drives.

Both engines must read ``set_joint_targets`` arguments identically (per-joint
broadcasting, URDF effort limits as the default cap, a pure velocity drive
when only velocities are given), so that logic lives here once and each
backend only applies the result in its own engine.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .interface import BackendError, JointInfo

#: stand-in for an unlimited force cap (engines want finite numbers)
UNLIMITED_FORCE = 1.0e9


def as_array(v: float | Sequence[float], n: int, what: str) -> np.ndarray:
    """A scalar broadcast to ``n`` values, or exactly ``n`` values (else a named error)."""
    a = np.asarray(v, dtype=float)
    if a.ndim == 0:
        return np.full(n, float(a))
    a = a.reshape(-1)
    if a.shape[0] != n:
        raise BackendError(f"{what}: expected {n} values, got {a.shape[0]}")
    return a


@dataclass(frozen=True)
class DriveCommand:
    """Per-joint PD drive settings for the selected joints."""

    q: np.ndarray  #: position targets
    v: np.ndarray  #: velocity targets
    k: np.ndarray  #: stiffness (0 for a pure velocity drive)
    d: np.ndarray  #: damping
    f: np.ndarray  #: force/torque caps (finite)


def drive_command(
    joints: Sequence[JointInfo],
    sel: np.ndarray,
    positions: Sequence[float] | None,
    velocities: Sequence[float] | None,
    stiffness: float | Sequence[float],
    damping: float | Sequence[float],
    force_limit: float | Sequence[float] | None,
    current_positions: Callable[[], np.ndarray],
) -> DriveCommand:
    """Normalise ``Backend.set_joint_targets`` arguments for the joints ``sel``.

    Without ``positions`` the drive holds the current positions, or, when
    velocities are given, becomes a pure velocity drive (stiffness 0).
    """
    n = len(sel)
    k = as_array(stiffness, n, "stiffness")
    d = as_array(damping, n, "damping")
    if force_limit is None:
        f = np.array([joints[i].max_effort for i in sel], dtype=float)
    else:
        f = as_array(force_limit, n, "force_limit")
    f = np.where(np.isfinite(f), f, UNLIMITED_FORCE)
    if positions is None:
        q = np.asarray(current_positions(), dtype=float)[sel]
        if velocities is not None:
            k = np.zeros(n)
    else:
        q = as_array(positions, n, "positions")
    v = np.zeros(n) if velocities is None else as_array(velocities, n, "velocities")
    return DriveCommand(q, v, k, d, f)


def joint_indices(b, joints: Sequence[str] | None) -> list[int]:
    """Indices into ``b.joints`` of the named movable joints (all when ``joints`` is None).

    ``b`` is a backend's body record with ``name``, ``joints`` (JointInfo list)
    and ``jmap`` (a name -> index cache, built on first use). Both backends
    resolve names this way, so a wrong name gets the same error on each.
    """
    if joints is None:
        return list(range(len(b.joints)))
    if len(b.jmap) != len(b.joints):  # name -> index, built once per body
        b.jmap = {j.name: i for i, j in enumerate(b.joints)}
    try:
        return [b.jmap[n] for n in joints]
    except KeyError as exc:
        names = [j.name for j in b.joints]
        raise BackendError(
            f"body {b.name!r} has no movable joint {exc.args[0]!r}; joints: {names}"
        ) from None
