"""Scenes shared by the conformance suite and ``bench/bench_backends.py``.

Only the Backend interface is used here, so every registered backend runs them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from benchharness.backends import Backend, Box
from benchharness.geometry import Pose

ASSETS = Path(__file__).resolve().parent / "assets"
GRIPPER_URDF = ASSETS / "gripper.urdf"
ARM_URDF = ASSETS / "arm2.urdf"
ROTOR_URDF = ASSETS / "rotor.urdf"

CUBE_HALF = 0.0285  #: 5.7 cm cube
CUBE_MASS = 0.094  #: kg
PAD_OFFSET = 0.009  #: a pad's inner face is at finger q - PAD_OFFSET
FINGER_K = 2000.0  #: N/m, spring-like finger drive
FINGER_D = 40.0  #: N s/m
SQUEEZE = 0.01  #: m past contact -> 20 N per finger
FINGER_FMAX = 40.0
LIFT_K = 20000.0
LIFT_D = 1000.0
LIFT_FMAX = 200.0
GRASP_Z = CUBE_HALF + 0.065  #: palm height that puts the pads' centres at the cube's centre
OPEN_Q = 0.06


@dataclass
class GripperScene:
    backend: Backend
    ground: int
    gripper: int
    cube: int
    lift_z: float = GRASP_Z
    finger_q: float = OPEN_Q

    def command(self) -> None:
        b = self.backend
        b.set_joint_targets(
            self.gripper,
            [self.lift_z],
            joints=["lift"],
            stiffness=LIFT_K,
            damping=LIFT_D,
            force_limit=LIFT_FMAX,
        )
        b.set_joint_targets(
            self.gripper,
            [self.finger_q, self.finger_q],
            joints=["left_finger", "right_finger"],
            stiffness=FINGER_K,
            damping=FINGER_D,
            force_limit=FINGER_FMAX,
        )

    def cube_in_palm(self) -> np.ndarray:
        b = self.backend
        return (b.get_link_pose(self.gripper, "palm").inv() * b.get_pose(self.cube)).p


def gripper_scene(backend: Backend) -> GripperScene:
    """The gripper open above a 5.7 cm, 94 g cube resting on the ground."""
    g = backend.add_ground(0.0, friction=1.0)
    grip = backend.load_urdf(GRIPPER_URDF, Pose(), fixed_base=True, name="gripper")
    cube = backend.add_body(
        [Box((CUBE_HALF,) * 3)], Pose([0, 0, CUBE_HALF]), CUBE_MASS, friction=1.0, name="cube"
    )
    backend.set_joint_positions(
        grip, [GRASP_Z, OPEN_Q, OPEN_Q], joints=["lift", "left_finger", "right_finger"]
    )
    s = GripperScene(backend, g, grip, cube)
    s.command()
    return s


def grasp_lift_hold(s: GripperScene, hold_s: float = 5.0, lift: float = 0.10) -> dict:
    """Close, lift ``lift`` m in 1 s, hold ``hold_s`` s. Returns what the test checks."""
    b = s.backend
    dt = b.config.timestep
    b.step(int(0.2 / dt))  # settle
    s.finger_q = CUBE_HALF + PAD_OFFSET - SQUEEZE
    s.command()
    b.step(int(0.5 / dt))
    grasp_rel = s.cube_in_palm()
    n_lift = int(1.0 / dt)
    for i in range(n_lift):
        s.lift_z = GRASP_Z + lift * (i + 1) / n_lift
        s.command()
        b.step()
    lifted_rel = s.cube_in_palm()
    b.step(int(hold_s / dt))
    end_rel = s.cube_in_palm()
    forces = {}
    for link in ("pad_l", "pad_r"):
        forces[link] = sum(
            c.normal_force for c in b.contacts(s.gripper, s.cube) if c.link_a == link
        )
    return {
        "grasp_rel": grasp_rel,
        "lifted_rel": lifted_rel,
        "end_rel": end_rel,
        "cube_z": float(b.get_pose(s.cube).p[2]),
        "pad_forces": forces,
        "finger_q": b.get_joint_state(s.gripper).positions,
    }


def trajectory_digest(backend_name: str, seconds: float = 0.5) -> str:
    """SHA-256 of the gripper scene's cube and joint trajectory (for determinism checks)."""
    import hashlib
    import warnings

    from benchharness.backends import PhysicsConfig
    from benchharness.plugin import get_manager

    warnings.simplefilter("ignore")
    b = get_manager().create("backend", backend_name, config=PhysicsConfig())
    try:
        s = gripper_scene(b)
        s.finger_q = CUBE_HALF + PAD_OFFSET - SQUEEZE
        s.command()
        h = hashlib.sha256()
        for _ in range(int(seconds / b.config.timestep)):
            b.step()
            h.update(b.get_pose(s.cube).as_array().tobytes())
            h.update(b.get_joint_state(s.gripper).positions.tobytes())
        return h.hexdigest()
    finally:
        b.close()
