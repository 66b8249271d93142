"""PR2 gripper on an ideal 6-DOF positioning stage (for the in-hand parallel-gripper baselines).

The gripper (palm, two prismatic fingers, 35 x 22 mm pads, 0-90 mm opening)
is built by the same code as the PR2's right gripper
(:func:`benchharness.robots.descriptions.pr2._gripper`), so its figures and
their sources are the PR2's. It is carried by a stage instead of the PR2 arm:

* three prismatic joints along the world x, y, z (``stage_x/y/z_joint``);
* a spherical wrist (``wrist_yaw/pitch/roll_joint``, intrinsic Z-Y-X) whose
  three axes intersect **at the tool centre point**, i.e. a remote centre of
  motion between the finger pads. A fixed mount turns the tool frame so that
  with all wrist joints at zero the fingers point straight down (tool x =
  world -z) and the grasp (opening) axis is world y; ``wrist_pitch`` then
  turns the gripper about its own grasp axis, which is what pivoting and the
  DMG rotations need, and Euler's singularity (pitch = +-90 deg) is the
  approach horizontal, outside the top-grasp workspace the baselines use.

Why a stage and not the PR2 arm: the in-hand benchmark measures the change
of grasp, not arm control; decoupled position/orientation joints make every
hand pose a direct joint target (no IK), on both engines, and keep the test
of the gripper-object physics free of arm tracking errors. The stage links
have no collision shapes.
"""

from __future__ import annotations

import math

from ..urdf_builder import UrdfBuilder
from .pr2 import TCP_X, _gripper

#: Stage travel (m) about the world origin; z from the floor up.
STAGE_XY = 0.5
STAGE_Z = (0.0, 1.0)
STAGE_EFFORT = 200.0  # N (assumed: well above the ~12 N the gripper weighs)
STAGE_VELOCITY = 0.5  # m/s (assumed)
WRIST_EFFORT = 20.0  # N m (assumed: twice the PR2 wrist's 10 N m, the stage carries no arm)
WRIST_VELOCITY = (
    0.6 * 6.0
)  # rad/s: PR2 wrist_roll_joint velocity (forearm_v0), x 0.6 (VELOCITY_LIMIT_SCALE)
SIDE = "r"  #: the PR2 gripper used: right (link/joint names r_gripper_*)
#: Fixed mount: tool frame at zero wrist angles = (x down, y = world y, z = world x), as rpy.
MOUNT_RPY = (0.0, math.pi / 2, 0.0)


def build() -> UrdfBuilder:
    m = UrdfBuilder("pr2_gripper", header=__doc__ or "")
    m.link(
        "stage_base", source="world-fixed stage origin (assumed positioning stage; no collision)"
    )
    parent = "stage_base"
    for axis_name, axis, lo, hi in (
        ("x", (1, 0, 0), -STAGE_XY, STAGE_XY),
        ("y", (0, 1, 0), -STAGE_XY, STAGE_XY),
        ("z", (0, 0, 1), *STAGE_Z),
    ):
        child = f"stage_{axis_name}_link"
        m.joint(
            f"stage_{axis_name}_joint",
            "prismatic",
            parent,
            child,
            axis=axis,
            lower=lo,
            upper=hi,
            effort=STAGE_EFFORT,
            velocity=STAGE_VELOCITY,
            source=f"ideal Cartesian stage along world {axis_name} (assumed figures, see module docstring)",
        )
        m.link(
            child,
            mass=0.1,
            point_mass_radius=0.02,
            source="0.1 kg stage carriage (assumed), shapeless: inertia of a 2 cm solid sphere",
        )
        parent = child
    for name, axis, lo, hi in (
        ("yaw", (0, 0, 1), -2 * math.pi, 2 * math.pi),
        ("pitch", (0, 1, 0), -math.pi, math.pi),
        ("roll", (1, 0, 0), -math.pi, math.pi),
    ):
        child = f"wrist_{name}_link"
        m.joint(
            f"wrist_{name}_joint",
            "revolute",
            parent,
            child,
            axis=axis,
            lower=lo,
            upper=hi,
            effort=WRIST_EFFORT,
            velocity=WRIST_VELOCITY,
            source=f"spherical wrist, {name} (intrinsic Z-Y-X), axes through the tool centre point "
            "(remote centre of motion; assumed figures, velocity as PR2 wrist_roll_joint x 0.6)",
        )
        m.link(
            child,
            mass=0.05,
            point_mass_radius=0.01,
            source="0.05 kg wrist frame (assumed), shapeless: inertia of a 1 cm solid sphere",
        )
        parent = child
    m.joint(
        "gripper_mount_joint",
        "fixed",
        parent,
        "gripper_mount_link",
        xyz=(0.0, 0.0, 0.0),
        rpy=MOUNT_RPY,
        source="fixed mount: tool x = world -z at zero wrist angles (pitch 90 deg about y)",
    )
    m.link(
        "gripper_mount_link",
        mass=0.05,
        point_mass_radius=0.01,
        source="mount frame at the wrist centre (assumed 0.05 kg); the palm is moved back below",
    )
    # the PR2 palm frame is TCP_X behind the tool frame: put it there, so the wrist centre is the TCP
    m.joint(
        "gripper_offset_joint",
        "fixed",
        "gripper_mount_link",
        "gripper_base_link",
        xyz=(-TCP_X, 0.0, 0.0),
        source=f"palm frame {TCP_X} m behind the tool frame (l_gripper_tool_frame origin, gripper_v0/gripper.urdf.xacro)",
    )
    m.link(
        "gripper_base_link",
        mass=0.05,
        point_mass_radius=0.01,
        source="frame at the PR2 wrist-roll position (assumed 0.05 kg, shapeless)",
    )
    _gripper_on(m, "gripper_base_link")
    return m


def _gripper_on(m: UrdfBuilder, parent: str) -> None:
    """The PR2 gripper (:func:`.pr2._gripper`) with its palm joint re-parented to ``parent``."""
    start = len(m.joints)
    _gripper(m, SIDE)
    palm = m.joints[start]
    assert palm.name == f"{SIDE}_gripper_palm_joint"
    palm.parent = parent
