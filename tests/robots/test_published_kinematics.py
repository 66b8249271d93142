"""Kinematic fidelity: our PR2 and Allegro against their published descriptions, in FK and on both engines.

The oracle is independent of our description code: the published joint
origins (xyz, rpy) and axes are copied below from the upstream files, with
their source, and composed here with NumPy/SciPy. Our FK (pytorch-kinematics
on the generated URDF) and each engine's link poses (PyBullet, SAPIEN: the
robot spawned, joints set, link frames read back) must agree with it within
1 mm and 0.5 deg at sampled joint vectors.

Sources (files read with ``git show <commit>:<path>``):

* PR2: github.com/PR2/pr2_common at c36a5c9c8d5e97d2d53a7c75fa57a3257a7c63cc,
  ``pr2_description/robots/pr2.urdf.xacro`` (torso origin, shoulder origins
  ``0 +-0.188 0``, every other arm origin 0), ``urdf/base_v0/base.urdf.xacro``
  (base_footprint_joint ``0 0 0.051``), ``urdf/torso_v0/torso.urdf.xacro``,
  ``urdf/shoulder_v0/shoulder.urdf.xacro``, ``urdf/upper_arm_v0/upper_arm.urdf.xacro``,
  ``urdf/forearm_v0/forearm.urdf.xacro``, ``urdf/gripper_v0/gripper.urdf.xacro``
  (``*_gripper_tool_joint`` ``0.18 0 0``).
  The gripper's finger macro ``pr2_finger_v0`` (finger and fingertip joint origins and
  axes, all mimicking ``*_l_finger_joint``) and the pad mesh
  ``meshes/gripper_v0/finger_tip_pad2_l.stl`` (its inner face), same file and commit.
* Allegro: github.com/simlabrobotics/allegro_hand_ros_v4 at
  b19b18ea130c4fbe343f2c178eec6cb55186a4ac,
  ``src/allegro_hand_description/allegro_hand_description_right.urdf``
  (joint ``joint_N.0`` / link ``link_N.0_tip`` upstream = ``joint_N`` / ``link_N_tip`` here).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import replace

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from benchharness.geometry import Pose
from benchharness.paths import robots_dir
from benchharness.robots.descriptions.pr2 import PAD_GAP
from benchharness.robots.kinematics import KinematicTree, pose_error

POS_TOL = 1e-3  # m
ROT_TOL = math.radians(0.5)

# -- the published descriptions, as (joint, type, parent, child, xyz, rpy, axis) ---------------------


def _pr2_published(s: str) -> list[tuple]:
    """One PR2 arm from base_footprint to the tool frame (reflect = +1 left, -1 right)."""
    r = 1.0 if s == "l" else -1.0
    z3 = (0.0, 0.0, 0.0)
    return [
        ("base_footprint_joint", "fixed", "base_footprint", "base_link", (0, 0, 0.051), z3, None),
        (
            "torso_lift_joint",
            "prismatic",
            "base_link",
            "torso_lift_link",
            (-0.05, 0, 0.739675),
            z3,
            (0, 0, 1),
        ),
        (
            f"{s}_shoulder_pan_joint",
            "revolute",
            "torso_lift_link",
            f"{s}_shoulder_pan_link",
            (0, r * 0.188, 0),
            z3,
            (0, 0, 1),
        ),
        (
            f"{s}_shoulder_lift_joint",
            "revolute",
            f"{s}_shoulder_pan_link",
            f"{s}_shoulder_lift_link",
            (0.1, 0, 0),
            z3,
            (0, 1, 0),
        ),
        (
            f"{s}_upper_arm_roll_joint",
            "revolute",
            f"{s}_shoulder_lift_link",
            f"{s}_upper_arm_roll_link",
            z3,
            z3,
            (1, 0, 0),
        ),
        (
            f"{s}_upper_arm_joint",
            "fixed",
            f"{s}_upper_arm_roll_link",
            f"{s}_upper_arm_link",
            z3,
            z3,
            None,
        ),
        (
            f"{s}_elbow_flex_joint",
            "revolute",
            f"{s}_upper_arm_link",
            f"{s}_elbow_flex_link",
            (0.4, 0, 0),
            z3,
            (0, 1, 0),
        ),
        (
            f"{s}_forearm_roll_joint",
            "continuous",
            f"{s}_elbow_flex_link",
            f"{s}_forearm_roll_link",
            z3,
            z3,
            (1, 0, 0),
        ),
        (
            f"{s}_forearm_joint",
            "fixed",
            f"{s}_forearm_roll_link",
            f"{s}_forearm_link",
            z3,
            z3,
            None,
        ),
        (
            f"{s}_wrist_flex_joint",
            "revolute",
            f"{s}_forearm_link",
            f"{s}_wrist_flex_link",
            (0.321, 0, 0),
            z3,
            (0, 1, 0),
        ),
        (
            f"{s}_wrist_roll_joint",
            "continuous",
            f"{s}_wrist_flex_link",
            f"{s}_wrist_roll_link",
            z3,
            z3,
            (1, 0, 0),
        ),
        (
            f"{s}_gripper_palm_joint",
            "fixed",
            f"{s}_wrist_roll_link",
            f"{s}_gripper_palm_link",
            z3,
            z3,
            None,
        ),
        (
            f"{s}_gripper_tool_joint",
            "fixed",
            f"{s}_gripper_palm_link",
            f"{s}_gripper_tool_frame",
            (0.18, 0, 0),
            z3,
            None,
        ),
    ]


def _pr2_hard_limits(s: str) -> dict[str, tuple[float, float]]:
    """Published hard ``<limit>`` of the PR2 joints (continuous joints: two turns, for sampling)."""
    r = 1.0 if s == "l" else -1.0
    return {
        "torso_lift_joint": (0.0, 0.33),
        f"{s}_shoulder_pan_joint": (r * math.pi / 4 - 1.5, r * math.pi / 4 + 1.5),
        f"{s}_shoulder_lift_joint": (-0.5236, 1.3963),
        f"{s}_upper_arm_roll_joint": (r * 1.55 - 2.35, r * 1.55 + 2.35),
        f"{s}_elbow_flex_joint": (-2.3213, 0.0),
        f"{s}_forearm_roll_joint": (-2 * math.pi, 2 * math.pi),
        f"{s}_wrist_flex_joint": (-2.18, 0.0),
        f"{s}_wrist_roll_joint": (-2 * math.pi, 2 * math.pi),
    }


def _pr2_soft_limits(s: str) -> dict[str, tuple[float, float]]:
    """Published ``<safety_controller soft_lower_limit soft_upper_limit>`` (evaluated xacro expressions)."""
    r = 1.0 if s == "l" else -1.0
    return {
        "torso_lift_joint": (0.0 + 0.0115, 0.33 - 0.005),
        f"{s}_shoulder_pan_joint": (r * math.pi / 4 - 1.5 + 0.15, r * math.pi / 4 + 1.5 - 0.15),
        f"{s}_shoulder_lift_joint": (-0.5236 + 0.17, 1.3963 - 0.10),
        f"{s}_upper_arm_roll_joint": (r * 1.55 - 2.35 + 0.15, r * 1.55 + 2.35 - 0.15),
        f"{s}_elbow_flex_joint": (-2.3213 + 0.2, 0.00 - 0.15),
        f"{s}_wrist_flex_joint": (-2.18 + 0.18, 0.0 - 0.10),
    }


#: Published inertials (mass kg, COM xyz m, (ixx, ixy, ixz, iyy, iyz, izz) kg m^2) of the PR2 links.
PR2_INERTIALS = {
    "base_link": (
        116.0,
        (-0.061, 0.0, 0.1465),
        (
            5.652232699207,
            -0.009719934438,
            1.293988226423,
            5.669473158652,
            -0.007379583694,
            3.683196351726,
        ),
    ),
    "torso_lift_link": (
        36.248046,
        (-0.1, 0.0, -0.0885),
        (
            2.771653750257,
            0.004284522609,
            -0.160418504506,
            2.510019507959,
            0.029664468704,
            0.526432355569,
        ),
    ),
    "l_shoulder_pan_link": (
        25.799322,
        (-0.001201, 0.024513, -0.098231),
        (
            0.866179142480,
            -0.06086507933,
            -0.12118061183,
            0.87421714893,
            -0.05886609911,
            0.27353821674,
        ),
    ),
    "l_shoulder_lift_link": (
        2.74988,
        (0.02195, -0.02664, -0.03127),
        (0.02105584615, 0.00496704022, -0.00194808955, 0.02127223737, 0.00110425490, 0.01975753814),
    ),
    "l_upper_arm_link": (
        6.01769,
        (0.21405, 0.01658, -0.00057),
        (
            0.01530603856,
            -0.00339324862,
            0.00060765455,
            0.07473694455,
            -0.00019953729,
            0.07601594191,
        ),
    ),
    "r_upper_arm_link": (
        6.01769,
        (0.21398, -0.01621, -0.00020),
        (
            0.01537748957,
            0.00375711247,
            -0.00070852914,
            0.07473670440,
            -0.00017936450,
            0.07608763307,
        ),
    ),
    "l_elbow_flex_link": (
        1.90327,
        (0.01014, 0.00032, -0.01211),
        (0.00346541989, 0.00004066825, 0.00043171614, 0.00441606455, -0.00003968914, 0.00359156824),
    ),
    "l_forearm_link": (
        2.57968,
        (0.18791, -0.00017, -0.00912),
        (0.00364857222, 0.00005215877, 0.00071534842, 0.01507736897, -0.00001310770, 0.01659310749),
    ),
    "l_wrist_flex_link": (
        0.61402,
        (-0.00157, 0.0, -0.00075),
        (0.00065165722, 0.00000028864, 0.00000303477, 0.00019824443, -0.00000022645, 0.00064450498),
    ),
    "l_gripper_palm_link": (
        0.58007,
        (0.06623, 0.00053, -0.00119),
        (
            0.00035223921,
            -0.00001580476,
            -0.00000091750,
            0.00067741312,
            -0.00000059554,
            0.00086563316,
        ),
    ),
}


def _allegro_published() -> list[tuple]:
    """The right Allegro hand v4, palm_link to the four fingertip frames (upstream names without ``.0``)."""
    z3 = (0.0, 0.0, 0.0)
    out = []
    for base, xyz, rpy in (
        (0, (0, 0.0435, -0.001542), (-0.08726646255, 0, 0)),
        (4, (0, 0, 0.0007), (0.0, 0, 0)),
        (8, (0, -0.0435, -0.001542), (0.08726646255, 0, 0)),
    ):
        n = [f"link_{base + k}" for k in range(4)]
        out += [
            (f"joint_{base}", "revolute", "palm_link", n[0], xyz, rpy, (0, 0, 1)),
            (f"joint_{base + 1}", "revolute", n[0], n[1], (0, 0, 0.0164), z3, (0, 1, 0)),
            (f"joint_{base + 2}", "revolute", n[1], n[2], (0, 0, 0.054), z3, (0, 1, 0)),
            (f"joint_{base + 3}", "revolute", n[2], n[3], (0, 0, 0.0384), z3, (0, 1, 0)),
            (f"joint_{base + 3}_tip", "fixed", n[3], f"{n[3]}_tip", (0, 0, 0.0267), z3, None),
        ]
    out += [
        (
            "joint_12",
            "revolute",
            "palm_link",
            "link_12",
            (-0.0182, 0.019333, -0.045987),
            (0, -1.65806278845, -1.5707963259),
            (-1, 0, 0),
        ),
        ("joint_13", "revolute", "link_12", "link_13", (-0.027, 0.005, 0.0399), z3, (0, 0, 1)),
        ("joint_14", "revolute", "link_13", "link_14", (0, 0, 0.0177), z3, (0, 1, 0)),
        ("joint_15", "revolute", "link_14", "link_15", (0, 0, 0.0514), z3, (0, 1, 0)),
        ("joint_15_tip", "fixed", "link_15", "link_15_tip", (0, 0, 0.0423), z3, None),
    ]
    return out


#: Published ranges of the Allegro joints (upstream ``<limit>``), per finger joint 0..3 and thumb 12..15.
ALLEGRO_LIMITS = {
    **{
        f"joint_{b + k}": lim
        for b in (0, 4, 8)
        for k, lim in enumerate(((-0.47, 0.47), (-0.196, 1.61), (-0.174, 1.709), (-0.227, 1.618)))
    },
    **{
        f"joint_{12 + k}": lim
        for k, lim in enumerate(((0.263, 1.396), (-0.105, 1.163), (-0.189, 1.644), (-0.162, 1.719)))
    },
}


def oracle_fk(joints: list[tuple], q: dict[str, float], root: str) -> dict[str, np.ndarray]:
    """Every link's 4x4 pose in ``root`` from published (xyz, rpy, axis): T = origin * motion(q)."""
    poses = {root: np.eye(4)}
    for name, kind, parent, child, xyz, rpy, axis in joints:
        t = np.eye(4)
        t[:3, :3] = Rotation.from_euler(
            "xyz", rpy
        ).as_matrix()  # URDF rpy: fixed-axis roll, pitch, yaw
        t[:3, 3] = xyz
        m = np.eye(4)
        if kind in ("revolute", "continuous"):
            m[:3, :3] = Rotation.from_rotvec(q[name] * np.asarray(axis, float)).as_matrix()
        elif kind == "prismatic":
            m[:3, 3] = q[name] * np.asarray(axis, float)
        poses[child] = poses[parent] @ t @ m
    return poses


