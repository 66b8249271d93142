"""Parameters of the DMG planner: the gripper model and the graph resolution.

Kept apart from the algorithms so that a result can be reproduced from the
printed config alone (every field is a plain number) and so that tests can
state their geometry next to the config they use.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

__all__ = ["DMGGripperModel", "DMGConfig", "DMGSurface", "YUMI_SMART_GRIPPER"]


@dataclass(frozen=True)
class DMGGripperModel:
    """A parallel-jaw gripper reduced to what decides whether a grasp fits.

    Frame convention (also used for the task files' quaternions): ``z`` is the
    closing direction, from the principal finger into the object; ``x``
    points from the palm to the fingertips, so the palm lies at ``-x`` from
    the contacts; ``y = z × x``. This reading makes the four published DMG
    tasks consistent (see ``docs/dmg.md``).

    ``max_opening`` is the YuMi smart gripper's stroke (50 mm);
    ``opening_tolerance`` lets a grasp of exactly that width (the potted meat
    can is 50 mm thick) count as feasible. ``finger_length`` is the reach
    from the contact to the palm: the object must end within it along
    ``-x``, otherwise the palm would collide -- this is what makes the set of
    admissible angles about the normal depend on where on a face the finger
    is. ``finger_clearance`` is how far outside the surface the finger
    samples are tested (it must exceed the occupancy grid's fuzz,
    ``pitch * sqrt(3)``). ``friction_coefficient`` bounds how far the
    opposite contact's normal may deviate from antiparallel (the friction
    cone half-angle ``atan(mu)``).
    """

    max_opening: float = 0.050
    min_opening: float = 0.0
    opening_tolerance: float = 0.001
    finger_length: float = 0.035
    palm_depth: float = 0.010
    finger_clearance: float = 0.003
    friction_coefficient: float = 0.5
    samples_per_finger: int = 12

    @property
    def friction_cone_half_angle(self) -> float:
        return math.atan(self.friction_coefficient)


YUMI_SMART_GRIPPER = DMGGripperModel()


@dataclass(frozen=True)
class DMGConfig:
    """Resolution of the graph and the planner's cost.

    ``patch_size`` (m): edge of the voxel cells that group faces into patches
    (the DMG's super-voxels); ``patch_normal_angle`` (deg): faces in one cell
    whose normals differ by more are split into separate patches (so the two
    sides of a thin plate or the two faces at a box edge never merge).
    ``angle_step`` (deg): discretisation of the gripper angle about the
    normal (must divide 360). ``translation_normal_angle`` (deg): adjacent
    patches are joined by a translation edge only if their normals differ by
    less (a finger slides over a gently curved surface, not round a box
    edge). ``occupancy_pitch`` (m): voxel size of the inside/outside test for
    the gripper collision samples. ``rotation_weight`` (m/rad): cost of one
    radian of rotation in metres of sliding, the trade-off of the shortest
    path; ``secondary_jump_factor``: a translation edge is dropped when the
    secondary finger's contact would move more than this times the principal's
    step (plus one patch), i.e. when the opposite surface is not continuous.
    """

    patch_size: float = 0.010
    patch_normal_angle: float = 30.0
    angle_step: float = 10.0
    translation_normal_angle: float = 25.0
    occupancy_pitch: float = 0.0015
    rotation_weight: float = 0.01
    secondary_jump_factor: float = 2.0
    gripper: DMGGripperModel = field(default_factory=DMGGripperModel)

    def __post_init__(self) -> None:
        n = 360.0 / self.angle_step
        if self.angle_step <= 0 or abs(n - round(n)) > 1e-9:
            raise ValueError(f"angle_step must divide 360 degrees, got {self.angle_step}")
        if self.patch_size <= 0 or self.occupancy_pitch <= 0:
            raise ValueError("patch_size and occupancy_pitch must be positive lengths (m)")

    @property
    def n_angles(self) -> int:
        return int(round(360.0 / self.angle_step))

    @property
    def angles(self):
        """The discrete gripper angles (rad), ``k * angle_step`` for k = 0..n-1."""
        import numpy as np

        return np.deg2rad(np.arange(self.n_angles) * self.angle_step)


@dataclass(frozen=True)
class DMGSurface:
    """Which model of the object the DMG plans on, the trial simulates and the contact errors use.

    ``model="ycb"`` (default): the vendored YCB scan, which is already in the
    published frame (``docs/objects.md``, "Frames of the published data":
    the DMG.ods contacts fixed it), so the task data need no placement; its
    zero-area faces are dropped for the graph (they have no normal).
    ``model="generated"``: the shape generated from the published dimensions
    with edge length ``resolution``, the published task data moved onto it by
    :mod:`.placement` (the default until 2026-12-05; ``--strategy-option
    model=generated``). The same model serves planning, the simulated body
    and G_euc / G_geo / G_min, so the contact errors are measured on the
    surface the gripper touched. Why the scan: the paper's objects are the
    YCB objects, and its G_min are the scans' (docs/dmg.md, "On the YCB
    scans").
    """

    #: the object model: the YCB scan, or the shape generated from the published dimensions
    model: Literal["generated", "ycb"] = "ycb"
    resolution: float = 0.003  #: m, edge length of the generated model (``model="generated"``)

    def __post_init__(self) -> None:
        if self.model not in ("generated", "ycb"):
            raise ValueError(f"surface model must be 'generated' or 'ycb', not {self.model!r}")
        if not self.resolution > 0:
            raise ValueError(
                f"resolution must be a positive length in metres, not {self.resolution!r}"
            )
