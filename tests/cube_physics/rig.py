"""Test-only grippers for the physical cube: driven bodies that touch it through real contacts.

Two fixed-base "grippers", generated as collision-only URDFs, whose palm frame
is the cube's centre:

* the **holder**: pads on the cube's ±x faces; which slabs it touches is set by
  the z spans of its pad segments (the three grasps of the paper's Fig. 2);
* the **rotator**: a wrist (revolute about world z through the cube's axis,
  3 N·m torque limit, the cube spike's figure) carrying two narrow pads on the ±y
  faces of the top slab.

Every pad segment sits on its own prismatic joint driven as a capped spring
(2000 N/m, pressed in far enough for its grip force, cap twice that), never a
constant force (docs/benchmarks/cube_spike.md: constant-force fingers let the cube drift).
A holder finger that spans slabs 0–1 *and* slab 2 is two such segments: a
real fingertip is compliant and keeps touching every slab it spans, whereas a
single rigid plate is lifted off slabs 0–1 by the first degree slab 2 turns
(its corners cam the plate open by 0.5 mm per degree). The cube hangs in the
air between the pads (no table), so every torque on it comes from a pad.
"""

from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from benchharness.backends import Backend, PhysicsConfig
from benchharness.cube_physics import CubeConfig, PhysicalCube, TwistOutcome
from benchharness.geometry import Pose
from benchharness.plugin import get_manager

CENTRE = np.array([0.0, 0.0, 0.5])
HALF = 0.0285  #: half the cube's edge
PAD_T = 0.004  #: pad thickness
HOLDER_PAD_W = 0.060  #: holder pads span the whole face, so a turning slab's corners bear on them
ROTATOR_PAD_W = 0.020  #: narrow fingertips: they reach the holder's pads only past ~50°
FINGER_K = 2000.0  #: N/m
FINGER_D = 20.0  #: N·s/m
GRIP = 20.0  #: N per finger (docs/benchmarks/cube_spike.md)
WRIST_K = 20.0  #: N·m/rad
WRIST_D = 1.0  #: N·m·s/rad
WRIST_TMAX = 3.0  #: N·m (the cube spike's wrist torque limit, docs/benchmarks/cube_spike.md)
OPEN = 0.045  #: finger position well clear of the cube
FINGER_MASS = 0.07  #: kg, a realistic fingertip

#: Holder pad segments per grasp: (z0, z1, grip N) relative to the cube's centre.
#: Slab 0 is z in [-28.5, -9.5] mm, slab 1 [-9.5, 9.5], slab 2 [9.5, 28.5].
#: The over-constrained holder holds slab 2 twice as hard as the rotator does: a hand
#: that holds firmly is what makes Fig. 2's bottom row jam. With equal grips the slab
#: is a tie between two identical friction grips and the engines break it differently
#: (see docs/cube_physics.md).
HOLDER_SEGMENTS = {
    "correct": [(-0.027, 0.0065, GRIP)],  # slabs 0 and 1
    "under": [(-0.027, -0.0125, GRIP)],  # slab 0 only
    "over": [(-0.027, 0.0065, GRIP), (0.0115, 0.027, 2 * GRIP)],  # all three
}
ROTATOR_SEGMENTS = [(0.0125, 0.027, GRIP)]  # slab 2 only


def make_backend(name: str) -> Backend:
    return get_manager().create("backend", name, config=PhysicsConfig())


def _inertial(mass: float, i: float) -> str:
    return (
        f'<inertial><origin xyz="0 0 0"/><mass value="{mass}"/>'
        f'<inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>'
    )


def finger_joints(segments: list) -> list[str]:
    return [f"finger_{side}{i}" for i in range(len(segments)) for side in "pn"]


def gripper_urdf(name: str, finger_axis: str, segments: list, wrist: bool, pad_width: float) -> str:
    """Pads on prismatic joints along ±``finger_axis``; joint q = the pad face's distance from the axis."""
    ax = {"x": (1, 0, 0), "y": (0, 1, 0)}[finger_axis]
    parts = [
        f'<?xml version="1.0"?><robot name="{name}">',
        f'<link name="base">{_inertial(1.0, 1e-3)}</link>',
    ]
    parent = "base"
    if wrist:
        parts += [
            f'<link name="palm">{_inertial(0.2, 1e-4)}</link>',
            '<joint name="wrist" type="revolute"><parent link="base"/><child link="palm"/>'
            '<origin xyz="0 0 0"/><axis xyz="0 0 1"/>'
            f'<limit lower="-6.3" upper="6.3" effort="{WRIST_TMAX}" velocity="10"/></joint>',
        ]
        parent = "palm"
    for i, (z0, z1, grip) in enumerate(segments):
        size = [pad_width, pad_width, z1 - z0]
        size["xy".index(finger_axis)] = PAD_T
        for side, sign in (("p", 1), ("n", -1)):
            off = [sign * PAD_T / 2 * a for a in ax]
            parts += [
                f'<link name="pad_{side}{i}">{_inertial(FINGER_MASS, 1e-5)}'
                f'<collision><origin xyz="{off[0]} {off[1]} {0.5 * (z0 + z1)}"/>'
                f'<geometry><box size="{size[0]} {size[1]} {size[2]}"/></geometry></collision></link>',
                f'<joint name="finger_{side}{i}" type="prismatic"><parent link="{parent}"/><child link="pad_{side}{i}"/>'
                f'<origin xyz="0 0 0"/><axis xyz="{sign * ax[0]} {sign * ax[1]} 0"/>'
                f'<limit lower="0" upper="0.08" effort="{2 * grip}" velocity="1"/></joint>',
            ]
    parts.append("</robot>")
    return "\n".join(parts)


