"""The cube's yaw, modulo its 90° symmetry.

A cube's outer box looks the same after any of its 24 rotations, so a range
sensor (or a camera fitting a box) cannot tell yaw ψ from ψ + 90°. The filter
therefore keeps yaw wrapped to (−45°, 45°], and errors are compared modulo
90°; otherwise an estimate of 44° against a truth of −46° would count as a
90° error although the two boxes coincide to within 2°.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ["QUARTER", "cube_yaw", "cube_tilt", "level_rotation", "wrap_quarter", "yaw_error"]

QUARTER = math.pi / 2.0


def wrap_quarter(angle: float | np.ndarray) -> float | np.ndarray:
    """Wrap an angle (rad) to (−π/4, π/4], the cube's distinct yaws."""
    a = np.asarray(angle, dtype=float)
    w = -(np.mod(-a + QUARTER / 2.0, QUARTER) - QUARTER / 2.0)
    return float(w) if w.ndim == 0 else w


def yaw_error(estimate: float, truth: float) -> float:
    """Signed yaw difference (rad) modulo the cube's 90° symmetry, in (−π/4, π/4]."""
    return float(wrap_quarter(estimate - truth))


def _vertical_axis(m: np.ndarray) -> int:
    return int(np.argmax(np.abs(m[2, :])))


def cube_yaw(rotation: Rotation) -> float:
    """Yaw (rad, wrapped) of a cube of any orientation, up to its symmetry.

    The body axis closest to world vertical is taken as "up"; the heading of
    either remaining axis, wrapped to (−45°, 45°], is the yaw. After a regrasp
    the cube's body frame may have any of 24 orientations; this reads the
    same yaw for all of them, which is what the box geometry (and so every
    sensor) sees.
    """
    m = rotation.as_matrix()
    k = _vertical_axis(m)
    j = (k + 1) % 3
    return float(wrap_quarter(math.atan2(m[1, j], m[0, j])))


def cube_tilt(rotation: Rotation) -> float:
    """Angle (rad) between the cube's most vertical body axis and world z.

    The filter assumes this is zero (a level cube); callers can check it.
    """
    m = rotation.as_matrix()
    return float(math.acos(min(1.0, abs(m[2, _vertical_axis(m)]))))


def level_rotation(yaw: float) -> Rotation:
    """The level cube orientation with the given yaw (a rotation about world z)."""
    return Rotation.from_euler("z", float(yaw))
