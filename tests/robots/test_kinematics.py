"""Kinematics of every arm / finger chain against independent oracles (no physics).

* pytorch-kinematics FK vs yourdfpy FK (a different URDF parser and FK code);
* Jacobians vs finite differences of FK;
* IK: random joint configurations within limits -> FK -> IK from other
  random seeds must reach >= 95 % of the poses within 1 mm / 1 degree;
* the NumPy FK/Jacobian/DLS twins vs pytorch-kinematics' own, the rotation
  error vs scipy, seed-first IK vs the restart solver;
* gravity feed-forward of a spawned robot (the engines' inverse dynamics)
  vs ``GravityModel``, itself checked against finite differences of the
  potential energy.
"""

from __future__ import annotations

import numpy as np
import pytest
import torch
import yourdfpy

from benchharness.robots.kinematics import pose_error

CHAINS = [
    ("pr2", "left_arm"),
    ("pr2", "right_arm"),
    ("herb", "left_arm"),
    ("herb", "right_arm"),
    ("allegro", "index"),
    ("allegro", "thumb"),
]


@pytest.fixture(scope="module")
def urdfs(robots):
    return {
        n: yourdfpy.URDF.load(
            str(r.urdf_path),
            load_meshes=False,
            build_scene_graph=True,
            build_collision_scene_graph=False,
        )
        for n, r in robots.items()
    }


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
def test_joint_origins_match_yourdfpy(robots, urdfs, robot, chain):
    """``RobotArm.joint_origins`` (the PR2 planner's arm-against-arm check) is each movable joint's child
    link origin, as yourdfpy places it."""
    arm = robots[robot].arm(chain)
    u = urdfs[robot]
    q = arm.chain.sample(10, torch.Generator().manual_seed(3))
    ours = arm.joint_origins(q)
    assert ours is not None and ours.shape == (len(q), len(arm.joints), 3)
    children = [u.joint_map[j].child for j in arm.chain.joint_names]
    for k in range(len(q)):
        cfg = dict(zip(u.actuated_joint_names, np.zeros(len(u.actuated_joint_names))))
        cfg.update(zip(arm.joints, q[k]))
        u.update_cfg(cfg)
        for i, child in enumerate(children):
            ref = u.get_transform(child, arm.config.base_link)[:3, 3]
            np.testing.assert_allclose(ours[k, i], ref, atol=1e-6)


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


@pytest.mark.parametrize(
    "robot,chain,n",
    [
        ("pr2", "left_arm", 200),
        ("pr2", "right_arm", 100),
        ("herb", "left_arm", 200),
        ("allegro", "index", 100),
        ("allegro", "thumb", 100),
    ],
)
def test_ik_reaches_sampled_poses(robots, robot, chain, n):
    arm = robots[robot].arm(chain)
    q_true = arm.chain.sample(n, torch.Generator().manual_seed(11))
    targets = arm.fk(q_true)
    res = arm.ik(targets, generator=torch.Generator().manual_seed(12))
    assert np.all(res.q >= arm.lower - 1e-9) and np.all(res.q <= arm.upper + 1e-9), (
        "IK left the joint limits"
    )
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
        return -sum(
            model.mass[lk] * model.gravity @ (tf[lk][:3, :3] @ model.com[lk] + tf[lk][:3, 3])
            for lk in model.mass
            if lk in tf
        )

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


@pytest.mark.parametrize("robot,chain", CHAINS)
def test_numpy_model_matches_pytorch_kinematics(robots, robot, chain):
    """The NumPy FK/Jacobian used for small batches and the seeded IK equals pytorch-kinematics'."""
    ch = robots[robot].arm(chain).chain
    assert ch._np is not None, "the NumPy model failed its construction-time check"
    q = ch.sample(64, torch.Generator().manual_seed(5))
    tip, jac = ch._np.fk_jacobian(q)
    np.testing.assert_allclose(tip, ch._fk_pk(q), atol=1e-12)
    np.testing.assert_allclose(jac, ch.chain.jacobian(torch.as_tensor(q)).numpy(), atol=1e-12)
    np.testing.assert_allclose(
        ch.fk(q[:3]), ch._fk_pk(q[:3]), atol=1e-12
    )  # small batch: NumPy path


