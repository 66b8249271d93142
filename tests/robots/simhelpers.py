"""Shared checks of the per-robot simulation tests (imported by the test modules)."""

from __future__ import annotations

import numpy as np
import torch

from benchharness.geometry import Pose
from benchharness.robots.kinematics import KinematicTree, pose_error

#: Tolerances stated for tracked motions (docs/robots.md repeats them).
TRACK_MAX_ERROR = 0.05  # rad, max |q_ref - q| during a move at half the velocity limits
FINAL_POS_ERROR = 0.003  # m, tool frame vs target after 0.3 s of settling
FINAL_ROT_ERROR = np.radians(1.0)


def check_fk_against_backend(robot, backend, n: int = 4, seed: int = 0) -> None:
    """Teleport random configurations; every TCP link's backend pose must equal our FK."""
    tree = KinematicTree(robot.urdf_text)
    gen = torch.Generator().manual_seed(seed)
    lo = np.array([robot.urdf_joints[j].lower for j in robot.joint_names])
    hi = np.array([robot.urdf_joints[j].upper for j in robot.joint_names])
    # continuous joints (PR2 forearm/wrist roll) have no limits: sample them over two turns
    lo, hi = np.where(np.isfinite(lo), lo, -2 * np.pi), np.where(np.isfinite(hi), hi, 2 * np.pi)
    base = backend.get_link_pose(robot.body, None)
    for _ in range(n):
        q = lo + torch.rand(len(lo), generator=gen, dtype=torch.float64).numpy() * (hi - lo)
        backend.set_joint_positions(robot.body, q)
        tf = tree.fk(dict(zip(robot.joint_names, q)))
        for link in robot.tcp_links().values():
            ours = (base * Pose.from_matrix(tf[link])).as_matrix()
            theirs = backend.get_link_pose(robot.body, link).as_matrix()
            dp, dr = pose_error(ours, theirs)
            assert dp[0] < 1e-4 and dr[0] < 1e-3, (
                f"{link}: backend differs from FK by {dp[0] * 1e3:.3f} mm, {np.degrees(dr[0]):.3f} deg"
            )


def offset_pose(p: Pose, dp, axis_angle) -> Pose:
    from scipy.spatial.transform import Rotation

    return Pose(
        p.p + np.asarray(dp, float), (Rotation.from_rotvec(axis_angle) * p.rotation).as_quat()
    )


def check_motion(res, position_only: bool = False) -> None:
    assert res.ik_success
    assert res.peak_velocity_ratio <= 1.0 + 1e-9, "trajectory exceeds a joint velocity limit"
    assert res.measured_velocity_ratio <= 1.0, (
        f"a joint moved at {res.measured_velocity_ratio:.2f} x its limit"
    )
    assert res.max_tracking_error < TRACK_MAX_ERROR, (
        f"tracking error {res.max_tracking_error:.4f} rad"
    )
    assert res.pos_error < FINAL_POS_ERROR, f"final position error {res.pos_error * 1e3:.2f} mm"
    if not position_only:
        assert res.rot_error < FINAL_ROT_ERROR, (
            f"final rotation error {np.degrees(res.rot_error):.2f} deg"
        )
