"""Scan paths planned from an estimate: where to hold a sensor to range a cube face.

A robot can only plan a pre-touch scan from what it believes, so paths are
laid out in the *estimated* cube frame. The link's x axis points horizontally
at the face and the path runs along the link's y axis, past both vertical
edges, so a mis-estimated cube still falls inside the sweep.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from ..geometry import Pose

__all__ = ["VERTICAL_FACES", "face_sweep"]

#: Heading (rad, in the cube frame) from which the link looks at each vertical face.
VERTICAL_FACES: dict[str, float] = {"-x": 0.0, "-y": math.pi / 2, "+x": math.pi, "+y": -math.pi / 2}


def face_sweep(
    center: np.ndarray,
    yaw: float,
    face: str,
    *,
    half_edge: float = 0.0285,
    standoff: float = 0.03,
    span: float = 0.08,
    steps: int = 33,
    height: float = 0.0,
) -> list[Pose]:
    """Link poses that sweep across one vertical face of a cube believed at ``center``/``yaw``.

    ``standoff`` (m) is the gap from the believed face to the link origin: 30 mm
    sits mid-way in a VL6180X's 5–100 mm window, so a centimetre of pose error
    either way stays in range. ``span`` (m) is the sweep length, centred on the
    face (80 mm covers the 57 mm face with 11 mm to spare each side);
    ``height`` offsets the path from the cube centre along world z.
    """
    if face not in VERTICAL_FACES:
        raise ValueError(f"face must be one of {sorted(VERTICAL_FACES)}, got {face!r}")
    if steps < 2:
        raise ValueError("a sweep needs at least 2 steps")
    heading = Rotation.from_euler("z", float(yaw) + VERTICAL_FACES[face])
    c = np.asarray(center, dtype=float).reshape(3)
    out = []
    for s in np.linspace(-span / 2.0, span / 2.0, steps):
        p = c + heading.apply([-(half_edge + standoff), s, 0.0]) + [0.0, 0.0, height]
        out.append(Pose.from_rotation(p, heading))
    return out
