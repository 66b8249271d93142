"""The SAPIEN 3 backend (PhysX 5 on the CPU, one ``sapien.Scene`` per instance).

Headless machines have no render device, so this backend never creates one:
the ground has no visual, URDFs are loaded from a collision-only copy, and
:meth:`render` raises :class:`CapabilityError`.

Engine-specific choices (so that the numbers mean what they mean on PyBullet):

* TGS solver, ``PhysicsConfig.solver_iterations`` position iterations;
  shape ``contact_offset`` from the config and ``rest_offset = 0``.
* PD drives are PhysX joint drives (implicit spring-damper, ``force`` mode).
* Joint friction: a velocity drive, target 0, large damping, force limit =
  the torque. The URDF's ``<dynamics>`` (damping, friction) is zeroed, as on PyBullet.
* Links joined through fixed links are filtered from colliding (collision
  group word 2 bits, word 3 = the body's handle), as on PyBullet.
* SAPIEN quaternions are (w, x, y, z); converted here only.
"""

from __future__ import annotations

import math
import os
import tempfile
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..geometry import Pose
from . import SAPIEN_CAPABILITIES
from ._bodies import BodyRecord, BodyTable, as_array, contact_side, drive_command, remove_files
from ._urdf import (
    BodyInertial,
    collision_only_copy,
    ground_ray_fixup,
    mass_properties,
    parse_urdf,
)
from .interface import (
    Backend,
    BackendError,
    BodyId,
    Box,
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

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # "Failed to find system libvulkan" on headless machines
    import sapien
    import sapien.physx as physx

#: a speed above this (m/s or rad/s) counts as a blow-up, as does a non-finite state
MAX_SPEED = 1.0e4
#: convex meshes are cooked in millimetres (scaled back by the shape's scale): PhysX merges vertices
#: within its plane tolerance (0.7 "units") of a hull face, which in metres dropped up to 1.6 mm of a
#: YCB scan's hull; in millimetres 0.0007 mm. PhysX's vertex limit on one hull is met by cutting
#: large hulls (:func:`_cookable_pieces`); bench/bench_object_surfaces.py measures the result
_COOK_UNITS = 1000.0
#: hull vertices of one cooked piece: PhysX keeps at most 255 vertices and 255 faces of a convex mesh
#: and simplifies a larger hull (a single-hull apple scan then sat up to 1.2 mm inside its model)
_PIECE_VERTICES = 100


def _cookable_pieces(vertices: np.ndarray) -> list[Any]:
    """The convex hull of ``vertices`` as convex pieces PhysX cooks without simplifying them.

    A hull within :data:`_PIECE_VERTICES` is one piece. A larger one is cut into cones from its
    centroid: its surface is split into patches by the direction of each face's normal (as many
    directions as the patches need, on a Fibonacci sphere), and each piece is the hull of one patch
    and the centroid. The pieces lie inside the hull and their union is the hull (the centroid is
    inside it), so the surface is the model's: measured within 0.03 mm along rays for the apple and
    orange (88 and 111 pieces of up to 135 / 152 vertices, which PhysX cooked without simplifying).
    """
    import trimesh

    hull = trimesh.convex.convex_hull(vertices)
    if len(hull.vertices) <= _PIECE_VERTICES:
        return [hull]
    k = int(math.ceil(2.0 * len(hull.vertices) / _PIECE_VERTICES))
    i = np.arange(k) + 0.5
    z = 1.0 - 2.0 * i / k
    phi = math.pi * (1.0 + 5.0**0.5) * i
    dirs = np.column_stack(
        [np.sqrt(1.0 - z * z) * np.cos(phi), np.sqrt(1.0 - z * z) * np.sin(phi), z]
    )
    label = np.argmax(hull.face_normals @ dirs.T, axis=1)
    centre = hull.vertices.mean(axis=0)
    pieces = []
    for j in np.unique(label):
        pts = hull.vertices[np.unique(hull.faces[label == j])]
        pieces.append(trimesh.convex.convex_hull(np.vstack([pts, centre])))
    return pieces


_FRICTION_DAMPING = 1.0e4  #: damping of the velocity drive that models Coulomb joint friction
_ATTACH_STIFFNESS = 1.0e7
_ATTACH_DAMPING = 1.0e4
_ATTACH_MAX_FORCE = 1.0e5
#: A joint coupling (:meth:`SapienBackend.couple_joints`) is a PhysX fixed tendon, a spring on
#: ``multiplier * q_leader - q_follower`` solved with the articulation: N/m (N m/rad) and N s/m. Stiff
#: enough that a 10 N difference between the fingers' loads moves them 0.1 mm apart, damped well
#: beyond critical for a PR2 finger (0.17 kg) so that it does not ring.
_COUPLING_STIFFNESS = 1.0e5
_COUPLING_DAMPING = 1.0e3
# x axis -> z axis: SAPIEN cylinders run along x, ours along z
_X_TO_Z = Pose(np.zeros(3), np.array([0.0, -math.sqrt(0.5), 0.0, math.sqrt(0.5)]))


def _sp(pose: Pose) -> sapien.Pose:
    q = pose.q
    return sapien.Pose(
        [float(x) for x in pose.p], [float(q[3]), float(q[0]), float(q[1]), float(q[2])]
    )


def _bp(pose: sapien.Pose) -> Pose:
    q = pose.q
    return Pose(np.asarray(pose.p, dtype=float), np.array([q[1], q[2], q[3], q[0]], dtype=float))


@dataclass(kw_only=True)
class _Body(BodyRecord):
    handle: int
    entity: Any = None  #: actor entity (rigid bodies)
    component: Any = None  #: PhysxRigidDynamicComponent / PhysxRigidStaticComponent
    articulation: Any = None
    links: dict[str, Any] = field(default_factory=dict)  #: URDF name -> link component
    sjoints: list[Any] = field(default_factory=list)  #: SAPIEN joints in our order
    perm: np.ndarray = field(
        default_factory=lambda: np.zeros(0, dtype=int)
    )  #: ours -> active index
    drive_props: dict[int, tuple[float, float, float]] = field(default_factory=dict)
    drive_targets: dict[int, tuple[float, float]] = field(
        default_factory=dict
    )  #: last (q*, v*) sent
    gravity_tree: Any = None  #: cached (links, downstream mask, prismatic, masses) for a free base
    #: (step, q, v) in our joint order, last read from PhysX: joints only change by stepping or a
    #: teleport (set_joint_positions clears it); controllers read them several times a step
    motion: tuple[int, np.ndarray, np.ndarray] | None = None

    @property
    def root(self) -> Any:
        return self.articulation.root if self.articulation is not None else self.component

    def components(self) -> list[Any]:
        if self.articulation is not None:
            return list(self.articulation.links)
        return [self.component]


class SapienBackend(Backend):
    name = "sapien"
    capabilities = SAPIEN_CAPABILITIES
    default_solver_iterations = 20  # cube spike (docs/benchmarks/cube_spike.md): TGS with 20 position iterations twists the cube correctly

    def __init__(self, config: PhysicsConfig | None = None) -> None:
        super().__init__(config)
        c = self.config
        physx.set_scene_config(
            gravity=np.asarray(c.gravity, dtype=np.float32), enable_tgs=True, cpu_workers=0
        )
        self._apply_global_config()
        self._system = physx.PhysxCpuSystem()
        self._scene = sapien.Scene([self._system])
        self._scene.set_timestep(c.timestep)
        #: the engine's own step (bench/bench_speed.py times this call to find the engine's floor)
        self._engine_step: Any = self._system.step
        self._bodies: BodyTable[_Body] = BodyTable()
        self._entity_map: dict[int, tuple[int, str | None]] = {}  # per_scene_id -> (handle, link)
        #: the same, keyed by the physical component itself (a contact's ``bodies``): SAPIEN hands
        #: back one Python object per component, and this saves two engine calls per contact body
        self._component_map: dict[Any, tuple[int, str | None]] = {}
        self._constraints: dict[int, Any] = {}
        self._next_constraint = 1
        self._steps = 0
        self._roots: list[tuple[int, Any]] | None = None  #: movable bases, see _step_engine
        #: the last step's contacts, read just before a body was removed and kept until the next step:
        #: the engine's own list then still refers to the removed components, and reading it crashes
        #: the process (seen: ``contacts()`` right after the cube swapped to its slabs)
        self._held_contacts: list[Contact] | None = None
        self._closed = False
        self._grounds: dict[int, float] = {}
        self._materials: dict[float, Any] = {}

    def _apply_global_config(self) -> None:
        """SAPIEN's shape/body settings are process-wide defaults read at creation: set them each time."""
        c = self.config
        physx.set_shape_config(contact_offset=float(c.contact_offset), rest_offset=0.0)
        physx.set_body_config(
            solver_position_iterations=self.solver_iterations,
            solver_velocity_iterations=int(c.solver_velocity_iterations),
            sleep_threshold=0.0,  # no sleeping: Bullet multibodies do not sleep either
        )

    def _material(self, friction: float | None) -> Any:
        f = float(self.config.default_friction if friction is None else friction)
        if f not in self._materials:
            self._materials[f] = physx.PhysxMaterial(f, f, 0.0)
        return self._materials[f]

    # -- lifetime --------------------------------------------------------------
    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._bodies.close()
        self._constraints.clear()
        self._entity_map.clear()
        self._component_map.clear()
        try:
            self._scene.clear()
        except Exception:  # noqa: BLE001 - best effort
            pass
        self._scene = None
        self._system = None
        self._engine_step = None

    # -- helpers ---------------------------------------------------------------
    def _b(self, body: BodyId) -> _Body:
        return self._bodies[body]

    def _link(self, b: _Body, link: str | None) -> Any:
        if link is None:
            return b.root
        if b.articulation is None:
            raise BackendError(f"body {b.name!r} has no links; use link=None")
        try:
            return b.links[link]
        except KeyError:
            raise BackendError(
                f"body {b.name!r} has no link {link!r}; links: {list(b.links)}"
            ) from None

    def _register(self, b: _Body) -> int:
        self._roots = None
        self._bodies.add(b.handle, b)
        if b.articulation is not None:
            root = b.urdf.root_link if b.urdf is not None else None
            for name, comp in b.links.items():
                link = None if name == root else name
                self._entity_map[comp.entity.per_scene_id] = (b.handle, link)
                self._component_map[comp] = (b.handle, link)
        else:
            self._entity_map[b.entity.per_scene_id] = (b.handle, None)
            self._component_map[b.component] = (b.handle, None)
        return b.handle

    def _new_handle(self) -> int:
        return self._bodies.new_handle()

    # -- time ------------------------------------------------------------------
    @property
    def time(self) -> float:
        return self._steps * self.config.timestep

    def _step_engine(self, n: int, after_step: StepCallback | None) -> None:
        if self._closed:
            raise BackendError("backend is closed")
        for _ in range(n):
            if self._roots is None:  # cached until a body is added or removed
                # bases that can move (a fixed base cannot; joints are checked after the loop)
                self._roots = [(h, b.root) for h, b in self._bodies.items() if not b.fixed]
            roots = self._roots
            self._engine_step()
            self._steps += 1
            self._held_contacts = None
            for h, comp in roots:
                lv = comp.linear_velocity
                av = comp.angular_velocity
                s = abs(lv[0]) + abs(lv[1]) + abs(lv[2]) + abs(av[0]) + abs(av[1]) + abs(av[2])
                if not s < MAX_SPEED:
                    self._blowup(h)
            if after_step is not None:
                after_step()
        # base poses (a non-finite pose can come with finite velocities) and joint states; sums
        # and maxima instead of np.isfinite on these tiny arrays: a third of the cost, NaN included
        for h, b in self._bodies.items():
            pose = b.root.entity_pose
            p, q = pose.p, pose.q
            if not math.isfinite(p[0] + p[1] + p[2] + q[0] + q[1] + q[2] + q[3]):
                self._blowup(h)
            art = b.articulation
            if art is not None and art.dof:
                if not math.isfinite(float(art.qpos.sum())):
                    self._blowup(h)
                if not float(np.abs(art.qvel).max()) < MAX_SPEED:  # NaN compares False
                    self._blowup(h)

    def _blowup(self, h: int) -> None:
        raise SimulationError(
            f"body {self._bodies[h].name!r} (handle {h}) has a non-finite or absurd state after step "
            f"{self._steps} (t = {self.time:.4f} s): the simulation blew up"
        )

    def pair_friction(self, a: float, b: float) -> float:
        """PhysX's combined friction of a contact: the mean of the two materials' (default combine mode)."""
        return 0.5 * (float(a) + float(b))

    # -- bodies ----------------------------------------------------------------
    def add_ground(self, height: float = 0.0, friction: float | None = None) -> BodyId:
        self._apply_global_config()
        ent = self._scene.add_ground(float(height), render=False, material=self._material(friction))
        h = self._new_handle()
        comp = ent.find_component_by_type(physx.PhysxRigidStaticComponent)
        self._grounds[h] = float(height)
        return self._register(
            _Body(handle=h, name="ground", entity=ent, component=comp, fixed=True)
        )

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
        del visuals  # render-only, and this backend has no renderer (module docstring)
        self._apply_global_config()
        shapes = list(shapes)
        mp: BodyInertial = mass_properties(shapes, mass if mass > 0 else 1.0, com, inertia_diag)
        mat = self._material(friction)
        builder = self._scene.create_actor_builder()
        tmp: list[str] = []
        try:  # a body that is not made leaves no hull file behind
            for s in shapes:
                if isinstance(s, Box):
                    builder.add_box_collision(
                        _sp(s.pose), [float(x) for x in s.half_extents], material=mat
                    )
                elif isinstance(s, Sphere):
                    builder.add_sphere_collision(_sp(s.pose), float(s.radius), material=mat)
                elif isinstance(s, Cylinder):
                    builder.add_cylinder_collision(
                        _sp(s.pose * _X_TO_Z), float(s.radius), float(s.half_length), material=mat
                    )
                elif isinstance(s, MeshShape):
                    for piece in _cookable_pieces(np.asarray(s.vertices, dtype=float)):
                        fd, fn = tempfile.mkstemp(suffix=".obj", prefix="bh_hull_")
                        os.close(fd)
                        tmp.append(fn)
                        piece.apply_scale(_COOK_UNITS)
                        piece.export(fn)
                        builder.add_convex_collision_from_file(
                            fn, _sp(s.pose), scale=(1.0 / _COOK_UNITS,) * 3, material=mat
                        )
                else:
                    raise BackendError(f"unknown shape {type(s).__name__}")
            builder.set_initial_pose(_sp(pose))
            h = self._new_handle()
            nm = name or f"body{h}"
            if fixed:
                ent = builder.build_static(name=nm)
                comp = ent.find_component_by_type(physx.PhysxRigidStaticComponent)
            else:
                builder.set_mass_and_inertia(
                    float(mass), _sp(mp.inertial_pose), [float(x) for x in mp.inertia_diag]
                )
                ent = builder.build(name=nm)
                comp = ent.find_component_by_type(physx.PhysxRigidDynamicComponent)
                comp.linear_damping = 0.0  # no artificial damping (PhysX defaults to 0.05 angular)
                comp.angular_damping = 0.0
        except BaseException:
            remove_files(tmp)
            raise
        return self._register(
            _Body(handle=h, name=nm, entity=ent, component=comp, fixed=fixed, temp_files=tmp)
        )

    def load_urdf(
        self,
        path: str | Path,
        base_pose: Pose,
        *,
        fixed_base: bool = True,
        name: str | None = None,
    ) -> BodyId:
        self._apply_global_config()
        model = parse_urdf(path)
        copy = collision_only_copy(path)
        loader = self._scene.create_urdf_loader()
        loader.fix_root_link = bool(fixed_base)
        f = float(self.config.default_friction)
        loader.set_material(f, f, 0.0)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                art = loader.load(copy, srdf_file="")
        except Exception as exc:
            raise BackendError(f"SAPIEN could not load {path}: {exc}") from exc
        finally:
            try:
                os.unlink(copy)
            except OSError:
                pass
        if art is None:
            raise BackendError(f"SAPIEN could not load {path}")
        h = self._new_handle()
        links = {l.name: l for l in art.links}
        active = [j.name for j in art.active_joints]
        joints = list(model.movable)
        perm = np.array([active.index(j.name) for j in joints], dtype=int)
        sjoints = [art.active_joints[i] for i in perm]
        for comp in art.links:
            comp.linear_damping = 0.0
            comp.angular_damping = 0.0
        for j in sjoints:  # the URDF's <dynamics> is not used; see set_joint_friction
            j.set_drive_property(0.0, 0.0, 0.0)
            j.set_friction(0.0)
        # filter links adjacent through fixed links; word 3 scopes the bits to this body
        cliques = model.filtered_link_pairs()
        for comp in art.links:
            for shape in comp.collision_shapes:
                g = list(shape.collision_groups)
                g[3] = h
                shape.set_collision_groups(g)
        for bit, clique in enumerate(cliques):
            if bit >= 32:
                warnings.warn(
                    f"{path}: more than 32 fixed-link collision filters; the rest are not applied",
                    stacklevel=2,
                )
                break
            for ln in clique:
                for shape in links[ln].collision_shapes:
                    g = list(shape.collision_groups)
                    g[2] |= 1 << bit
                    shape.set_collision_groups(g)
        b = _Body(
            handle=h,
            name=name or model.root_link,
            articulation=art,
            urdf=model,
            links=links,
            joints=joints,
            sjoints=sjoints,
            perm=perm,
            fixed=bool(fixed_base),
        )
        art.set_root_pose(_sp(base_pose))
        art.set_qpos(np.zeros(art.dof, dtype=np.float32))
        return self._register(b)

    def remove_body(self, body: BodyId) -> None:
        b = self._b(body)
        if self._held_contacts is None:
            self._held_contacts = self.contacts()
        self._held_contacts = [c for c in self._held_contacts if body not in (c.body_a, c.body_b)]
        for c, (_drive, pb_, cb_) in list(self._constraints.items()):
            if body in (pb_, cb_):
                self.detach(c)
        if b.articulation is not None:
            for comp in b.links.values():
                self._entity_map.pop(comp.entity.per_scene_id, None)
                self._component_map.pop(comp, None)
            self._scene.remove_articulation(b.articulation)
        else:
            self._entity_map.pop(b.entity.per_scene_id, None)
            self._component_map.pop(b.component, None)
            self._scene.remove_entity(b.entity)
        self._bodies.pop(body)
        self._roots = None
        self._grounds.pop(body, None)

    def get_pose(self, body: BodyId) -> Pose:
        b = self._b(body)
        return _bp(b.root.entity_pose)

    def set_pose(self, body: BodyId, pose: Pose) -> None:
        b = self._b(body)
        if b.articulation is not None:
            b.articulation.set_root_pose(_sp(pose))
        else:
            b.entity.set_pose(_sp(pose))
            if not b.fixed:
                b.component.wake_up()

    def get_velocity(self, body: BodyId) -> tuple[np.ndarray, np.ndarray]:
        b = self._b(body)
        if b.fixed and b.articulation is None:
            return np.zeros(3), np.zeros(3)
        r = b.root
        return np.asarray(r.linear_velocity, dtype=float), np.asarray(
            r.angular_velocity, dtype=float
        )

    def set_velocity(
        self,
        body: BodyId,
        linear: Sequence[float] | np.ndarray,
        angular: Sequence[float] | np.ndarray,
    ) -> None:
        b = self._b(body)
        lin = np.asarray(linear, dtype=np.float32)
        ang = np.asarray(angular, dtype=np.float32)
        if b.articulation is not None:
            b.articulation.set_root_linear_velocity(lin)
            b.articulation.set_root_angular_velocity(ang)
        elif not b.fixed:
            b.component.set_linear_velocity(lin)
            b.component.set_angular_velocity(ang)
            b.component.wake_up()

    def get_link_pose(self, body: BodyId, link: str | None) -> Pose:
        b = self._b(body)
        return _bp(self._link(b, link).entity_pose)

    def get_mass(self, body: BodyId) -> float:
        b = self._b(body)
        if b.urdf is not None:  # engines zero a fixed base's mass; report the description's
            return b.urdf.total_mass
        if b.fixed and b.articulation is None:
            return 0.0
        return float(sum(c.mass for c in b.components()))

    # -- joints ----------------------------------------------------------------
    def joint_info(self, body: BodyId) -> list[JointInfo]:
        return list(self._b(body).joints)

    def link_names(self, body: BodyId) -> list[str]:
        b = self._b(body)
        return list(b.urdf.links) if b.urdf else []

    def get_joint_state(self, body: BodyId) -> JointState:
        b = self._b(body)
        if b.articulation is None or not b.joints:
            z = np.zeros(0)
            return JointState(z, z.copy(), z.copy())
        art = b.articulation
        q = np.asarray(art.qpos, dtype=float)[b.perm]
        v = np.asarray(art.qvel, dtype=float)[b.perm]
        # PhysX does not report drive forces: evaluate the (capped) drive law at the current state
        return JointState(q, v, b.drive.efforts(q, v))

    def get_joint_motion(self, body: BodyId) -> tuple[np.ndarray, np.ndarray]:
        b = self._b(body)
        art = b.articulation
        if art is None or not b.joints:
            return np.zeros(0), np.zeros(0)
        m = b.motion
        if m is None or m[0] != self._steps:
            q = np.asarray(art.qpos, dtype=float)[b.perm]
            m = b.motion = (self._steps, q, np.asarray(art.qvel, dtype=float)[b.perm])
        return m[1].copy(), m[2].copy()

    def set_joint_positions(
        self, body: BodyId, positions: Sequence[float], joints: Sequence[str] | None = None
    ) -> None:
        b = self._b(body)
        sel = b.joint_indices(joints)
        pos = as_array(positions, len(sel), "positions")
        art = b.articulation
        q = np.asarray(art.qpos, dtype=np.float32).copy()
        v = np.asarray(art.qvel, dtype=np.float32).copy()
        for i, x in zip(sel, pos):
            q[b.perm[i]] = x
            v[b.perm[i]] = 0.0
        art.set_qpos(q)
        art.set_qvel(v)
        b.motion = None

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
        b.drive.set_targets(sel, cmd)
        q, v, k, d, f = cmd.q, cmd.v, cmd.k, cmd.d, cmd.f
        # PhysX keeps drive settings until changed: only changed values are sent (a held robot
        # re-sends the same targets every control tick, and each setter is a C++ call)
        props = b.drive_props
        idx = sel.tolist()
        for i, ki, di, fi in zip(idx, k.tolist(), d.tolist(), f.tolist()):
            prop = (ki, di, fi)
            if props.get(i) != prop:
                b.sjoints[i].set_drive_property(*prop, "force")
                props[i] = prop
        self._send_targets(b, idx, q.tolist(), v.tolist())

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
        idx = b.drive.retarget(sel, positions, velocities, stiffness, damping, force_limit)
        if idx is None:
            return False
        # the values just stored, as Python floats (what target_q[sel].tolist() gives back)
        self._send_targets(b, idx, [float(x) for x in positions], [float(x) for x in velocities])
        return True

    @staticmethod
    def _send_targets(b: _Body, sel: Sequence[int], q: list[float], v: list[float]) -> None:
        """Position and velocity targets to PhysX, only those that changed (each setter is a C++ call)."""
        targets = b.drive_targets
        for i, qi, vi in zip(sel, q, v):
            j = b.sjoints[i]
            last = targets.get(i)
            if last is None or last[0] != qi:
                j.set_drive_target(qi)
            if last is None or last[1] != vi:
                j.set_drive_velocity_target(vi)
            targets[i] = (qi, vi)

    def gravity_torques(self, body: BodyId) -> np.ndarray:
        """Gravity holding torques in our joint order.

        Fixed base: PhysX's generalized gravity force
        (``compute_passive_force(gravity=True)``). A free-floating
        articulation gets zeros from PhysX (gravity alone accelerates no
        joint of a falling body), so there the holding torques for a base
        held in place are summed from PhysX's own link masses, mass centres
        and joint frames: ``tau_j = -a_j . sum_i (c_i - o_j) x m_i g`` over the
        links ``i`` downstream of revolute joint ``j`` (prismatic:
        ``-a_j . sum_i m_i g``).
        """
        b = self._b(body)
        if b.articulation is None or not b.joints:
            return np.zeros(0)
        art = b.articulation
        if b.fixed:
            qf = art.compute_passive_force(gravity=True, coriolis_and_centrifugal=False)
            return np.asarray(qf, dtype=float)[b.perm]
        if b.gravity_tree is None:
            links = list(art.links)
            index = {id(l): k for k, l in enumerate(links)}
            parent = [-1] * len(links)
            for j in art.joints:
                if j.parent_link is not None:
                    parent[index[id(j.child_link)]] = index[id(j.parent_link)]
            down = np.zeros((len(b.sjoints), len(links)))
            for r, j in enumerate(b.sjoints):
                top = index[id(j.child_link)]
                for k in range(len(links)):
                    a = k
                    while a != -1 and a != top:
                        a = parent[a]
                    down[r, k] = a == top
            prism = np.array([j.type == "prismatic" for j in b.sjoints])
            b.gravity_tree = (links, down, prism, np.array([l.mass for l in links]))
        links, down, prism, mass = b.gravity_tree
        g = np.asarray(self.config.gravity, dtype=float)
        com = np.array([_bp(l.entity_pose * l.cmass_local_pose).p for l in links])
        frames = [_bp(j.get_global_pose()) for j in b.sjoints]
        axis = np.array(
            [f.rotation.as_matrix()[:, 0] for f in frames]
        )  # PhysX joints move along/about x
        origin = np.array([f.p for f in frames])
        m_down = down @ mass
        moment = down @ (mass[:, None] * com) - m_down[:, None] * origin
        tau = -np.einsum("ji,ji->j", axis, np.cross(moment, g))
        tau[prism] = -m_down[prism] * (axis[prism] @ g)
        return tau

    def set_joint_friction(
        self, body: BodyId, torques: float | Sequence[float], joints: Sequence[str] | None = None
    ) -> None:
        b = self._b(body)
        sel = b.joint_indices(joints)
        t = as_array(torques, len(sel), "torques")
        for i, tau in zip(sel, t):
            b.drive.friction[i] = float(tau)
            if not b.drive.driven[i]:
                j = b.sjoints[i]
                prop = (0.0, _FRICTION_DAMPING if tau > 0 else 0.0, float(tau))
                j.set_drive_property(*prop, "force")
                b.drive_props[int(i)] = prop
                j.set_drive_velocity_target(0.0)
                b.drive_targets.pop(int(i), None)

    # -- interaction -----------------------------------------------------------
    def contacts(self, body_a: BodyId | None = None, body_b: BodyId | None = None) -> list[Contact]:
        if body_a is not None:
            self._b(body_a)
        if body_b is not None:
            self._b(body_b)
        if self._held_contacts is not None:  # a body was removed since the last step
            out_held: list[Contact] = []
            for c in self._held_contacts:
                flip = contact_side(c.body_a, c.body_b, body_a, body_b)
                if flip is None:
                    continue
                out_held.append(
                    Contact(
                        c.body_b,
                        c.link_b,
                        c.body_a,
                        c.link_a,
                        c.position,
                        -c.normal,
                        c.normal_force,
                        c.distance,
                    )  # fmt: skip
                    if flip
                    else c
                )
            return out_held
        inv_dt = 1.0 / self.config.timestep
        out: list[Contact] = []
        cmap = self._component_map
        for c in self._system.get_contacts():
            c0, c1 = c.bodies
            e0 = cmap.get(c0) or self._entity_map.get(c0.entity.per_scene_id)
            e1 = cmap.get(c1) or self._entity_map.get(c1.entity.per_scene_id)
            if e0 is None or e1 is None:
                continue
            flip = contact_side(e0[0], e1[0], body_a, body_b)
            if flip is None:
                continue
            # PhysX: the normal points from the second body towards the first
            (ha, la), (hb, lb), sign = (e1, e0, -1.0) if flip else (e0, e1, 1.0)
            for p in c.points:
                n64 = np.asarray(p.normal, dtype=float)  # read once (each read makes a new array)
                nrm = sign * n64
                imp = np.asarray(p.impulse, dtype=float)
                # the float32 normal widened first, as np.dot widens it: the same product
                fn = abs(float(np.dot(imp, n64))) * inv_dt
                out.append(
                    Contact(
                        ha,
                        la,
                        hb,
                        lb,
                        np.asarray(p.position, dtype=float),
                        nrm,
                        fn,
                        float(p.separation),
                    )
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
        maxd = np.broadcast_to(np.asarray(max_distance, dtype=float), (n,))
        ignore = set(int(x) for x in ignore_bodies)
        ignore_link = set()  # (handle, link name or None), as _entity_map reports them
        for h, link in ignore_links:
            lb = self._b(int(h))
            self._link(lb, link)  # unknown links raise
            root = lb.urdf.root_link if lb.urdf is not None else None
            ignore_link.add((int(h), None if link == root else link))
        hit = np.zeros(n, dtype=bool)
        dist = np.full(n, np.inf)
        point = np.full((n, 3), np.nan)
        normal = np.full((n, 3), np.nan)
        body = np.full(n, -1, dtype=int)
        emap = self._entity_map
        for i in range(n):
            start = 0.0
            for _ in range(64):
                if start >= maxd[i]:
                    break
                org = o[i] + dvec[i] * start
                r = self._system.raycast(
                    org.astype(np.float32), dvec[i].astype(np.float32), float(maxd[i] - start)
                )
                if r is None:
                    break
                ent = emap.get(r.component.entity.per_scene_id)
                d_hit = start + float(r.distance)
                if ent is not None and (ent[0] in ignore or ent in ignore_link):
                    exit_d = _ray_exit(r.shape, _bp(r.component.entity_pose), org, dvec[i])
                    start = start + max(float(r.distance), exit_d) + 1e-6
                    continue
                hit[i] = True
                dist[i] = d_hit
                point[i] = np.asarray(r.position, dtype=float)
                normal[i] = np.asarray(r.normal, dtype=float)
                body[i] = ent[0] if ent is not None else -1
                break
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
        pb_, cb_ = self._b(parent), self._b(child)
        pcomp, ccomp = self._link(pb_, parent_link), self._link(cb_, child_link)
        drive = physx.PhysxDriveComponent(ccomp)
        drive.parent = pcomp
        drive.pose_in_parent = _sp(child_in_parent)
        drive.pose_in_child = sapien.Pose()
        for ax in ("x", "y", "z"):
            getattr(drive, f"set_drive_property_{ax}")(
                _ATTACH_STIFFNESS, _ATTACH_DAMPING, _ATTACH_MAX_FORCE
            )
        drive.set_drive_property_slerp(_ATTACH_STIFFNESS, _ATTACH_DAMPING, _ATTACH_MAX_FORCE)
        drive.set_drive_target(sapien.Pose())
        ccomp.entity.add_component(drive)
        h = self._next_constraint
        self._next_constraint += 1
        self._constraints[h] = (drive, parent, child)
        return h

    def detach(self, constraint: int) -> None:
        try:
            drive, _, _ = self._constraints.pop(constraint)
        except KeyError:
            raise BackendError(f"no attachment with handle {constraint}") from None
        body = drive.entity.find_component_by_type(physx.PhysxRigidBodyComponent)
        drive.entity.remove_component(drive)
        for comp in (body, drive.parent):
            if comp is not None and hasattr(comp, "wake_up"):
                comp.wake_up()

    def couple_joints(
        self, body: BodyId, follower: str, leader: str, multiplier: float = 1.0
    ) -> None:
        """A PhysX fixed tendon over the two joints, rooted at their common parent link.

        PhysX has no mimic joints; a fixed tendon's length is a weighted sum
        of joint positions and its spring pulls ``multiplier * q_leader -
        q_follower`` to zero inside the articulation solve (implicit, so the
        stiff coupling stays stable). The two joints must hang from one link.
        """
        b = self._b(body)
        fi, li = b.coupled_joints(follower, leader, multiplier)
        jf, jl = b.joints[fi], b.joints[li]
        if b.articulation is None or jf.parent_link != jl.parent_link:
            raise BackendError(
                f"cannot couple {follower!r} to {leader!r}: the joints must share a parent link"
            )
        m = float(multiplier)
        b.articulation.create_fixed_tendon(
            [b.links[jl.parent_link], b.links[jl.child_link], b.links[jf.child_link]],
            [0.0, m, -1.0],
            [0.0, 1.0 / m, -1.0],
            rest_length=0.0,
            stiffness=_COUPLING_STIFFNESS,
            damping=_COUPLING_DAMPING,
        )

    def check_finite(self, bodies: Sequence[BodyId]) -> None:
        for h in bodies:
            b = self._b(h)
            r = b.root
            arrs = [r.entity_pose.p, r.entity_pose.q]
            if not (b.fixed and b.articulation is None):
                arrs += [r.linear_velocity, r.angular_velocity]
            if b.articulation is not None:
                arrs += [b.articulation.qpos, b.articulation.qvel]
            if not all(np.all(np.isfinite(a)) for a in arrs):
                raise SimulationError(
                    f"body {b.name!r} (handle {h}) has a non-finite state (simulation blew up)"
                )


def _ray_exit(shape: Any, body_pose: Pose, origin: np.ndarray, direction: np.ndarray) -> float:
    """Distance along the ray at which it leaves ``shape`` (0 if it never enters)."""
    world = body_pose * _bp(shape.get_local_pose())
    inv = world.inv()
    o = inv.apply(origin)
    d = inv.rotation.apply(direction)
    big = 1.0e9
    if isinstance(shape, physx.PhysxCollisionShapeBox):
        h = np.asarray(shape.half_size, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = (-h - o) / d
            t2 = (h - o) / d
        t1 = np.where(np.abs(d) < 1e-12, np.where(np.abs(o) <= h, -big, big), t1)
        t2 = np.where(np.abs(d) < 1e-12, np.where(np.abs(o) <= h, big, -big), t2)
        return float(max(0.0, np.min(np.maximum(t1, t2))))
    if isinstance(shape, physx.PhysxCollisionShapeSphere):
        r = float(shape.radius)
        b = float(np.dot(o, d))
        c = float(np.dot(o, o)) - r * r
        disc = b * b - c
        return float(max(0.0, -b + math.sqrt(disc))) if disc > 0 else 0.0
    if isinstance(shape, (physx.PhysxCollisionShapeCylinder, physx.PhysxCollisionShapeCapsule)):
        r, hl = float(shape.radius), float(shape.half_length)
        if isinstance(shape, physx.PhysxCollisionShapeCapsule):
            hl += r
        # axis x: slab in x, circle in y-z
        tx = big if abs(d[0]) < 1e-12 else max((-hl - o[0]) / d[0], (hl - o[0]) / d[0])
        a = d[1] ** 2 + d[2] ** 2
        if a < 1e-12:
            tr = big
        else:
            b = o[1] * d[1] + o[2] * d[2]
            c = o[1] ** 2 + o[2] ** 2 - r * r
            disc = b * b - a * c
            tr = (-b + math.sqrt(disc)) / a if disc > 0 else 0.0
        return float(max(0.0, min(tx, tr)))
    if isinstance(shape, physx.PhysxCollisionShapeConvexMesh):
        v = np.asarray(shape.vertices, dtype=float) * np.asarray(shape.scale, dtype=float)
        from scipy.spatial import ConvexHull

        eq = ConvexHull(v).equations  # n.x + off <= 0 inside
        nd = eq[:, :3] @ d
        no = eq[:, :3] @ o + eq[:, 3]
        with np.errstate(divide="ignore"):
            t = np.where(nd > 1e-12, -no / nd, big)
        return float(max(0.0, np.min(t)))
    return 0.0