def _assert_close(ours: np.ndarray, theirs: np.ndarray, what: str) -> None:
    dp, dr = pose_error(ours[None], theirs[None])
    assert dp[0] < POS_TOL and dr[0] < ROT_TOL, (
        f"{what}: {dp[0] * 1e3:.3f} mm, {math.degrees(dr[0]):.3f} deg from the published description"
    )


def _pr2_samples(n: int, seed: int) -> list[dict[str, float]]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q: dict[str, float] = {}
        for s in "lr":
            for j, (lo, hi) in _pr2_hard_limits(s).items():
                q[j] = float(rng.uniform(lo, hi))
        out.append(q)
    return out


#: our link name for a published one (the tool frame is ``*_gripper_tcp`` here)
PR2_LINKS = (
    {
        f"{s}_{n}": f"{s}_{n}"
        for s in "lr"
        for n in (
            "shoulder_pan_link",
            "shoulder_lift_link",
            "upper_arm_roll_link",
            "upper_arm_link",
            "elbow_flex_link",
            "forearm_roll_link",
            "forearm_link",
            "wrist_flex_link",
            "wrist_roll_link",
            "gripper_palm_link",
        )
    }
    | {f"{s}_gripper_tool_frame": f"{s}_gripper_tcp" for s in "lr"}
    | {"torso_lift_link": "torso_lift_link"}
)


