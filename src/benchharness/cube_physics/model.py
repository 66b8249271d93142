"""Geometry, mass properties and the generated URDF of the physical cube.

Body frame (fixed once, used by every other module): origin at the cube's
centre, faces normal to the axes, **U along +z, R along +x, F along -y** (so a
cube at the identity pose sits "U up, F towards -y", the natural way to put it
on a table in a z-up world). The cube core (:mod:`benchharness.cube.facelets`)
uses its own frame (x → R, y → U, z → F); :data:`BODY_FROM_CORE` maps it into
the body frame, and all facelet geometry is derived from the core's table
through that one rotation.

Why the centres never move in this frame: while articulated, the middle slab
is the articulation's root and, after the twist, the rigid body takes the
middle slab's pose. The middle slab carries the four centres around the twist
axis and the two outer slabs carry the centres *on* the axis, which only spin
in place. So facelet position ``i`` of the logical state is always at
:data:`FACELET_BODY_POSITIONS` ``[i]`` and the face whose centre points along
body ``+z`` is always U; a whole-cube turn shows up as a change of the body's
pose, never of this mapping.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..cube.facelets import FACE_NORMALS, FACELET_NAMES, FACELET_POSITIONS
from ..inertia import box_inertia
from .config import CubeConfig

__all__ = [
    "AXES",
    "AXIS_FACES",
    "AXIS_SLICES",
    "BODY_FROM_CORE",
    "FACE_BODY_AXES",
    "FACELET_BODY_NORMALS",
    "FACELET_BODY_POSITIONS",
    "JOINT_NAMES",
    "PLASTIC_RGBA",
    "SLAB_LINKS",
    "STICKER_RGBA",
    "SlabGeometry",
    "Sticker",
    "articulated_urdf",
    "axis_index",
    "rigid_half_extents",
    "rigid_inertia",
    "slab_geometry",
    "stickers",
    "write_articulated_urdf",
]

#: Body axes a twist can be about.
AXES = ("x", "y", "z")

#: Rotation taking the cube core's coordinates (x → R, y → U, z → F) into the body frame.
BODY_FROM_CORE = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=np.int64)

#: Outward normal of each face in the body frame (unit integer vectors).
FACE_BODY_AXES: dict[str, np.ndarray] = {
    f: BODY_FROM_CORE @ np.array(n, dtype=np.int64) for f, n in FACE_NORMALS.items()
}

#: Per axis: (face on the -axis side, face on the +axis side) = faces of slab 0 and slab 2.
AXIS_FACES: dict[str, tuple[str, str]] = {}
for _a, _name in enumerate(AXES):
    _neg = next(f for f, n in FACE_BODY_AXES.items() if n[_a] == -1)
    _pos = next(f for f, n in FACE_BODY_AXES.items() if n[_a] == 1)
    AXIS_FACES[_name] = (_neg, _pos)

#: The slice move of each axis' middle layer (M turns like L, E like D, S like F).
AXIS_SLICES: dict[str, str] = {"x": "M", "y": "S", "z": "E"}

#: Links of the articulated cube, slab 0 on the -axis side; slab 1 is the root.
SLAB_LINKS = ("slab_0", "slab_1", "slab_2")
#: Movable joints, in the order the URDF declares them: slab 1→0, slab 1→2.
JOINT_NAMES = ("layer_0", "layer_2")


def _facelet_geometry() -> tuple[np.ndarray, np.ndarray]:
    # The core's sticker coordinates are 2·cubie + normal, in -3..3; ±3 is the surface.
    pos = (BODY_FROM_CORE @ FACELET_POSITIONS.T).T.astype(float) / 6.0
    nrm = np.array([FACE_BODY_AXES[name[0]] for name in FACELET_NAMES], dtype=float)
    pos.setflags(write=False)
    nrm.setflags(write=False)
    return pos, nrm


#: Facelet centres in the body frame for a unit edge (multiply by ``edge``), shape (54, 3).
FACELET_BODY_POSITIONS, FACELET_BODY_NORMALS = _facelet_geometry()


#: Sticker colours by colour code (the face letter of the centre it matches, ``FACES`` order
#: URFDLB), the usual scheme: U white, R red, F green, D yellow, L orange, B blue.
STICKER_RGBA: dict[str, tuple[float, float, float, float]] = {
    "U": (0.95, 0.95, 0.95, 1.0),
    "R": (0.80, 0.04, 0.04, 1.0),
    "F": (0.00, 0.62, 0.22, 1.0),
    "D": (1.00, 0.84, 0.00, 1.0),
    "L": (1.00, 0.42, 0.00, 1.0),
    "B": (0.00, 0.27, 0.80, 1.0),
}
#: The cubies' black plastic between the stickers.
PLASTIC_RGBA = (0.04, 0.04, 0.04, 1.0)
#: A sticker covers this fraction of its facelet's side; 0.6 mm thick, its inner face on the surface.
STICKER_FILL = 0.86
STICKER_THICKNESS = 0.0006


@dataclass(frozen=True)
class Sticker:
    """One facelet's sticker, a thin box for rendering only (never part of the physics)."""

    facelet: int  #: 0..53, position in the state string
    slab: int  #: the slab it rides on for a twist about the axis asked (1 = middle / rigid)
    centre: np.ndarray  #: (3,) in the body frame, or the slab's frame when a slab was asked
    half_extents: tuple[float, float, float]
    rgba: tuple[float, float, float, float]


