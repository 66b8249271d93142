"""HERB: two Barrett WAM 7-DOF arms on a fixed torso, each with a BarrettHand BH8-280.

WAM kinematics are the standard Denavit-Hartenberg parameters of the WAM
manual (a, alpha, d per joint; also in Barrett's libbarrett configuration
and jhu-lcsr/barrett_model), converted to URDF joint origins: joint i+1's
origin in link i is ``xyz=(a_i, 0, d_i) rpy=(alpha_i, 0, 0)`` and each joint
turns about its local z. Link masses are Barrett's published WAM inertial
figures. BarrettHand finger offsets are those of the BH8-280 kinematics
(palm-to-knuckle 25 mm / 41.5 mm, knuckle-to-flex 50 mm / 33.9 mm, proximal
link 69.94 mm); joint ranges and the distal/proximal coupling 0.3442 come
from the BH8-280 manual as reproduced in public bhand URDF/MJCF models.

Simplifications (also in robots/herb/README.md):
* HERB's exact arm-mount transform and torso shape are not in any source we
  could reach: each WAM base stands upright on a fixed torso, 0.44 m apart;
* the distal finger link is straight at q=0 (the real one has a fixed bend)
  and 55 mm long (approximate); distal and spread coupling is done in the
  controller (no ``<mimic>``: PhysX has none);
* the Segway base is one fixed box.
"""

from __future__ import annotations

import math

from ..urdf_builder import Geom, UrdfModel

