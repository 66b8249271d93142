"""HERB against its published descriptions: WAM frames and BarrettHand fingertips, in our FK and both engines.

The oracle is written out here, independently of our generator: the published
joint origins (xyz, rpy) and axes, copied from

* personalrobotics/herb_description @ 2604b90b3e89a9f1133355abbe2c9818509392ca:
  ``robots/herb_base.urdf.xacro`` (``root_to_frame``), ``robots/herb.urdf.xacro``
  (``/left|/right/wam_mount``, ``force_torque_mount``, ``hand_mount``),
  ``robots/wam.urdf.xacro`` (j1..j7; HERB's j1 carries a +180 deg offset, so
  herb q1 = our q1 + pi), ``config/bh280_params.urdf.xacro`` (distal mimic 45/140);
* jhu-lcsr/barrett_model @ b58cf4c0fbb0cd32fc0e8729f10a3d57d52715fc:
  ``models/hand.urdf.xacro`` (``prox_joint``, ``med_joint``, ``dist_joint``,
  ``tip_joint``, ``bhand_grasp_joint`` of fingers 1-3),

composed with numpy/scipy (URDF: T = Trans(xyz) Rot_rpy, then Rot(axis, q)).
Tolerance: 1 mm and 0.5 deg (issue 11).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.geometry import Pose
from benchharness.robots.kinematics import KinematicTree, pose_error

PI = np.pi
TOL_M, TOL_RAD = 1e-3, np.radians(0.5)

# --- published joints: (xyz, rpy, axis or None for fixed) -----------------------------------
HERB_FRAME = ((0.0, 0.0, 1.05), (0.0, 0.0, -1.57075), None)  # herb_base.urdf.xacro root_to_frame
WAM_MOUNT = {  # herb.urdf.xacro /left/wam_mount, /right/wam_mount
    "l": ((-0.355924, 0.005376, -0.357421), (0.0, -1.57075, -1.57075), None),
    "r": ((0.050805, 0.005376, -0.357421), (0.0, -1.57075, -1.57075), None),
}
WAM_JOINTS = [  # wam.urdf.xacro j1..j7
    ((0.22, 0.14, 0.346), (-1.1127e-16, 0.0, 0.0), (0, 0, 1)),
    ((0.0, 0.0, 0.0), (-1.5708, -4.0281e-16, -3.9443e-31), (0, 0, 1)),
    ((0.0, 0.0, 0.0), (1.5708, -3.9443e-31, 4.0281e-16), (0, 0, 1)),
    ((0.045, 0.0, 0.55), (-1.5708, 0.0, 0.0), (0, 0, 1)),
    ((-0.045, 0.0, 0.0), (1.5708, 0.0, 0.0), (0, 0, 1)),
    ((0.0, 0.0, 0.3), (-1.5708, 0.0, 0.0), (0, 0, 1)),
    ((0.0, 0.0, 0.0), (1.5708, 0.0, 0.0), (0, 0, 1)),
]
FORCE_TORQUE = ((0.0, 0.0, 0.06), (0.0, 0.0, 0.0), None)  # herb.urdf.xacro force_torque_mount
HAND_MOUNT = ((0.0, 0.0, 0.012), (0.0, 0.0, PI / 2), None)  # herb.urdf.xacro hand_mount
GRASP = ((0.0, 0.0, 0.12), (0.0, 0.0, 0.0), None)  # hand.urdf.xacro bhand_grasp_joint
FINGER_PROX = {  # hand.urdf.xacro finger_1/2 prox_joint (spread)
    "1": ((-0.025, 0.0, 0.0415), (0.0, 0.0, -PI / 2), (0, 0, -1)),
    "2": ((0.025, 0.0, 0.0415), (0.0, 0.0, -PI / 2), (0, 0, 1)),
}
FINGER_MED = {  # hand.urdf.xacro med_joint (proximal flex)
    "1": ((0.05, 0.0, 0.0339), (PI / 2, 0.0, 0.0), (0, 0, 1)),
    "2": ((0.05, 0.0, 0.0339), (PI / 2, 0.0, 0.0), (0, 0, 1)),
    "3": ((0.0, 0.05, 0.0754), (PI / 2, 0.0, PI / 2), (0, 0, 1)),
}
DIST = ((0.06994, 0.003, 0.0), (0.0, 0.0, PI / 4), (0, 0, 1))  # hand.urdf.xacro dist_joint
TIP = ((0.05, 0.0, 0.0), (0.0, 0.0, 0.0), None)  # hand.urdf.xacro tip_joint
COUPLING = 45.0 / 140.0  # bh280_params.urdf.xacro mimic multiplier of the distal joints


def _joint(origin, q: float = 0.0) -> np.ndarray:
    xyz, rpy, axis = origin
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
    T[:3, 3] = xyz
    if axis is not None:
        M = np.eye(4)
        M[:3, :3] = Rotation.from_rotvec(np.asarray(axis, float) * q).as_matrix()
        T = T @ M
    return T


def oracle(
    side: str, arm_q: np.ndarray, spread: float, prox: dict[str, float]
) -> dict[str, np.ndarray]:
    """Published frames of one side, in the base footprint: our link name -> 4x4."""
    out = {}
    T = _joint(HERB_FRAME) @ _joint(WAM_MOUNT[side])
    out[f"{side}_wam_base_link"] = T
    herb_q = np.array(arm_q, float)
    herb_q[0] += PI  # HERB's +180 deg j1 offset
    for i, origin in enumerate(WAM_JOINTS):
        T = T @ _joint(origin, herb_q[i])
    out[f"{side}_wam_link7"] = T
    T = T @ _joint(FORCE_TORQUE)
    out[f"{side}_wam_ft_link"] = T
    palm = T @ _joint(HAND_MOUNT)
    out[f"{side}_bh_palm_link"] = palm
    out[f"{side}_bh_tcp"] = palm @ _joint(GRASP)
    for f in "123":
        T = palm
        if f in FINGER_PROX:
            T = T @ _joint(FINGER_PROX[f], spread)
        T = T @ _joint(FINGER_MED[f], prox[f]) @ _joint(DIST, COUPLING * prox[f]) @ _joint(TIP)
        out[f"{side}_bh_finger_{f}_tip"] = T
    return out


def _samples(robot, n: int, seed: int):
    """Joint dicts (our names) at random arm and hand values, distal joints coupled; and the inputs."""
    rng = np.random.default_rng(seed)
    lim = robot.urdf_joints
    for _ in range(n):
        q: dict[str, float] = {}
        inputs = {}
        for s in "lr":
            arm = np.array(
                [
                    rng.uniform(lim[f"{s}_wam_j{i}"].lower, lim[f"{s}_wam_j{i}"].upper)
                    for i in range(1, 8)
                ]
            )
            spread = rng.uniform(0.0, PI)
            prox = {f: rng.uniform(0.0, np.radians(140.0)) for f in "123"}
            q.update({f"{s}_wam_j{i + 1}": v for i, v in enumerate(arm)})
            q[f"{s}_bh_j11_joint"] = q[f"{s}_bh_j21_joint"] = spread
            for f in "123":
                q[f"{s}_bh_j{f}2_joint"] = prox[f]
                q[f"{s}_bh_j{f}3_joint"] = COUPLING * prox[f]
            inputs[s] = (arm, spread, prox)
        yield q, inputs


def _assert_close(ours: np.ndarray, ref: np.ndarray, what: str) -> None:
    dp, dr = pose_error(ours, ref)
    assert dp[0] < TOL_M and dr[0] < TOL_RAD, (
        f"{what}: {dp[0] * 1e3:.3f} mm, {np.degrees(dr[0]):.3f} deg from the published description"
    )


def test_oracle_reproduces_published_layout():
    """The oracle itself against figures stated in the sources: j1 axes horizontal along +x, 0.407 m apart."""
    j1 = {}
    for s in "lr":
        T = _joint(HERB_FRAME) @ _joint(WAM_MOUNT[s]) @ _joint(WAM_JOINTS[0])
        assert np.allclose(T[:3, 2], [1.0, 0.0, 0.0], atol=1e-4)
        j1[s] = T[:3, 3]
    assert np.linalg.norm(j1["l"] - j1["r"]) == pytest.approx(0.4067, abs=1e-3)
    assert j1["l"][2] == pytest.approx(0.9126, abs=1e-3) and j1["l"][0] == pytest.approx(
        0.351, abs=1e-3
    )
    # BarrettHand zero: every proximal link flat, pointing radially out of the palm
    tips = oracle("l", np.zeros(7), 0.0, {f: 0.0 for f in "123"})
    palm = tips["l_bh_palm_link"]
    for f in "123":
        local = np.linalg.inv(palm) @ tips[f"l_bh_finger_{f}_tip"]
        # flex axis 75.4 mm up, 3 mm distal offset and the 45 deg bent 50 mm tip rising from it
        assert local[2, 3] == pytest.approx(0.0754 + 0.003 + 0.05 * np.sin(PI / 4), abs=1e-6)
        # radially out: 50 mm knuckle-to-flex (finger 3: flex axis 50 mm off the palm axis),
        # 69.94 mm proximal link, 50 mm cos 45 deg of the tip; fingers 1/2 25 mm to the side
        radial = 0.05 + 0.06994 + 0.05 * np.cos(PI / 4)
        expect = (0.0, radial) if f == "3" else ((-0.025 if f == "1" else 0.025), -radial)
        assert local[:2, 3] == pytest.approx(expect, abs=1e-6)


def test_our_fk_matches_published(robots):
    robot = robots["herb"]
    tree = KinematicTree(robot.urdf_text)
    for q, inputs in _samples(robot, 20, seed=0):
        tf = tree.fk(q)
        for s in "lr":
            for link, ref in oracle(s, *inputs[s]).items():
                _assert_close(tf[link], ref, f"FK {link}")
            # and the arm's own chain (IK base -> tool frame)
            arm = robot.arm("left_arm" if s == "l" else "right_arm")
            import torch

            T = arm.fk(torch.tensor(inputs[s][0], dtype=torch.float64)[None])[0]
            ref = oracle(s, *inputs[s])
            rel = np.linalg.inv(ref[f"{s}_wam_base_link"]) @ ref[f"{s}_bh_tcp"]
            _assert_close(np.asarray(T), rel, f"arm chain {s} tcp")


@pytest.mark.parametrize("backend", ("pybullet", "sapien"))
def test_engine_link_poses_match_published(make_backend, make_robot, backend):
    be = make_backend(backend)
    robot = make_robot("herb")
    base = Pose([0.3, -0.2, 0.0], [0.0, 0.0, np.sin(0.2), np.cos(0.2)])
    robot.spawn(be, base)
    Tb = base.as_matrix()
    for q, inputs in _samples(robot, 4, seed=1):
        be.set_joint_positions(robot.body, np.array([q[j] for j in robot.joint_names]))
        for s in "lr":
            for link, ref in oracle(s, *inputs[s]).items():
                got = be.get_link_pose(robot.body, link).as_matrix()
                _assert_close(got, Tb @ ref, f"{backend} {link}")
