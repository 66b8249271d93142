"""PR2: mobile base (fixed), torso lift, two 7-DOF arms, two parallel grippers.

Joint origins, axes, limits and link masses are those of the Willow Garage
``pr2_description`` xacros (github.com/PR2/pr2_common, files named in each
comment); velocity limits there are ``VELOCITY_LIMIT_SCALE * v`` with the
scale 0.6 from ``pr2_description/urdf/common.xacro``. Collision shapes are
primitive stand-ins for the meshes, sized to keep non-adjacent links apart
in the home pose.

Simplifications (also in robots/pr2/README.md):
* the gripper is two prismatic fingers (the real one is a four-bar linkage
  whose pads stay parallel); the fingers are coupled in the controller, not
  by ``<mimic>`` (PhysX has no mimic joints);
* forearm roll and wrist roll are ``continuous``, as on the robot: a twist
  or a hand-over turn can carry on past +/-pi without the arm having to
  switch IK branch (unwind) mid-turn. IK searches them over +/-pi and
  ``RobotArm.ik`` unwraps each solution to the 2*pi-branch nearest the seed;
  PyBullet and SAPIEN load them as unlimited revolute joints;
* no head, no laser tilt, no casters: the base is one fixed box.
"""

from __future__ import annotations

import math

from ..urdf_builder import Geom, UrdfModel

PR2_SRC = "PR2/pr2_common pr2_description"
VSCALE = 0.6  # VELOCITY_LIMIT_SCALE, pr2_description/urdf/common.xacro

#: Gripper figures.
GRIPPER_MAX_OPENING = (
    0.09  # m; PR2 gripper opens to ~90 mm (l_gripper_joint upper 0.088 in pr2_description)
)
PAD_GAP = 0.001  # m; each pad's inner face sits this far out from the finger joint value (pads never interpenetrate)
FINGER_TRAVEL = (GRIPPER_MAX_OPENING - 2 * PAD_GAP) / 2  # per finger
PAD_SIZE = (
    0.035,
    0.006,
    0.022,
)  # m (along approach, thickness, height): PR2 fingertip pad ~22 mm tall; 35 mm long covers <= 2 of the 19 mm cube slabs
TCP_X = 0.18  # m; l_gripper_tool_frame origin xyz="0.18 0 0" (pr2_description gripper_v0/gripper.urdf.xacro)
FINGER_X = 0.07691  # m; l_gripper_l_finger_joint origin x (gripper_v0/gripper.urdf.xacro)