def _pr2_oracle(q: dict[str, float]) -> dict[str, np.ndarray]:
    out = {}
    for s in "lr":
        out.update(oracle_fk(_pr2_published(s), q, "base_footprint"))
    return out


# -- PR2 ------------------------------------------------------------------------------------------


def test_pr2_fk_matches_published_description(robots):
    """Every arm link and both tool frames, from our URDF (pytorch-kinematics) and from the arm chains."""
    pr2 = robots["pr2"]
    tree = KinematicTree(pr2.urdf_text)
    for q in _pr2_samples(6, seed=11):
        want = _pr2_oracle(q)
        ours = tree.fk(q)
        for pub, link in PR2_LINKS.items():
            _assert_close(ours[link], want[pub], f"FK {link}")
        for side in "lr":
            arm = pr2.arm(f"{'left' if side == 'l' else 'right'}_arm")
            tcp = arm.fk([q[j] for j in arm.joints])[0]  # in torso_lift_link
            rel = np.linalg.inv(want["torso_lift_link"]) @ want[f"{side}_gripper_tool_frame"]
            _assert_close(tcp, rel, f"arm chain {arm.name}")


@pytest.mark.sim
@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_pr2_engine_link_poses_match_published_description(make_backend, make_robot, backend):
    be = make_backend(backend)
    pr2 = make_robot("pr2")
    pr2.spawn(be)
    root = be.get_link_pose(pr2.body, None).as_matrix()
    for q in _pr2_samples(4, seed=12):
        vec = np.array([q.get(n, 0.0) for n in pr2.joint_names])  # fingers closed
        be.set_joint_positions(pr2.body, vec)
        want = _pr2_oracle(q)
        for pub, link in PR2_LINKS.items():
            got = be.get_link_pose(pr2.body, link).as_matrix()
            _assert_close(got, root @ want[pub], f"{backend} {link}")


