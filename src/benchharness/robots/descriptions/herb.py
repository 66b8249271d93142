"""HERB: two Barrett WAM 7-DOF arms mounted as on the real robot, each with a BarrettHand BH8-280.

Figures and where they come from (every link and joint of the URDF names its
source in a comment):

* **Arm mounts, torso frame, force/torque plate, hand rotation**:
  personalrobotics/herb_description @ 2604b90b3e89a9f1133355abbe2c9818509392ca,
  ``robots/herb.urdf.xacro`` (``/left/wam_mount``, ``/right/wam_mount``,
  ``force_torque_mount`` 0.06 m, ``hand_mount`` 0.012 m and yaw pi/2),
  ``robots/herb_base.urdf.xacro`` (``root_to_frame``: ``herb_frame`` 1.05 m
  up, yaw -pi/2), ``robots/wam.urdf.xacro`` (j1 origin 0.22/0.14/0.346 m in
  ``wam_base``; HERB's j1 has a +180 deg offset, ``limit`` 0.5416..5.7416).
  Both WAM j1 axes end up horizontal along the base's +x, at
  (0.3514, 0.2160, 0.9126) and (0.3514, -0.1908, 0.9126) m, 0.4068 m apart.
* **WAM joints**: the standard DH table of the WAM manual (the same origins
  as herb_description's ``wam.urdf.xacro`` j2..j7); limits and speed limits
  from that file; link masses from Barrett's WAM inertial specification
  (herb_description ``config/wam_params.urdf.xacro``).
* **BarrettHand**: jhu-lcsr/barrett_model @ b58cf4c0fbb0cd32fc0e8729f10a3d57d52715fc,
  ``models/hand.urdf.xacro``: every finger joint origin, axis and the
  zero convention (at joint 0 the proximal link lies flat, pointing radially
  out of the palm), the fixed 45 deg distal bend and 3 mm offset at the
  distal joint (``dist_joint`` origin (0.06994, 0.003, 0), rpy (0, 0, pi/4)),
  the 50 mm tip (``tip_joint``), the grasp frame 0.12 m out of the palm
  (``bhand_grasp_joint``), ranges spread 0..180, proximal 0..140, distal
  0..48 deg. The distal coupling 45/140 is herb_description's
  ``config/bh280_params.urdf.xacro`` (``mimic multiplier="${45./140.}"``).

Our joint q is the published one for every joint but HERB's j1, where our q1
= herb_description's q1 - pi (the standard WAM convention, range +-2.6 rad):
the pi turn is folded into the j1 joint origin.

Simplifications (also in robots/herb/README.md): collision shapes are
primitives (boxes, cylinders) around the published frames; torso and base are
boxes; the mass split inside the hand and WAM peak torques are assumed;
distal and spread coupling is done in the controller (no ``<mimic>``: PhysX
has none).
"""

from __future__ import annotations

import math

from ..urdf_builder import Geom, UrdfBuilder

HERB_DESCRIPTION = "personalrobotics/herb_description@2604b90b3e89a9f1133355abbe2c9818509392ca"
BARRETT_MODEL = "jhu-lcsr/barrett_model@b58cf4c0fbb0cd32fc0e8729f10a3d57d52715fc"

#: (a, alpha, d) of the WAM's 7 joints, metres/radians (WAM manual DH table; the same as
#: herb_description robots/wam.urdf.xacro j2..j7 origins and force_torque_mount 0.06 m).
WAM_DH = [
    (0.0, -math.pi / 2, 0.0),
    (0.0, math.pi / 2, 0.0),
    (0.045, -math.pi / 2, 0.55),
    (-0.045, math.pi / 2, 0.0),
    (0.0, -math.pi / 2, 0.3),
    (0.0, math.pi / 2, 0.0),
    (0.0, 0.0, 0.06),
]
#: Joint ranges (rad), herb_description robots/wam.urdf.xacro (j1: 0.5416..5.7416 less the pi offset).
WAM_LIMITS = [
    (0.54159265359 - math.pi, 5.74159265359 - math.pi),
    (-2.0, 2.0),
    (-2.8, 2.8),
    (-0.9, 3.1),
    (-4.76, 1.24),
    (-1.6, 1.6),
    (-3.0, 3.0),
]
#: Link masses (kg), Barrett WAM inertial specifications (links 1..7; link 0 = base 9.97 kg).
WAM_MASS = [10.7677, 3.8749, 1.8023, 2.4007, 0.1239, 0.4181, 0.0691]
#: Peak joint torques (N m), approximate WAM figures (motor torque x transmission ratio).
WAM_EFFORT = [77.3, 160.6, 95.6, 29.4, 11.6, 11.6, 2.7]
#: Joint speed limits (rad/s), herb_description robots/wam.urdf.xacro ``velocity``.
WAM_VELOCITY = [0.75, 0.75, 2.0, 2.0, 2.5, 2.5, 2.5]
#: j1 origin in wam_base (herb_description robots/wam.urdf.xacro, joint j1).
WAM_J1_XYZ = (0.22, 0.14, 0.346)
#: herb_frame in the base footprint (herb_description robots/herb_base.urdf.xacro, root_to_frame).
HERB_FRAME = ((0.0, 0.0, 1.05), (0.0, 0.0, -1.57075))
#: wam_base in herb_frame (herb_description robots/herb.urdf.xacro, /left|/right/wam_mount).
WAM_MOUNT = {
    "l": ((-0.355924, 0.005376, -0.357421), (0.0, -1.57075, -1.57075)),
    "r": ((0.050805, 0.005376, -0.357421), (0.0, -1.57075, -1.57075)),
}
#: WAM flange (Barrett's wam7 frame, 0.06 m past URDF wam7) -> hand base: the 12 mm force/torque
#: sensor, hand turned pi/2 about the flange axis (herb_description robots/herb.urdf.xacro).
FT_THICKNESS = 0.012
FT_MASS = 0.133278
HAND_YAW = math.pi / 2

