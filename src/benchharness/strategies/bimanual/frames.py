"""Pure frame computations: gripper targets from an *estimated* cube pose (no physics).

Robot-independent grip geometry of the bimanual Rubik's machine
(:mod:`.machine`). Conventions (docs/robots.md, docs/planner.md): a *grip
frame* has x = approach (pointing from the palm into the object), y = the
direction the fingers open and close, as the PR2's tool frame does; the
PR2's wrist-roll joint turns about tool x through the tool-frame origin. A
robot whose tool frame is laid out otherwise turns these frames into its own
(HERB: ``herb_rubiks.frames.HERB_FROM_PR2``). The cube body frame is ``cube_physics``' (U = +z, R = +x,
F = -y). A grip "from direction d" puts the tool frame on the cube's face
whose estimated outward normal is nearest the world direction ``d``, at
``offset`` from the cube centre along that normal, approaching along -normal,
with the fingers on one of the two perpendicular pairs of faces. Everything
is expressed in the *estimated* cube frame and mapped to the world with the
estimated pose, so a tilted or yawed estimate tilts or yaws the target too.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose

__all__ = [
    "DIRECTIONS",
    "along",
    "body_axis_along",
    "grip_candidates",
    "grip_pose",
    "rotate_about_point",
    "turned_about_approach",
    "unit_box_grid",
]

DIRECTIONS: dict[str, np.ndarray] = {
    "+x": np.array([1.0, 0.0, 0.0]),
    "-x": np.array([-1.0, 0.0, 0.0]),
    "+y": np.array([0.0, 1.0, 0.0]),
    "-y": np.array([0.0, -1.0, 0.0]),
    "+z": np.array([0.0, 0.0, 1.0]),
    "-z": np.array([0.0, 0.0, -1.0]),
    "x": np.array([1.0, 0.0, 0.0]),
    "y": np.array([0.0, 1.0, 0.0]),
    "z": np.array([0.0, 0.0, 1.0]),
}


def along(axis: int, value: float) -> np.ndarray:
    """The tool-frame vector ``value`` along tool axis ``axis`` (0 = x, 1 = y, 2 = z), zeros elsewhere.

    Built by assignment, not as ``value * unit``, so that a move of ``d`` along
    tool x is exactly ``[d, 0, 0]`` (the same floats the PR2 baselines always used).
    """
    out = np.zeros(3)
    out[axis] = value
    return out


def _vec(d: str | np.ndarray) -> np.ndarray:
    return DIRECTIONS[d] if isinstance(d, str) else np.asarray(d, dtype=float)


def body_axis_along(cube: Pose, world_dir: str | np.ndarray) -> np.ndarray:
    """The signed body unit axis (in the body frame) whose world image is nearest ``world_dir``."""
    local = cube.rotation.inv().apply(_vec(world_dir))
    k = int(np.argmax(np.abs(local)))
    out = np.zeros(3)
    out[k] = np.sign(local[k]) or 1.0
    return out


def grip_pose(
    cube: Pose, world_dir: str | np.ndarray, offset: float, fingers: str | np.ndarray
) -> Pose:
    """Tool-frame target of a grip from ``world_dir``, ``offset`` m from the centre, fingers along ``fingers``.

    ``fingers`` is a world direction; the body axis perpendicular to the
    approach that is nearest to it becomes tool y.
    """
    n = body_axis_along(cube, world_dir)  # outward normal of the gripped face, body frame
    f_local = cube.rotation.inv().apply(_vec(fingers))
    f_local = f_local - np.dot(f_local, n) * n
    k = int(np.argmax(np.abs(f_local)))
    y = np.zeros(3)
    y[k] = np.sign(f_local[k]) or 1.0
    x = -n
    z = np.cross(x, y)
    local = Pose.from_rotation(n * offset, Rotation.from_matrix(np.column_stack([x, y, z])))
    return cube * local


def grip_candidates(cube: Pose, world_dir: str | np.ndarray, offset: float) -> list[Pose]:
    """The four grips from ``world_dir`` (fingers on either pair of faces, either way round)."""
    n = body_axis_along(cube, world_dir)
    out = []
    for k in range(3):
        if n[k] != 0:
            continue
        for s in (1.0, -1.0):
            e = np.zeros(3)
            e[k] = s
            out.append(grip_pose(cube, world_dir, offset, cube.rotation.apply(e)))
    return out


def rotate_about_point(
    pose: Pose, centre: np.ndarray, axis: str | np.ndarray, angle: float
) -> Pose:
    """``pose`` carried rigidly by a rotation of ``angle`` rad about world ``axis`` through ``centre``."""
    r = Rotation.from_rotvec(_vec(axis) * angle)
    c = np.asarray(centre, dtype=float)
    return Pose.from_rotation(c + r.apply(pose.p - c), r * pose.rotation)


def turned_about_approach(tcp: Pose, angle: float) -> Pose:
    """The tool frame after a wrist roll of ``angle`` rad (about its own x, through its origin)."""
    return Pose.from_rotation(tcp.p, tcp.rotation * Rotation.from_rotvec([angle, 0.0, 0.0]))


def unit_box_grid(n: int = 5) -> np.ndarray:
    """``n`` x ``n`` x ``n`` points evenly filling the unit box [-0.5, 0.5]^3, corners included ((n^3) x 3):
    scaled by a box's size and moved to its centre they fill a hand's collision box for the sweep checks
    (the grasp modules' ``hand_points``)."""
    g = np.linspace(-0.5, 0.5, n)
    return np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