def _arm(m: UrdfModel, side: str) -> None:
    reflect = 1 if side == "l" else -1
    s = side
    src = PR2_SRC
    m.joint(
        f"{s}_shoulder_pan_joint",
        "revolute",
        "torso_lift_link",
        f"{s}_shoulder_pan_link",
        xyz=(0.0, reflect * 0.188, 0.0),
        axis=(0, 0, 1),
        lower=reflect * math.pi / 4 - 1.5,
        upper=reflect * math.pi / 4 + 1.5,
        effort=30,
        velocity=VSCALE * 3.48,
        damping=10.0,
        source=f"origin 0 +-0.188 0 (pr2_description/urdf/arm_v0 / pr2.urdf.xacro); limits reflect*pi/4 +- 1.5, "
        f"effort 30, velocity 0.6*3.48 ({src} shoulder_v0/shoulder.urdf.xacro)",
    )
    m.link(
        f"{s}_shoulder_pan_link",
        [Geom("cylinder", (0.06, 0.30), (0.0, 0.0, -0.10))],
        25.799322,
        source="mass 25.799322 kg, COM z -0.098 (shoulder_v0/shoulder.urdf.xacro); cylinder stands in for the shoulder mesh",
    )
    m.joint(
        f"{s}_shoulder_lift_joint",
        "revolute",
        f"{s}_shoulder_pan_link",
        f"{s}_shoulder_lift_link",
        xyz=(0.1, 0.0, 0.0),
        axis=(0, 1, 0),
        lower=-0.5236,
        upper=1.3963,
        effort=30,
        velocity=VSCALE * 3.47,
        damping=10.0,
        source="origin 0.1 0 0, axis y, limits -0.5236..1.3963, effort 30, velocity 0.6*3.47 (shoulder_v0/shoulder.urdf.xacro)",
    )
    m.link(
        f"{s}_shoulder_lift_link",
        [Geom("sphere", (0.06,))],
        2.74988,
        source="mass 2.74988 kg (shoulder_v0/shoulder.urdf.xacro)",
    )
    m.joint(
        f"{s}_upper_arm_roll_joint",
        "revolute",
        f"{s}_shoulder_lift_link",
        f"{s}_upper_arm_roll_link",
        axis=(1, 0, 0),
        lower=reflect * 1.55 - 2.35,
        upper=reflect * 1.55 + 2.35,
        effort=30,
        velocity=VSCALE * 5.45,
        damping=0.1,
        source="origin 0, axis x, limits reflect*1.55 +- 2.35, effort 30, velocity 0.6*5.45 (shoulder_v0/shoulder.urdf.xacro)",
    )
    m.link(
        f"{s}_upper_arm_roll_link",
        mass=0.1,
        point_mass_radius=0.02,
        source="0.1 kg placeholder mass as in pr2_description (upper_arm_roll_link); inertia of a 2 cm solid sphere",
    )
    m.joint(
        f"{s}_upper_arm_joint",
        "fixed",
        f"{s}_upper_arm_roll_link",
        f"{s}_upper_arm_link",
        source="fixed, origin 0 (upper_arm_v0/upper_arm.urdf.xacro)",
    )
    m.link(
        f"{s}_upper_arm_link",
        [Geom("box", (0.21, 0.09, 0.09), (0.175, 0.0, 0.0))],
        6.01769,
        source="mass 6.01769 kg (upper_arm_v0/upper_arm.urdf.xacro); box x 0.07..0.28 m of the 0.4 m upper arm "
        "(ends 0.12 m short of the elbow so that the full -2.32 rad elbow flex is collision-free)",
    )
    m.joint(
        f"{s}_elbow_flex_joint",
        "revolute",
        f"{s}_upper_arm_link",
        f"{s}_elbow_flex_link",
        xyz=(0.4, 0.0, 0.0),
        axis=(0, 1, 0),
        lower=-2.3213,
        upper=0.0,
        effort=30,
        velocity=VSCALE * 5.5,
        damping=1.0,
        source="origin 0.4 0 0, axis y, limits -2.3213..0, effort 30, velocity 0.6*5.5 (upper_arm_v0/upper_arm.urdf.xacro)",
    )
    m.link(
        f"{s}_elbow_flex_link",
        [Geom("sphere", (0.05,))],
        1.90327,
        source="mass 1.90327 kg (upper_arm_v0/upper_arm.urdf.xacro)",
    )
    m.joint(
        f"{s}_forearm_roll_joint",
        "continuous",
        f"{s}_elbow_flex_link",
        f"{s}_forearm_roll_link",
        axis=(1, 0, 0),
        effort=30,
        velocity=VSCALE * 6,
        damping=0.1,
        source="continuous, axis x, effort 30, velocity 0.6*6 (upper_arm_v0/upper_arm.urdf.xacro)",
    )
    m.link(
        f"{s}_forearm_roll_link",
        mass=0.1,
        point_mass_radius=0.02,
        source="0.1 kg placeholder mass as in pr2_description; inertia of a 2 cm solid sphere",
    )
    m.joint(
        f"{s}_forearm_joint",
        "fixed",
        f"{s}_forearm_roll_link",
        f"{s}_forearm_link",
        source="fixed, origin 0 (forearm_v0/forearm.urdf.xacro via arm macro)",
    )
    m.link(
        f"{s}_forearm_link",
        [Geom("box", (0.12, 0.08, 0.08), (0.18, 0.0, 0.0))],
        2.57968,
        source="mass 2.57968 kg, COM x 0.188 (forearm_v0/forearm.urdf.xacro); box x 0.12..0.24 m "
        "(ends 0.081 m short of the wrist flex axis, where the real forearm tapers, so that the full -2.094 rad "
        "wrist flex is collision-free with the palm at any wrist roll)",
    )
    m.joint(
        f"{s}_wrist_flex_joint",
        "revolute",
        f"{s}_forearm_link",
        f"{s}_wrist_flex_link",
        xyz=(0.321, 0.0, 0.0),
        axis=(0, 1, 0),
        lower=-2.094,
        upper=0.0,
        effort=10,
        velocity=VSCALE * 5.13,
        damping=0.1,
        source="origin 0.321 0 0, axis y, limits -2.094..0, effort 10, velocity 0.6*5.13 (forearm_v0/forearm.urdf.xacro)",
    )
    m.link(
        f"{s}_wrist_flex_link",
        [Geom("sphere", (0.035,))],
        0.61402,
        source="mass 0.61402 kg (forearm_v0/forearm.urdf.xacro)",
    )
    m.joint(
        f"{s}_wrist_roll_joint",
        "continuous",
        f"{s}_wrist_flex_link",
        f"{s}_wrist_roll_link",
        axis=(1, 0, 0),
        effort=10,
        velocity=VSCALE * 6,
        damping=0.1,
        source="continuous, axis x, effort 10, velocity 0.6*6 (forearm_v0/forearm.urdf.xacro)",
    )
    m.link(
        f"{s}_wrist_roll_link",
        mass=0.1,
        point_mass_radius=0.02,
        source="0.1 kg placeholder mass as in pr2_description; inertia of a 2 cm solid sphere",
    )
    _gripper(m, s)