#: BarrettHand BH8-280, jhu-lcsr/barrett_model models/hand.urdf.xacro (m, rad).
BH_KNUCKLE = (0.025, 0.0415)  # F1/F2 spread axes at x = -+25 mm, z = 41.5 mm (prox_joint xyz)
BH_FLEX = (0.05, 0.0339)  # flex axis 50 mm out from the spread axis, 33.9 mm higher (med_joint xyz)
BH_F3_FLEX = (0.0, 0.05, 0.0754)  # finger 3 flex axis on the palm (finger_3 med_joint xyz)
BH_DIST_XYZ = (0.06994, 0.003, 0.0)  # distal joint in the proximal link (dist_joint xyz)
BH_DIST_BEND = math.pi / 4  # fixed bend of the distal link towards the palm (dist_joint rpy)
BH_TIP_LEN = 0.05  # distal joint to fingertip (tip_joint xyz)
BH_GRASP_Z = 0.12  # grasp frame on the palm axis (bhand_grasp_joint xyz)
BH_SPREAD = (0.0, math.pi)  # 0..180 degrees
BH_PROX = (0.0, 140.0 / 180.0 * math.pi)  # 0..140 degrees
BH_DIST = (0.0, 48.0 / 180.0 * math.pi)  # 0..48 degrees
#: distal = ratio * proximal (herb_description config/bh280_params.urdf.xacro: mimic 45/140)
BH_COUPLING = 45.0 / 140.0
BH_PALM_MASS = 0.80  # kg; BH8-280 weighs 1.18 kg in all (datasheet), palm share assumed
BH_KNUCKLE_MASS = 0.03
BH_PROX_MASS = 0.07
BH_DIST_MASS = 0.04
#: collision boxes in the finger link frames (x along the link, y its closing side, z the joint
#: axis): proximal 58 x 16 x 24 mm centred 37 mm out; distal 47 x 14 x 22 mm from 3 mm to the tip.
PROX_BOX = ((0.058, 0.016, 0.024), (0.037, 0.0, 0.0))
DIST_BOX = ((BH_TIP_LEN - 0.003, 0.014, 0.022), ((BH_TIP_LEN + 0.003) / 2, 0.0, 0.0))
#: the palm's collision cylinder in the palm link frame: (radius, length), centre (m)
PALM_CYLINDER = ((0.045, 0.07), (0.0, 0.0, 0.035))


