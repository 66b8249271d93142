"""The PyBullet backend (DIRECT mode, one physics client per instance).

Engine-specific choices, all so that the numbers mean what they mean on SAPIEN:

* PD drives: PhysX's implicit law ``f = k (q* - q') + d (v* - v')``,
  realised by Bullet's velocity motor (solved with the contacts) whose target
  is the backward-Euler velocity and whose force cap is the law's force at
  rest; see :meth:`_apply_drives`.
* Joint friction: a velocity motor with target 0 capped at the torque.
* URDF inertias are taken from the file; self-collision is on, excluding
  parent/child pairs (as PhysX does) and the pairs adjacent through fixed
  links (filtered on both engines).
* Poses are URDF link frames; PyBullet's base pose is the base's inertial
  frame and is converted here. Base velocities are those of the base's centre
  of mass (as on PhysX).
"""

from __future__ import annotations

import functools
import math
import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pybullet as pb

from ..geometry import Pose
from . import PYBULLET_CAPABILITIES
from ._bodies import BodyRecord, BodyTable, as_array, contact_side, drive_command, remove_files
from ._urdf import BodyInertial, ground_ray_fixup, mass_properties, parse_urdf
from .interface import (
    Backend,
    BackendError,
    BodyId,
    Box,
    CameraSpec,
    Contact,
    Cylinder,
    JointInfo,
    JointState,
    MeshShape,
    PhysicsConfig,
    RayHits,
    Shape,
    SimulationError,
    Sphere,
    StepCallback,
)

#: the colour of a shape drawn without an ``rgba``, and of a URDF link without a ``<visual>`` colour
_GREY = (0.45, 0.5, 0.6, 1.0)
_URDF_GREY = (0.45, 0.47, 0.52, 1.0)


def _rgb8(rgba: Sequence[float] | None) -> tuple[int, int, int]:
    r, g, b = (int(round(255 * min(max(float(x), 0.0), 1.0))) for x in (rgba or _GREY)[:3])
    return r, g, b


def _triangles(s: Shape) -> tuple[np.ndarray, np.ndarray]:
    """A shape's surface in the body frame: triangles (n, 3, 3) and their unit normals (n, 3)."""
    import trimesh

    if isinstance(s, Box):
        m = trimesh.creation.box(extents=2.0 * np.asarray(s.half_extents, dtype=float))
    elif isinstance(s, Sphere):
        m = trimesh.creation.icosphere(subdivisions=2, radius=float(s.radius))
    elif isinstance(s, Cylinder):
        m = trimesh.creation.cylinder(
            radius=float(s.radius), height=2.0 * float(s.half_length), sections=24
        )
    elif isinstance(s, MeshShape):
        m = trimesh.convex.convex_hull(np.asarray(s.vertices, dtype=float))
    else:
        raise BackendError(f"unknown shape {type(s).__name__}")
    rot = s.pose.rotation.as_matrix()
    tri = np.asarray(m.vertices, dtype=float)[np.asarray(m.faces)] @ rot.T + s.pose.p
    return tri, np.asarray(m.face_normals, dtype=float) @ rot.T


#: a base speed above this (m/s or rad/s) counts as a blow-up, as does a non-finite state
MAX_SPEED = 1.0e4
_RAY_BATCH = 16000
#: children ``createCollisionShapeArray`` keeps (PyBullet's MAX_COMPOUND_COLLISION_SHAPES); the rest
#: are dropped silently, so a body with more is built another way or refused
_MAX_COMPOUND_SHAPES = 16
#: collision margin (m) of convex mesh bodies. Bullet's default, 1 mm, puts every contact 1 mm outside
#: the object's model (an in-hand fingertip then presses ~0.65 N harder than its squeeze asks); at 0
#: contacts are exact but Bullet's ray casts miss thin hulls; at 0.1 mm contacts sit 0.1 mm out and
#: rays hit (bench/bench_object_surfaces.py, docs/backends.md "Object surfaces")
_MESH_MARGIN = 1.0e-4
_ATTACH_MAX_FORCE = 1.0e5
#: N (or N m): the most a joint coupling (:meth:`PyBulletBackend.couple_joints`) transmits; the
#: PR2 gripper's mimic linkage is rated ``finger_joint_effort_limit`` 1000 (gripper_v0/gripper.urdf.xacro)
_COUPLING_MAX_FORCE = 1000.0
#: position error correction of a joint coupling per step (Bullet's ERP; 0 would couple velocities only
#: and let a start-up offset between the joints stay)
_COUPLING_ERP = 0.2


def _convex_hull(s: MeshShape) -> Any:
    """The convex hull of a mesh shape's vertices (a ``trimesh.Trimesh``): what Bullet collides with."""
    import trimesh

    return trimesh.convex.convex_hull(np.asarray(s.vertices, dtype=float))


#: rad or m: the drive law's cached inverse mass matrix is recomputed once a joint moved this far
MASS_MATRIX_REFRESH = 1.0e-3


@dataclass(kw_only=True)
class _Body(BodyRecord):
    uid: int
    link_index: dict[str, int] = field(default_factory=dict)  #: URDF link -> pybullet index
    joint_index: list[int] = field(default_factory=list)  #: pybullet joint index, per movable joint
    couplings: list[int] = field(default_factory=list)  #: gear constraints (couple_joints)
    base_inertial: Pose = field(default_factory=Pose)  #: base inertial frame in the base link frame
    # the drive law's state and caches, per movable joint (position in self.joints)
    q_prev: np.ndarray | None = None  #: joint positions at the start of the last driven step
    q_prev_step: int = -10
    driven_idx: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    minv: np.ndarray | None = (
        None  #: cached inverse mass matrix (see PyBulletBackend._mass_inverse)
    )
    minv_q: np.ndarray | None = None  #: joint positions it was computed at
    meff: np.ndarray | None = None  #: 1 / diag(minv) of the movable joints
    gravity_base: np.ndarray | None = (
        None  #: world gravity in a fixed base's inertial frame (cached)
    )
    gravity_tilted: bool = False  #: gravity_base differs from world gravity (cached with it)
    #: (step, q, v) last read from the engine: joints only change by stepping or a teleport
    #: (set_joint_positions clears it), and the drive law and the controllers read them several
    #: times a step (see _motion)
    motion: tuple[int, np.ndarray, np.ndarray] | None = None
    driven_pb: list[int] = field(default_factory=list)
    ones: list[float] = field(default_factory=list)  #: velocity gains (1.0) for driven_pb
    drive_cache: tuple | None = (
        None  #: per-step constants of the drive law (cleared by set_joint_targets)
    )

    @property
    def index_link(self) -> dict[int, str | None]:
        d: dict[int, str | None] = {i: n for n, i in self.link_index.items()}
        d[-1] = None
        return d