def test_pr2_hard_and_soft_limits_are_published(robots):
    """Hard ``<limit>`` (incl. wrist flex -2.18) and ``<safety_controller>`` soft limits, both arms and torso."""
    pr2 = robots["pr2"]
    for s in "lr":
        for j, (lo, hi) in _pr2_hard_limits(s).items():
            if pr2.urdf_joints[j].type == "continuous":
                assert math.isinf(pr2.urdf_joints[j].lower)
                continue
            assert (pr2.urdf_joints[j].lower, pr2.urdf_joints[j].upper) == pytest.approx(
                (lo, hi), abs=1e-8
            ), j
        for j, (lo, hi) in _pr2_soft_limits(s).items():
            uj = pr2.urdf_joints[j]
            assert uj.has_soft_limits, j
            assert (uj.soft_lower, uj.soft_upper) == pytest.approx((lo, hi), abs=1e-8), j
    # the figures the issue quotes, written out
    lim = pr2.urdf_joints["l_shoulder_lift_joint"]
    assert (lim.soft_lower, lim.soft_upper) == pytest.approx((-0.3536, 1.2963))
    assert pr2.urdf_joints["r_wrist_flex_joint"].lower == -2.18


def test_pr2_inertials_are_published():
    """Masses, COMs and full inertia tensors (written diagonalised: R diag(I) R^T must give them back)."""
    root = ET.parse(robots_dir() / "pr2" / "pr2.urdf").getroot()
    links = {lk.get("name"): lk for lk in root.findall("link")}
    for name, (mass, com, tensor) in PR2_INERTIALS.items():
        for link in {
            name,
            "r" + name[1:] if name.startswith("l_") and name != "l_upper_arm_link" else name,
        }:
            inertial = links[link].find("inertial")
            assert float(inertial.find("mass").get("value")) == pytest.approx(mass), link
            o = inertial.find("origin")
            np.testing.assert_allclose([float(x) for x in o.get("xyz").split()], com, atol=1e-9)
            r = Rotation.from_euler("xyz", [float(x) for x in o.get("rpy").split()]).as_matrix()
            i = inertial.find("inertia")
            d = np.diag([float(i.get(k)) for k in ("ixx", "iyy", "izz")])
            xx, xy, xz, yy, yz, zz = tensor
            np.testing.assert_allclose(
                r @ d @ r.T, [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], atol=1e-8, err_msg=link
            )


