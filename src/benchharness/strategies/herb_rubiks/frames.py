"""HERB tool frames for push-grasps, from an *estimated* cube pose (no physics).

HERB's tool frame ``{l,r}_bh_tcp`` has z = approach (out of the palm) and
y towards the thumb (F3); with the spread at 90 deg the outer fingers F1/F2
face each other across tool x. The machine's grip frames
(:mod:`benchharness.strategies.bimanual.frames`) are robot-independent
grip geometry with x = approach and y = the finger axis, so a HERB grip is
that frame turned by :data:`HERB_FROM_PR2`: HERB z = PR2 x (approach),
HERB x = PR2 y (the pinch axis), HERB y = PR2 z.

A push-grasp of a face puts the tool frame on the face's outward normal at
``half edge + face_depth`` from the centre, where ``face_depth`` is how far
beyond the tool frame the thumb's tip stands in the pre-shape: that is where
the tool frame will be when the thumb touches the face.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose
from ...robots.descriptions.herb import DIST_BOX, PALM_CYLINDER, PROX_BOX
from ..bimanual.frames import DIRECTIONS, grip_candidates, rotate_about_point, unit_box_grid

__all__ = [
    "CUBE_HALF",
    "DIRECTIONS",
    "HERB_FROM_PR2",
    "PROX_CORNERS",
    "PROX_FILL",
    "DIST_FILL",
    "PALM_FILL",
    "DIST_CORNERS",
    "approach_axis",
    "band_clear",
    "finger_extent",
    "pinch_axis",
    "push_grip_candidates",
    "reanchor_along_approach",
    "rotate_about_point",
    "rolled_about_approach",
    "thumb_face_depth",
    "thumb_tip_lateral",
]

CUBE_HALF = 0.0285
#: rotation PR2 tool frame -> HERB tool frame (columns: HERB axes in PR2 tool coordinates)
HERB_FROM_PR2 = Rotation.from_matrix(np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]))


def _box_corners(box) -> np.ndarray:
    (sx, sy, sz), (cx, cy, cz) = box
    return np.array(
        [
            [cx + a * sx / 2, cy + b * sy / 2, cz + c * sz / 2]
            for a in (-1, 1)
            for b in (-1, 1)
            for c in (-1, 1)
        ]
    )


#: BarrettHand distal and proximal link boxes (robots/descriptions/herb.py), corners in the link frame
#: (x along the link, y its closing side, z the joint axis)
_DIST_CORNERS = _box_corners(DIST_BOX)
DIST_CORNERS = _DIST_CORNERS
PROX_CORNERS = _box_corners(PROX_BOX)


def _box_fill(box) -> np.ndarray:
    size, centre = box
    return np.asarray(centre) + unit_box_grid() * np.asarray(size)


def _cylinder_fill(cylinder, n_angle: int = 12) -> np.ndarray:
    (radius, length), centre = cylinder
    pts = [
        (r * np.cos(a), r * np.sin(a), z)
        for z in np.linspace(-length / 2, length / 2, 5)
        for r in (0.0, radius / 2, radius)
        for a in np.linspace(0.0, 2 * np.pi, n_angle if r > 0 else 1, endpoint=False)
    ]
    return np.asarray(pts) + np.asarray(centre)


#: points filling the BarrettHand's collision shapes in their link frames (5 x 5 x 5 a finger box; the
#: palm cylinder on 5 levels of 3 rings): what the hand's sweep checks move along a joint path
PROX_FILL = _box_fill(PROX_BOX)
DIST_FILL = _box_fill(DIST_BOX)
PALM_FILL = _cylinder_fill(PALM_CYLINDER)


def approach_axis(tool: Pose) -> np.ndarray:
    return tool.rotation.apply([0.0, 0.0, 1.0])


def pinch_axis(tool: Pose) -> np.ndarray:
    """World direction across which the outer fingers F1/F2 pinch (tool x)."""
    return tool.rotation.apply([1.0, 0.0, 0.0])


def push_grip_candidates(cube: Pose, world_dir: str, face_depth: float) -> list[Pose]:
    """The four push-grasp tool frames on the face nearest ``world_dir`` (pinch across either face pair, either way)."""
    return [
        Pose.from_rotation(p.p, p.rotation * HERB_FROM_PR2)
        for p in grip_candidates(cube, world_dir, CUBE_HALF + face_depth)
    ]


def rolled_about_approach(tool: Pose, angle: float) -> Pose:
    """The tool frame after a wrist roll (WAM joint 7, about tool z through the tool origin)."""
    return Pose.from_rotation(tool.p, tool.rotation * Rotation.from_rotvec([0.0, 0.0, angle]))


def thumb_face_depth(tool: Pose, distal: Pose) -> float:
    """How far beyond the tool frame, along the approach, the thumb's distal link reaches (m).

    ``tool`` and ``distal`` are the tool-frame and thumb-distal-link poses
    (from the robot's own joint readings): a face perpendicular to the approach
    is first touched by the distal link's corner that reaches farthest.
    """
    corners = distal.rotation.apply(_DIST_CORNERS) + distal.p
    local = tool.rotation.inv().apply(corners - tool.p)
    return float(np.max(local[:, 2]))


def thumb_tip_lateral(tool: Pose, distal: Pose) -> float:
    """Where across the palm (tool y, m) the thumb's tip touches a face perpendicular to the approach.

    The corners of the distal link within 2 mm of the farthest along the
    approach are the ones that touch; their mean tool-y coordinate is the
    tip's lateral position (negative: the tip curls past the palm axis, away
    from the thumb's root).
    """
    corners = distal.rotation.apply(_DIST_CORNERS) + distal.p
    local = tool.rotation.inv().apply(corners - tool.p)
    top = local[:, 2] > np.max(local[:, 2]) - 0.002
    return float(np.mean(local[top, 1]))


def finger_extent(
    tool_cmd: Pose, tool_measured: Pose, link_poses: list[tuple[Pose, np.ndarray]], frame: Pose
) -> tuple[np.ndarray, np.ndarray]:
    """Extent (min, max) in ``frame``'s coordinates of finger link boxes of a hand believed at ``tool_cmd``.

    ``link_poses`` are (measured link pose, box corners in the link frame)
    of the hand's own links, and ``tool_measured`` its measured tool pose: the
    boxes are placed relative to the *believed* tool pose (what the strategy
    knows of where the hand is relative to the cube), from the robot's own
    kinematics.
    """
    pts = []
    rel = tool_cmd * tool_measured.inv()
    for link, corners in link_poses:
        w = rel * link
        pts.append(w.rotation.apply(corners) + w.p)
    loc = frame.rotation.inv().apply(np.vstack(pts) - frame.p)
    return loc.min(axis=0), loc.max(axis=0)


def band_clear(
    lo: np.ndarray,
    hi: np.ndarray,
    lateral: float,
    half_width: float,
    reach: float,
    clearance: float,
) -> bool:
    """Whether a hand's closing outer fingers stay clear of an obstacle box (``lo``, ``hi``) in its tool frame.

    The closing fingers sweep, across the palm (tool y), ``lateral`` +-
    ``half_width`` and along the approach (tool z) everything up to ``reach``
    beyond the tool frame; both spans padded by ``clearance``. The pinch
    axis (tool x) is not checked: the fingers of both hands lie on the same
    two faces when the hand pinches the faces the other hand pinches.
    """
    y_clear = lateral + half_width + clearance <= lo[1] or lateral - half_width - clearance >= hi[1]
    z_clear = lo[2] >= reach + clearance
    return bool(y_clear or z_clear)


def reanchor_along_approach(
    belief: Pose, tool_at_contact: Pose, face_depth: float
) -> tuple[Pose, float]:
    """The belief moved along the approach so that its near face is where the thumb touched; and the shift (m).

    The push stopped when the thumb's tip, ``face_depth`` beyond the
    (believed) tool frame along its z, touched the face: the face's distance
    along the approach is known from the hand alone. Only that one component
    of the belief changes; across the approach the push tells nothing.
    """
    z = approach_axis(tool_at_contact)
    face_seen = float(np.dot(tool_at_contact.p, z)) + face_depth
    face_believed = float(np.dot(belief.p, z)) - CUBE_HALF
    shift = face_seen - face_believed
    return Pose(belief.p + shift * z, belief.q), shift
