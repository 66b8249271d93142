"""PR2: mobile base (fixed), torso lift, two 7-DOF arms, two parallel grippers.

Joint origins, axes, limits, soft limits, link masses, centres of mass and
inertia tensors are those of the Willow Garage ``pr2_description`` xacros
(github.com/PR2/pr2_common at commit c36a5c9c8d5e97d2d53a7c75fa57a3257a7c63cc,
files named in each comment); velocity limits there are
``VELOCITY_LIMIT_SCALE * v`` with the scale 0.6 from
``pr2_description/urdf/common.xacro``. Collision shapes are primitive
stand-ins for the meshes, sized to keep non-adjacent links apart in the home
pose; the inertials are the published ones, not the shapes' (a shape's
centre lies up to 16 cm from the real COM).

Soft limits: the real PR2's safety controller keeps every arm joint and the
torso inside ``<safety_controller soft_lower_limit/soft_upper_limit>``, a few
tenths of a radian inside the hard ``<limit>``. Both are written here as
published; the harness's IK and motion primitives respect the soft limits
(``RobotConfig.soft_limits``), the engines the hard ones.

Simplifications (also in robots/pr2/README.md):
* the gripper's four-bar fingers: each finger is a lateral prismatic joint
  (the commanded half opening) carrying a fingertip slide along the approach
  that the controller keeps on the linkage's arc (``FingertipLinkage``), so
  the fingertip frames and pads are where the published linkage puts them at
  every opening, parallel to the palm; the proximal bar is a box that
  translates with the finger (the real link turns), and a load along the
  approach is carried by the fingertip's stiff drive, not the linkage. The
  file has no ``<mimic>`` (PhysX has no mimic joints): the fingers take one
  command in the controller, and the published left-right mimic is an engine
  constraint the robot makes at spawn (``GripperConfig.mimic``;
  docs/robots.md, "PR2 gripper: symmetric fingers");
* forearm roll and wrist roll are ``continuous``, as on the robot: a twist
  or a hand-over turn can carry on past +/-pi without the arm having to
  switch IK branch (unwind) mid-turn. IK searches them over +/-pi and
  ``RobotArm.ik`` unwraps each solution to the 2*pi-branch nearest the seed;
  PyBullet and SAPIEN load them as unlimited revolute joints;
* no head, no laser tilt, no casters: the base is one fixed box.
"""

from __future__ import annotations

import math

from ..urdf_builder import Geom, UrdfBuilder

PR2_COMMIT = (
    "c36a5c9c8d5e97d2d53a7c75fa57a3257a7c63cc"  #: PR2/pr2_common commit the figures are read at
)
PR2_SRC = "PR2/pr2_common pr2_description"
VSCALE = 0.6  # VELOCITY_LIMIT_SCALE, pr2_description/urdf/common.xacro

#: ``<safety_controller>`` of each limited joint: (soft margin above the hard lower limit, soft margin below
#: the hard upper limit, k_position, k_velocity), as written in pr2_description: shoulder_v0/shoulder.urdf.xacro
#: (pan ``+-0.15``, lift ``-0.5236+0.17`` / ``1.3963-0.10``, upper-arm roll ``+-0.15``),
#: upper_arm_v0/upper_arm.urdf.xacro (elbow ``-2.3213+0.2`` / ``0.00-0.15``), forearm_v0/forearm.urdf.xacro
#: (wrist flex ``-2.18+0.18`` / ``0.0-0.10``), torso_v0/torso.urdf.xacro (``0.0+0.0115`` / ``0.33-0.005``).
#: Forearm and wrist roll are continuous: their safety controllers limit velocity only.
SAFETY: dict[str, tuple[float, float, float, float]] = {
    "shoulder_pan": (0.15, 0.15, 100.0, 10.0),
    "shoulder_lift": (0.17, 0.10, 100.0, 10.0),
    "upper_arm_roll": (0.15, 0.15, 100.0, 2.0),
    "elbow_flex": (0.2, 0.15, 100.0, 3.0),
    "wrist_flex": (0.18, 0.10, 20.0, 4.0),
    "torso_lift": (0.0115, 0.005, 100.0, 2000000.0),
}
WRIST_FLEX_LOWER = -2.18  # rad, l_wrist_flex_joint limit lower (forearm_v0/forearm.urdf.xacro)


