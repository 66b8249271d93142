"""Allegro hand v4, right: 16 joints, index / middle / ring fingers and thumb.

Joint origins, axes, link box sizes, fingertip sphere radius, joint ranges
and link masses are those of Wonik Robotics' / SimLab's
``allegro_hand_description_right.xacro`` (github.com/simlabrobotics/
allegro_hand_ros_v4, ``src/allegro_hand_description``); the ranges there are
the hardware limits shrunk by a 0.1 rad safety margin, used as is.

Differences from that file: the fingertip is a sphere link per finger named
``link_<n>_tip`` as there, but every inertia here is computed from the box
and mass (the upstream file mixes computed and placeholder values); joint
effort is the hand's 0.7 N m rated joint torque (upstream says 15); the
palm is a box as upstream. The hand's base frame is the palm frame
(``palm_link``, z along the fingers, y from ring to index): give the robot a
base pose to fix it in space, or attach it to an arm's flange.
"""

from __future__ import annotations

import math

from ..urdf_builder import Geom, UrdfBuilder

DEG = math.pi / 180.0
SRC = "allegro_hand_description_right.xacro (simlabrobotics/allegro_hand_ros_v4)"
LINKS_X, LINKS_Y = 0.0196, 0.0275  # finger link cross-section
LINK_Z = (
    0.0164,
    0.0540,
    0.0384,
    0.0387,
)  # link0..link3 (link3 to the tip, incl. the tip sphere radius)
TIP_R = 0.012
THUMB_Z = (0.0177, 0.0514, 0.0543)  # link13, link14, link15 (to the tip)
MASS = (0.0119, 0.065, 0.0355, 0.0096)
THUMB_MASS = (0.0176, 0.0119, 0.038, 0.0388)
TIP_MASS = 0.0168
PALM_MASS = 0.4154
#: Finger limits (rad) after the upstream 0.1 rad safety margin.
LIMITS = [(-0.47, 0.47), (-0.196, 1.61), (-0.174, 1.709), (-0.227, 1.618)]
THUMB_LIMITS = [(0.263, 1.396), (-0.105, 1.163), (-0.189, 1.644), (-0.162, 1.719)]
THUMB13_CLEARANCE = 0.007  # m, see _thumb (our change)
EFFORT = 0.7  # N m, Allegro v4 rated joint torque (Wonik datasheet)
VELOCITY = 7.0  # rad/s (upstream <limit velocity>)


def _finger(m: UrdfBuilder, n: int, y: float, z: float, roll: float) -> None:
    base = 4 * n
    parent = "palm_link"
    origins = [
        ((0.0, y, z), (roll, 0.0, 0.0)),
        ((0.0, 0.0, LINK_Z[0]), (0, 0, 0)),
        ((0.0, 0.0, LINK_Z[1]), (0, 0, 0)),
        ((0.0, 0.0, LINK_Z[2]), (0, 0, 0)),
    ]
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (0, 1, 0)]
    for k in range(4):
        length = LINK_Z[k] if k < 3 else LINK_Z[3] - TIP_R
        lo, hi = LIMITS[k]
        m.joint(
            f"joint_{base + k}",
            "revolute",
            parent,
            f"link_{base + k}",
            xyz=origins[k][0],
            rpy=origins[k][1],
            axis=axes[k],
            lower=lo,
            upper=hi,
            effort=EFFORT,
            velocity=VELOCITY,
            damping=0.01,
            source=f"origin, axis, range {lo}..{hi} ({SRC})",
        )
        m.link(
            f"link_{base + k}",
            [Geom("box", (LINKS_X, LINKS_Y, length), (0.0, 0.0, length / 2))],
            MASS[k],
            source=f"box {LINKS_X} x {LINKS_Y} x {length:.4f} m, mass {MASS[k]} kg ({SRC})",
        )
        parent = f"link_{base + k}"
    _tip(m, base + 3, LINK_Z[3] - TIP_R)


