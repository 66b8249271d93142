"""Conformance suite: every registered backend must pass it.

Backends come from the plugin manager, so a third-party backend installed
through the ``benchharness`` entry-point group is tested too. Each test checks
an analytic answer or a stated bound.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from backend_scenes import (
    ARM_URDF,
    ASSETS,
    CUBE_HALF,
    CUBE_MASS,
    FINGER_D,
    FINGER_K,
    GRASP_Z,
    GRIPPER_URDF,
    OPEN_Q,
    PAD_OFFSET,
    ROTOR_URDF,
    SQUEEZE,
    GripperScene,
    grasp_lift_hold,
    gripper_scene,
    trajectory_digest,
)
from scipy.spatial.transform import Rotation

from benchharness.backends import (
    Backend,
    BackendError,
    Box,
    CameraSpec,
    CapabilityError,
    Cylinder,
    MeshShape,
    SimulationError,
    Sphere,
)
from benchharness.geometry import Pose

G = 9.81


# -- bodies and time ----------------------------------------------------------
def test_free_fall_matches_analytic(backend: Backend):
    """z(t) = z0 - g t^2 / 2. Semi-implicit Euler is off by g dt t / 2; allow g dt t."""
    dt = backend.config.timestep
    s = backend.add_body([Sphere(0.05)], Pose([0, 0, 10.0]), 1.0)
    arm = backend.load_urdf(ARM_URDF, Pose([1.0, 0, 10.0]), fixed_base=False)
    for _ in range(4):
        backend.step(30)
        t = backend.time
        z = 10.0 - 0.5 * G * t * t
        tol = G * dt * t + 1e-6
        assert abs(backend.get_pose(s).p[2] - z) <= tol
        assert abs(backend.get_pose(arm).p[2] - z) <= tol  # a free-base articulation falls alike
        lin, ang = backend.get_velocity(s)
        assert lin[2] == pytest.approx(-G * t, rel=1e-3)
        assert np.allclose(lin[:2], 0, atol=1e-9) and np.allclose(ang, 0, atol=1e-9)
    assert backend.time == pytest.approx(120 * dt)


def test_pose_velocity_roundtrip(backend: Backend):
    b = backend.add_body([Box((0.1, 0.05, 0.02)), Sphere(0.03, Pose([0.1, 0, 0]))], Pose(), 2.0)
    pose = Pose([0.3, -0.2, 1.5], Rotation.from_euler("xyz", [0.3, -0.2, 1.0]).as_quat())
    backend.set_velocity(b, [0.1, 0.2, 0.3], [0.5, -0.4, 0.2])
    backend.set_pose(b, pose)  # keeps velocity
    assert backend.get_pose(b).allclose(pose, atol_p=1e-6, atol_q=1e-6)
    lin, ang = backend.get_velocity(b)
    assert np.allclose(lin, [0.1, 0.2, 0.3], atol=1e-6) and np.allclose(
        ang, [0.5, -0.4, 0.2], atol=1e-6
    )
    assert backend.get_mass(b) == pytest.approx(2.0)


def test_shapes_rest_at_their_height(backend: Backend):
    """Each primitive, resting on the ground, has its lowest point at z = 0 (within 1 mm)."""
    backend.add_ground()
    verts = np.array(
        [[x, y, z] for x in (-0.03, 0.03) for y in (-0.02, 0.02) for z in (-0.01, 0.01)]
    )
    faces = np.array([[0, 1, 2]])
    cases = [
        (Box((0.03, 0.02, 0.01)), 0.01),
        (Sphere(0.025), 0.025),
        (Cylinder(0.02, 0.04), 0.04),  # axis along local z: stands on its end
        (MeshShape(verts, faces), 0.01),
    ]
    bodies = []
    for i, (shape, h) in enumerate(cases):
        bodies.append((backend.add_body([shape], Pose([0.2 * i, 0, h + 0.002]), 0.1), h))
    backend.step(120)
    for b, h in bodies:
        assert backend.get_pose(b).p[2] == pytest.approx(h, abs=1e-3)


def test_compound_body(backend: Backend):
    """A box with a convex-mesh foot rests on the foot; uniform density puts the COM between them."""
    backend.add_ground()
    foot = np.array(
        [[x, y, z] for x in (-0.02, 0.02) for y in (-0.02, 0.02) for z in (-0.01, 0.01)]
    )
    shapes = [
        Box((0.05, 0.05, 0.05)),
        MeshShape(foot, np.zeros((0, 3), dtype=int), Pose([0, 0, -0.06])),
    ]
    b = backend.add_body(shapes, Pose([0, 0, 0.072]), 1.0)
    backend.step(240)
    assert backend.get_pose(b).p[2] == pytest.approx(0.07, abs=1e-3)
    assert backend.get_pose(b).rotation.magnitude() < 1e-2


def test_box_resting_contacts(backend: Backend):
    """Normal from B (ground) to A (box) is +z; the normal forces add up to m g within 3%."""
    g = backend.add_ground()
    m = 0.5
    box = backend.add_body([Box((0.05, 0.04, 0.03))], Pose([0, 0, 0.03]), m)
    backend.step(120)
    cs = backend.contacts(box, g)
    assert cs, "a resting box must report contacts"
    for c in cs:
        assert (c.body_a, c.body_b, c.link_a, c.link_b) == (box, g, None, None)
        assert c.normal @ [0, 0, 1] > 0.99
        assert c.normal_force >= 0
        assert abs(c.position[2]) < 2e-3 and abs(c.distance) < 2e-3
    assert sum(c.normal_force for c in cs) == pytest.approx(m * G, rel=0.03)
    flipped = backend.contacts(g, box)
    assert flipped and all(c.body_a == g and c.normal @ [0, 0, 1] < -0.99 for c in flipped)
    assert sum(c.normal_force for c in backend.contacts(body_b=g)) == pytest.approx(m * G, rel=0.03)
    assert all(c.body_b == g for c in backend.contacts(body_b=g))


# -- URDF, joints, drives ---------------------------------------------------------
def test_urdf_joint_and_link_info(backend: Backend):
    arm = backend.load_urdf(ARM_URDF, Pose([0.5, 0, 0]))
    info = backend.joint_info(arm)
    assert [j.name for j in info] == ["yaw", "pitch"] == backend.joint_names(arm)
    assert (info[0].lower, info[0].upper, info[0].max_effort, info[0].max_velocity) == (
        -3.0,
        3.0,
        50.0,
        3.0,
    )
    assert (info[1].parent_link, info[1].child_link, info[1].type) == ("upper", "fore", "revolute")
    assert backend.link_names(arm) == ["base", "upper", "fore", "tip"]
    assert backend.get_mass(arm) == pytest.approx(2.85)
    rot = backend.load_urdf(ROTOR_URDF, Pose())
    j = backend.joint_info(rot)[0]
    assert j.type == "continuous" and j.lower == -math.inf and j.upper == math.inf
    with pytest.raises(BackendError):
        backend.get_link_pose(arm, "no_such_link")


def test_link_poses_match_forward_kinematics(backend: Backend):
    base = Pose([0.5, -0.2, 0.1], Rotation.from_euler("z", 0.4).as_quat())
    arm = backend.load_urdf(ARM_URDF, base)
    q = np.array([0.7, -0.5])
    backend.set_joint_positions(arm, q)
    st = backend.get_joint_state(arm)
    assert np.allclose(st.positions, q, atol=1e-6) and np.allclose(st.velocities, 0, atol=1e-9)
    up = base * Pose([0, 0, 0.1], Rotation.from_euler("z", q[0]).as_quat())
    fore = up * Pose([0, 0, 0.2], Rotation.from_euler("y", q[1]).as_quat())
    tip = fore * Pose([0.2, 0, 0], Rotation.from_euler("y", math.pi / 2).as_quat())
    for name, want in (("base", base), (None, base), ("upper", up), ("fore", fore), ("tip", tip)):
        assert backend.get_link_pose(arm, name).allclose(want, atol_p=1e-5, atol_q=1e-5), name
    backend.set_joint_positions(arm, [0.1], joints=["pitch"])
    assert backend.get_joint_state(arm).positions == pytest.approx([0.7, 0.1], abs=1e-6)


def test_pd_gains_are_physical(backend: Backend):
    """A 1-DOF rotor (I = 0.01 kg m^2), k = 1, d = 0.1: a damped oscillator, omega 10 rad/s, zeta 0.5.

    Bound: 0.01 rad (2% of the 0.5 rad step) from the analytic response over 1 s.
    """
    rot = backend.load_urdf(ROTOR_URDF, Pose())
    backend.set_joint_targets(rot, [0.5], stiffness=1.0, damping=0.1)
    w, z = 10.0, 0.5
    wd = w * math.sqrt(1 - z * z)
    worst = 0.0
    for _ in range(int(1.0 / backend.config.timestep)):
        backend.step()
        t = backend.time
        qa = 0.5 * (
            1
            - math.exp(-z * w * t)
            * (math.cos(wd * t) + z / math.sqrt(1 - z * z) * math.sin(wd * t))
        )
        worst = max(worst, abs(backend.get_joint_state(rot).positions[0] - qa))
    assert worst < 0.01


def test_gravity_torques(backend: Backend):
    """Holding torques G(q) against analytic values, the URDF model (tilted and free bases), and physics.

    The 2-DOF arm upright: the yaw joint carries nothing, the pitch joint
    -g (0.3 * 0.1 + 0.05 * 0.2) cos(pitch) = -0.3924 cos(pitch) N m. Tilted or
    free-floating bases are checked against ``GravityModel`` (an independent
    summation over the URDF's masses). Finally the torques must hold the arm:
    a PD drive aimed at ``q + G/k`` keeps the tilted arm within 0.5 mrad
    (without the feed-forward it sags by G/k ~ 2.4 mrad).
    """
    from benchharness.robots.gravity import GravityModel

    arm = backend.load_urdf(ARM_URDF, Pose([0.5, 0, 0]))
    if not backend.capabilities.gravity_torques:
        with pytest.raises(CapabilityError):
            backend.gravity_torques(arm)
        return
    for q in ([0.7, -0.5], [0.0, 0.0], [-1.0, 1.2]):
        backend.set_joint_positions(arm, q)
        assert backend.gravity_torques(arm) == pytest.approx(
            [0.0, -G * 0.04 * math.cos(q[1])], abs=1e-5
        )
    names = backend.joint_names(arm)
    base = Pose([-0.5, 0.3, 0.2], Rotation.from_euler("xyz", [0.4, -0.3, 0.2]).as_quat())
    q = np.array([0.6, -0.4])
    model = GravityModel(ARM_URDF, backend.config.gravity)
    want = model.torques(dict(zip(names, q)), names, base.rotation.as_matrix())
    assert np.abs(want).min() > 0.05  # the tilt loads both joints
    for fixed, dx in ((True, 0.0), (False, 1.0)):
        b = backend.load_urdf(ARM_URDF, Pose(base.p + [0, dx, 0], base.q), fixed_base=fixed)
        backend.set_joint_positions(b, q)
        assert backend.gravity_torques(b) == pytest.approx(want, abs=1e-5), f"fixed_base={fixed}"
    body = backend.add_body([Sphere(0.05)], Pose([2.0, 0, 1.0]), 1.0)
    assert backend.gravity_torques(body).shape == (0,)
    k = np.array([100.0, 100.0])
    tilted = backend.load_urdf(ARM_URDF, Pose([-1.5, -1.0, 0.2], base.q))  # away from the free arm
    backend.set_joint_positions(tilted, q)
    for _ in range(60):  # 0.25 s, gravity re-fed every 2 steps
        tau = backend.gravity_torques(tilted)
        backend.set_joint_targets(tilted, q + tau / k, stiffness=k, damping=10.0)
        backend.step(2)
    assert backend.get_joint_state(tilted).positions == pytest.approx(q, abs=5e-4)


def test_velocity_drive(backend: Backend):
    """A pure velocity drive (no position target) spins the free rotor up to v* (tau = I/d = 10 ms)."""
    rot = backend.load_urdf(ROTOR_URDF, Pose())
    backend.set_joint_targets(rot, velocities=[2.0], damping=1.0)
    backend.step(120)
    st = backend.get_joint_state(rot)
    assert st.velocities[0] == pytest.approx(2.0, rel=0.01)
    assert st.positions[0] == pytest.approx(2.0 * (0.5 - 0.01), abs=0.02)  # lags the ramp by tau
    with pytest.raises(BackendError):
        backend.set_joint_targets(rot, [0.0], joints=["no_such_joint"])


def test_joint_tracking(backend: Backend):
    """The 2-DOF arm follows a 1 s ramp within 0.05 rad and settles within 0.01 rad, in gravity."""
    arm = backend.load_urdf(ARM_URDF, Pose())
    goal = np.array([1.0, -0.6])
    n = int(1.0 / backend.config.timestep)
    worst = 0.0
    for i in range(n):
        target = goal * (i + 1) / n
        backend.set_joint_targets(arm, target, stiffness=200.0, damping=10.0)
        backend.step()
        worst = max(worst, float(np.max(np.abs(backend.get_joint_state(arm).positions - target))))
    backend.step(n // 2)
    st = backend.get_joint_state(arm)
    assert worst < 0.05
    assert np.allclose(st.positions, goal, atol=0.01)
    assert np.all(np.abs(st.efforts) <= 50.0 + 1e-6)


def test_retarget_joints_is_set_joint_targets(make):
    """The per-step re-aim call: the same motion, bit for bit, as set_joint_targets, and it applies
    new gains when it is given some (falling back to the full call)."""
    worlds = []
    for lean in (False, True):
        b = make()
        arm = b.load_urdf(ARM_URDF, Pose())
        joints = [j.name for j in b.joint_info(arm)]
        kp, kd, cap = [200.0, 150.0], [10.0, 8.0], [40.0, 30.0]
        b.set_joint_targets(
            arm, [0.0, 0.0], joints=joints, stiffness=kp, damping=kd, force_limit=cap
        )
        n = int(0.5 / b.config.timestep)
        for i in range(n):
            q, v = [0.8 * i / n, -0.5 * i / n], [0.8 / 0.5, -0.5 / 0.5]
            if i == n // 2:
                kp = [400.0, 300.0]  # new gains mid-way: the lean call must not keep the old ones
            call = b.retarget_joints if lean else b.set_joint_targets
            call(arm, q, v, joints=joints, stiffness=kp, damping=kd, force_limit=cap)
            b.step()
        worlds.append(b.get_joint_state(arm))
    a, c = worlds
    np.testing.assert_array_equal(a.positions, c.positions)
    np.testing.assert_array_equal(a.velocities, c.velocities)


def test_free_base_articulation_drives(backend: Backend):
    """The arm standing free on the ground reaches its joint targets (within 0.01 rad in 1 s)."""
    backend.add_ground()
    arm = backend.load_urdf(ARM_URDF, Pose(), fixed_base=False)
    backend.set_joint_targets(arm, [0.5, -0.5], stiffness=200.0, damping=10.0)
    backend.step(240)
    assert backend.get_joint_state(arm).positions == pytest.approx([0.5, -0.5], abs=0.01)
    assert abs(backend.get_pose(arm).p[2]) < 0.01  # still standing on its base


def test_force_limit_caps_the_drive(backend: Backend):
    """The gravity torque on the pitch joint is 0.39 N m: a 50 N m drive holds it, a 0.2 N m one cannot.

    The strong drive holds the forearm within k's static deflection (0.39 / 1000 rad); the
    capped one lets it drop and reports exactly its cap as its effort (k (q* - q) is ~300
    N m by then), so a backend that ignores drives, or their caps, fails here. (The strong
    drive's reported effort is not checked: PhysX reports a held joint's velocity as
    ~-0.035 rad/s while it stands still, which SAPIEN's evaluated law turns into the
    wrong effort; see docs/backends.md, "Reported joint efforts".)
    """
    strong = backend.load_urdf(ARM_URDF, Pose())
    weak = backend.load_urdf(ARM_URDF, Pose([1.0, 0, 0]))
    for arm, cap in ((strong, 50.0), (weak, 0.2)):
        backend.set_joint_targets(
            arm, [0.0, 0.0], stiffness=1000.0, damping=10.0, force_limit=[50.0, cap]
        )
    backend.step(120)
    s, w = backend.get_joint_state(strong), backend.get_joint_state(weak)
    assert abs(s.positions[1]) < 1e-3 and abs(s.positions[0]) < 1e-3  # the strong joint holds
    assert w.positions[1] > 0.3  # pitch about +y: the weak arm's tip drops
    assert w.efforts[1] == pytest.approx(-0.2, rel=1e-3)  # saturated at the cap, pushing up


def test_joint_friction(backend: Backend):
    """Coulomb friction above the gravity torque (0.39 N m) holds the forearm; below it, it falls."""
    for torque, falls in ((0.6, False), (0.2, True)):
        b = backend
        arm = b.load_urdf(ARM_URDF, Pose([2.0 * torque, 0, 0]))
        b.set_joint_friction(arm, [5.0, torque])
        b.step(120)
        q = b.get_joint_state(arm).positions
        assert abs(q[0]) < 1e-3
        if falls:
            assert q[1] > 0.3
        else:
            assert abs(q[1]) < 0.01
    # a joint with a position target keeps it when friction is set
    arm = backend.load_urdf(ARM_URDF, Pose([-1.0, 0, 0]))
    backend.set_joint_targets(arm, [0.5, 0.0], stiffness=200.0, damping=10.0)
    backend.set_joint_friction(arm, 0.05)
    backend.step(240)
    assert backend.get_joint_state(arm).positions == pytest.approx([0.5, 0.0], abs=0.01)


def test_self_collision_filtering(backend: Backend):
    """Links adjacent through a fixed link do not collide; other link pairs do."""
    body = backend.load_urdf(ASSETS / "filtered.urdf", Pose())
    backend.set_joint_targets(body, [0.5], stiffness=10.0, damping=1.0)
    backend.step(120)
    assert backend.get_joint_state(body).positions[0] == pytest.approx(0.5, abs=0.01)
    assert not [c for c in backend.contacts(body, body) if c.normal_force > 0]
    # the gripper's pads (siblings' children) do collide: closing fully stops the fingers at q = 9 mm
    grip = backend.load_urdf(GRIPPER_URDF, Pose([1.0, 0, 0]))
    backend.set_joint_positions(grip, [0.3, 0.03, 0.03])
    backend.set_joint_targets(
        grip, [0.3, 0.0, 0.0], stiffness=[20000.0, 2000.0, 2000.0], damping=[1000.0, 40.0, 40.0]
    )
    backend.step(120)
    q = backend.get_joint_state(grip).positions
    assert q[1:] == pytest.approx([0.009, 0.009], abs=1e-3)
    pads = {
        frozenset((c.link_a, c.link_b)) for c in backend.contacts(grip, grip) if c.normal_force > 0
    }
    assert frozenset(("pad_l", "pad_r")) in pads


# -- ray casts -------------------------------------------------------------------
def test_ray_cast(backend: Backend):
    g = backend.add_ground()
    box = backend.add_body([Box((0.05, 0.05, 0.05))], Pose([0.3, 0.1, 0.2]), 1.0, fixed=True)
    xy = np.array([[0.3, 0.1], [0.27, 0.13], [0.34, 0.06]])
    o = np.column_stack([xy, np.full(3, 1.0)])
    d = np.tile([0.0, 0.0, -1.0], (3, 1))
    r = backend.ray_cast(o, d, 2.0)
    assert r.hit.all() and (r.body == box).all()
    assert np.allclose(r.distance, 0.75, atol=1e-3)  # top face at z = 0.25
    assert np.allclose(r.point[:, 2], 0.25, atol=1e-3)
    assert np.allclose(r.normal, [0, 0, 1], atol=1e-3)
    # sideways onto the -x face at x = 0.25
    r = backend.ray_cast(np.array([[0.0, 0.1, 0.2]]), np.array([[1.0, 0, 0]]), 1.0)
    assert r.hit[0] and r.distance[0] == pytest.approx(0.25, abs=1e-3)
    # misses: nothing there, and too short
    r = backend.ray_cast(
        np.array([[5.0, 5.0, 1.0], [0.3, 0.1, 1.0]]),
        np.array([[0, 0, 1.0], [0, 0, -1.0]]),
        [2.0, 0.5],
    )
    assert not r.hit.any() and np.isinf(r.distance).all() and np.isnan(r.point).all()
    assert np.isnan(r.normal).all() and (r.body == -1).all()
    # ignore_bodies: through the box to the ground
    r = backend.ray_cast(o, d, 2.0, ignore_bodies=[box])
    assert r.hit.all() and (r.body == g).all() and np.allclose(r.distance, 1.0, atol=1e-3)
    r = backend.ray_cast(o, d, 2.0, ignore_bodies=[box, g])
    assert not r.hit.any()


def test_ray_cast_ignore_links(backend: Backend):
    """Rays pass through ignored links only: the rest of the articulation still blocks them.

    The 2-DOF arm (base at z = 0.2, q = 0) over a box whose top is at z = 0.1:
    a ray down the z axis from z = 1 meets the upper link's top face
    (z = 0.48), then the base cylinder's (z = 0.3), then the box, then the ground.
    """
    g = backend.add_ground()
    arm = backend.load_urdf(ARM_URDF, Pose([0.0, 0.0, 0.2]))
    box = backend.add_body([Box((0.05, 0.05, 0.05))], Pose([0.0, 0.0, 0.05]), 1.0, fixed=True)
    backend.set_joint_targets(arm, [0.0, 0.0], stiffness=1000.0, damping=10.0)
    backend.step(
        1
    )  # PhysX's scene queries see a just-loaded articulation's links only after a step
    o, d = np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, -1.0]])
    r = backend.ray_cast(o, d, 2.0)
    assert r.hit[0] and r.body[0] == arm and r.distance[0] == pytest.approx(0.52, abs=1e-3)
    r = backend.ray_cast(o, d, 2.0, ignore_links=[(arm, "upper")])
    assert r.hit[0] and r.body[0] == arm and r.distance[0] == pytest.approx(0.70, abs=1e-3)
    for base in (None, "base"):  # the root link by None or by its name
        r = backend.ray_cast(o, d, 2.0, ignore_links=[(arm, "upper"), (arm, base)])
        assert r.hit[0] and r.body[0] == box and r.distance[0] == pytest.approx(0.90, abs=1e-3)
    r = backend.ray_cast(o, d, 2.0, ignore_links=[(arm, "upper")], ignore_bodies=[arm, box])
    assert r.hit[0] and r.body[0] == g and r.distance[0] == pytest.approx(1.0, abs=1e-3)
    with pytest.raises(BackendError):
        backend.ray_cast(o, d, 2.0, ignore_links=[(arm, "no_such_link")])


# -- grasping --------------------------------------------------------------------
def test_gripper_grasp_lift_hold(backend: Backend):
    """Grip 20 N per finger (2000 N/m x 1 cm), lift 10 cm in 1 s, hold 5 s: slip < 5 mm."""
    s = gripper_scene(backend)
    r = grasp_lift_hold(s, hold_s=5.0, lift=0.10)
    assert r["cube_z"] == pytest.approx(CUBE_HALF + 0.10, abs=0.005)
    assert np.linalg.norm(r["end_rel"] - r["grasp_rel"]) < 0.005
    for f in r["pad_forces"].values():
        assert f == pytest.approx(20.0, rel=0.05)
    assert backend.get_mass(s.cube) == pytest.approx(CUBE_MASS)
    # links joined through fixed links (pads, palm, carriage) never touch each other
    assert not [c for c in backend.contacts(s.gripper, s.gripper) if c.normal_force > 0]


def test_pinch_torsional_friction_is_a_pad_patch(make):
    """A pinched cube spun about the pinch axis slows under the pads' sliding torque.

    Analytic: uniform pressure on two 20 mm square pads, 20 N each, friction 1:
    T = 2 mu N r_mean with r_mean = a (sqrt 2 + asinh 1) / 6 = 7.65 mm, i.e. 0.306 N m.
    Engines model a patch differently (PhysX's patch friction acts at the corners:
    0.57 N m), so the bound is a factor of two. Gravity is off and the cube's inertia
    raised so the deceleration T / I lasts several steps. Without
    ``PhysicsConfig.torsional_friction`` PyBullet's point contacts give ~0.001 N m:
    the cube turns in the grip like a hinge.
    """
    backend = make(gravity=(0.0, 0.0, 0.0))
    inertia = 0.01  # kg m^2
    grip = backend.load_urdf(GRIPPER_URDF, Pose(), fixed_base=True, name="gripper")
    cube = backend.add_body(
        [Box((CUBE_HALF,) * 3)],
        Pose([0, 0, CUBE_HALF]),
        CUBE_MASS,
        friction=1.0,
        name="cube",
        inertia_diag=[inertia] * 3,
    )
    backend.set_joint_positions(
        grip, [GRASP_Z, OPEN_Q, OPEN_Q], joints=["lift", "left_finger", "right_finger"]
    )
    s = GripperScene(backend, -1, grip, cube)
    s.finger_q = CUBE_HALF + PAD_OFFSET - SQUEEZE
    s.command()
    dt = backend.config.timestep
    backend.step(int(0.3 / dt))
    forces = [
        sum(c.normal_force for c in backend.contacts(grip, cube) if c.link_a == link)
        for link in ("pad_l", "pad_r")
    ]
    assert forces == pytest.approx([20.0, 20.0], rel=0.05)
    w0 = 3.0
    backend.set_velocity(cube, [0.0, 0.0, 0.0], [0.0, w0, 0.0])
    n = 8
    backend.step(n)
    w = backend.get_velocity(cube)[1][1]
    torque = inertia * (w0 - w) / (n * dt)
    a = 0.020
    analytic = 2 * 1.0 * 20.0 * a * (math.sqrt(2) + math.asinh(1)) / 6
    assert w > 0.5  # still sliding: the measurement is the sliding torque
    assert analytic / 2 < torque < 2 * analytic


@pytest.mark.parametrize("box_mu, ground_mu", [(1.0, 1.0), (0.5, 1.0), (0.3, 0.6)])
def test_pair_friction_is_what_the_engine_simulates(make, box_mu: float, ground_mu: float):
    """``pair_friction`` is the coefficient a sliding contact decelerates with: a box sliding on the
    ground slows at ``mu g`` (analytic, Coulomb), ``mu = pair_friction(box, ground)``."""
    backend = make()
    mu = backend.pair_friction(box_mu, ground_mu)
    assert backend.pair_friction(ground_mu, box_mu) == pytest.approx(mu)
    backend.add_ground(friction=ground_mu)
    box = backend.add_body([Box((0.05, 0.05, 0.05))], Pose([0, 0, 0.05]), 1.0, friction=box_mu)
    backend.step(int(0.2 / backend.config.timestep))  # settle on the ground
    v0 = 1.0
    backend.set_velocity(box, [v0, 0.0, 0.0], [0.0, 0.0, 0.0])
    x0 = backend.get_pose(box).p[0]
    n = int(0.05 / backend.config.timestep)
    backend.step(n)
    decel = (v0 - backend.get_velocity(box)[0][0]) / (n * backend.config.timestep)
    assert backend.get_velocity(box)[0][0] > 0.2  # still sliding
    assert backend.get_pose(box).p[0] > x0
    assert decel == pytest.approx(mu * G, rel=0.1)


def test_attach_detach(backend: Backend):
    """An attached box stays put (< 1 mm in 1 s) at the requested relative pose; detached, it falls."""
    backend.add_ground()
    post = backend.add_body([Box((0.02, 0.02, 0.25))], Pose([0, 0, 0.25]), 1.0, fixed=True)
    box = backend.add_body([Box((0.03, 0.03, 0.03))], Pose([0.1, 0, 0.4]), 0.2)
    rel = Pose([0.1, 0, 0.15])
    c = backend.attach(post, None, box, None, rel)
    backend.step(240)
    assert np.linalg.norm(backend.get_pose(box).p - [0.1, 0, 0.4]) < 1e-3
    backend.detach(c)
    backend.step(60)
    assert backend.get_pose(box).p[2] < 0.4 - 0.05
    with pytest.raises(BackendError):
        backend.detach(c)
    # attach to a URDF link (the gripper's palm) and move the link
    grip = backend.load_urdf(GRIPPER_URDF, Pose([1.0, 0, 0]))
    backend.set_joint_positions(grip, [0.3, 0.06, 0.06])
    backend.set_joint_targets(grip, [0.3, 0.06, 0.06], stiffness=20000.0, damping=1000.0)
    ball = backend.add_body([Sphere(0.02)], Pose([1.0, 0, 0.25]), 0.1)
    backend.attach(grip, "palm", ball, None, Pose([0, 0, -0.05]))
    backend.step(120)
    assert np.linalg.norm(backend.get_pose(ball).p - [1.0, 0, 0.25]) < 2e-3


def _coupling_or_skip(backend: Backend) -> None:
    # an optional capability: a backend without it must refuse
    if not backend.capabilities.joint_coupling:
        grip = backend.load_urdf(GRIPPER_URDF, Pose())
        with pytest.raises(CapabilityError):
            backend.couple_joints(grip, "right_finger", "left_finger")
        pytest.skip(f"{type(backend).__name__} has no joint couplings")


@pytest.mark.parametrize("multiplier", [1.0, 0.5])
def test_couple_joints_drives_the_follower(backend: Backend, multiplier: float):
    """Only the left finger is driven (to 40 mm); the coupled right one stands at multiplier x 40 mm.

    The right finger's own drive is off (cap 0), so nothing but the coupling can move it; the
    analytic answer is the coupling's definition, ``q_follower = multiplier * q_leader``.
    """
    _coupling_or_skip(backend)
    grip = backend.load_urdf(GRIPPER_URDF, Pose())
    backend.set_joint_positions(grip, [0.3, 0.02, 0.02 * multiplier])
    backend.couple_joints(grip, "right_finger", "left_finger", multiplier)
    backend.set_joint_targets(grip, [0.3], joints=["lift"], stiffness=2.0e4, damping=1.0e3)
    backend.set_joint_targets(
        grip, [0.04], joints=["left_finger"], stiffness=2000.0, damping=40.0, force_limit=40.0
    )
    backend.set_joint_targets(grip, [0.0], joints=["right_finger"], force_limit=0.0)
    backend.step(240)
    q = backend.get_joint_state(grip).positions
    assert q[1] == pytest.approx(0.04, abs=1e-3)
    assert q[2] == pytest.approx(multiplier * q[1], abs=2e-4)
    backend.remove_body(grip)  # the coupling goes with its body
    backend.step(1)


def test_couple_joints_refuses_what_it_cannot_tie(backend: Backend):
    """An unknown joint and a zero multiplier are errors, on every engine alike."""
    _coupling_or_skip(backend)
    grip = backend.load_urdf(GRIPPER_URDF, Pose())
    with pytest.raises(BackendError, match="no movable joint 'thumb'"):
        backend.couple_joints(grip, "thumb", "left_finger")
    with pytest.raises(BackendError, match="non-zero multiplier"):
        backend.couple_joints(grip, "right_finger", "left_finger", 0.0)


@pytest.mark.parametrize("coupled", [True, False], ids=["coupled", "independent"])
def test_coupled_fingers_centre_what_they_squeeze(backend: Backend, coupled: bool):
    """A cube resting 6 mm off the fingers' centre, squeezed by two equal force-capped drives (5 N each).

    Coupled (the fingers symmetric, as one mechanism moves them; they start open, symmetric):
    they can close only symmetrically, so they push the cube to the centre, within 0.5 mm.
    Independent (the control; they start with both pads on the cube): two equal forces balance
    wherever the cube is, so it stays off centre -- a neutral pair, which is what the coupling
    removes.
    """
    if coupled:
        _coupling_or_skip(backend)
    s = gripper_scene(backend)
    b = backend
    off = 0.006
    b.set_pose(s.cube, Pose([0.0, off, CUBE_HALF]))
    if coupled:
        b.couple_joints(s.gripper, "right_finger", "left_finger")
    else:  # each pad's inner face on the cube (left finger along +y, right along -y)
        q = [CUBE_HALF + off + PAD_OFFSET, CUBE_HALF - off + PAD_OFFSET]
        b.set_joint_positions(s.gripper, q, joints=["left_finger", "right_finger"])
        b.set_joint_targets(
            s.gripper,
            q,
            joints=["left_finger", "right_finger"],
            stiffness=FINGER_K,
            damping=FINGER_D,
        )
    b.step(60)
    b.set_joint_targets(
        s.gripper,
        [0.0, 0.0],
        joints=["left_finger", "right_finger"],
        stiffness=FINGER_K,
        damping=FINGER_D,
        force_limit=5.0,
    )
    b.step(240)
    y = float(s.cube_in_palm()[1])
    assert y == pytest.approx(0.0 if coupled else off, abs=5e-4)


def test_remove_and_replace_without_jump(backend: Backend):
    """Swap a resting cube for an identical body in place: it moves < 0.5 mm in the next 0.5 s."""
    backend.add_ground()
    cube = backend.add_body([Box((CUBE_HALF,) * 3)], Pose([0, 0, CUBE_HALF]), CUBE_MASS)
    backend.step(120)
    pose = backend.get_pose(cube)
    lin, ang = backend.get_velocity(cube)
    backend.remove_body(cube)
    with pytest.raises(BackendError):
        backend.get_pose(cube)
    slabs = [
        Box((CUBE_HALF, CUBE_HALF, CUBE_HALF / 3), Pose([0, 0, dz]))
        for dz in (-2 * CUBE_HALF / 3, 0.0, 2 * CUBE_HALF / 3)
    ]
    new = backend.add_body(slabs, pose, CUBE_MASS)
    backend.set_velocity(new, lin, ang)
    backend.step(120)
    assert np.linalg.norm(backend.get_pose(new).p - pose.p) < 5e-4
    assert new != cube  # handles are never reused
    # articulations can be removed too, with their attachments
    grip = backend.load_urdf(GRIPPER_URDF, Pose([1.0, 0, 0.5]))
    ball = backend.add_body([Sphere(0.02)], Pose([1.0, 0, 0.45]), 0.1)
    c = backend.attach(grip, "palm", ball, None, Pose([0, 0, -0.05]))
    backend.remove_body(grip)
    with pytest.raises(BackendError):
        backend.detach(c)
    backend.step(12)
    assert backend.get_pose(ball).p[2] == pytest.approx(
        0.45 - 0.5 * G * (12 * backend.config.timestep) ** 2, abs=2e-3
    )


def test_contacts_right_after_a_removal(backend: Backend):
    """Contacts asked for between a body's removal and the next step are the last step's, less the
    removed body's, on either engine. SAPIEN's own contact list then still refers to the removed
    components: reading it crashed the process (a trace that read contacts right after the cube swapped
    to its slabs). After the next step they are the engine's again."""
    g = backend.add_ground()
    a = backend.add_body([Box((0.03, 0.03, 0.03))], Pose([0.0, 0, 0.03]), 0.2)
    b = backend.add_body([Box((0.03, 0.03, 0.03))], Pose([0.2, 0, 0.03]), 0.2)
    backend.step(60)
    before = backend.contacts(body_b=g)
    assert {c.body_a for c in before} == {a, b}
    backend.remove_body(a)
    held = backend.contacts(body_b=g)
    assert held and all(c.body_a == b for c in held)
    assert [c.normal_force for c in held] == [c.normal_force for c in before if c.body_a == b]
    flipped = backend.contacts(g, b)
    assert flipped and all(c.body_a == g and c.normal @ [0, 0, 1] < -0.99 for c in flipped)
    with pytest.raises(BackendError):  # a removed body is no body
        backend.contacts(a)
    backend.step(1)
    after = backend.contacts(body_b=g)
    assert after and all(c.body_a == b for c in after)


# -- robustness --------------------------------------------------------------------
def test_determinism_in_process(item):
    assert trajectory_digest(item.name, 0.3) == trajectory_digest(item.name, 0.3)


def test_determinism_across_processes(item):
    here = Path(__file__).resolve().parent
    code = (
        f"import sys; sys.path.insert(0, {str(here)!r}); from backend_scenes import trajectory_digest; "
        f"print(trajectory_digest({item.name!r}, 0.3))"
    )
    procs = [
        subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
        for _ in range(2)
    ]
    here_digest = trajectory_digest(item.name, 0.3)
    outs = []
    for p in procs:
        out, _ = p.communicate(timeout=120)
        assert p.returncode == 0
        outs.append(out.split()[-1])
    assert outs[0] == outs[1] == here_digest


def test_blowup_raises_simulation_error(backend: Backend):
    backend.add_ground()
    b = backend.add_body([Box((0.05, 0.05, 0.05))], Pose([0, 0, 0.05]), 1.0, name="victim")
    backend.step(2)
    backend.set_velocity(b, [float("nan"), 0, 0], [0, 0, 0])  # (Bullet clamps huge speeds to 100)
    with pytest.raises(SimulationError, match="victim"):
        backend.step(10)
    with pytest.raises(SimulationError):
        backend.check_finite([b])


@pytest.mark.parametrize("fixed", [False, True], ids=["dynamic", "static"])
def test_blowup_in_a_pose_raises(backend: Backend, fixed: bool):
    """A non-finite base pose is a blow-up even while the velocities stay finite (a teleport)."""
    backend.add_ground()
    b = backend.add_body(
        [Box((0.05, 0.05, 0.05))], Pose([0, 0, 0.05]), 1.0, name="victim", fixed=fixed
    )
    backend.step(2)
    backend.set_pose(b, Pose([float("nan"), 0.0, 0.05]))
    with pytest.raises(SimulationError, match="victim"):
        backend.step(3)
    with pytest.raises(SimulationError):
        backend.check_finite([b])


def test_blowup_in_joints_raises(backend: Backend):
    arm = backend.load_urdf(ARM_URDF, Pose(), name="arm")
    backend.set_joint_positions(arm, [float("nan"), 0.0])
    with pytest.raises(SimulationError, match="arm"):
        backend.step(5)


def test_the_builtin_backends_are_registered():
    """The suite parametrises over the registry: without these it would test nothing."""
    from benchharness.plugin import get_manager

    assert {"pybullet", "sapien"} <= {it.name for it in get_manager().items("backend")}


def test_capabilities(backend: Backend, item):
    caps = backend.capabilities
    meta = item.meta.get("capabilities")
    if meta is not None:  # a registration that states capabilities must tell the truth
        assert meta == {k: getattr(caps, k) for k in meta}
    cam = CameraSpec(eye=(0.5, 0.5, 0.5), target=(0, 0, 0), width=64, height=48)
    if caps.camera:
        backend.add_ground()
        backend.add_body([Box((0.05, 0.05, 0.05))], Pose([0, 0, 0.05]), 1.0)
        img = backend.render(cam)
        assert img.shape == (48, 64, 3) and img.dtype == np.uint8
        assert img.std() > 1.0  # not a blank frame
    else:
        with pytest.raises(CapabilityError):
            backend.render(cam)


GREEN = (0.1, 0.9, 0.1, 1.0)
BLUE = (0.1, 0.2, 0.95, 1.0)
RED = (0.95, 0.1, 0.1, 1.0)
TOP_CAM = CameraSpec(eye=(0.0, -0.15, 0.6), target=(0, 0, 0.05), width=96, height=72, fov_deg=40)


def _pixels_like(img: np.ndarray, rgba: tuple[float, ...]) -> int:
    """Pixels whose hue is the colour's (lit or shaded): the colour direction, any brightness."""
    c = np.asarray(rgba[:3]) / np.linalg.norm(rgba[:3])
    px = img.reshape(-1, 3).astype(float)
    n = np.linalg.norm(px, axis=1)
    lit = n > 40
    return int(np.sum(lit & (px @ c > 0.97 * np.where(lit, n, 1.0))))


def _visual_scene(b: Backend, with_visuals: bool) -> int:
    b.add_ground()
    plate = Box((0.08, 0.02, 0.004), Pose([0, 0, 0.06]), rgba=GREEN)  # a strip overhanging in x
    return b.add_body(
        [Box((0.05, 0.05, 0.05), rgba=RED)],
        Pose([0, 0, 0.06], Rotation.from_euler("xy", [0.2, 0.1]).as_quat()),
        1.0,
        visuals=[plate] if with_visuals else (),
    )


def test_visual_shapes_are_render_only(make):
    """``add_body(visuals=...)`` changes nothing physical: mass, fall, contacts, rays are as without."""
    a, b = make(), make()
    ba, bb = _visual_scene(a, True), _visual_scene(b, False)
    assert a.get_mass(ba) == pytest.approx(1.0)
    a.step(120)
    b.step(120)
    pa, pb_ = a.get_pose(ba), b.get_pose(bb)
    np.testing.assert_array_equal(pa.p, pb_.p)
    np.testing.assert_array_equal(pa.q, pb_.q)
    # a ray past the box's side, through the overhanging plate, reaches the ground
    hits = a.ray_cast(np.array([[0.07, 0.0, 0.3]]), np.array([[0.0, 0.0, -1.0]]), 1.0)
    assert hits.body[0] != ba
    if a.capabilities.camera:
        img = a.render(TOP_CAM)
        assert _pixels_like(img, GREEN) > 100 and _pixels_like(img, RED) > 100  # strip and box
        plain = b.render(TOP_CAM)
        assert _pixels_like(plain, GREEN) == 0 and _pixels_like(plain, RED) > 200
    a.close()
    b.close()


def test_set_visuals_off_changes_no_physics_and_draws_no_colour(make):
    """``set_visuals(False)`` (an unfilmed trial): the same fall, bit for bit; no colour drawn."""
    a, b = make(), make()
    b.set_visuals(False)
    assert a.draws_visuals and not b.draws_visuals
    ba, bb = _visual_scene(a, True), _visual_scene(b, True)
    a.step(120)
    b.step(120)
    pa, pb_ = a.get_pose(ba), b.get_pose(bb)
    np.testing.assert_array_equal(pa.p, pb_.p)
    np.testing.assert_array_equal(pa.q, pb_.q)
    if b.capabilities.camera:
        img = b.render(TOP_CAM)
        assert _pixels_like(img, GREEN) == 0 and _pixels_like(img, RED) == 0


def test_urdf_visual_colours_are_render_only(backend: Backend, tmp_path: Path):
    """A URDF link's ``<visual>`` with a material colour is drawn where there is a camera, never hit."""
    urdf = tmp_path / "painted.urdf"
    urdf.write_text(
        """<?xml version="1.0"?>
<robot name="painted">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.1 0.1 0.1"/></geometry>
      <material name="blue"><color rgba="0.1 0.2 0.95 1"/></material></visual>
    <visual><origin xyz="0 0 0.06"/><geometry><box size="0.16 0.16 0.008"/></geometry>
      <material name="green"><color rgba="0.1 0.9 0.1 1"/></material></visual>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="stub">
    <inertial><mass value="0.1"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="-0.3 0 0"/><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="stub"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>
""",
        encoding="utf-8",
    )
    body = backend.load_urdf(urdf, Pose([0, 0, 0.05]))
    backend.step(1)  # PhysX's scene query sees a new pose after a step
    assert backend.get_mass(body) == pytest.approx(1.1)
    hits = backend.ray_cast(np.array([[0.07, 0.0, 0.3]]), np.array([[0.0, 0.0, -1.0]]), 1.0)
    assert not hits.hit[0]
    hits = backend.ray_cast(np.array([[0.0, 0.0, 0.3]]), np.array([[0.0, 0.0, -1.0]]), 1.0)
    assert hits.body[0] == body and hits.distance[0] == pytest.approx(0.2, abs=1e-4)
    if backend.capabilities.camera:
        img = backend.render(TOP_CAM)
        assert _pixels_like(img, GREEN) > 200


def test_worlds_are_independent(make):
    a, b = make(), make(gravity=(0.0, 0.0, 0.0))
    ba = a.add_body([Sphere(0.05)], Pose([0, 0, 1.0]), 1.0)
    bb = b.add_body([Sphere(0.05)], Pose([0, 0, 1.0]), 1.0)
    a.step(60)
    b.step(60)
    assert a.get_pose(ba).p[2] < 0.9 and b.get_pose(bb).p[2] == pytest.approx(1.0)
    a.close()
    a.close()  # safe twice
    b.step(1)


@pytest.mark.slow
def test_gripper_long_hold(backend: Backend):
    """The same grasp held for 60 s: slip < 5 mm, grip within 5% of 20 N (run with -m slow)."""
    s = gripper_scene(backend)
    r = grasp_lift_hold(s, hold_s=60.0, lift=0.10)
    assert np.linalg.norm(r["end_rel"] - r["grasp_rel"]) < 0.005
    for f in r["pad_forces"].values():
        assert f == pytest.approx(20.0, rel=0.05)


# -- step callbacks ----------------------------------------------------------------
def test_step_callbacks_run_after_every_physics_step_in_order(backend: Backend):
    """step(n) runs n physics steps, each followed by every callback in registration order."""
    dt = backend.config.timestep
    calls: list[tuple[str, float]] = []
    handles = {
        name: backend.add_step_callback(lambda name=name: calls.append((name, backend.time)))
        for name in ("c", "a", "b")  # registration order, not name order
    }
    backend.step(3)
    backend.step()
    want = [(name, k * dt) for k in range(1, 5) for name in ("c", "a", "b")]
    assert [c[0] for c in calls] == [w[0] for w in want]
    assert [c[1] for c in calls] == pytest.approx([w[1] for w in want], abs=1e-12)
    backend.remove_step_callback(handles["a"])
    calls.clear()
    backend.step(2)
    assert [c[0] for c in calls] == ["c", "b", "c", "b"]
    with pytest.raises(BackendError):
        backend.remove_step_callback(handles["a"])  # already removed
    backend.remove_step_callback(handles["c"])
    backend.remove_step_callback(handles["b"])
    calls.clear()
    backend.step(5)
    assert calls == [] and backend.time == pytest.approx(11 * dt)


def test_step_callbacks_see_every_intermediate_state(make):
    """A callback during step(10) sees what stepping one at a time shows (and it changes nothing)."""
    worlds = [make(), make()]
    bodies = [w.add_body([Sphere(0.05)], Pose([0, 0, 1.0]), 1.0) for w in worlds]
    seen: list[float] = []
    worlds[0].add_step_callback(lambda: seen.append(float(worlds[0].get_pose(bodies[0]).p[2])))
    worlds[0].step(10)
    alone = []
    for _ in range(10):
        worlds[1].step()
        alone.append(float(worlds[1].get_pose(bodies[1]).p[2]))
    assert seen == alone
    assert len(set(seen)) == 10  # falling: every step is a new height


def test_step_callback_can_command_the_world(backend: Backend):
    """A callback's joint targets act from the next physics step (how the cube's detents work)."""
    rot = backend.load_urdf(ROTOR_URDF, Pose())
    backend.set_joint_targets(rot, velocities=[2.0], damping=1.0)
    flipped: list[float] = []

    def reverse() -> None:
        if not flipped and backend.get_joint_state(rot).positions[0] > 0.2:
            flipped.append(backend.time)
            backend.set_joint_targets(rot, velocities=[-2.0], damping=1.0)

    backend.add_step_callback(reverse)
    backend.step(240)
    assert flipped and backend.get_joint_state(rot).velocities[0] == pytest.approx(-2.0, rel=0.01)


def test_step_callback_exceptions_propagate(backend: Backend):
    """An exception in a callback ends step() at that physics step; later callbacks do not run."""
    dt = backend.config.timestep
    count = {"n": 0, "after": 0}

    def fail_on_third() -> None:
        count["n"] += 1
        if count["n"] == 3:
            raise ValueError("callback failed")

    h = backend.add_step_callback(fail_on_third)
    backend.add_step_callback(lambda: count.__setitem__("after", count["after"] + 1))
    with pytest.raises(ValueError, match="callback failed"):
        backend.step(10)
    assert backend.time == pytest.approx(3 * dt) and count["after"] == 2
    backend.remove_step_callback(h)
    backend.step(2)  # the world is still usable
    assert backend.time == pytest.approx(5 * dt) and count["after"] == 4


def test_step_callback_may_not_step(backend: Backend):
    backend.add_step_callback(lambda: backend.step())
    with pytest.raises(BackendError, match="may not step"):
        backend.step()
    with pytest.raises(BackendError):
        backend.add_step_callback(42)  # type: ignore[arg-type]