def test_ik_and_primitives_respect_pr2_soft_limits(robots):
    """IK solutions lie inside the soft limits even for targets that need a pose beyond them.

    Targets: FK of joint vectors drawn over the *hard* ranges (so about a third need a joint beyond a
    soft limit, e.g. the shoulder lift at its hard limit); seeds: the same vectors (the seeded
    descent starts outside and must be brought in) or home.
    """
    pr2 = robots["pr2"]
    soft = _pr2_soft_limits("l") | _pr2_soft_limits("r")
    for side in ("left_arm", "right_arm"):
        arm = pr2.arm(side)
        s = side[0]
        hard = _pr2_hard_limits(s)
        lo = np.array([soft.get(j, (-np.inf, np.inf))[0] for j in arm.joints])
        hi = np.array([soft.get(j, (-np.inf, np.inf))[1] for j in arm.joints])
        np.testing.assert_allclose(arm.lower, lo)
        np.testing.assert_allclose(arm.upper, hi)
        rng = np.random.default_rng(5)
        qs = np.array([[rng.uniform(*hard[j]) for j in arm.joints] for _ in range(40)])
        qs[:10, 1] = 1.3963  # shoulder lift at its hard upper limit, beyond the soft 1.2963
        targets = arm.fk(qs)
        outside = ~np.all((qs >= lo) & (qs <= hi), axis=1)
        assert outside.sum() >= 10
        home = pr2.home()[[pr2.joint_names.index(j) for j in arm.joints]]
        for seed_q in (qs, home):
            sol = arm.ik(targets, seed_q=seed_q, seed=3)
            q = sol.q
            finite = np.isfinite(lo)
            assert np.all(q[:, finite] >= lo[finite] - 1e-9) and np.all(
                q[:, finite] <= hi[finite] + 1e-9
            )
            # the in-range targets are still reached
            assert sol.success[~outside].mean() >= 0.95