def _soft(key: str, lower: float, upper: float) -> dict[str, float]:
    """Joint keyword arguments for the published soft limits of joint ``key`` with hard ``lower..upper``."""
    lo, hi, kp, kv = SAFETY[key]
    return {
        "lower": lower,
        "upper": upper,
        "soft_lower": round(lower + lo, 10),
        "soft_upper": round(upper - hi, 10),
        "k_position": kp,
        "k_velocity": kv,
    }


#: Gripper figures. The real finger is a parallelogram four-bar (pr2_description
#: gripper_v0/gripper.urdf.xacro): ``*_l_finger_joint`` turns the proximal link by theta about z at
#: (FINGER_X, FINGER_Y), and ``*_l_finger_tip_joint`` (mimic +1, axis -z) turns the fingertip back by theta at
#: FINGER_TO_TIP along it, so the fingertip stays parallel to the palm while its origin travels on a
#: circle of radius FINGER_RADIUS about the pivot. We model exactly that pad motion with two prismatic
#: joints per finger (see :func:`_gripper`).
GRIPPER_MAX_OPENING = 0.09  # m; l_gripper_joint upper="0.09" (gripper_v0/gripper.urdf.xacro)
#: m/s per finger: l_gripper_joint (the gap between the fingers) velocity="0.2" (gripper_v0/gripper.urdf.xacro)
GRIPPER_CLOSE_SPEED = 0.2 / 2
PAD_GAP = 0.001  # m; each pad's inner face sits this far out from the finger joint value (pads never interpenetrate)
FINGER_TRAVEL = (GRIPPER_MAX_OPENING - 2 * PAD_GAP) / 2  # per finger
TCP_X = 0.18  # m; l_gripper_tool_frame origin xyz="0.18 0 0" (pr2_description gripper_v0/gripper.urdf.xacro)
FINGER_X = 0.07691  # m; l_gripper_l_finger_joint origin x (palm_to_finger_x, gripper_v0/gripper.urdf.xacro)
FINGER_Y = 0.01  # m; l_gripper_l_finger_joint origin y (gripper_v0/gripper.urdf.xacro)
#: l_gripper_l_finger_tip_joint origin in the proximal link: finger_to_finger_tip_x, 0.00495 (gripper.urdf.xacro)
FINGER_TO_TIP = (0.09137, 0.00495)
FINGER_RADIUS = math.hypot(
    *FINGER_TO_TIP
)  # 0.091504 m: the transmission's r = 91.5 mm (pr2.urdf.xacro)
#: The fingertip pad (meshes/gripper_v0/finger_tip_pad2_l.stl, in the fingertip frame): x -0.00475..0.03125,
#: inner face at y = -0.01495 (so the faces meet at theta = 0, the closed gripper: 0.01 + 0.00495 - 0.01495),
#: z -0.0115..0.0115 (bounds read with trimesh from the file at the commit above).
PAD_FACE_Y = 0.01495
PAD_CENTRE_X = (0.03125 - 0.00475) / 2  # 0.01325 m in the fingertip frame
PAD_SIZE = (
    0.036,
    0.006,
    0.023,
)  # m (along approach, thickness, height): the pad mesh's 36 x 23 mm face; 6 mm of fingertip behind it
#: Published fingertip inertial (l/r_gripper_*_finger_tip_link, gripper.urdf.xacro): our fingertip link
#: frame is the real one (the same origin and, the linkage being a parallelogram, the same orientation).
TIP_MASS = 0.04419
TIP_COM = {"l": (0.00423, 0.00284, 0.0), "r": (0.00423, -0.00284, 0.0)}
TIP_INERTIA = {
    "l": (0.00000837047, 0.00000583632, 0.0, 0.00000987067, 0.0, 0.00001541768),
    "r": (0.00000837047, -0.00000583632, 0.0, 0.00000987067, 0.0, 0.00001541768),
}
FINGER_MASS = {"l": 0.17126, "r": 0.17389}  # kg, l/r_gripper_*_finger_link (gripper.urdf.xacro)