def _gripper(m: UrdfModel, s: str) -> None:
    m.joint(
        f"{s}_gripper_palm_joint",
        "fixed",
        f"{s}_wrist_roll_link",
        f"{s}_gripper_palm_link",
        source="fixed, origin 0 (gripper_v0/gripper.urdf.xacro)",
    )
    m.link(
        f"{s}_gripper_palm_link",
        [Geom("box", (0.06, 0.07, 0.05), (0.08, 0.0, 0.0))],
        0.58007,
        source="mass 0.58007 kg (gripper_v0/gripper.urdf.xacro); box x 0.05..0.11 m stands in for the palm mesh",
    )
    m.joint(
        f"{s}_gripper_tcp_joint",
        "fixed",
        f"{s}_gripper_palm_link",
        f"{s}_gripper_tcp",
        xyz=(TCP_X, 0.0, 0.0),
        source="tool centre point = l_gripper_tool_frame, origin 0.18 0 0 (gripper_v0/gripper.urdf.xacro)",
    )
    m.link(
        f"{s}_gripper_tcp",
        source="tool-centre-point frame: x = approach, y = finger opening direction",
    )
    pad_cx = TCP_X - FINGER_X
    bar_len = pad_cx - PAD_SIZE[0] / 2 - 0.02
    for finger, sign in (("l", 1.0), ("r", -1.0)):
        m.joint(
            f"{s}_gripper_{finger}_finger_joint",
            "prismatic",
            f"{s}_gripper_palm_link",
            f"{s}_gripper_{finger}_finger_link",
            xyz=(FINGER_X, 0.0, 0.0),
            axis=(0.0, sign, 0.0),
            lower=0.0,
            upper=FINGER_TRAVEL,
            effort=100.0,
            velocity=0.2,
            damping=0.0,
            source=f"finger base x {FINGER_X} (l_gripper_l_finger_joint origin, gripper_v0/gripper.urdf.xacro); "
            "prismatic stand-in for the linkage: travel 0..0.044 m per finger = 0..90 mm opening with 1 mm pad gaps; "
            "velocity 0.2 m/s as l_gripper_joint; effort 100 N (assumed, above the 20 N default grip)",
        )
        pad_y = sign * (PAD_GAP + PAD_SIZE[1] / 2)
        bar_y = sign * (PAD_GAP + PAD_SIZE[1] + 0.004)
        m.link(
            f"{s}_gripper_{finger}_finger_link",
            [
                Geom("box", PAD_SIZE, (pad_cx, pad_y, 0.0)),
                Geom("box", (bar_len, 0.008, 0.02), (0.02 + bar_len / 2, bar_y, 0.0)),
            ],
            0.17126 + 0.04419,
            source="mass 0.17126 + 0.04419 kg = finger + fingertip links (gripper_v0/gripper.urdf.xacro); "
            "pad centred on the tool frame, 35 x 22 mm face",
        )


def build() -> UrdfModel:
    m = UrdfModel(
        "pr2",
        header=__doc__ or "",
    )
    m.link("base_footprint", source="floor frame under the base (pr2_description base_v0)")
    m.joint(
        "base_footprint_joint",
        "fixed",
        "base_footprint",
        "base_link",
        xyz=(0.0, 0.0, 0.051),
        source="base_link 0.051 m above base_footprint (pr2_description base_v0/base.urdf.xacro)",
    )
    m.link(
        "base_link",
        [Geom("box", (0.65, 0.65, 0.29), (0.0, 0.0, 0.105))],
        116.0,
        source="mass 116 kg (base_v0/base.urdf.xacro); box 0.65 m square (0.668 m footprint), top 0.35 m above floor",
    )
    m.joint(
        "torso_lift_joint",
        "prismatic",
        "base_link",
        "torso_lift_link",
        xyz=(-0.05, 0.0, 0.739675),
        axis=(0, 0, 1),
        lower=0.0,
        upper=0.33,
        effort=10000,
        velocity=0.013,
        damping=20000.0,
        source="origin -0.05 0 0.739675, limits 0..0.33 m, effort 10000, velocity 0.013 (torso_v0/torso.urdf.xacro)",
    )
    m.link(
        "torso_lift_link",
        [Geom("box", (0.20, 0.14, 0.80), (-0.075, 0.0, -0.25))],
        36.248046,
        source="mass 36.248046 kg (torso_v0/torso.urdf.xacro); column box stands in for the torso mesh, "
        "its front face 0.025 m ahead of the shoulder pan axes and 0.14 m wide (the 0.376 m between the "
        "shoulder pan axes is shoulder, not column) so that the shoulders pan fully inwards without touching it",
    )
    _arm(m, "l")
    _arm(m, "r")
    return m