def test_soft_limits_switch_off_gives_hard_limits():
    from benchharness.robots import Robot
    from benchharness.robots.pr2 import pr2_config

    robot = Robot(replace(pr2_config(), soft_limits=False))
    arm = robot.arm("left_arm")
    assert arm.lower[1] == -0.5236 and arm.upper[1] == 1.3963
    assert arm.chain.upper[1] == 1.3963 and arm.chain.lower[5] == -2.18


def test_robots_without_soft_limits_are_unaffected(robots):
    """HERB and the Allegro hand have no safety controller: their limits stay the hard ones."""
    for name in ("herb", "allegro"):
        r = robots[name]
        lo, hi = r.joint_limits()
        assert not any(j.has_soft_limits for j in r.urdf_joints.values())
        np.testing.assert_array_equal(lo, [r.urdf_joints[j].lower for j in r.joint_names])
        np.testing.assert_array_equal(hi, [r.urdf_joints[j].upper for j in r.joint_names])


@pytest.mark.sim
def test_move_to_joints_stops_at_the_soft_limit(make_backend, make_robot):
    """A joint goal beyond a soft limit is clipped to it (the safety controller would resist the rest)."""
    be = make_backend("pybullet")
    pr2 = make_robot("pr2")
    pr2.spawn(be)
    arm = pr2.arm("left_arm")
    goal = arm.positions().copy()
    goal[1] = 1.3963  # hard limit; soft 1.2963
    res = arm.move_to_joints(goal, duration=2.0)
    assert res.q_goal[1] == pytest.approx(1.3963 - 0.10)
    assert arm.positions()[1] == pytest.approx(1.2963, abs=0.02)
    # from a pose beyond the soft limit (as after a push), every PD target the move sends is inside
    q = arm.positions().copy()
    q[1] = 1.35
    be.set_joint_positions(pr2.body, q, joints=list(arm.joints))
    sent = []
    drive = pr2.drive
    pr2.drive = lambda joints, qq, qd=None: (sent.append(np.array(qq)), drive(joints, qq, qd))[1]
    goal[1] = 1.0
    arm.move_to_joints(goal, duration=1.0, settle=0.0)
    lifts = [
        t[list(arm.joints).index("l_shoulder_lift_joint")] for (t,) in zip(sent) if len(t) == 7
    ]
    assert lifts and max(lifts) <= 1.2963 + 1e-9


# -- Allegro --------------------------------------------------------------------------------------

ALLEGRO_TIPS = ("link_3_tip", "link_7_tip", "link_11_tip", "link_15_tip")


def _allegro_samples(n: int, seed: int) -> list[dict[str, float]]:
    rng = np.random.default_rng(seed)
    return [
        {j: float(rng.uniform(lo, hi)) for j, (lo, hi) in ALLEGRO_LIMITS.items()} for _ in range(n)
    ]


# -- PR2 gripper: the four-bar fingers -------------------------------------------------------------