def tip_x(half_opening: float) -> float:
    """Fingertip-frame origin along the approach (palm frame, m) with the pads ``half_opening`` out.

    The tip origin is FINGER_RADIUS from the pivot at angle ``theta + phi``; its lateral
    coordinate ``FINGER_Y + R sin(theta + phi) = half_opening + PAD_FACE_Y`` fixes the angle.
    """
    s = (half_opening + PAD_FACE_Y - FINGER_Y) / FINGER_RADIUS
    return FINGER_X + FINGER_RADIUS * math.sqrt(max(0.0, 1.0 - s * s))


def pad_setback(opening: float) -> float:
    """How far (m) the pads' centre sits behind the tool frame with the pads ``opening`` apart.

    -1.5 mm (in front) closed, 4.7 mm at a 57 mm grip, 13.2 mm at the 90 mm opening: the four-bar's
    arc. Strategies that place a pad on part of an object use this, not the tool frame.
    """
    return TCP_X - (tip_x(opening / 2.0) + PAD_CENTRE_X)


#: (centre, size) in the palm frame of the palm's collision box (a stand-in for the palm mesh, see _gripper)
PALM_BOX = ((0.08, 0.0, 0.0), (0.06, 0.07, 0.05))
BAR_X0 = FINGER_X + 0.02  # m: the finger bar's palm end (a stand-in for the proximal link's shape)
BAR_SIZE_YZ = (0.008, 0.02)  # m


def _bar_length() -> float:
    """The bar reaches the fully open pad's back end (it rides the lateral joint only)."""
    return tip_x(FINGER_TRAVEL + PAD_GAP) + PAD_CENTRE_X - PAD_SIZE[0] / 2 - BAR_X0


def _pad_centre(sign: float) -> tuple[float, float, float]:
    """Centre of the pad box in its fingertip frame (``sign`` +1 left finger, -1 right)."""
    return (PAD_CENTRE_X, sign * (PAD_SIZE[1] / 2 - PAD_FACE_Y), 0.0)


def _bar_centre(sign: float) -> tuple[float, float, float]:
    """Centre of the finger bar in its finger frame (level with the fingertip frame), outside the pad."""
    return (BAR_X0 + _bar_length() / 2, sign * (PAD_SIZE[1] + 0.004 - PAD_FACE_Y), 0.0)


def finger_boxes(
    opening: float,
) -> list[tuple[tuple[float, float, float], tuple[float, float, float]]]:
    """(centre, size) in the palm frame of each pad and finger bar with the pads ``opening`` apart.

    The collision geometry :func:`_gripper` writes, placed at an opening: for planners that must
    keep the fingers clear of something before commanding them.
    """
    h = opening / 2.0
    x_tip = tip_x(h)
    bar_size = (_bar_length(), *BAR_SIZE_YZ)
    out = []
    for sign in (1.0, -1.0):
        y_tip = sign * (h + PAD_FACE_Y)  # the fingertip and finger frames' lateral position
        px, py, pz = _pad_centre(sign)
        bx, by, bz = _bar_centre(sign)
        out.append(((x_tip + px, y_tip + py, pz), PAD_SIZE))
        out.append(((bx, y_tip + by, bz), bar_size))
    return out


def tip_slide(half_opening: float) -> float:
    """The model's fingertip slide joint value (m) for pads ``half_opening`` out: 0 when closed."""
    return tip_x(half_opening) - tip_x(0.0)


#: Upper-arm COM and inertia, which pr2_description gives per side (``ual_*`` left, ``uar_*`` right,
#: upper_arm_v0/upper_arm.urdf.xacro).
UPPER_ARM_COM = {"l": (0.21405, 0.01658, -0.00057), "r": (0.21398, -0.01621, -0.00020)}
UPPER_ARM_INERTIA = {
    "l": (
        0.01530603856,
        -0.00339324862,
        0.00060765455,
        0.07473694455,
        -0.00019953729,
        0.07601594191,
    ),
    "r": (
        0.01537748957,
        0.00375711247,
        -0.00070852914,
        0.07473670440,
        -0.00017936450,
        0.07608763307,
    ),
}