def _load(backend: Backend, text: str, name: str) -> int:
    fd, path = tempfile.mkstemp(suffix=".urdf", prefix=f"bh_test_{name}_")
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    try:
        return backend.load_urdf(Path(path), Pose(CENTRE), fixed_base=True, name=name)
    finally:
        os.unlink(path)


@dataclass
class TwistRig:
    backend: Backend
    cube: PhysicalCube
    holder: int
    rotator: int
    holder_segments: list
    wrist_log: list[float] = field(default_factory=list)

    def grip(self, body: int, closed: bool) -> None:
        """Close (every segment pressed in for its grip force) or open a gripper."""
        segments = self.holder_segments if body == self.holder else ROTATOR_SEGMENTS
        targets, caps = [], []
        for _, _, grip in segments:
            q = HALF - grip / FINGER_K if closed else OPEN
            targets += [q, q]
            caps += [2 * grip, 2 * grip]
        self.backend.set_joint_targets(
            body,
            targets,
            joints=finger_joints(segments),
            stiffness=FINGER_K,
            damping=FINGER_D,
            force_limit=caps,
        )

    def wrist(self, angle: float) -> None:
        self.backend.set_joint_targets(
            self.rotator,
            [angle],
            joints=["wrist"],
            stiffness=WRIST_K,
            damping=WRIST_D,
            force_limit=WRIST_TMAX,
        )

    def seconds(self, t: float) -> int:
        return max(1, int(round(t / self.backend.config.timestep)))


#: Cube orientations that put body axis ``axis`` along world +z (the wrist's axis).
AXIS_UP = {
    "z": Rotation.identity(),
    "x": Rotation.from_euler("y", -90, degrees=True),
    "y": Rotation.from_euler("x", 90, degrees=True),
}


def build_rig(
    backend: Backend,
    grasp: str,
    config: CubeConfig | None = None,
    axis: str = "z",
    cube_pose: Pose | None = None,
) -> TwistRig:
    """The cube held in the air by the holder (a grasp of HOLDER_SEGMENTS) and the rotator on its top slab.

    ``axis`` is the body axis that points up, i.e. the one the wrist twists about;
    ``cube_pose`` overrides the cube's pose (to test small placement errors).
    """
    pose = cube_pose or Pose.from_rotation(CENTRE, AXIS_UP[axis])
    cube = PhysicalCube(backend, pose, config)
    segments = HOLDER_SEGMENTS[grasp]
    holder = _load(
        backend,
        gripper_urdf("holder", "x", segments, wrist=False, pad_width=HOLDER_PAD_W),
        "holder",
    )
    rotator = _load(
        backend,
        gripper_urdf("rotator", "y", ROTATOR_SEGMENTS, wrist=True, pad_width=ROTATOR_PAD_W),
        "rotator",
    )
    backend.set_joint_positions(holder, [HALF] * 2 * len(segments), joints=finger_joints(segments))
    backend.set_joint_positions(
        rotator, [0.0, HALF, HALF], joints=["wrist"] + finger_joints(ROTATOR_SEGMENTS)
    )
    rig = TwistRig(backend, cube, holder, rotator, segments)
    rig.grip(holder, closed=True)
    rig.grip(rotator, closed=True)
    rig.wrist(0.0)
    return rig


def twist(
    rig: TwistRig, angle_deg: float, intended: str | None, *, turn_s: float = 0.75, axis: str = "z"
) -> TwistOutcome:
    """Settle, articulate, turn the wrist by ``angle_deg`` about +z, let go of the top, end the twist."""
    cube, b = rig.cube, rig.backend
    b.step(rig.seconds(0.05))
    cube.begin_twist(axis, intended=intended)
    b.step(rig.seconds(0.02))
    n = rig.seconds(turn_s)
    target = math.radians(angle_deg)
    for i in range(n):
        s = (i + 1) / n
        rig.wrist(target * (3 * s * s - 2 * s**3))  # smooth start and stop
        b.step(1)
        rig.wrist_log.append(float(b.get_joint_state(rig.rotator).positions[0]))
    b.step(rig.seconds(0.1))
    rig.grip(rig.rotator, closed=False)
    b.step(rig.seconds(0.1))
    return cube.end_twist()