#: pr2_description ``urdf/gripper_v0/gripper.urdf.xacro`` (same commit): the finger macro
#: ``pr2_finger_v0``. Every finger joint mimics ``*_l_finger_joint`` with multiplier +1; the axes make
#: the proximal links open outwards and the fingertips turn back by the same angle.
def _gripper_published(s: str) -> list[tuple]:
    z3 = (0.0, 0.0, 0.0)
    palm = f"{s}_gripper_palm_link"
    return [
        (
            f"{s}_gripper_l_finger_joint",
            "revolute",
            palm,
            f"{s}_gripper_l_finger_link",
            (0.07691, 0.01, 0),
            z3,
            (0, 0, 1),
        ),
        (
            f"{s}_gripper_r_finger_joint",
            "revolute",
            palm,
            f"{s}_gripper_r_finger_link",
            (0.07691, -0.01, 0),
            z3,
            (0, 0, -1),
        ),
        (
            f"{s}_gripper_l_finger_tip_joint",
            "revolute",
            f"{s}_gripper_l_finger_link",
            f"{s}_gripper_l_finger_tip_link",
            (0.09137, 0.00495, 0),
            z3,
            (0, 0, -1),
        ),
        (
            f"{s}_gripper_r_finger_tip_joint",
            "revolute",
            f"{s}_gripper_r_finger_link",
            f"{s}_gripper_r_finger_tip_link",
            (0.09137, -0.00495, 0),
            z3,
            (0, 0, 1),
        ),
    ]


#: Centre of each pad's contact face in its fingertip frame: ``meshes/gripper_v0/finger_tip_pad2_l.stl``
#: (same commit) spans x -0.00475..0.03125 with its inner face at y = -0.01495 (read with trimesh);
#: the right fingertip shows the mesh turned by pi about x (``rpy="${M_PI} 0 0"``), so its face is at +y.
PAD_FACE_IN_TIP = {"l": np.array([0.01325, -0.01495, 0.0]), "r": np.array([0.01325, 0.01495, 0.0])}


def _gripper_oracle(
    s: str, theta: float
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], float]:
    """Fingertip frames and pad-face centres (palm frame) at finger angle ``theta``, and the opening."""
    q = {j[0]: theta for j in _gripper_published(s)}
    poses = oracle_fk(_gripper_published(s), q, f"{s}_gripper_palm_link")
    tips = {f: poses[f"{s}_gripper_{f}_finger_tip_link"] for f in "lr"}
    faces = {f: tips[f][:3, :3] @ PAD_FACE_IN_TIP[f] + tips[f][:3, 3] for f in "lr"}
    return tips, faces, float(faces["l"][1] - faces["r"][1])


def _our_pad_faces(pr2_urdf: str, s: str) -> dict[str, np.ndarray]:
    """Inner-face centre of each fingertip's pad box in its link frame, read from our URDF."""
    root = ET.fromstring(pr2_urdf)
    out = {}
    for f, sign in (("l", 1.0), ("r", -1.0)):
        link = next(
            lk
            for lk in root.findall("link")
            if lk.get("name") == f"{s}_gripper_{f}_finger_tip_link"
        )
        col = link.find("collision")
        xyz = np.array([float(v) for v in col.find("origin").get("xyz").split()])
        size = np.array([float(v) for v in col.find("geometry/box").get("size").split()])
        out[f] = xyz - sign * np.array([0.0, size[1] / 2, 0.0])  # the face towards the other pad
    return out


#: finger angles sampled over the range our 2..90 mm opening covers (published limit 0..0.548 rad)
GRIPPER_THETAS = (0.02, 0.1, 0.2, 0.3, 0.4, 0.5)


def test_pr2_gripper_pads_match_the_published_four_bar(robots):
    """At each sampled finger angle of the published linkage, our fingertip frames and pad faces (FK,
    the fingers set to the published opening, the fingertips where the linkage puts them) lie within
    1 mm / 0.5 deg of the published ones: parallel to the palm, sliding along the approach."""
    pr2 = robots["pr2"]
    tree = KinematicTree(pr2.urdf_text)
    faces_ours = _our_pad_faces(pr2.urdf_text, "l")
    names = pr2.joint_names
    xs = []
    for theta in GRIPPER_THETAS:
        tips, faces, opening = _gripper_oracle("l", theta)
        q = pr2.home()
        for f in "lr":
            q[names.index(f"l_gripper_{f}_finger_joint")] = opening / 2 - PAD_GAP
        q = pr2.with_linkages(q)
        ours = tree.fk(dict(zip(names, q)))
        palm = ours["l_gripper_palm_link"]
        for f in "lr":
            tip = np.linalg.inv(palm) @ ours[f"l_gripper_{f}_finger_tip_link"]
            _assert_close(tip, tips[f], f"FK fingertip {f} at theta {theta}")
            face = tip[:3, :3] @ faces_ours[f] + tip[:3, 3]
            assert np.linalg.norm(face - faces[f]) < POS_TOL, (f, theta, face, faces[f])
        xs.append(faces["l"][0])
    # the published pads travel back along the approach as the gripper opens: 13 mm over the range
    assert np.all(np.diff(xs) < 0) and xs[0] - xs[-1] > 0.01