def _arm(m: UrdfBuilder, side: str) -> None:
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
        **_soft("shoulder_pan", reflect * math.pi / 4 - 1.5, reflect * math.pi / 4 + 1.5),
        effort=30,
        velocity=VSCALE * 3.48,
        damping=10.0,
        source=f"origin 0 +-0.188 0 (pr2_description/robots/pr2.urdf.xacro); limits reflect*pi/4 +- 1.5, "
        f"soft limits 0.15 inside, effort 30, velocity 0.6*3.48 ({src} shoulder_v0/shoulder.urdf.xacro)",
    )
    m.link(
        f"{s}_shoulder_pan_link",
        [Geom("cylinder", (0.06, 0.30), (0.0, 0.0, -0.10))],
        25.799322,
        com=(-0.001201, 0.024513, -0.098231),
        inertia=(
            0.866179142480,
            -0.06086507933,
            -0.12118061183,
            0.87421714893,
            -0.05886609911,
            0.27353821674,
        ),
        source="mass, COM and inertia as published, the same for both sides (shoulder_v0/shoulder.urdf.xacro); "
        "cylinder stands in for the shoulder mesh",
    )
    m.joint(
        f"{s}_shoulder_lift_joint",
        "revolute",
        f"{s}_shoulder_pan_link",
        f"{s}_shoulder_lift_link",
        xyz=(0.1, 0.0, 0.0),
        axis=(0, 1, 0),
        **_soft("shoulder_lift", -0.5236, 1.3963),
        effort=30,
        velocity=VSCALE * 3.47,
        damping=10.0,
        source="origin 0.1 0 0, axis y, limits -0.5236..1.3963, soft -0.3536..1.2963, effort 30, velocity 0.6*3.47 "
        "(shoulder_v0/shoulder.urdf.xacro)",
    )
    m.link(
        f"{s}_shoulder_lift_link",
        [Geom("sphere", (0.06,))],
        2.74988,
        com=(0.02195, -0.02664, -0.03127),
        inertia=(
            0.02105584615,
            0.00496704022,
            -0.00194808955,
            0.02127223737,
            0.00110425490,
            0.01975753814,
        ),
        source="mass, COM and inertia as published (shoulder_v0/shoulder.urdf.xacro)",
    )
    m.joint(
        f"{s}_upper_arm_roll_joint",
        "revolute",
        f"{s}_shoulder_lift_link",
        f"{s}_upper_arm_roll_link",
        axis=(1, 0, 0),
        **_soft("upper_arm_roll", reflect * 1.55 - 2.35, reflect * 1.55 + 2.35),
        effort=30,
        velocity=VSCALE * 5.45,
        damping=0.1,
        source="origin 0, axis x, limits reflect*1.55 +- 2.35, soft limits 0.15 inside, effort 30, velocity 0.6*5.45 "
        "(shoulder_v0/shoulder.urdf.xacro)",
    )
    m.link(
        f"{s}_upper_arm_roll_link",
        mass=0.1,
        point_mass_radius=0.02,
        source="0.1 kg placeholder mass at the origin as in pr2_description (upper_arm_roll_link, 'dummy mass, "
        "to be removed'); inertia of a 2 cm solid sphere, not the placeholder 0.01 kg m^2",
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
        com=UPPER_ARM_COM[s],
        inertia=UPPER_ARM_INERTIA[s],
        source="mass 6.01769 kg, COM and inertia as published for this side (ual_*/uar_*, "
        "upper_arm_v0/upper_arm.urdf.xacro); box x 0.07..0.28 m of the 0.4 m upper arm "
        "(ends 0.12 m short of the elbow so that the full -2.32 rad elbow flex is collision-free)",
    )
    m.joint(
        f"{s}_elbow_flex_joint",
        "revolute",
        f"{s}_upper_arm_link",
        f"{s}_elbow_flex_link",
        xyz=(0.4, 0.0, 0.0),
        axis=(0, 1, 0),
        **_soft("elbow_flex", -2.3213, 0.0),
        effort=30,
        velocity=VSCALE * 5.5,
        damping=1.0,
        source="origin 0.4 0 0, axis y, limits -2.3213..0, soft -2.1213..-0.15, effort 30, velocity 0.6*5.5 "
        "(upper_arm_v0/upper_arm.urdf.xacro)",
    )
    m.link(
        f"{s}_elbow_flex_link",
        [Geom("sphere", (0.05,))],
        1.90327,
        com=(0.01014, 0.00032, -0.01211),
        inertia=(
            0.00346541989,
            0.00004066825,
            0.00043171614,
            0.00441606455,
            -0.00003968914,
            0.00359156824,
        ),
        source="mass, COM and inertia as published (upper_arm_v0/upper_arm.urdf.xacro)",
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
        source="0.1 kg placeholder mass at the origin as in pr2_description ('dummy masses, to be removed'); "
        "inertia of a 2 cm solid sphere, not the placeholder 0.01 kg m^2",
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
        com=(0.18791, -0.00017, -0.00912),
        inertia=(
            0.00364857222,
            0.00005215877,
            0.00071534842,
            0.01507736897,
            -0.00001310770,
            0.01659310749,
        ),
        source="mass, COM and inertia as published (forearm_v0/forearm.urdf.xacro); box x 0.12..0.24 m "
        "(ends 0.081 m short of the wrist flex axis, where the real forearm tapers, so that the full -2.18 rad "
        "wrist flex is collision-free with the palm at any wrist roll)",
    )
    m.joint(
        f"{s}_wrist_flex_joint",
        "revolute",
        f"{s}_forearm_link",
        f"{s}_wrist_flex_link",
        xyz=(0.321, 0.0, 0.0),
        axis=(0, 1, 0),
        **_soft("wrist_flex", WRIST_FLEX_LOWER, 0.0),
        effort=10,
        velocity=VSCALE * 5.13,
        damping=0.1,
        source="origin 0.321 0 0, axis y, limits -2.18..0, soft -2.0..-0.1, effort 10, velocity 0.6*5.13 "
        "(forearm_v0/forearm.urdf.xacro)",
    )
    m.link(
        f"{s}_wrist_flex_link",
        [Geom("sphere", (0.035,))],
        0.61402,
        com=(-0.00157, 0.0, -0.00075),
        inertia=(
            0.00065165722,
            0.00000028864,
            0.00000303477,
            0.00019824443,
            -0.00000022645,
            0.00064450498,
        ),
        source="mass, COM and inertia as published (forearm_v0/forearm.urdf.xacro)",
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
        source="0.1 kg placeholder mass at the origin as in pr2_description ('dummy masses, to be removed'); "
        "inertia of a 2 cm solid sphere, not the placeholder 0.01 kg m^2",
    )
    _gripper(m, s)