def stickers(config: CubeConfig, state: np.ndarray, axis: str | None = None) -> list[Sticker]:
    """The 54 stickers of ``state`` (colour codes, ``FACES`` order), in the body frame.

    With ``axis``, each sticker says which slab of a twist about ``axis``
    carries it and is placed in that slab's frame (the frame the URDF's slab
    link has), so the stickers turn with the layer they are on.
    """
    from ..cube.facelets import FACES

    edge = config.edge
    side = STICKER_FILL * edge / 3.0 / 2.0
    a = None if axis is None else axis_index(axis)
    out = []
    for i in range(54):
        n = FACELET_BODY_NORMALS[i]
        k = int(np.argmax(np.abs(n)))
        half = [side, side, side]
        half[k] = STICKER_THICKNESS / 2.0
        centre = FACELET_BODY_POSITIONS[i] * edge + n * (STICKER_THICKNESS / 2.0)
        slab = 1
        if a is not None:
            c = FACELET_BODY_POSITIONS[i][a]  # -1/2, -1/3, 0, 1/3 or 1/2 of the edge
            slab = 1 if abs(c) < 1.0 / 6.0 else (0 if c < 0 else 2)
            centre = centre.copy()
            centre[a] -= (slab - 1) * config.slab_thickness
        h = (half[0], half[1], half[2])
        out.append(Sticker(i, slab, centre, h, STICKER_RGBA[FACES[int(state[i])]]))
    return out


def axis_index(axis: str) -> int:
    try:
        return AXES.index(axis)
    except ValueError:
        raise ValueError(f"unknown twist axis {axis!r}; axes are x, y, z (body frame)") from None


def rigid_half_extents(config: CubeConfig) -> tuple[float, float, float]:
    h = config.edge / 2.0
    return (h, h, h)


def rigid_inertia(config: CubeConfig) -> np.ndarray:
    """Principal moments of the rigid cube (uniform density: ``m a² / 6`` on each axis)."""
    return box_inertia(config.mass, np.full(3, config.edge))


@dataclass(frozen=True)
class SlabGeometry:
    """One slab of the articulated cube, in the body (= root slab) frame."""

    link: str
    index: int  #: 0, 1, 2 from -axis to +axis
    centre: np.ndarray  #: (3,) m
    size: np.ndarray  #: (3,) full side lengths, m
    mass: float
    inertia: np.ndarray  #: principal moments about the slab's centre


def slab_geometry(config: CubeConfig, axis: str) -> tuple[SlabGeometry, SlabGeometry, SlabGeometry]:
    """The three slabs for a twist about ``axis``; they tile the rigid cube exactly."""
    a = axis_index(axis)
    t = config.slab_thickness
    size = np.full(3, config.edge)
    size[a] = t
    out = []
    for i in range(3):
        centre = np.zeros(3)
        centre[a] = (i - 1) * t
        out.append(
            SlabGeometry(
                SLAB_LINKS[i],
                i,
                centre,
                size.copy(),
                config.slab_mass,
                box_inertia(config.slab_mass, size),
            )
        )
    return tuple(out)  # type: ignore[return-value]