def _wam(m: UrdfBuilder, side: str) -> None:
    s = side
    xyz, rpy = WAM_MOUNT[s]
    m.joint(
        f"{s}_wam_mount_joint",
        "fixed",
        "torso_link",
        f"{s}_wam_base_link",
        xyz=xyz,
        rpy=rpy,
        source=f"{HERB_DESCRIPTION} robots/herb.urdf.xacro /{'left' if s == 'l' else 'right'}/wam_mount",
    )
    jx, jy, jz = WAM_J1_XYZ
    m.link(
        f"{s}_wam_base_link",
        [Geom("box", (0.18, 0.18, 0.22), (jx, jy, 0.14))],
        9.97,
        source="WAM base (link 0) 9.97 kg (Barrett WAM inertial specifications); box stands in for "
        "the base below j1; frame = herb_description wam_base",
    )
    parent = f"{s}_wam_base_link"
    # HERB's j1 is published with a +pi offset: fold it into the origin (our q1 = herb q1 - pi).
    origin = ((jx, jy, jz), (0.0, 0.0, math.pi))
    for i in range(7):
        a, alpha, d = WAM_DH[i]
        link = f"{s}_wam_link{i + 1}"
        lo, hi = WAM_LIMITS[i]
        m.joint(
            f"{s}_wam_j{i + 1}",
            "revolute",
            parent,
            link,
            xyz=origin[0],
            rpy=origin[1],
            axis=(0, 0, 1),
            lower=lo,
            upper=hi,
            effort=WAM_EFFORT[i],
            velocity=WAM_VELOCITY[i],
            damping=0.5,
            source=(
                f"WAM joint 1: origin {HERB_DESCRIPTION} robots/wam.urdf.xacro j1, turned by pi "
                "(HERB's +180 deg j1 offset)"
                if i == 0
                else f"WAM joint {i + 1}: origin from DH row {i - 1} (a, alpha, d) of the WAM manual"
            )
            + f"; range {lo:.4f}..{hi:.4f} rad, {WAM_VELOCITY[i]} rad/s (herb_description wam.urdf.xacro)",
        )
        m.link(
            link,
            _wam_link_geoms(i),
            WAM_MASS[i],
            source=f"WAM link {i + 1} mass {WAM_MASS[i]} kg (Barrett WAM inertial specifications)",
        )
        origin = ((a, 0.0, d), (alpha, 0.0, 0.0))
        parent = link
    m.joint(
        f"{s}_wam_flange_joint",
        "fixed",
        parent,
        f"{s}_wam_ft_link",
        xyz=origin[0],
        rpy=origin[1],
        source=f"force/torque sensor on the WAM flange, d7 = 0.06 m ({HERB_DESCRIPTION} "
        "robots/herb.urdf.xacro force_torque_mount)",
    )
    m.link(
        f"{s}_wam_ft_link",
        [Geom("cylinder", (0.045, FT_THICKNESS), (0.0, 0.0, FT_THICKNESS / 2))],
        FT_MASS,
        source=f"force/torque sensor plate, 12 mm thick, {FT_MASS} kg (herb_description "
        "robots/herb.urdf.xacro force_torque link)",
    )
    m.joint(
        f"{s}_bh_mount_joint",
        "fixed",
        f"{s}_wam_ft_link",
        f"{s}_bh_palm_link",
        xyz=(0.0, 0.0, FT_THICKNESS),
        rpy=(0.0, 0.0, HAND_YAW),
        source=f"hand on the 12 mm sensor, turned pi/2 about the flange axis ({HERB_DESCRIPTION} "
        "robots/herb.urdf.xacro hand_mount)",
    )
    _hand(m, s)


def _wam_link_geoms(i: int) -> list[Geom]:
    """Primitive stand-ins. Link i+1's frame is at joint i+1; the next joint is at (a, 0, d)."""
    if i == 0:  # shoulder housing around j1
        return [Geom("cylinder", (0.08, 0.12), (0.0, 0.0, -0.04))]
    if i == 1:  # shoulder pitch housing
        return [Geom("sphere", (0.07,))]
    if i == 2:  # upper arm tube along z to the elbow at (0.045, 0, 0.55)
        return [Geom("cylinder", (0.045, 0.36), (0.0, 0.0, 0.28))]
    if i == 3:  # elbow + forearm tube: forearm runs along -y of this frame from (-0.045, 0, 0)
        return [
            Geom("sphere", (0.055,), (0.0, 0.0, 0.0)),
            Geom("cylinder", (0.04, 0.17), (-0.045, -0.155, 0.0), (math.pi / 2, 0.0, 0.0)),
        ]
    if i == 4:  # wrist base, just before j6 at z = 0.3
        return [Geom("cylinder", (0.035, 0.04), (0.0, 0.0, 0.22))]
    if i == 5:  # wrist pitch housing
        return [Geom("sphere", (0.035,))]
    return [Geom("cylinder", (0.035, 0.02), (0.0, 0.0, 0.045))]  # j7 output flange