def _gripper(m: UrdfBuilder, s: str) -> None:
    m.joint(
        f"{s}_gripper_palm_joint",
        "fixed",
        f"{s}_wrist_roll_link",
        f"{s}_gripper_palm_link",
        source="fixed, origin 0 (gripper_v0/gripper.urdf.xacro)",
    )
    m.link(
        f"{s}_gripper_palm_link",
        [Geom("box", PALM_BOX[1], PALM_BOX[0])],
        0.58007,
        com=(0.06623, 0.00053, -0.00119),
        inertia=(
            0.00035223921,
            -0.00001580476,
            -0.00000091750,
            0.00067741312,
            -0.00000059554,
            0.00086563316,
        ),
        source="mass, COM and inertia as published (gripper_v0/gripper.urdf.xacro); box x 0.05..0.11 m stands in "
        "for the palm mesh",
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
    # Each finger: a lateral prismatic joint (the commanded half opening, N of grip force) carrying the
    # proximal bar, then a fingertip slide along the approach that the controller keeps at
    # tip_slide(half opening) (FingertipLinkage in robots/config.py): the pad face then is where the
    # real four-bar puts it at every opening, parallel to the palm, as the real mimic chain keeps it.
    bar_size = (_bar_length(), *BAR_SIZE_YZ)
    for finger, sign in (("l", 1.0), ("r", -1.0)):
        m.joint(
            f"{s}_gripper_{finger}_finger_joint",
            "prismatic",
            f"{s}_gripper_palm_link",
            f"{s}_gripper_{finger}_finger_link",
            xyz=(0.0, sign * (PAD_GAP + PAD_FACE_Y), 0.0),
            axis=(0.0, sign, 0.0),
            lower=0.0,
            upper=FINGER_TRAVEL,
            effort=100.0,
            velocity=0.2,
            damping=0.0,
            source="lateral stand-in for the four-bar's proximal joint (l_gripper_l_finger_joint, "
            "gripper_v0/gripper.urdf.xacro): the child frame is level with the real fingertip frame; travel "
            "0..0.044 m per finger = 0..90 mm opening with 1 mm pad gaps; velocity 0.2 m/s as l_gripper_joint; "
            "effort 100 N (assumed, above the 20 N default grip)",
        )
        m.link(
            f"{s}_gripper_{finger}_finger_link",
            [Geom("box", bar_size, _bar_centre(sign))],
            FINGER_MASS[finger],
            source=f"mass {FINGER_MASS[finger]} kg of {s}_gripper_{finger}_finger_link (gripper_v0/gripper.urdf.xacro); "
            "COM and inertia from the bar (the published ones are of the revolute proximal link)",
        )
        m.joint(
            f"{s}_gripper_{finger}_finger_tip_joint",
            "prismatic",
            f"{s}_gripper_{finger}_finger_link",
            f"{s}_gripper_{finger}_finger_tip_link",
            xyz=(tip_x(0.0), 0.0, 0.0),
            axis=(1.0, 0.0, 0.0),
            lower=round(tip_slide(FINGER_TRAVEL + PAD_GAP), 9),
            upper=0.0,
            effort=1000.0,
            velocity=0.2,
            damping=0.0,
            source="fingertip slide along the approach, kept at the four-bar's arc: tip x = 0.07691 + R cos(theta + phi), "
            "R = |(0.09137, 0.00495)| (finger and fingertip joint origins, gripper_v0/gripper.urdf.xacro); "
            "effort 1000 as finger_joint_effort_limit (the linkage is rigid)",
        )
        m.link(
            f"{s}_gripper_{finger}_finger_tip_link",
            [Geom("box", PAD_SIZE, _pad_centre(sign))],
            TIP_MASS,
            com=TIP_COM[finger],
            inertia=TIP_INERTIA[finger],
            source=f"{s}_gripper_{finger}_finger_tip_link: mass, COM and inertia as published (gripper.urdf.xacro); "
            "pad box = the 36 x 23 mm face of meshes/gripper_v0/finger_tip_pad2_l.stl, inner face 0.01495 m "
            "inside the fingertip frame",
        )


def build() -> UrdfBuilder:
    m = UrdfBuilder(
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
        com=(-0.061, 0.0, 0.5 * 0.293),
        inertia=(
            5.652232699207,
            -0.009719934438,
            1.293988226423,
            5.669473158652,
            -0.007379583694,
            3.683196351726,
        ),
        source="mass 116 kg, COM (base_cg_x/y/z) and inertia as published (base_v0/base.urdf.xacro); box 0.65 m "
        "square (0.668 m footprint), top 0.35 m above floor",
    )
    m.joint(
        "torso_lift_joint",
        "prismatic",
        "base_link",
        "torso_lift_link",
        xyz=(-0.05, 0.0, 0.739675),
        axis=(0, 0, 1),
        **_soft("torso_lift", 0.0, 0.33),
        effort=10000,
        velocity=0.013,
        damping=20000.0,
        source="origin -0.05 0 0.739675 (pr2_description/robots/pr2.urdf.xacro), limits 0..0.33 m, soft "
        "0.0115..0.325 m, effort 10000, velocity 0.013 (torso_v0/torso.urdf.xacro)",
    )
    m.link(
        "torso_lift_link",
        [Geom("box", (0.20, 0.14, 0.80), (-0.075, 0.0, -0.25))],
        36.248046,
        com=(-0.1, 0.0, -0.0885),
        inertia=(
            2.771653750257,
            0.004284522609,
            -0.160418504506,
            2.510019507959,
            0.029664468704,
            0.526432355569,
        ),
        source="mass, COM and inertia as published (torso_v0/torso.urdf.xacro); column box stands in for the torso mesh, "
        "its front face 0.025 m ahead of the shoulder pan axes and 0.14 m wide (the 0.376 m between the "
        "shoulder pan axes is shoulder, not column) so that the shoulders pan fully inwards without touching it",
    )
    _arm(m, "l")
    _arm(m, "r")
    return m