def _fmt(v: np.ndarray | tuple[float, ...]) -> str:
    return " ".join(f"{float(x):.9g}" for x in v)


def articulated_urdf(config: CubeConfig, axis: str, state: np.ndarray | None = None) -> str:
    """A collision-only URDF of the three-slab cube for a twist about ``axis``.

    The middle slab is the root (its link frame is the cube's centre, axes the
    body axes), so the articulated body's base pose *is* the rigid cube's pose
    and the swap needs no frame conversion. The outer slabs hang off it by
    continuous joints through the slab interfaces (``±edge/6`` along the axis);
    continuous, because a layer may legitimately turn 180° or more. Joint
    friction and the detent are not in the URDF (engines read URDF dynamics
    differently); :class:`~benchharness.cube_physics.mechanism.PhysicalCube`
    sets them through the Backend interface.

    With ``state`` (the 54 colour codes), each slab also gets ``<visual>``
    elements for a renderer: its black plastic and the stickers it carries
    (:func:`stickers`); engines without a renderer ignore them.
    """
    a = axis_index(axis)
    slabs = slab_geometry(config, axis)
    visuals: dict[int, list[str]] = {0: [], 1: [], 2: []}
    if state is not None:

        def visual(centre: np.ndarray, size: np.ndarray, rgba: tuple[float, ...]) -> str:
            return (
                f'    <visual><origin xyz="{_fmt(centre)}" rpy="0 0 0"/>'
                f'<geometry><box size="{_fmt(size)}"/></geometry>'
                f'<material name="rgba_{_fmt(rgba).replace(" ", "_")}">'
                f'<color rgba="{_fmt(rgba)}"/></material></visual>'
            )

        for s in slabs:
            visuals[s.index].append(visual(np.zeros(3), s.size, PLASTIC_RGBA))
        for st in stickers(config, state, axis):
            visuals[st.slab].append(visual(st.centre, 2.0 * np.asarray(st.half_extents), st.rgba))
    axis_vec = np.zeros(3)
    axis_vec[a] = 1.0
    lines = ['<?xml version="1.0"?>', f'<robot name="rubiks_cube_axis_{axis}">']
    for s in (slabs[1], slabs[0], slabs[2]):
        ixx, iyy, izz = s.inertia
        lines += [
            f'  <link name="{s.link}">',
            "    <inertial>",
            '      <origin xyz="0 0 0" rpy="0 0 0"/>',
            f'      <mass value="{s.mass:.9g}"/>',
            f'      <inertia ixx="{ixx:.9g}" ixy="0" ixz="0" iyy="{iyy:.9g}" iyz="0" izz="{izz:.9g}"/>',
            "    </inertial>",
            *visuals[s.index],
            "    <collision>",
            '      <origin xyz="0 0 0" rpy="0 0 0"/>',
            f'      <geometry><box size="{_fmt(s.size)}"/></geometry>',
            "    </collision>",
            f'    <contact><lateral_friction value="{config.surface_friction:.9g}"/></contact>',
            "  </link>",
        ]
    # A generous effort/velocity: the limits are the drives' business, not the URDF's.
    for joint, child in zip(JOINT_NAMES, (slabs[0], slabs[2])):
        lines += [
            f'  <joint name="{joint}" type="continuous">',
            f'    <parent link="{SLAB_LINKS[1]}"/>',
            f'    <child link="{child.link}"/>',
            f'    <origin xyz="{_fmt(child.centre)}" rpy="0 0 0"/>',
            f'    <axis xyz="{_fmt(axis_vec)}"/>',
            '    <limit effort="100" velocity="100"/>',
            "  </joint>",
        ]
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def write_articulated_urdf(
    config: CubeConfig,
    axis: str,
    directory: str | Path | None = None,
    state: np.ndarray | None = None,
) -> Path:
    """Write :func:`articulated_urdf` to a new file (the caller deletes it)."""
    fd, name = tempfile.mkstemp(suffix=".urdf", prefix=f"bh_cube_{axis}_", dir=directory)
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(articulated_urdf(config, axis, state))
    return Path(name)