def _tip(m: UrdfBuilder, n: int, z: float) -> None:
    m.joint(
        f"joint_{n}_tip",
        "fixed",
        f"link_{n}",
        f"link_{n}_tip",
        xyz=(0.0, 0.0, z),
        source=f"fingertip sphere centre ({SRC})",
    )
    m.link(
        f"link_{n}_tip",
        [Geom("sphere", (TIP_R,))],
        TIP_MASS,
        source=f"fingertip sphere r {TIP_R} m, {TIP_MASS} kg ({SRC})",
    )


def _thumb(m: UrdfBuilder) -> None:
    lo, hi = THUMB_LIMITS[0]
    m.joint(
        "joint_12",
        "revolute",
        "palm_link",
        "link_12",
        xyz=(-0.0182, 0.019333, -0.045987),
        rpy=(0.0, -95 * DEG, -90 * DEG),
        axis=(-1, 0, 0),
        lower=lo,
        upper=hi,
        effort=EFFORT,
        velocity=VELOCITY,
        damping=0.01,
        source=f"thumb base: origin, rpy (0, -95, -90) deg, axis -x ({SRC})",
    )
    m.link(
        "link_12",
        [Geom("box", (0.0358, 0.034, 0.0455), (-0.0179, 0.009, 0.0145))],
        THUMB_MASS[0],
        source=f"thumb base box, mass {THUMB_MASS[0]} kg ({SRC})",
    )
    specs = [
        ("joint_13", "link_12", "link_13", (-0.027, 0.005, 0.0399), (0, 0, 1), THUMB_Z[0]),
        ("joint_14", "link_13", "link_14", (0.0, 0.0, THUMB_Z[0]), (0, 1, 0), THUMB_Z[1]),
        ("joint_15", "link_14", "link_15", (0.0, 0.0, THUMB_Z[1]), (0, 1, 0), THUMB_Z[2] - TIP_R),
    ]
    for k, (jn, par, ch, xyz, axis, length) in enumerate(specs, start=1):
        lo, hi = THUMB_LIMITS[k]
        m.joint(
            jn,
            "revolute",
            par,
            ch,
            xyz=xyz,
            axis=axis,
            lower=lo,
            upper=hi,
            effort=EFFORT,
            velocity=VELOCITY,
            damping=0.01,
            source=f"origin, axis, range {lo}..{hi} ({SRC})",
        )
        # link_13's box (the thumb's rotator) starts THUMB13_CLEARANCE up its axis: at full length it
        # interpenetrates the palm box, a non-adjacent link, in the zero and home poses.
        z0 = THUMB13_CLEARANCE if ch == "link_13" else 0.0
        m.link(
            ch,
            [Geom("box", (LINKS_X, LINKS_Y, length - z0), (0.0, 0.0, z0 + (length - z0) / 2))],
            THUMB_MASS[k],
            source=f"box {LINKS_X} x {LINKS_Y} x {length - z0:.4f} m, mass {THUMB_MASS[k]} kg ({SRC})",
        )
    _tip(m, 15, THUMB_Z[2] - TIP_R)


def build() -> UrdfBuilder:
    m = UrdfBuilder("allegro_hand_right", header=__doc__ or "")
    m.link(
        "palm_link",
        [Geom("box", (0.0408, 0.1130, 0.095), (-0.0093, 0.0, -0.0475))],
        PALM_MASS,
        source=f"palm box 0.0408 x 0.1130 x 0.095 m at (-0.0093, 0, -0.0475), mass {PALM_MASS} kg ({SRC})",
    )
    _finger(m, 0, 0.0435, -0.001542, -5 * DEG)  # index
    _finger(m, 1, 0.0, 0.0007, 0.0)  # middle
    _finger(m, 2, -0.0435, -0.001542, 5 * DEG)  # ring
    _thumb(m)
    m.joint(
        "palm_tcp_joint",
        "fixed",
        "palm_link",
        "palm_tcp",
        xyz=(0.0, 0.0, 0.0),
        source="hand frame at the palm frame (where the in-hand benchmark's palm pose is measured)",
    )
    m.link("palm_tcp", source="hand pose frame")
    return m
