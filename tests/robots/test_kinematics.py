"""Kinematics of every arm / finger chain against independent oracles (no physics).

* pytorch-kinematics FK vs yourdfpy FK (a different URDF parser and FK code);
* Jacobians vs finite differences of FK;
* IK: random joint configurations within limits -> FK -> IK from other
  random seeds must reach >= 95 % of the poses within 1 mm / 1 degree.
"""

from __future__ import annotations

import numpy as np
import pytest
import torch
import yourdfpy

from benchharness.kinematics import pose_error

CHAINS = [("pr2", "left_arm"), ("pr2", "right_arm"), ("herb", "left_arm"), ("herb", "right_arm"),
          ("allegro", "index"), ("allegro", "thumb")]


@pytest.fixture(scope="module")
def urdfs(robots):
    return {n: yourdfpy.URDF.load(str(r.urdf_path), load_meshes=False, build_scene_graph=True,
                                  build_collision_scene_graph=False) for n, r in robots.items()}


@pytest.mark.parametrize("robot,chain", CHAINS)
def test_fk_matches_yourdfpy(robots, urdfs, robot, chain):
    arm = robots[robot].arm(chain)
    u = urdfs[robot]
    q = arm.chain.sample(20, torch.Generator().manual_seed(7))
    ours = arm.fk(q)
    for k in range(len(q)):
        cfg = dict(zip(u.actuated_joint_names, np.zeros(len(u.actuated_joint_names))))
        cfg.update(zip(arm.joints, q[k]))
        u.update_cfg(cfg)
        ref = u.get_transform(arm.config.tcp_link, arm.config.base_link)
        dp, dr = pose_error(ours[k], ref)
        assert dp[0] < 1e-6 and dr[0] < 1e-6


@pytest.mark.parametrize("robot,chain", CHAINS)
def test_jacobian_matches_finite_differences(robots, robot, chain):
    arm = robots[robot].arm(chain)
    q = arm.chain.sample(3, torch.Generator().manual_seed(3), margin=0.05)
    jac = arm.jacobian(q)
    h = 1e-6
    for k in range(len(q)):
        t0 = arm.fk(q[k])[0]
        for i in range(arm.chain.dof):
            dq = q[k].copy()
            dq[i] += h
            t1 = arm.fk(dq)[0]
            v = (t1[:3, 3] - t0[:3, 3]) / h
            w_hat = (t1[:3, :3] - t0[:3, :3]) / h @ t0[:3, :3].T
            w = np.array([w_hat[2, 1], w_hat[0, 2], w_hat[1, 0]])
            np.testing.assert_allclose(jac[k, :3, i], v, atol=1e-5)
            np.testing.assert_allclose(jac[k, 3:, i], w, atol=1e-5)


@pytest.mark.parametrize("robot,chain,n", [("pr2", "left_arm", 200), ("pr2", "right_arm", 100), ("herb", "left_arm", 200),
                                           ("allegro", "index", 100), ("allegro", "thumb", 100)])
def test_ik_reaches_sampled_poses(robots, robot, chain, n):
    arm = robots[robot].arm(chain)
    q_true = arm.chain.sample(n, torch.Generator().manual_seed(11))
    targets = arm.fk(q_true)
    res = arm.ik(targets, generator=torch.Generator().manual_seed(12))
    assert np.all(res.q >= arm.lower - 1e-9) and np.all(res.q <= arm.upper + 1e-9), "IK left the joint limits"
    reached = arm.fk(res.q)
    dp, dr = pose_error(reached, targets)
    ok = dp <= 1e-3
    if not arm.config.position_only:
        ok &= dr <= np.radians(1.0)
    assert ok.mean() >= 0.95, f"{robot}.{chain}: {ok.mean():.1%} of {n} targets within 1 mm / 1 deg"


def test_ik_is_deterministic_given_a_seed(robots):
    arm = robots["pr2"].arm("left_arm")
    targets = arm.fk(arm.chain.sample(10, torch.Generator().manual_seed(1)))
    a = arm.ik(targets, seed=5)
    b = arm.ik(targets, seed=5)
    np.testing.assert_array_equal(a.q, b.q)


def test_ik_prefers_the_solution_near_the_seed(robots):
    arm = robots["pr2"].arm("left_arm")
    q0 = arm.chain.sample(1, torch.Generator().manual_seed(2), margin=0.3)[0]
    res = arm.ik(arm.fk(q0), seed_q=q0, seed=3)
    assert res.success[0]
    assert np.max(np.abs(res.q[0] - q0)) < 1e-3


@pytest.mark.parametrize("robot", ["pr2", "herb"])
def test_gravity_torques_are_the_gradient_of_potential_energy(robots, robot):
    """Holding torque = dV/dq with V = -sum m_i g . c_i (an independent finite-difference oracle)."""
    from benchharness.robots.gravity import GravityModel

    r = robots[robot]
    model = GravityModel(r.urdf_path)
    q = dict(zip(r.joint_names, r.home()))
    joints = [j for j in r.joint_names if "finger" not in j and "_bh_" not in j]

    def potential(qq):
        tf = model.tree.fk(qq)
        return -sum(model.mass[lk] * model.gravity @ (tf[lk][:3, :3] @ model.com[lk] + tf[lk][:3, 3])
                    for lk in model.mass if lk in tf)

    tau = model.torques(q, joints)
    h = 1e-6
    for k, j in enumerate(joints):
        qp, qm = dict(q), dict(q)
        qp[j] += h
        qm[j] -= h
        assert tau[k] == pytest.approx((potential(qp) - potential(qm)) / (2 * h), abs=1e-4)


@pytest.mark.slow
@pytest.mark.parametrize("robot,chain", CHAINS + [("allegro", "middle"), ("allegro", "ring")])
def test_ik_reaches_1000_sampled_poses(robots, robot, chain):
    """The full-size version of test_ik_reaches_sampled_poses (about 5-10 s per arm)."""
    arm = robots[robot].arm(chain)
    q_true = arm.chain.sample(1000, torch.Generator().manual_seed(21))
    targets = arm.fk(q_true)
    res = arm.ik(targets, generator=torch.Generator().manual_seed(22))
    dp, dr = pose_error(arm.fk(res.q), targets)
    ok = (dp <= 1e-3) & ((dr <= np.radians(1.0)) | arm.config.position_only)
    assert ok.mean() >= 0.95