@pytest.mark.parametrize("robot,chain", CHAINS)
def test_numpy_jacobian_is_numpys_cross_product_to_the_bit(robots, robot, chain):
    """The Jacobian's linear rows are ``np.cross(z, tip - origin)`` exactly, at every batch size.

    The NumPy model writes the cross product and the rotation vector with fewer array operations
    than the textbook form (a speed-up); the claim is that every element is the same products and
    differences, so seeded IK results did not move by a bit. ``np.cross`` is the oracle, with exact
    zeros among the joint values (sign-of-zero cases) and batches 1, 3 and 40 (pytorch-kinematics'
    size) covered.
    """
    from benchharness.robots.kinematics import _rotvec_between

    ch = robots[robot].arm(chain).chain
    model = ch._np
    for b in (1, 3, 40):
        q = ch.sample(b, torch.Generator().manual_seed(b))
        q[: max(1, b // 3)] = np.round(q[: max(1, b // 3)])  # whole radians, zeros among them
        q = np.clip(q, ch.lower, ch.upper)
        tip, jac = model.fk_jacobian(q)
        origins = ch.joint_origins(q)
        z = jac[:, 3:, :].transpose(0, 2, 1)
        expect = np.cross(z, tip[:, None, :3, 3] - origins)
        assert jac[:, :3, :].transpose(0, 2, 1).tobytes() == expect.tobytes()
        r = tip[:, :3, :3]
        t = r[::-1].copy()
        rr = t @ r.transpose(0, 2, 1)
        v = 0.5 * np.stack(
            [rr[:, 2, 1] - rr[:, 1, 2], rr[:, 0, 2] - rr[:, 2, 0], rr[:, 1, 0] - rr[:, 0, 1]],
            axis=1,
        )
        n = np.linalg.norm(v, axis=1)
        ang = np.arctan2(n, 0.5 * (rr[:, 0, 0] + rr[:, 1, 1] + rr[:, 2, 2] - 1.0))
        ok = ang < np.pi - 1e-3
        want = v * (ang / np.maximum(n, 1e-300))[:, None]
        assert _rotvec_between(t, r)[ok].tobytes() == want[ok].tobytes()


@pytest.mark.parametrize("robot,chain", [("pr2", "left_arm"), ("herb", "right_arm")])
def test_seeded_ik_matches_the_restart_solver(robots, robot, chain):
    """Seed-first (NumPy descent) vs the pytorch-kinematics restart solver on motion-sized targets.

    Targets are 0.15 rad (std) away from the seed, as in a motion. Both must
    reach 1e-4 m / 1e-3 rad, and the seed-first answer must be the one
    continuous with the seed: no farther from it than the restart solver's.
    """
    from dataclasses import replace

    arm = robots[robot].arm(chain)
    ch = arm.chain
    rng = np.random.default_rng(4)
    seeds = ch.sample(30, torch.Generator().manual_seed(4), margin=0.3)
    goals = np.clip(seeds + rng.normal(0.0, 0.15, seeds.shape), ch.lower, ch.upper)
    targets = ch.fk(goals)
    fast = ch.ik(targets, seed_q=seeds, seed=0)
    slow = ch.ik(
        targets, seed_q=seeds, seed=0, config=replace(arm.robot.ik_config, seed_first=False)
    )
    assert fast.success.all() and slow.success.all()
    dp, dr = pose_error(ch.fk(fast.q), targets)
    assert dp.max() < 1e-4 and dr.max() < 1e-3
    d_fast = np.abs(fast.q - seeds).max(axis=1)
    d_slow = np.abs(slow.q - seeds).max(axis=1)
    assert np.all(d_fast <= d_slow + 1e-3)
    again = ch.ik(targets, seed_q=seeds, seed=0)
    np.testing.assert_array_equal(fast.q, again.q)  # deterministic


def test_seeded_ik_falls_back_to_restarts(robots):
    """A seed whose descent cannot converge (2 iterations) still gets a solution from the restarts."""
    from dataclasses import replace

    arm = robots["pr2"].arm("left_arm")
    ch = arm.chain
    q_true = ch.sample(5, torch.Generator().manual_seed(8), margin=0.2)
    seeds = ch.sample(5, torch.Generator().manual_seed(9), margin=0.2)
    cfg = replace(arm.robot.ik_config, max_iterations=2, refine_iterations=0, retry_num_retries=32)
    first = ch._ik_seeded(ch.fk(q_true), seeds, cfg)
    assert not first.success.any()
    res = ch.ik(ch.fk(q_true), seed_q=seeds, seed=1, config=cfg)
    assert res.success.mean() >= 0.8
    dp, _ = pose_error(ch.fk(res.q), ch.fk(q_true))
    assert np.all(dp[res.success] < 1e-4)


def test_rotation_error_matches_scipy():
    """The seeded IK's rotation error (shortest rotation vector) vs scipy, incl. angles near 0 and pi."""
    from scipy.spatial.transform import Rotation

    from benchharness.robots.kinematics import _rotvec_between

    cur = Rotation.random(300, random_state=2)
    rng = np.random.default_rng(0)
    cases = [
        Rotation.random(300, random_state=1),
        Rotation.from_rotvec(rng.normal(0.0, 1e-9, (300, 3))) * cur,
        Rotation.from_rotvec(np.outer(np.linspace(np.pi - 2e-3, np.pi, 300), [0.6, 0.0, 0.8]))
        * cur,
    ]
    for tgt in cases:
        got = _rotvec_between(tgt.as_matrix(), cur.as_matrix())
        want = (tgt * cur.inv()).as_rotvec()
        assert (
            Rotation.from_rotvec(got) * Rotation.from_rotvec(want).inv()
        ).magnitude().max() < 1e-9
        np.testing.assert_allclose(
            np.linalg.norm(got, axis=1), np.linalg.norm(want, axis=1), atol=1e-9
        )


@pytest.mark.parametrize(
    "robot,chain", [("pr2", "left_arm"), ("herb", "left_arm"), ("allegro", "index")]
)
def test_numpy_dls_matches_pytorch_kinematics_solver(robots, robot, chain):
    """The NumPy solver (small IK passes) vs pytorch-kinematics' PseudoInverseIK from the same restarts.

    Same iteration, same sticky convergence and limit refinement: they must
    converge on the same restarts (but for a rare borderline one) and, where
    both converge, land on the same joint vector (to 1e-6 rad) for >= 90 %.
    """
    import torch as _t

    arm = robots[robot].arm(chain)
    ch = arm.chain
    cfg = arm.robot.ik_config
    targets = ch.fk(ch.sample(20, _t.Generator().manual_seed(31)))
    init = ch.sample(20 * 3, _t.Generator().manual_seed(32)).reshape(20, 3, ch.dof)
    q_np, _, _, c_np = ch._dls(targets, init, cfg, cfg.max_iterations, stop_when_any=False)
    q_pk, _, c_pk = ch._pk_solve(targets, init, cfg, cfg.max_iterations, False)
    both = c_np & c_pk
    assert (c_np == c_pk).mean() >= 0.95 and both.sum() >= 10  # random restarts: ~40 % converge
    diff = np.abs(q_np[both] - q_pk[both]).max(axis=1)
    # a redundant arm's solutions form a continuum: a restart that crosses the tolerance one iteration
    # apart (rounding) ends on a nearby point of it, so a few may differ by mrad
    assert (diff < 1e-6).mean() >= 0.9 and diff.max() < 2e-2


def test_small_unseeded_batches_use_numpy_and_reach_targets(robots):
    """40 targets x 4 restarts run in NumPy: >= 95 % within 1 mm / 1 deg, deterministic."""
    arm = robots["pr2"].arm("right_arm")
    ch = arm.chain
    targets = ch.fk(ch.sample(40, torch.Generator().manual_seed(41)))
    a = ch.ik(targets, seed=2)
    dp, dr = pose_error(ch.fk(a.q), targets)
    assert ((dp <= 1e-3) & (dr <= np.radians(1.0))).mean() >= 0.95
    np.testing.assert_array_equal(a.q, ch.ik(targets, seed=2).q)


@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
@pytest.mark.parametrize("robot", ["pr2", "herb"])
def test_robot_gravity_feed_forward_matches_urdf_model(make_backend, make_robot, backend, robot):
    """Robot's feed-forward (the engine's gravity_torques) vs GravityModel, and the fallback path.

    The robot is spawned on a yawed base at a random configuration; hand
    joints get 0 (the hands hold by their own drives). A backend without
    the capability makes the robot use GravityModel itself: same torques.
    """
    from dataclasses import replace

    from benchharness.geometry import Pose
    from benchharness.robots.gravity import GravityModel

    be = make_backend(backend)
    r = make_robot(robot)
    base = Pose([0.2, -0.1, 0.0], [0.0, 0.0, np.sin(0.3), np.cos(0.3)])
    r.spawn(be, base)
    lo = np.array([r.urdf_joints[j].lower for j in r.joint_names])
    hi = np.array([r.urdf_joints[j].upper for j in r.joint_names])
    lo, hi = np.where(np.isfinite(lo), lo, -np.pi), np.where(np.isfinite(hi), hi, np.pi)
    q = lo + np.random.default_rng(3).uniform(0.1, 0.9, len(lo)) * (hi - lo)
    be.set_joint_positions(r.body, q)
    joints = r._gravity_joints()
    want = GravityModel(r.urdf_path, be.config.gravity).torques(
        dict(zip(r.joint_names, q)), joints, base.rotation.as_matrix()
    )
    assert np.abs(want).max() > 1.0
    got = r._gravity_torques(joints)
    np.testing.assert_allclose(got, want, atol=1e-4 * max(1.0, np.abs(want).max()))
    grip = [j for j in r.joint_names if j not in joints]
    if grip:
        assert not np.any(r._gravity_torques(grip))
    be.capabilities = replace(be.capabilities, gravity_torques=False)  # this instance only
    r._gcache = None
    # (SAPIEN reports q in float32: the model sees q to ~1e-7 rad)
    np.testing.assert_allclose(
        r._gravity_torques(joints), want, atol=1e-6 * max(1.0, np.abs(want).max())
    )
