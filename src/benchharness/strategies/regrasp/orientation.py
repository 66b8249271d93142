"""The cube's orientation in the workspace: which logical face points where.

Frames:

* **cube body frame** — the physical cube's (:mod:`benchharness.cube_physics.model`):
  U along +z, R along +x, F along -y. Because the middle slab carries the
  body frame through every twist, a face's body axis never changes, so the
  planner can speak of "the face whose centre is U" at all times;
* **workspace frame** — the robot's base frame: x forward (away from the
  robot), y to the robot's left, z up.

An :class:`Orientation` is the rotation *workspace ← body*, one of the 24
proper rotations that map the cube's axes onto the workspace axes, stored as
an integer matrix so that equality and hashing are exact (no float drift over
hundreds of regrasps).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, lru_cache

import numpy as np

from ...cube.facelets import FACE_NORMALS

#: The physical cube's body frame (``cube_physics.model.BODY_FROM_CORE``: U = +z, R = +x, F = -y), restated
#: here because importing ``cube_physics`` pulls in its mechanism and SciPy, and the built-in strategies
#: plugin imports this package just to list strategies. A test pins the two to each other.
BODY_FROM_CORE = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=np.int64)
#: Outward normal of each face in the body frame.
FACE_BODY_AXES: dict[str, np.ndarray] = {
    f: BODY_FROM_CORE @ np.array(n, dtype=np.int64) for f, n in FACE_NORMALS.items()
}

__all__ = [
    "AXIS_VECTORS",
    "BODY_FROM_CORE",
    "FACE_BODY_AXES",
    "DIRECTIONS",
    "INITIAL_ORIENTATION",
    "Orientation",
    "all_orientations",
    "direction_name",
    "quarter_rotation",
]

#: Unit vectors of the workspace axes.
AXIS_VECTORS: dict[str, tuple[int, int, int]] = {"x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1)}
#: The six signed workspace directions, in a fixed order used for display.
DIRECTIONS: tuple[str, ...] = ("+y", "-y", "+z", "-z", "-x", "+x")


def direction_vector(name: str) -> np.ndarray:
    """``"+y"`` → (0, 1, 0) etc."""
    sign = 1 if name[0] == "+" else -1
    return sign * np.array(AXIS_VECTORS[name[1]], dtype=np.int64)


def direction_name(v: np.ndarray) -> str:
    """Inverse of :func:`direction_vector` for a signed unit axis vector."""
    (i,) = np.flatnonzero(v)
    return ("+" if v[i] > 0 else "-") + "xyz"[i]


def quarter_rotation(axis: str, quarter_turns: int) -> np.ndarray:
    """Right-handed rotation by ``quarter_turns`` × 90° about the workspace ``axis``, as integers."""
    k = quarter_turns % 4
    c, s = (1, 0, -1, 0)[k], (0, 1, 0, -1)[k]
    i = "xyz".index(axis)
    j, m = (i + 1) % 3, (i + 2) % 3
    r = np.zeros((3, 3), dtype=np.int64)
    r[i, i] = 1
    r[j, j], r[j, m] = c, -s
    r[m, j], r[m, m] = s, c
    return r


@dataclass(frozen=True)
class Orientation:
    """Rotation workspace ← cube body, as a row-major tuple of 9 integers (hashable, exact)."""

    matrix: tuple[int, ...]

    @classmethod
    def from_array(cls, m: np.ndarray) -> Orientation:
        m = np.asarray(m, dtype=np.int64)
        if (
            m.shape != (3, 3)
            or round(float(np.linalg.det(m))) != 1
            or not np.array_equal(m.T @ m, np.eye(3, dtype=np.int64))
        ):
            raise ValueError(f"not one of the 24 cube rotations: {m.tolist()}")
        return cls(tuple(int(v) for v in m.ravel()))

    @classmethod
    def from_faces(cls, up: str, front: str) -> Orientation:
        """The orientation with face ``up`` along +z and face ``front`` towards the robot (-x)."""
        b_up, b_front = FACE_BODY_AXES[up], FACE_BODY_AXES[front]
        if int(b_up @ b_front) != 0:
            raise ValueError(f"faces {up} and {front} are not adjacent")
        # Columns: images of the body axes. Solve M b_up = z, M b_front = -x, M (b_up × b_front) = z × -x = -y.
        body = np.stack([b_up, b_front, np.cross(b_up, b_front)], axis=1)
        world = np.stack([[0, 0, 1], [-1, 0, 0], [0, -1, 0]], axis=1)
        return cls.from_array(world @ body.T)  # body is orthogonal: inverse = transpose

    @property
    def array(self) -> np.ndarray:
        return np.array(self.matrix, dtype=np.int64).reshape(3, 3)

    def direction_of(self, face: str) -> str:
        """The workspace direction the outward normal of ``face`` points along."""
        return direction_name(self.array @ FACE_BODY_AXES[face])

    def face_along(self, direction: str) -> str:
        """The face whose outward normal points along the workspace ``direction`` (``"+y"``, ``"-x"``, …)."""
        return _faces_along(self)[direction]

    def rotated(self, axis: str, quarter_turns: int) -> Orientation:
        """The orientation after turning the whole cube about a workspace axis."""
        return Orientation.from_array(quarter_rotation(axis, quarter_turns) @ self.array)

    def describe(self) -> str:
        """E.g. ``+y L  -y R  +z U  -z D  -x F  +x B``."""
        return "  ".join(f"{d} {self.face_along(d)}" for d in DIRECTIONS)

    def __str__(self) -> str:
        return self.describe()


@cache
def _faces_along(o: Orientation) -> dict[str, str]:
    m = o.array
    return {direction_name(m @ n): f for f, n in FACE_BODY_AXES.items()}


@lru_cache(maxsize=1)
def all_orientations() -> tuple[Orientation, ...]:
    """The 24 orientations, in a fixed order (closure from the identity under x, y, z quarter turns)."""
    seen = [Orientation.from_array(np.eye(3, dtype=np.int64))]
    frontier = list(seen)
    while frontier:
        nxt = []
        for o in frontier:
            for axis in "xyz":
                r = o.rotated(axis, 1)
                if r not in seen:
                    seen.append(r)
                    nxt.append(r)
        frontier = nxt
    assert len(seen) == 24
    return tuple(seen)


#: The protocol's start (Yang et al., Sec. III-A): top face parallel to the table (U up), back face
#: perpendicular to the robot's sagittal plane — read here as F facing the robot, B away from it, so
#: R is at the robot's right (-y) and L at its left (+y).
INITIAL_ORIENTATION: Orientation = Orientation.from_faces("U", "F")