def _hand(m: UrdfBuilder, s: str) -> None:
    p = f"{s}_bh"
    src = f"{BARRETT_MODEL} models/hand.urdf.xacro"
    m.link(
        f"{p}_palm_link",
        [Geom("cylinder", *PALM_CYLINDER)],
        BH_PALM_MASS,
        source="BH8-280 palm (frame = barrett_model bhand_palm_link = herb_description hand_base): "
        "1.18 kg hand (datasheet), palm share assumed; cylinder r 45 mm, 70 mm tall",
    )
    m.joint(
        f"{p}_tcp_joint",
        "fixed",
        f"{p}_palm_link",
        f"{p}_tcp",
        xyz=(0.0, 0.0, BH_GRASP_Z),
        source=f"grasp frame on the palm axis, 0.12 m out ({src} bhand_grasp_joint)",
    )
    m.link(
        f"{p}_tcp",
        source="tool-centre-point frame: z = approach (out of the palm), y towards finger 3",
    )
    kx, kz = BH_KNUCKLE
    fx, fz = BH_FLEX
    for f, x, axis_sign in (("1", -kx, -1.0), ("2", kx, 1.0)):
        m.joint(
            f"{p}_j{f}1_joint",
            "revolute",
            f"{p}_palm_link",
            f"{p}_finger_{f}1_link",
            xyz=(x, 0.0, kz),
            rpy=(0.0, 0.0, -math.pi / 2),
            axis=(0.0, 0.0, axis_sign),
            lower=BH_SPREAD[0],
            upper=BH_SPREAD[1],
            effort=2.0,
            velocity=2.0,
            damping=0.05,
            source=f"F{f} spread ({src} finger_{f}/prox_joint); range 0..180 deg; "
            "F1 and F2 spread together (coupled in the controller)",
        )
        m.link(
            f"{p}_finger_{f}1_link",
            [Geom("cylinder", (0.012, 0.02), (fx, 0.0, fz - 0.022))],
            BH_KNUCKLE_MASS,
            source="knuckle (spread) link; mass share assumed",
        )
        _finger(m, p, f, f"{p}_finger_{f}1_link", ((fx, 0.0, fz), (math.pi / 2, 0.0, 0.0)), src)
    _finger(m, p, "3", f"{p}_palm_link", (BH_F3_FLEX, (math.pi / 2, 0.0, math.pi / 2)), src)


def _finger(m: UrdfBuilder, p: str, f: str, parent: str, flex_origin, src: str) -> None:
    m.joint(
        f"{p}_j{f}2_joint",
        "revolute",
        parent,
        f"{p}_finger_{f}2_link",
        xyz=flex_origin[0],
        rpy=flex_origin[1],
        axis=(0.0, 0.0, 1.0),
        lower=BH_PROX[0],
        upper=BH_PROX[1],
        effort=5.0,
        velocity=2.5,
        damping=0.02,
        source=f"proximal flex ({src} finger_{f}/med_joint): 0 = flat, radially out of the palm; "
        "0..140 deg; effort 5 N m (assumed: ~15 N fingertip force over the finger, with margin)",
    )
    m.link(
        f"{p}_finger_{f}2_link",
        [Geom("box", PROX_BOX[0], PROX_BOX[1])],
        BH_PROX_MASS,
        source="proximal link (barrett_model med_link), 69.94 mm to the distal joint; mass share assumed",
    )
    m.joint(
        f"{p}_j{f}3_joint",
        "revolute",
        f"{p}_finger_{f}2_link",
        f"{p}_finger_{f}3_link",
        xyz=BH_DIST_XYZ,
        rpy=(0.0, 0.0, BH_DIST_BEND),
        axis=(0.0, 0.0, 1.0),
        lower=BH_DIST[0],
        upper=BH_DIST[1],
        effort=3.0,
        velocity=1.0,
        damping=0.02,
        source=f"distal joint, 3 mm offset, fixed 45 deg bend ({src} finger_{f}/dist_joint); 0..48 deg; "
        f"follows proximal x {BH_COUPLING:.4f} = 45/140 (herb_description config/bh280_params.urdf.xacro; "
        "coupled in the controller)",
    )
    m.link(
        f"{p}_finger_{f}3_link",
        [Geom("box", DIST_BOX[0], DIST_BOX[1])],
        BH_DIST_MASS,
        source="distal link (barrett_model dist_link, x along the bent link); mass share assumed",
    )
    m.joint(
        f"{p}_finger_{f}_tip_joint",
        "fixed",
        f"{p}_finger_{f}3_link",
        f"{p}_finger_{f}_tip",
        xyz=(BH_TIP_LEN, 0.0, 0.0),
        source=f"fingertip 50 mm along the distal link ({src} finger_{f}/tip_joint)",
    )
    m.link(f"{p}_finger_{f}_tip", source="fingertip frame")


def build() -> UrdfBuilder:
    m = UrdfBuilder("herb", header=__doc__ or "")
    m.link(
        "base_link",
        [Geom("box", (0.6, 0.5, 0.4), (-0.1, 0.0, 0.2))],
        80.0,
        source="mobile base as one fixed box, frame = herb_description base_footprint (box and mass assumed)",
    )
    xyz, rpy = HERB_FRAME
    m.joint(
        "torso_joint",
        "fixed",
        "base_link",
        "torso_link",
        xyz=xyz,
        rpy=rpy,
        source=f"{HERB_DESCRIPTION} robots/herb_base.urdf.xacro root_to_frame",
    )
    m.link(
        "torso_link",
        [Geom("box", (0.5, 0.2, 0.65), (0.0, -0.15, -0.325))],
        20.0,
        source="torso column behind the arm mounts, frame = herb_description herb_frame (box and mass assumed)",
    )
    _wam(m, "l")
    _wam(m, "r")
    return m