#: (a, alpha, d) of the WAM's 7 joints, metres/radians (WAM manual DH table).
WAM_DH = [
    (0.0, -math.pi / 2, 0.0),
    (0.0, math.pi / 2, 0.0),
    (0.045, -math.pi / 2, 0.55),
    (-0.045, math.pi / 2, 0.0),
    (0.0, -math.pi / 2, 0.3),
    (0.0, math.pi / 2, 0.0),
    (0.0, 0.0, 0.06),
]
#: Joint ranges (rad), WAM manual: +-150, +-113, +-157, -50..180, -273..71, +-90, +-172 degrees.
WAM_LIMITS = [
    (-2.6, 2.6),
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
#: Joint speed limits (rad/s): conservative figures for a WAM under position control (assumed).
WAM_VELOCITY = [2.0, 2.0, 2.0, 2.0, 2.5, 2.5, 2.5]
WAM_J1_HEIGHT = 0.346  # m, base mounting plate to j1/j2 intersection (barrett_model wam base)

#: BarrettHand BH8-280 figures (m, rad).
BH_KNUCKLE = (0.025, 0.0415)  # F1/F2 spread axes at x = -+25 mm, z = 41.5 mm above the palm base
BH_FLEX = (
    0.05,
    0.0339,
)  # flex axis 50 mm out from the spread axis and 33.9 mm higher (z = 75.4 mm)
BH_PROX_LEN = 0.06994  # proximal link, flex axis to distal axis
BH_DIST_LEN = 0.055  # distal link length (approximate)
BH_SPREAD = (0.0, math.pi)  # 0..180 degrees
BH_PROX = (0.0, 2.44346)  # 0..140 degrees
BH_DIST = (0.0, 0.837758)  # 0..48 degrees
BH_COUPLING = (
    0.3442622950819672  # distal = ratio * proximal (42/122, BH8-280 breakaway-free coupling)
)
BH_TCP_Z = 0.145  # m: grasp centre for a 5.7 cm cube, pinched where the proximal links end and the distal links begin (derived from the figures above)
BH_PALM_MASS = (
    0.80  # kg; BH8-280 weighs 1.18 kg in all (datasheet), split palm / fingers (assumed split)
)
BH_KNUCKLE_MASS = 0.03
BH_PROX_MASS = 0.07
BH_DIST_MASS = 0.04


def _wam(m: UrdfModel, side: str, mount_xyz: tuple[float, float, float]) -> None:
    s = side
    m.joint(
        f"{s}_wam_mount_joint",
        "fixed",
        "torso_link",
        f"{s}_wam_base_link",
        xyz=mount_xyz,
        source="arm mount on the torso (assumed; see module docstring)",
    )
    m.link(
        f"{s}_wam_base_link",
        [Geom("box", (0.18, 0.18, 0.25), (0.0, 0.0, 0.125))],
        9.97,
        source="WAM base (link 0) 9.97 kg (Barrett WAM inertial specifications); box stands in for the base tower",
    )
    parent = f"{s}_wam_base_link"
    origin = ((0.0, 0.0, WAM_J1_HEIGHT), (0.0, 0.0, 0.0))
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
            source=f"WAM joint {i + 1}: origin from DH row {i} (a, alpha, d) of the WAM manual; range {lo}..{hi} rad",
        )
        geoms = _wam_link_geoms(i)
        m.link(
            link,
            geoms,
            WAM_MASS[i],
            source=f"WAM link {i + 1} mass {WAM_MASS[i]} kg (Barrett WAM inertial specifications)",
        )
        origin = ((a, 0.0, d), (alpha, 0.0, 0.0))
        parent = link
    # The flange: the hand mounts at d7 = 0.06 m along j7.
    m.joint(
        f"{s}_wam_flange_joint",
        "fixed",
        parent,
        f"{s}_bh_palm_link",
        xyz=origin[0],
        rpy=origin[1],
        source="BarrettHand mounts on the WAM flange, d7 = 0.06 m (WAM manual)",
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


def _hand(m: UrdfModel, s: str) -> None:
    p = f"{s}_bh"
    m.link(
        f"{p}_palm_link",
        [Geom("cylinder", (0.045, 0.07), (0.0, 0.0, 0.035))],
        BH_PALM_MASS,
        source="BH8-280 palm: 1.18 kg hand (datasheet), palm share assumed; cylinder r 45 mm, 70 mm tall",
    )
    m.joint(
        f"{p}_tcp_joint",
        "fixed",
        f"{p}_palm_link",
        f"{p}_tcp",
        xyz=(0.0, 0.0, BH_TCP_Z),
        source="grasp centre on the palm axis (derived from the finger figures)",
    )
    m.link(
        f"{p}_tcp",
        source="tool-centre-point frame: z = approach (out of the palm), y towards finger 3",
    )
    kx, kz = BH_KNUCKLE
    fy, fz = BH_FLEX
    finger_geoms_prox = [Geom("box", (0.024, 0.016, 0.058), (0.0, 0.0, 0.037))]
    finger_geoms_dist = [
        Geom(
            "box",
            (0.022, 0.014, BH_DIST_LEN - 0.006),
            (0.0, 0.0, 0.003 + (BH_DIST_LEN - 0.006) / 2),
        )
    ]
    # Fingers 1 and 2 spread about z through knuckles at x = -+25 mm; their frames are turned by pi
    # so that, like finger 3, each finger sits at local +y and closes towards local -y.
    for f, x, axis_sign in (("1", -kx, -1.0), ("2", kx, 1.0)):
        m.joint(
            f"{p}_j{f}1_joint",
            "revolute",
            f"{p}_palm_link",
            f"{p}_finger_{f}1_link",
            xyz=(x, 0.0, kz),
            rpy=(0.0, 0.0, math.pi),
            axis=(0.0, 0.0, axis_sign),
            lower=BH_SPREAD[0],
            upper=BH_SPREAD[1],
            effort=2.0,
            velocity=2.0,
            damping=0.05,
            source=f"F{f} spread axis at x={x} m, z={kz} m (BH8-280 kinematics); range 0..180 deg; "
            "F1 and F2 spread symmetrically (coupled in the controller)",
        )
        m.link(
            f"{p}_finger_{f}1_link",
            [Geom("cylinder", (0.012, 0.02), (0.0, fy, fz - 0.012))],
            BH_KNUCKLE_MASS,
            source="knuckle (spread) link; mass share assumed",
        )
        _finger(
            m, p, f, f"{p}_finger_{f}1_link", (0.0, fy, fz), finger_geoms_prox, finger_geoms_dist
        )
    _finger(m, p, "3", f"{p}_palm_link", (0.0, fy, kz + fz), finger_geoms_prox, finger_geoms_dist)


def _finger(m: UrdfModel, p: str, f: str, parent: str, flex_xyz, prox_geoms, dist_geoms) -> None:
    m.joint(
        f"{p}_j{f}2_joint",
        "revolute",
        parent,
        f"{p}_finger_{f}2_link",
        xyz=flex_xyz,
        axis=(1.0, 0.0, 0.0),
        lower=BH_PROX[0],
        upper=BH_PROX[1],
        effort=5.0,
        velocity=2.5,
        damping=0.02,
        source="proximal flex: 50 mm from the spread axis, z 75.4 mm (BH8-280 kinematics); 0..140 deg; "
        "effort 5 N m (assumed: ~15 N fingertip force over the 0.125 m finger, with margin)",
    )
    m.link(
        f"{p}_finger_{f}2_link",
        prox_geoms,
        BH_PROX_MASS,
        source=f"proximal link, {BH_PROX_LEN} m (BH8-280 kinematics); mass share assumed",
    )
    m.joint(
        f"{p}_j{f}3_joint",
        "revolute",
        f"{p}_finger_{f}2_link",
        f"{p}_finger_{f}3_link",
        xyz=(0.0, 0.0, BH_PROX_LEN),
        axis=(1.0, 0.0, 0.0),
        lower=BH_DIST[0],
        upper=BH_DIST[1],
        effort=3.0,
        velocity=1.0,
        damping=0.02,
        source=f"distal joint at the proximal link end; 0..48 deg; follows proximal x {BH_COUPLING:.4f} (coupled in the controller)",
    )
    m.link(
        f"{p}_finger_{f}3_link",
        dist_geoms,
        BH_DIST_MASS,
        source=f"distal link, ~{BH_DIST_LEN} m; mass share assumed",
    )


def build() -> UrdfModel:
    m = UrdfModel("herb", header=__doc__ or "")
    m.link(
        "base_link",
        [Geom("box", (0.6, 0.5, 0.4), (0.0, 0.0, 0.2))],
        80.0,
        source="Segway-based mobile base as one fixed box (HERB, Srinivasa et al. 2010: ~0.6 m footprint; mass assumed)",
    )
    m.joint(
        "torso_joint",
        "fixed",
        "base_link",
        "torso_link",
        xyz=(0.0, 0.0, 0.4),
        source="torso on the base",
    )
    m.link(
        "torso_link",
        [Geom("box", (0.2, 0.2, 0.42), (-0.15, 0.0, 0.21))],
        20.0,
        source="torso column (assumed dimensions and mass); arms mount on its top plate",
    )
    _wam(m, "l", (0.0, 0.22, 0.45))
    _wam(m, "r", (0.0, -0.22, 0.45))
    return m