class PyBulletBackend(Backend):
    name = "pybullet"
    capabilities = PYBULLET_CAPABILITIES
    default_solver_iterations = (
        50  # docs/benchmarks/cube_spike.md: >= 50 at 1/240 s, else a 90 deg twist ends at ~102 deg
    )

    def __init__(self, config: PhysicsConfig | None = None) -> None:
        super().__init__(config)
        c = self.config
        self._cid = pb.connect(pb.DIRECT)
        if self._cid < 0:
            raise BackendError("could not start a PyBullet DIRECT client")
        pb.resetSimulation(physicsClientId=self._cid)
        pb.setTimeStep(c.timestep, physicsClientId=self._cid)
        pb.setGravity(*c.gravity, physicsClientId=self._cid)
        pb.setPhysicsEngineParameter(
            numSolverIterations=self.solver_iterations,
            deterministicOverlappingPairs=1,
            physicsClientId=self._cid,
        )
        self._bodies: BodyTable[_Body] = BodyTable()  #: our handles (PyBullet reuses its ids)
        self._uid2h: dict[int, int] = {}
        self._constraints: dict[int, int] = {}  #: our handle -> PyBullet constraint id
        self._next_constraint = 1
        self._steps = 0
        self._step_lists: tuple[list[_Body], list[tuple[int, int]]] | None = None
        self._closed = False
        self._grounds: dict[int, float] = {}
        self._palettes: dict[tuple[tuple[int, int, int], ...], int] = {}  #: colours -> texture id
        self._gravity = np.asarray(c.gravity, dtype=float)
        #: the engine's own step (bench/bench_speed.py times this call to find the engine's floor)
        self._engine_step = functools.partial(pb.stepSimulation, physicsClientId=self._cid)

    # -- lifetime --------------------------------------------------------------
    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._bodies.close()
        try:
            pb.disconnect(physicsClientId=self._cid)
        except pb.error:
            pass

    def __del__(self) -> None:  # pragma: no cover - best effort
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown: nothing to report to
            pass

    # -- helpers ---------------------------------------------------------------
    def _register(self, b: _Body) -> int:
        self._step_lists = None
        h = self._bodies.add(self._bodies.new_handle(), b)
        self._uid2h[b.uid] = h
        return h

    def _b(self, body: BodyId) -> _Body:
        return self._bodies[body]

    def _link(self, b: _Body, link: str | None) -> int:
        if link is None or (b.urdf is not None and link == b.urdf.root_link):
            return -1
        try:
            return b.link_index[link]
        except KeyError:
            raise BackendError(
                f"body {b.name!r} has no link {link!r}; links: {list(b.link_index)}"
            ) from None

    # -- time ------------------------------------------------------------------
    @property
    def time(self) -> float:
        return self._steps * self.config.timestep

    def _stepped(self) -> tuple[list[_Body], list[tuple[int, int]]]:
        """The driven bodies and the movable bases ``(uid, handle)``; cached until bodies or drives change."""
        if self._step_lists is None:
            driven = [b for b in self._bodies.values() if b.drive.driven.any()]
            # bases that can move (a fixed base cannot; its joints are checked after the loop)
            dynamic = [(b.uid, h) for h, b in self._bodies.items() if not b.fixed]
            self._step_lists = (driven, dynamic)
        return self._step_lists

    def _step_engine(self, n: int, after_step: StepCallback | None) -> None:
        if self._closed:
            raise BackendError("backend is closed")
        cid = self._cid
        for _ in range(n):
            driven, dynamic = self._stepped()
            for b in driven:
                self._apply_drives(b)
            self._engine_step()
            self._steps += 1
            for uid, h in dynamic:
                lin, ang = pb.getBaseVelocity(uid, physicsClientId=cid)
                s = (
                    abs(lin[0])
                    + abs(lin[1])
                    + abs(lin[2])
                    + abs(ang[0])
                    + abs(ang[1])
                    + abs(ang[2])
                )
                if not s < MAX_SPEED:  # also catches NaN
                    self._blowup(h)
            if after_step is not None:
                after_step()
        for h, b in self._bodies.items():
            # a non-finite pose can come with finite velocities (e.g. teleported there)
            p, q = pb.getBasePositionAndOrientation(b.uid, physicsClientId=cid)
            if not math.isfinite(p[0] + p[1] + p[2] + q[0] + q[1] + q[2] + q[3]):
                self._blowup(h)
            if b.joints:  # read through the per-step cache: the next drive law and reads reuse it
                q, v = self._motion(b)
                if not (np.isfinite(q).all() and (np.abs(v) < MAX_SPEED).all()):  # NaN fails too
                    self._blowup(h)

    def _blowup(self, h: int) -> None:
        b = self._bodies[h]
        raise SimulationError(
            f"body {b.name!r} (handle {h}) has a non-finite or absurd state after step {self._steps} "
            f"(t = {self.time:.4f} s): the simulation blew up"
        )

    def _inverse_dynamics(self, b: _Body, q: Sequence[float], v: Sequence[float]) -> np.ndarray:
        """Joint part of ``calculateInverseDynamics(q, v, 0)``: gravity + Coriolis torques, world gravity.

        PyBullet's inverse dynamics expresses the world's gravity vector in
        the base's inertial frame without rotating it, i.e. it is only right
        for an upright base. So gravity is set to ``R^T g`` (``R`` = the base
        inertial frame's world rotation) for the call and restored after;
        nothing is stepped in between. A free base gets zero base
        acceleration (its 6 base rows are dropped).
        """
        cid = self._cid
        n = len(q)
        g = self._gravity
        gb = b.gravity_base
        if gb is None:
            _, orn = pb.getBasePositionAndOrientation(b.uid, physicsClientId=cid)
            gb = np.asarray(pb.getMatrixFromQuaternion(orn), dtype=float).reshape(3, 3).T @ g
            tilted = bool(np.max(np.abs(gb - g)) > 1e-12)
            if b.fixed:  # a fixed base only turns through set_pose, which clears this
                b.gravity_base, b.gravity_tilted = gb, tilted
        else:
            tilted = b.gravity_tilted
        if tilted:
            pb.setGravity(*gb.tolist(), physicsClientId=cid)
        try:
            if b.fixed:
                tau = pb.calculateInverseDynamics(
                    b.uid, list(q), list(v), [0.0] * n, physicsClientId=cid
                )
            else:
                tau = pb.calculateInverseDynamics(
                    b.uid,
                    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0] + list(q),
                    [0.0] * 6 + list(v),
                    [0.0] * (6 + n),
                    physicsClientId=cid,
                )
        finally:
            if tilted:
                pb.setGravity(*self.config.gravity, physicsClientId=cid)
        return np.asarray(tau, dtype=float)[-n:]

    def gravity_torques(self, body: BodyId) -> np.ndarray:
        b = self._b(body)
        if not b.joints:
            return np.zeros(0)
        q = [s[0] for s in pb.getJointStates(b.uid, b.joint_index, physicsClientId=self._cid)]
        return self._inverse_dynamics(b, q, [0.0] * len(q))

    def _mass_inverse(self, b: _Body, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Inverse mass matrix and each joint's effective inertia ``1/(M^-1)_ii``, cached.

        Why cached: ``calculateMassMatrix`` plus the inverse of the PR2's
        19x19 matrix cost ~75 us, a quarter of a physics step, and a held
        robot's ``M(q)`` does not change. It is recomputed whenever any joint
        has moved more than :data:`MASS_MATRIX_REFRESH` (rad or m) since, so
        the effective inertia and free acceleration used by the drive law are
        those of the current configuration to ~0.1 %.
        """
        if (
            b.minv is None
            or b.minv_q is None
            or float(np.abs(q - b.minv_q).max()) > MASS_MATRIX_REFRESH
        ):
            m = np.array(
                pb.calculateMassMatrix(b.uid, q.tolist(), physicsClientId=self._cid), dtype=float
            )
            try:
                minv = np.linalg.inv(m)
            except np.linalg.LinAlgError:
                minv = np.diag(1.0 / np.maximum(np.diag(m), 1e-12))
            b.minv, b.minv_q = minv, q.copy()
            b.meff = 1.0 / np.diag(minv)[m.shape[0] - len(q) :]
        assert b.meff is not None  # set together with minv
        return b.minv, b.meff

    def _apply_drives(self, b: _Body) -> None:
        """PhysX's implicit drive law, realised by Bullet's velocity motor inside its solver.

        The implicit law ``f = k (q* - q') + d (v* - v')`` with ``q' = q + dt v'``
        is a damper ``c = k dt + d`` towards ``v_t = (k (q* - q) + d v*) / c``.
        With ``m`` the joint's effective inertia and ``v_ref = v + dt a`` the
        velocity it would reach under gravity and Coriolis forces alone, free
        motion ends the step at ``v' = (m v_ref + dt c v_t) / (m + dt c)``.
        The motor targets ``v'`` with its force capped at the larger of
        ``c |v_t|`` (the law's force at rest) and the force free motion needs
        to reach ``v'``, ``m c |v_t - v_ref| / (m + dt c)``; then the force limit:

        * free motion: the motor reaches ``v'``, i.e. backward Euler, stable
          for any gains and link mass;
        * a blocked joint (a finger on a cube) cannot move, so the motor pushes
          with ``k (q* - q) + d v*``, as a PhysX drive does;
        * everything is solved together with the contacts.

        ``a = M^-1 (-bias)`` with the bias (gravity + Coriolis) from inverse
        dynamics every step and ``M^-1`` from :meth:`_mass_inverse`.
        """
        dt = self.config.timestep
        sel = b.driven_idx
        q, v = self._motion(b)
        # The joint's actual motion over the last step. Bullet's reported velocity can carry
        # motion that contacts undo at the position level (split impulse); feeding that back
        # into the drive makes a blocked finger push harder and harder.
        if b.q_prev is not None and b.q_prev_step == self._steps - 1:
            v = (q - b.q_prev) / dt
        b.q_prev = q
        b.q_prev_step = self._steps
        minv, meff = self._mass_inverse(b, q)
        if b.drive_cache is None:  # the drive settings' per-step constants, until set_joint_targets
            ds = b.drive
            k, d = ds.kp[sel], ds.kd[sel]
            c = k * dt + d
            inv_c = np.divide(1.0, c, out=np.zeros_like(c), where=c > 0)
            b.drive_cache = (
                k,
                d * ds.target_v[sel],
                ds.target_q[sel],
                c,
                dt * c,
                inv_c,
                ds.fmax[sel],
            )
        k, dv, tq, c, dtc, inv_c, fmax = b.drive_cache
        m = meff[sel]
        if b.fixed:
            a = (minv @ -self._inverse_dynamics(b, q.tolist(), v.tolist()))[sel]
        else:
            # the joints of a free-floating body: gravity alone gives no relative joint
            # acceleration; Coriolis terms are neglected
            a = 0.0
        vt = (k * (tq - q[sel]) + dv) * inv_c
        vref = v[sel] + dt * a
        mdc = m + dtc
        vnext = (m * vref + dtc * vt) / mdc
        # cap: the law's force at rest (what a blocked joint pushes with), or the force that
        # free motion needs to reach v' if larger; never an explicit c |v| term, which would be
        # unstable (period-2 chatter) on light links in contact
        f = np.minimum(np.maximum(c * np.abs(vt), m * c * np.abs(vt - vref) / mdc), fmax)
        pb.setJointMotorControlArray(
            b.uid,
            b.driven_pb,
            pb.VELOCITY_CONTROL,
            targetVelocities=vnext.tolist(),
            forces=f.tolist(),
            velocityGains=b.ones,
            physicsClientId=self._cid,
        )

    def _spinning(self, friction: float) -> float:
        """A body's ``spinningFriction`` for :attr:`PhysicsConfig.torsional_friction`.

        Bullet combines a pair as ``s_a mu_b + s_b mu_a``; half the arm times the body's own
        friction makes that ``arm * mu_a * mu_b``, i.e. the arm times the pair's friction.
        """
        return 0.5 * float(self.config.torsional_friction) * float(friction)

    def pair_friction(self, a: float, b: float) -> float:
        """Bullet's combined friction of a contact: the product of the two bodies' coefficients."""
        return float(a) * float(b)

    # -- bodies ----------------------------------------------------------------
    def add_ground(self, height: float = 0.0, friction: float | None = None) -> BodyId:
        cid = self._cid
        shape = pb.createCollisionShape(pb.GEOM_PLANE, planeNormal=[0, 0, 1], physicsClientId=cid)
        # Not drawn: filling most of a frame, a floor doubled TinyRenderer's time per 640 x 480
        # image (measured 150 vs 60 ms, PR2 scene; BENCHMARKS.md, "Trial video"), and the
        # renderer's light grey background reads as the floor anyway. Without a visual shape
        # PyBullet would draw the plane as a checkerboard, so it gets a 1 mm box 1 m below.
        vis = pb.createVisualShape(
            pb.GEOM_BOX,
            halfExtents=[0.0005] * 3,
            visualFramePosition=[0, 0, -1.0],
            rgbaColor=[0.8, 0.8, 0.8, 1],
            physicsClientId=cid,
        )
        uid = pb.createMultiBody(0.0, shape, vis, basePosition=[0, 0, height], physicsClientId=cid)
        fr = self.config.default_friction if friction is None else friction
        pb.changeDynamics(
            uid, -1, lateralFriction=fr, spinningFriction=self._spinning(fr), physicsClientId=cid
        )
        h = self._register(_Body(uid=uid, name="ground", fixed=True))
        self._grounds[h] = float(height)
        return h

    def _shape_args(self, s: Shape, tmp: list[str]) -> dict:
        base = {
            "collisionFramePosition": s.pose.p.tolist(),
            "collisionFrameOrientation": s.pose.q.tolist(),
        }
        if isinstance(s, Box):
            return {
                "shapeType": pb.GEOM_BOX,
                "halfExtents": list(map(float, s.half_extents)),
                **base,
            }
        if isinstance(s, Sphere):
            return {"shapeType": pb.GEOM_SPHERE, "radius": float(s.radius), **base}
        if isinstance(s, Cylinder):
            return {
                "shapeType": pb.GEOM_CYLINDER,
                "radius": float(s.radius),
                "height": 2.0 * float(s.half_length),
                **base,
            }
        if isinstance(s, MeshShape):
            return {
                "shapeType": pb.GEOM_MESH,
                "vertices": np.asarray(s.vertices, dtype=float).tolist(),
                **base,
            }
        raise BackendError(f"unknown shape {type(s).__name__}")

    def add_body(
        self,
        shapes: Sequence[Shape],
        pose: Pose,
        mass: float,
        *,
        friction: float | None = None,
        fixed: bool = False,
        name: str | None = None,
        com: Sequence[float] | None = None,
        inertia_diag: Sequence[float] | None = None,
        visuals: Sequence[Shape] = (),
    ) -> BodyId:
        cid = self._cid
        shapes = list(shapes)
        visuals = list(visuals)
        # drawn geometry only where something may be filmed (set_visuals): it never changes physics
        coloured = self.draws_visuals and (bool(visuals) or any(s.rgba is not None for s in shapes))
        mp: BodyInertial = mass_properties(shapes, mass if mass > 0 else 1.0, com, inertia_diag)
        if len(shapes) > _MAX_COMPOUND_SHAPES and not all(isinstance(s, MeshShape) for s in shapes):
            raise BackendError(
                f"{len(shapes)} collision shapes in one body: PyBullet keeps at most "
                f"{_MAX_COMPOUND_SHAPES} of a mixed compound (convex meshes alone have no limit)"
            )
        tmp: list[str] = []
        hulls = {i: _convex_hull(s) for i, s in enumerate(shapes) if isinstance(s, MeshShape)}
        try:  # a body the engine does not make leaves no hull file behind
            # mesh hulls are written to disk once, here
            arrays = self._shape_arrays(shapes, tmp, hulls)
            if len(shapes) == 1:
                col = pb.createCollisionShape(
                    **self._shape_args(shapes[0], tmp), physicsClientId=cid
                )
            elif all(isinstance(s, MeshShape) for s in shapes):  # convex pieces of a scanned object
                col = self._mesh_compound(shapes, hulls, tmp)
            else:  # one single-link multibody; several shapes become one compound collision shape
                col = self._compound(arrays)
            texture = -1
            if coloured:  # one textured mesh: createVisualShapeArray draws at most 16 shapes
                vis, texture = self._coloured_visual(shapes + visuals)
            else:
                vis = self._visuals(arrays)
            m = 0.0 if fixed else float(mass)
            uid = pb.createMultiBody(
                baseMass=m,
                baseCollisionShapeIndex=col,
                baseVisualShapeIndex=vis,
                basePosition=pose.apply(mp.com).tolist(),
                baseOrientation=(pose.rotation * mp.inertial_pose.rotation).as_quat().tolist(),
                baseInertialFramePosition=mp.com.tolist(),
                baseInertialFrameOrientation=mp.principal.tolist(),
                physicsClientId=cid,
            )
        except BaseException:
            remove_files(tmp)
            raise
        # createMultiBody takes the base pose as the inertial frame's pose
        pb.resetBasePositionAndOrientation(
            uid, *self._com_pose_of(pose, mp.inertial_pose), physicsClientId=cid
        )
        fr = self.config.default_friction if friction is None else friction
        kw = {
            "lateralFriction": fr,
            "spinningFriction": self._spinning(fr),
            "linearDamping": 0.0,
            "angularDamping": 0.0,
            "frictionAnchor": 1,
        }
        if not fixed:
            kw["localInertiaDiagonal"] = mp.inertia_diag.tolist()
        if any(isinstance(s, MeshShape) for s in shapes):
            # Bullet grows a convex hull by its collision margin, 1 mm by default: the object was 1 mm
            # fatter than its model (bench/bench_object_surfaces.py)
            kw["collisionMargin"] = _MESH_MARGIN
        pb.changeDynamics(uid, -1, **kw, physicsClientId=cid)
        if vis >= 0 and texture >= 0:
            pb.changeVisualShape(
                uid, -1, textureUniqueId=texture, rgbaColor=[1, 1, 1, 1], physicsClientId=cid
            )
        elif vis >= 0:
            pb.changeVisualShape(uid, -1, rgbaColor=list(_GREY), physicsClientId=cid)
        return self._register(
            _Body(
                uid=uid,
                name=name or "",
                base_inertial=mp.inertial_pose,
                fixed=fixed,
                temp_files=tmp,
            )
        )

    def _shape_arrays(
        self, shapes: list[Shape], tmp: list[str], hulls: dict[int, Any]
    ) -> tuple[list, ...]:
        """Per-shape fields for PyBullet's ``create*ShapeArray`` calls (collision and visual alike).

        ``hulls``: the convex hull of each mesh shape, by index.

        Returns ``(types, half_extents, radii, lengths, file_names, positions, orientations)``.
        """
        types: list[int] = []
        half: list[list[float]] = []
        radii: list[float] = []
        lengths: list[float] = []
        files: list[str] = []
        poss: list[list[float]] = []
        orns: list[list[float]] = []
        fields: tuple[int, list[float], float, float, str]
        for i, s in enumerate(shapes):
            if isinstance(s, MeshShape):
                fields = (pb.GEOM_MESH, [0, 0, 0], 0.0, 0.0, self._hull_obj(hulls[i], tmp))
            elif isinstance(s, Box):
                fields = (pb.GEOM_BOX, list(map(float, s.half_extents)), 0.0, 0.0, "")
            elif isinstance(s, Sphere):
                fields = (pb.GEOM_SPHERE, [0, 0, 0], float(s.radius), 0.0, "")
            elif isinstance(s, Cylinder):
                fields = (
                    pb.GEOM_CYLINDER,
                    [0, 0, 0],
                    float(s.radius),
                    2.0 * float(s.half_length),
                    "",
                )
            else:
                raise BackendError(f"unknown shape {type(s).__name__}")
            types.append(fields[0])
            half.append(fields[1])
            radii.append(fields[2])
            lengths.append(fields[3])
            files.append(fields[4])
            poss.append(s.pose.p.tolist())
            orns.append(s.pose.q.tolist())
        return types, half, radii, lengths, files, poss, orns

    def _mesh_compound(self, shapes: Sequence[Shape], hulls: dict[int, Any], tmp: list[str]) -> int:
        """Convex pieces as one compound, all of them: one OBJ file with an object per piece.

        ``createCollisionShapeArray`` keeps only the first ``_MAX_COMPOUND_SHAPES`` (16) children and
        drops the rest without a word (measured: a 32-piece YCB scan kept 16, and rays passed through
        the missing half). A GEOM_MESH file with several objects becomes a compound with one convex
        hull child per object, with no such limit. Each piece's pose is baked into its vertices.
        ``hulls``: each piece's convex hull, by index.
        """
        fd, fn = tempfile.mkstemp(suffix=".obj", prefix="bh_pieces_")
        os.close(fd)
        tmp.append(fn)
        offset = 1
        with open(fn, "w") as out:
            for i, s in enumerate(shapes):
                hull = hulls[i]
                v = s.pose.apply(np.asarray(hull.vertices, dtype=float))
                out.write(f"o piece{i}\n")
                out.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in v.tolist())
                out.writelines(
                    f"f {a + offset} {b + offset} {c + offset}\n"
                    for a, b, c in np.asarray(hull.faces).tolist()
                )
                offset += len(v)
        return pb.createCollisionShape(pb.GEOM_MESH, fileName=fn, physicsClientId=self._cid)

    def _compound(self, arrays: tuple[list, ...]) -> int:
        cid = self._cid
        types, half, radii, lengths, files, poss, orns = arrays
        scales = [[1, 1, 1]] * len(types)
        return pb.createCollisionShapeArray(
            shapeTypes=types,
            halfExtents=half,
            radii=radii,
            lengths=lengths,
            fileNames=files,
            meshScales=scales,
            collisionFramePositions=poss,
            collisionFrameOrientations=orns,
            physicsClientId=cid,
        )

    def _visuals(self, arrays: tuple[list, ...]) -> int:
        """Grey visual shapes mirroring the collision shapes (only the renderer sees them)."""
        types, half, radii, lengths, files, poss, orns = arrays
        try:
            return pb.createVisualShapeArray(
                shapeTypes=types,
                halfExtents=half,
                radii=radii,
                lengths=lengths,
                fileNames=files,
                meshScales=[[1, 1, 1]] * len(types),
                visualFramePositions=poss,
                visualFrameOrientations=orns,
                physicsClientId=self._cid,
            )
        except pb.error:  # rendering is a nicety; physics does not need it
            return -1

    def _coloured_visual(self, shapes: list[Shape]) -> tuple[int, int]:
        """All of a body's drawn shapes as one triangle mesh, coloured through a palette texture.

        PyBullet gives a vertex no colour and a link at most 16 visual shapes
        (a stickered cube has 55), so every triangle's three UVs point at the
        centre of its colour's 4 x 4 texel block in a small palette image
        (one per set of colours, loaded once per world). Alpha is not drawn.
        Returns ``(visual shape id, texture id)``, ``(-1, -1)`` if PyBullet refuses.
        """
        parts = [(_triangles(s), _rgb8(s.rgba)) for s in shapes]
        colours = tuple(sorted({c for _, c in parts}))
        slot = {c: i for i, c in enumerate(colours)}
        verts, normals, uvs = [], [], []
        for (tri, nrm), c in parts:
            verts.append(tri.reshape(-1, 3))
            normals.append(np.repeat(nrm, 3, axis=0))
            uv = np.array([(slot[c] + 0.5) / len(colours), 0.5])
            uvs.append(np.tile(uv, (3 * len(tri), 1)))
        v = np.concatenate(verts)
        try:
            vis = pb.createVisualShape(
                pb.GEOM_MESH,
                vertices=v.tolist(),
                indices=list(range(len(v))),
                uvs=np.concatenate(uvs).tolist(),
                normals=np.concatenate(normals).tolist(),
                physicsClientId=self._cid,
            )
            return vis, self._palette(colours)
        except pb.error:  # rendering is a nicety; physics does not need it
            return -1, -1

    def _palette(self, colours: tuple[tuple[int, int, int], ...]) -> int:
        tex = self._palettes.get(colours)
        if tex is None:
            img = np.repeat(np.repeat(np.array([colours], dtype=np.uint8), 4, axis=0), 4, axis=1)
            from PIL import Image  # Pillow comes with matplotlib, a dependency

            fd, fn = tempfile.mkstemp(suffix=".png", prefix="bh_palette_")
            os.close(fd)
            try:
                Image.fromarray(img).save(fn)
                tex = int(pb.loadTexture(fn, physicsClientId=self._cid))
            finally:
                os.unlink(fn)
            self._palettes[colours] = tex
        return tex

    @staticmethod
    def _hull_obj(hull: Any, tmp: list[str]) -> str:
        fd, fn = tempfile.mkstemp(suffix=".obj", prefix="bh_hull_")
        os.close(fd)
        tmp.append(fn)
        hull.export(fn)
        return fn

    @staticmethod
    def _com_pose_of(link_pose: Pose, inertial: Pose) -> tuple[list[float], list[float]]:
        w = link_pose * inertial
        return w.p.tolist(), w.q.tolist()

    def load_urdf(
        self,
        path: str | Path,
        base_pose: Pose,
        *,
        fixed_base: bool = True,
        name: str | None = None,
    ) -> BodyId:
        cid = self._cid
        model = parse_urdf(path)
        flags = (
            pb.URDF_USE_INERTIA_FROM_FILE
            | pb.URDF_USE_SELF_COLLISION
            | pb.URDF_USE_IMPLICIT_CYLINDER
        )
        try:
            uid = pb.loadURDF(
                str(Path(path).resolve()),
                basePosition=[0, 0, 0],
                useFixedBase=bool(fixed_base),
                flags=flags,
                physicsClientId=cid,
            )
        except pb.error as exc:
            raise BackendError(f"PyBullet could not load {path}: {exc}") from exc
        link_index: dict[str, int] = {}
        joint_by_name: dict[str, int] = {}
        for i in range(pb.getNumJoints(uid, physicsClientId=cid)):
            info = pb.getJointInfo(uid, i, physicsClientId=cid)
            joint_by_name[info[1].decode()] = i
            link_index[info[12].decode()] = i
        joints = list(model.movable)
        jidx = [joint_by_name[j.name] for j in joints]
        # default motors off; URDF friction/damping are not used (set_joint_friction instead)
        if jidx:
            pb.setJointMotorControlArray(
                uid, jidx, pb.VELOCITY_CONTROL, forces=[0.0] * len(jidx), physicsClientId=cid
            )
        for i in range(-1, pb.getNumJoints(uid, physicsClientId=cid)):
            pb.changeDynamics(
                uid,
                i,
                linearDamping=0.0,
                angularDamping=0.0,
                jointDamping=0.0,
                lateralFriction=float(self.config.default_friction),
                spinningFriction=self._spinning(float(self.config.default_friction)),
                frictionAnchor=1,
                physicsClientId=cid,
            )

        # filter pairs adjacent through fixed links (PhysX does not, we do on both engines)
        def idx(l: str) -> int:
            return -1 if l == model.root_link else link_index[l]

        for clique in model.filtered_link_pairs():
            ls = sorted(clique)
            for a in range(len(ls)):
                for c in range(a + 1, len(ls)):
                    pb.setCollisionFilterPair(
                        uid, uid, idx(ls[a]), idx(ls[c]), 0, physicsClientId=cid
                    )
        di = pb.getDynamicsInfo(uid, -1, physicsClientId=cid)
        base_inertial = Pose(di[3], di[4])
        b = _Body(
            uid=uid,
            name=name or model.root_link,
            urdf=model,
            link_index=link_index,
            joints=joints,
            joint_index=jidx,
            base_inertial=base_inertial,
            fixed=bool(fixed_base),
        )
        h = self._register(b)
        self.set_pose(h, base_pose)
        # links drawn from their collision geometry (no <visual>) come out white: grey them, so
        # a robot stands out from the background; a URDF's own (non-white) colours stay
        white = {
            int(v[1])
            for v in pb.getVisualShapeData(uid, physicsClientId=cid)
            if tuple(v[7]) == (1.0, 1.0, 1.0, 1.0)
        }
        for link in sorted(white):
            pb.changeVisualShape(uid, link, rgbaColor=list(_URDF_GREY), physicsClientId=cid)
        return h

    def remove_body(self, body: BodyId) -> None:
        b = self._b(body)
        for c, pc in list(self._constraints.items()):
            info = pb.getConstraintInfo(pc, physicsClientId=self._cid)
            if b.uid in (info[0], info[2]):
                self.detach(c)
        for cid in b.couplings:
            pb.removeConstraint(cid, physicsClientId=self._cid)
        pb.removeBody(b.uid, physicsClientId=self._cid)
        self._bodies.pop(body)
        self._step_lists = None
        self._uid2h.pop(b.uid, None)
        self._grounds.pop(body, None)

    def get_pose(self, body: BodyId) -> Pose:
        b = self._b(body)
        p, q = pb.getBasePositionAndOrientation(b.uid, physicsClientId=self._cid)
        return Pose(p, q) * b.base_inertial.inv()

    def set_pose(self, body: BodyId, pose: Pose) -> None:
        b = self._b(body)
        b.gravity_base = None
        lin, ang = pb.getBaseVelocity(b.uid, physicsClientId=self._cid)
        pb.resetBasePositionAndOrientation(
            b.uid, *self._com_pose_of(pose, b.base_inertial), physicsClientId=self._cid
        )
        pb.resetBaseVelocity(b.uid, lin, ang, physicsClientId=self._cid)

    def get_velocity(self, body: BodyId) -> tuple[np.ndarray, np.ndarray]:
        b = self._b(body)
        lin, ang = pb.getBaseVelocity(b.uid, physicsClientId=self._cid)
        return np.asarray(lin, dtype=float), np.asarray(ang, dtype=float)

    def set_velocity(
        self,
        body: BodyId,
        linear: Sequence[float] | np.ndarray,
        angular: Sequence[float] | np.ndarray,
    ) -> None:
        b = self._b(body)
        pb.resetBaseVelocity(
            b.uid, list(map(float, linear)), list(map(float, angular)), physicsClientId=self._cid
        )

    def get_link_pose(self, body: BodyId, link: str | None) -> Pose:
        b = self._b(body)
        i = self._link(b, link)
        if i == -1:
            return self.get_pose(body)
        st = pb.getLinkState(b.uid, i, computeForwardKinematics=True, physicsClientId=self._cid)
        return Pose(st[4], st[5])

    def get_mass(self, body: BodyId) -> float:
        b = self._b(body)
        if b.urdf is not None:  # engines zero a fixed base's mass; report the description's
            return b.urdf.total_mass
        return float(
            sum(
                pb.getDynamicsInfo(b.uid, i, physicsClientId=self._cid)[0]
                for i in range(-1, pb.getNumJoints(b.uid, physicsClientId=self._cid))
            )
        )

    # -- joints ----------------------------------------------------------------
    def joint_info(self, body: BodyId) -> list[JointInfo]:
        return list(self._b(body).joints)

    def link_names(self, body: BodyId) -> list[str]:
        b = self._b(body)
        return list(b.urdf.links) if b.urdf else []

    def get_joint_state(self, body: BodyId) -> JointState:
        b = self._b(body)
        if not b.joints:
            z = np.zeros(0)
            return JointState(z, z.copy(), z.copy())
        st = pb.getJointStates(b.uid, b.joint_index, physicsClientId=self._cid)
        return JointState(
            np.array([s[0] for s in st]), np.array([s[1] for s in st]), np.array([s[3] for s in st])
        )

    def _motion(self, b: _Body) -> tuple[np.ndarray, np.ndarray]:
        """The body's joint positions and velocities, read once per step (shared, never mutated)."""
        m = b.motion
        if m is None or m[0] != self._steps:
            st = pb.getJointStates(b.uid, b.joint_index, physicsClientId=self._cid)
            m = b.motion = (self._steps, np.array([s[0] for s in st]), np.array([s[1] for s in st]))
        return m[1], m[2]

    def get_joint_motion(self, body: BodyId) -> tuple[np.ndarray, np.ndarray]:
        b = self._b(body)
        if not b.joints:
            return np.zeros(0), np.zeros(0)
        q, v = self._motion(b)
        return q.copy(), v.copy()

    def set_joint_positions(
        self, body: BodyId, positions: Sequence[float], joints: Sequence[str] | None = None
    ) -> None:
        b = self._b(body)
        sel = b.joint_indices(joints)
        pos = as_array(positions, len(sel), "positions")
        b.q_prev = None  # a teleport is not motion
        b.minv = None
        b.motion = None
        for i, q in zip(sel, pos):
            pb.resetJointState(b.uid, b.joint_index[i], float(q), 0.0, physicsClientId=self._cid)

    def set_joint_targets(
        self,
        body: BodyId,
        positions: Sequence[float] | None = None,
        velocities: Sequence[float] | None = None,
        *,
        joints: Sequence[str] | None = None,
        stiffness: float | Sequence[float] = 1000.0,
        damping: float | Sequence[float] = 100.0,
        force_limit: float | Sequence[float] | None = None,
    ) -> None:
        b = self._b(body)
        sel = b.joint_selection(joints)
        n = len(sel)
        if n == 0:
            return
        cmd = drive_command(
            b.joints,
            sel,
            positions,
            velocities,
            stiffness,
            damping,
            force_limit,
            lambda: self.get_joint_state(body).positions,
        )
        newly_driven = not b.drive.driven[sel].all()
        b.drive.set_targets(sel, cmd)
        if newly_driven:  # re-targeting driven joints (most calls) keeps the lists
            self._step_lists = None
            b.driven_idx = np.nonzero(b.drive.driven)[0]
            b.driven_pb = [b.joint_index[i] for i in b.driven_idx]
            b.ones = [1.0] * len(b.driven_pb)
        b.drive_cache = None

    def _retarget_driven(
        self,
        body: BodyId,
        positions: Sequence[float],
        velocities: Sequence[float],
        joints: Sequence[str],
        stiffness: Sequence[float],
        damping: Sequence[float],
        force_limit: Sequence[float],
    ) -> bool:
        b = self._b(body)
        sel = b.joint_selection(joints)
        if b.drive.retarget(sel, positions, velocities, stiffness, damping, force_limit) is None:
            return False
        b.drive_cache = None
        return True

    def set_joint_friction(
        self, body: BodyId, torques: float | Sequence[float], joints: Sequence[str] | None = None
    ) -> None:
        b = self._b(body)
        sel = b.joint_indices(joints)
        t = as_array(torques, len(sel), "torques")
        for i, tau in zip(sel, t):
            b.drive.friction[i] = float(tau)
            if not b.drive.driven[i]:
                pb.setJointMotorControl2(
                    b.uid,
                    b.joint_index[i],
                    pb.VELOCITY_CONTROL,
                    targetVelocity=0.0,
                    force=float(tau),
                    velocityGain=1.0,
                    physicsClientId=self._cid,
                )

    # -- interaction -----------------------------------------------------------
    def contacts(self, body_a: BodyId | None = None, body_b: BodyId | None = None) -> list[Contact]:
        kw = {}
        if body_a is not None:
            kw["bodyA"] = self._b(body_a).uid
        if body_b is not None:
            kw["bodyB"] = self._b(body_b).uid
        out = []
        for c in pb.getContactPoints(**kw, physicsClientId=self._cid):
            a, bb = self._uid2h.get(c[1]), self._uid2h.get(c[2])
            if a is None or bb is None:
                continue
            flip = contact_side(a, bb, body_a, body_b)
            if flip is None:
                continue
            la, lb = self._bodies[a].index_link.get(c[3]), self._bodies[bb].index_link.get(c[4])
            pos = 0.5 * (np.asarray(c[5]) + np.asarray(c[6]))
            nrm = np.asarray(c[7], dtype=float)
            fn, dist = max(0.0, float(c[9])), float(c[8])
            out.append(
                Contact(bb, lb, a, la, pos, -nrm, fn, dist)
                if flip
                else Contact(a, la, bb, lb, pos, nrm, fn, dist)
            )
        return out

    def ray_cast(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        max_distance: float | np.ndarray,
        *,
        ignore_bodies: Sequence[BodyId] = (),
        ignore_links: Sequence[tuple[BodyId, str | None]] = (),
    ) -> RayHits:
        o = np.atleast_2d(np.asarray(origins, dtype=float))
        dvec = np.atleast_2d(np.asarray(directions, dtype=float))
        n = o.shape[0]
        dvec = dvec / np.linalg.norm(dvec, axis=1, keepdims=True)
        maxd = np.broadcast_to(np.asarray(max_distance, dtype=float), (n,)).copy()
        ignore = set(int(x) for x in ignore_bodies)
        ignore_uid = {self._bodies[h].uid for h in ignore if h in self._bodies}
        ignore_link = set()  # (uid, pybullet link index)
        for h, link in ignore_links:
            lb = self._b(int(h))
            ignore_link.add((lb.uid, self._link(lb, link)))
        hit = np.zeros(n, dtype=bool)
        dist = np.full(n, np.inf)
        point = np.full((n, 3), np.nan)
        normal = np.full((n, 3), np.nan)
        body = np.full(n, -1, dtype=int)
        start = np.zeros(n)  # distance already travelled
        todo = np.arange(n)
        for _ in range(64):
            if todo.size == 0:
                break
            nxt = []
            for c0 in range(0, todo.size, _RAY_BATCH):
                idx = todo[c0 : c0 + _RAY_BATCH]
                fr = o[idx] + dvec[idx] * start[idx, None]
                to = o[idx] + dvec[idx] * maxd[idx, None]
                res = pb.rayTestBatch(fr.tolist(), to.tolist(), physicsClientId=self._cid)
                for i, r in zip(idx, res):
                    uid = r[0]
                    if uid < 0 or uid not in self._uid2h:
                        continue
                    d_hit = start[i] + r[2] * (maxd[i] - start[i])
                    if uid in ignore_uid or (uid, r[1]) in ignore_link:
                        start[i] = d_hit + 1e-4  # rays starting inside a convex shape do not hit it
                        if start[i] < maxd[i]:
                            nxt.append(i)
                        continue
                    hit[i] = True
                    dist[i] = d_hit
                    point[i] = r[3]
                    normal[i] = r[4]
                    body[i] = self._uid2h[uid]
            todo = np.asarray(nxt, dtype=int)
        ground_ray_fixup(self._grounds, ignore, o, dvec, maxd, hit, dist, point, normal, body)
        return RayHits(hit, dist, point, normal, body)

    def attach(
        self,
        parent: BodyId,
        parent_link: str | None,
        child: BodyId,
        child_link: str | None,
        child_in_parent: Pose,
    ) -> int:
        pbody, cbody = self._b(parent), self._b(child)
        pi, ci = self._link(pbody, parent_link), self._link(cbody, child_link)
        pin = self._inertial(pbody, pi)
        cin = self._inertial(cbody, ci)
        fp = pin.inv() * child_in_parent
        fc = cin.inv()
        cid = pb.createConstraint(
            pbody.uid,
            pi,
            cbody.uid,
            ci,
            pb.JOINT_FIXED,
            [0, 0, 0],
            parentFramePosition=fp.p.tolist(),
            childFramePosition=fc.p.tolist(),
            parentFrameOrientation=fp.q.tolist(),
            childFrameOrientation=fc.q.tolist(),
            physicsClientId=self._cid,
        )
        pb.changeConstraint(cid, maxForce=_ATTACH_MAX_FORCE, physicsClientId=self._cid)
        h = self._next_constraint
        self._next_constraint += 1
        self._constraints[h] = cid
        return h

    def couple_joints(
        self, body: BodyId, follower: str, leader: str, multiplier: float = 1.0
    ) -> None:
        """A Bullet gear constraint between the two joints' links (follower as A, leader as B).

        Bullet's multibody gear keeps ``v_A + ratio * v_B = 0`` and, with an
        ERP, corrects the position error too; ``ratio = -multiplier`` gives
        ``q_follower = multiplier * q_leader``.
        """
        b = self._b(body)
        fi, li = b.coupled_joints(follower, leader, multiplier)
        cid = pb.createConstraint(
            b.uid,
            b.joint_index[fi],
            b.uid,
            b.joint_index[li],
            pb.JOINT_GEAR,
            [0, 0, 1],  # unused by a multibody gear: it acts on the joints' own axes
            parentFramePosition=[0, 0, 0],
            childFramePosition=[0, 0, 0],
            physicsClientId=self._cid,
        )
        pb.changeConstraint(
            cid,
            gearRatio=-float(multiplier),
            maxForce=_COUPLING_MAX_FORCE,
            erp=_COUPLING_ERP,
            physicsClientId=self._cid,
        )
        b.couplings.append(cid)

    def check_finite(self, bodies: Sequence[BodyId]) -> None:
        for h in bodies:
            b = self._b(h)
            p, q = pb.getBasePositionAndOrientation(b.uid, physicsClientId=self._cid)
            lin, ang = pb.getBaseVelocity(b.uid, physicsClientId=self._cid)
            vals = list(p) + list(q) + list(lin) + list(ang)
            if b.joints:
                for st in pb.getJointStates(b.uid, b.joint_index, physicsClientId=self._cid):
                    vals += [st[0], st[1]]
            if not all(math.isfinite(v) for v in vals):
                raise SimulationError(
                    f"body {b.name!r} (handle {h}) has a non-finite state (simulation blew up)"
                )

    def _inertial(self, b: _Body, link: int) -> Pose:
        if link == -1:
            return b.base_inertial
        di = pb.getDynamicsInfo(b.uid, link, physicsClientId=self._cid)
        return Pose(di[3], di[4])

    def detach(self, constraint: int) -> None:
        try:
            pc = self._constraints.pop(constraint)
        except KeyError:
            raise BackendError(f"no attachment with handle {constraint}") from None
        pb.removeConstraint(pc, physicsClientId=self._cid)

    def render(self, camera: CameraSpec) -> np.ndarray:
        view = pb.computeViewMatrix(camera.eye, camera.target, camera.up, physicsClientId=self._cid)
        proj = pb.computeProjectionMatrixFOV(
            camera.fov_deg,
            camera.width / camera.height,
            camera.near,
            camera.far,
            physicsClientId=self._cid,
        )
        _, _, rgba, _, _ = pb.getCameraImage(
            camera.width,
            camera.height,
            view,
            proj,
            renderer=pb.ER_TINY_RENDERER,
            flags=pb.ER_NO_SEGMENTATION_MASK,  # only the colours are returned
            physicsClientId=self._cid,
        )
        img = np.asarray(rgba, dtype=np.uint8).reshape(camera.height, camera.width, 4)
        return img[:, :, :3].copy()