@pytest.mark.sim
@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_pr2_gripper_pads_on_the_engines_match_the_published_four_bar(
    make_backend, make_robot, backend
):
    """The same on each engine: the gripper commanded to each published opening and driven there
    (the fingertips following through the controller), link poses read back from the engine."""
    be = make_backend(backend)
    pr2 = make_robot("pr2")
    pr2.spawn(be)
    g = pr2.gripper("left_gripper")
    for theta in GRIPPER_THETAS[::-1]:  # closing, as a grasp does
        tips, _, opening = _gripper_oracle("l", theta)
        g.set_command([opening / 2 - PAD_GAP])
        pr2.step(int(0.5 / be.config.timestep))
        palm = be.get_link_pose(pr2.body, "l_gripper_palm_link").as_matrix()
        for f in "lr":
            tip = (
                np.linalg.inv(palm)
                @ be.get_link_pose(pr2.body, f"l_gripper_{f}_finger_tip_link").as_matrix()
            )
            _assert_close(tip, tips[f], f"{backend} fingertip {f} at theta {theta}")


def test_allegro_fk_matches_published_description(robots):
    hand = robots["allegro"]
    tree = KinematicTree(hand.urdf_text)
    for q in _allegro_samples(8, seed=21):
        want = oracle_fk(_allegro_published(), q, "palm_link")
        ours = tree.fk(q)
        for link in [*ALLEGRO_TIPS, *(f"link_{k}" for k in range(16))]:
            _assert_close(ours[link], want[link], f"FK {link}")


@pytest.mark.sim
@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_allegro_engine_fingertips_match_published_description(make_backend, make_robot, backend):
    be = make_backend(backend)
    hand = make_robot("allegro", base_pose=Pose((0.0, 0.0, 0.5)))
    hand.spawn(be)
    palm = be.get_link_pose(hand.body, "palm_link").as_matrix()
    for q in _allegro_samples(4, seed=22):
        be.set_joint_positions(hand.body, np.array([q[n] for n in hand.joint_names]))
        want = oracle_fk(_allegro_published(), q, "palm_link")
        for link in ALLEGRO_TIPS:
            got = be.get_link_pose(hand.body, link).as_matrix()
            _assert_close(got, palm @ want[link], f"{backend} {link}")


def test_oracle_composes_like_a_urdf_parser():
    """The oracle itself, checked once against pytorch-kinematics on a URDF written from the same rows."""
    rows = _allegro_published()[-5:]
    links = {"palm_link"} | {r[3] for r in rows}
    xml = ['<robot name="t">'] + [f'<link name="{lk}"/>' for lk in sorted(links)]
    for name, kind, parent, child, xyz, rpy, axis in rows:
        lim = '<limit lower="-3" upper="3" effort="1" velocity="1"/>' if kind != "fixed" else ""
        ax = f'<axis xyz="{" ".join(map(str, axis))}"/>' if axis else ""
        xml.append(
            f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{" ".join(map(str, xyz))}" rpy="{" ".join(map(str, rpy))}"/>{ax}{lim}</joint>'
        )
    xml.append("</robot>")
    tree = KinematicTree("".join(xml))
    gen = torch.Generator().manual_seed(0)
    for _ in range(3):
        q = {
            n: float(v)
            for n, v in zip(
                tree.joint_names, torch.rand(4, generator=gen, dtype=torch.float64) * 2 - 1
            )
        }
        want = oracle_fk(rows, q, "palm_link")
        got = tree.fk(q)
        np.testing.assert_allclose(
            got["link_15_tip"], want["link_15_tip"], atol=1e-6
        )  # pk parses in float32
