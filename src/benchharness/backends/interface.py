"""The Backend interface: everything above ``backends/`` talks to physics through it.

Only modules in ``benchharness.backends`` import ``pybullet`` or ``sapien``.
Robots, sensors, strategies and the cube mechanism use this interface alone,
so each of them runs on every backend, and a new engine is added by one
class that passes ``tests/backends/test_conformance.py``.

Conventions (see :mod:`benchharness.geometry`): SI units; poses are
:class:`~benchharness.geometry.Pose` with scalar-last quaternions; joint
vectors follow :meth:`Backend.joint_names` order (movable joints only); a
body is an integer handle; a link is named by its URDF name, ``None`` for a
body's base.

Contact normals point from body B towards body A (the direction of the force
that B exerts on A), so for a box A resting on ground B the normal is +z and
the normal force is about the box's weight.
"""

from __future__ import annotations

import abc
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from ..geometry import Pose

__all__ = [
    "Backend",
    "BackendError",
    "BodyId",
    "Box",
    "CameraSpec",
    "Capabilities",
    "CapabilityError",
    "Contact",
    "Cylinder",
    "JointInfo",
    "JointState",
    "MeshShape",
    "PhysicsConfig",
    "RayHits",
    "Rgba",
    "Shape",
    "SimulationError",
    "Sphere",
    "StepCallback",
]

BodyId = int

#: Called with no arguments after each physics step (see :meth:`Backend.add_step_callback`).
StepCallback = Callable[[], None]


class BackendError(RuntimeError):
    """A backend could not do what was asked (bad handle, unknown joint, ...)."""


class CapabilityError(BackendError):
    """The backend lacks a capability (see :class:`Capabilities`)."""


class SimulationError(BackendError):
    """The simulation blew up (non-finite state); ends one trial, never a sweep."""


@dataclass(frozen=True)
class Capabilities:
    """What a backend can do. Callers check these instead of catching errors.

    Only optional methods get a flag; everything else in the interface
    (convex meshes, joint friction, ...) every backend must provide.
    """

    camera: bool = False  #: :meth:`Backend.render` returns images (read by ``run --video``)
    #: :meth:`Backend.gravity_torques` is the engine's own inverse dynamics (read by ``Robot``)
    gravity_torques: bool = False
    #: :meth:`Backend.couple_joints` ties two joints of a body (a hand's ``<mimic>``; read by ``Robot``)
    joint_coupling: bool = False


@dataclass(frozen=True)
class PhysicsConfig:
    """Engine-independent simulation settings.

    Defaults are the ones the cube spike (docs/benchmarks/cube_spike.md) found
    to work for a 5.7 cm cube held by parallel grippers on both engines.
    """

    timestep: float = 1.0 / 240.0  #: seconds per :meth:`Backend.step`
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    #: Solver (position) iterations per step; ``None`` = the engine's validated
    #: default (:attr:`Backend.default_solver_iterations`: PyBullet 50, which it
    #: needs at 1/240 s for accurate twists; SAPIEN/PhysX TGS 20).
    solver_iterations: int | None = None
    solver_velocity_iterations: int = 1
    contact_offset: float = (
        0.002  #: SAPIEN/PhysX contact offset (m); 1 cm default is too large here
    )
    default_friction: float = 1.0
    #: PyBullet only: torsional friction arm (m) of every contact, as Bullet's ``spinningFriction``
    #: (a pair gets this times the pair's friction coefficient). Bullet's point contacts have next to no
    #: torsional friction once sliding, so a pinched cube turns about the pinch axis like a hinge; a real
    #: pad's pressure patch resists with mu N r_mean (r_mean = 11 mm for the PR2's 35 x 22 mm pad, 7.7 mm
    #: for a 20 mm square). Measured, 20 mm pads, 2 x 20 N, friction 1 (analytic 0.31 N m): PyBullet 0.001
    #: N m without this, 0.40 N m with 0.01 m; PhysX 0.57 N m (its patch friction acts at the patch corners
    #: and needs no correction). See docs/backends.md. 0 = Bullet's own behaviour.
    torsional_friction: float = 0.01
    seed: int = 0  #: seeds any randomness a backend itself uses

    def __post_init__(self) -> None:
        """Refuse settings no engine can simulate, here so the Python API is guarded too.

        A zero timestep divides by zero in the stepping loop, a negative one
        runs simulated time backwards, NaN poisons every pose, and zero solver
        iterations or negative friction are not physics. ``ValueError`` names
        the field and the value (``--physics`` prints it as is).
        """
        import math
        from numbers import Integral, Real

        def real(name: str, value: object, *, positive: bool) -> None:
            ok = isinstance(value, Real) and not isinstance(value, bool)
            if ok:
                x = float(value)  # type: ignore[arg-type]
                ok = math.isfinite(x) and (x > 0 if positive else x >= 0)
            if not ok:
                kind = "a positive" if positive else "a non-negative"
                raise ValueError(f"{name}={value!r}: must be {kind} finite number")

        real("timestep", self.timestep, positive=True)
        real("contact_offset", self.contact_offset, positive=True)
        real("default_friction", self.default_friction, positive=False)
        real("torsional_friction", self.torsional_friction, positive=False)
        g = tuple(self.gravity)
        if len(g) != 3 or not all(
            isinstance(v, Real) and not isinstance(v, bool) and math.isfinite(v) for v in g
        ):
            raise ValueError(f"gravity={self.gravity!r}: must be three finite numbers")
        it = self.solver_iterations
        if it is not None and (isinstance(it, bool) or not isinstance(it, Integral) or it < 1):
            raise ValueError(f"solver_iterations={it!r}: must be an integer >= 1 (or None)")
        vit = self.solver_velocity_iterations
        if isinstance(vit, bool) or not isinstance(vit, Integral) or vit < 0:
            raise ValueError(f"solver_velocity_iterations={vit!r}: must be an integer >= 0")
        if isinstance(self.seed, bool) or not isinstance(self.seed, Integral) or self.seed < 0:
            raise ValueError(f"seed={self.seed!r}: must be an integer >= 0")


#: A render colour: red, green, blue, alpha in 0..1.
Rgba = tuple[float, float, float, float]


@dataclass(frozen=True)
class Box:
    half_extents: tuple[float, float, float]
    pose: Pose = field(default_factory=Pose)  #: shape pose in the body frame
    #: colour in rendered images (``None``: the backend's default grey); physics ignores it
    rgba: Rgba | None = None


@dataclass(frozen=True)
class Sphere:
    radius: float
    pose: Pose = field(default_factory=Pose)
    rgba: Rgba | None = None  #: as :attr:`Box.rgba`


@dataclass(frozen=True)
class Cylinder:
    """A cylinder whose axis is the local z axis."""

    radius: float
    half_length: float
    pose: Pose = field(default_factory=Pose)
    rgba: Rgba | None = None  #: as :attr:`Box.rgba`


@dataclass(frozen=True)
class MeshShape:
    """A convex collision mesh (the convex hull of the vertices is used)."""

    vertices: np.ndarray
    faces: np.ndarray
    pose: Pose = field(default_factory=Pose)
    rgba: Rgba | None = None  #: as :attr:`Box.rgba`


Shape = Box | Sphere | Cylinder | MeshShape


@dataclass(frozen=True)
class JointInfo:
    name: str
    type: str  #: "revolute", "prismatic" or "continuous"
    lower: float
    upper: float
    max_velocity: float
    max_effort: float
    parent_link: str
    child_link: str


@dataclass(frozen=True)
class JointState:
    positions: np.ndarray
    velocities: np.ndarray
    efforts: np.ndarray  #: applied joint torques/forces from the last step where available


@dataclass(frozen=True)
class Contact:
    body_a: BodyId
    link_a: str | None
    body_b: BodyId
    link_b: str | None
    position: np.ndarray  #: world contact point (m)
    normal: np.ndarray  #: unit normal, from B towards A
    normal_force: float  #: N, >= 0
    distance: float  #: signed separation (m), negative when penetrating


@dataclass(frozen=True)
class RayHits:
    """Results of a batch of ray casts, one row per ray."""

    hit: np.ndarray  #: (n,) bool
    distance: np.ndarray  #: (n,) metres; ``inf`` where nothing was hit
    point: np.ndarray  #: (n, 3) world hit points; NaN where nothing was hit
    normal: np.ndarray  #: (n, 3) surface normals; NaN where nothing was hit
    body: np.ndarray  #: (n,) hit body handle; -1 where nothing was hit


@dataclass(frozen=True)
class CameraSpec:
    """A pinhole camera looking from ``eye`` to ``target``."""

    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    width: int = 320
    height: int = 240
    fov_deg: float = 60.0
    near: float = 0.01
    far: float = 5.0


class Backend(abc.ABC):
    """One physics world. Create through the plugin manager: ``create("backend", name)``."""

    name: ClassVar[str]
    capabilities: ClassVar[Capabilities]
    default_solver_iterations: ClassVar[int] = 50

    def __init__(self, config: PhysicsConfig | None = None) -> None:
        self.config = config or PhysicsConfig()
        self._step_callbacks: dict[int, StepCallback] = {}  # handle -> fn, in registration order
        self._next_step_callback = 1
        self._in_step_callback = False
        #: bodies added from now on carry what :meth:`render` draws beyond their collision shapes
        #: (colours, render-only shapes); see :meth:`set_visuals`
        self.draws_visuals = True

    @property
    def solver_iterations(self) -> int:
        """The solver iterations in force: the config's, or this engine's default."""
        n = self.config.solver_iterations
        return self.default_solver_iterations if n is None else int(n)

    def set_visuals(self, enabled: bool) -> None:
        """Whether bodies added from now on carry drawn geometry (colours, render-only shapes).

        Never changes physics: collision shapes, masses and contacts are the
        same either way. The runner turns it off for every trial that is not
        filmed, because building a coloured mesh is CPU spent for no one
        (PyBullet: trimesh's import and ~0.1 s a stickered cube, measured). A
        backend without a renderer may ignore it.
        """
        self.draws_visuals = bool(enabled)

    # -- lifetime ------------------------------------------------------------
    @abc.abstractmethod
    def close(self) -> None:
        """Release the engine's resources. Safe to call twice."""

    def __enter__(self) -> Backend:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- time ----------------------------------------------------------------
    @property
    @abc.abstractmethod
    def time(self) -> float:
        """Simulated seconds since the world was created."""

    def step(self, n: int = 1) -> None:
        """Advance ``n`` timesteps. Raises :class:`SimulationError` on a blow-up.

        Each physics step runs the engine's step, then every registered step
        callback in registration order (as dm_control's composer runs its
        ``after_substep`` hooks), so a callback sees every intermediate state
        however the caller batches its steps. An exception raised by a
        callback (or a blow-up) propagates at once: the remaining steps of
        this call are not taken.
        """
        if self._in_step_callback:
            raise BackendError("a step callback may not step the world")
        self._step_engine(int(n), self._run_step_callbacks if self._step_callbacks else None)

    def _run_step_callbacks(self) -> None:
        # a snapshot: a callback added or removed by a callback counts from the next step
        callbacks = tuple(self._step_callbacks.values())
        self._in_step_callback = True
        try:
            for fn in callbacks:
                fn()
        finally:
            self._in_step_callback = False

    @abc.abstractmethod
    def _step_engine(self, n: int, after_step: StepCallback | None) -> None:
        """Advance the engine ``n`` physics steps, calling ``after_step()`` after each.

        The one method an engine implements for time; :meth:`step` calls it
        (``after_step`` runs the step callbacks, ``None`` when there are
        none). ``after_step`` runs after the step's own per-step blow-up
        checks; it may add, remove or drive bodies, which the engine must
        honour from the next physics step.
        """

    def add_step_callback(self, fn: StepCallback) -> int:
        """Call ``fn()`` after every physics step from now on; returns a handle for removal.

        Callbacks run in registration order, after the engine's step and its
        blow-up check; they may read and command the world (poses, contacts,
        joint targets, rendering) but not step it. This is how the runner
        watches budgets and first contact, and how the physical cube keeps
        its detents current while articulated.
        """
        if not callable(fn):
            raise BackendError(f"a step callback must be callable, got {type(fn).__name__}")
        h = self._next_step_callback
        self._next_step_callback += 1
        self._step_callbacks[h] = fn
        return h

    def remove_step_callback(self, handle: int) -> None:
        """Stop calling the callback registered as ``handle`` (an unknown handle raises)."""
        try:
            del self._step_callbacks[handle]
        except KeyError:
            raise BackendError(f"no step callback with handle {handle}") from None

    @abc.abstractmethod
    def pair_friction(self, a: float, b: float) -> float:
        """The Coulomb coefficient this engine gives a contact between bodies of friction ``a`` and ``b``.

        Engines combine the two bodies' coefficients differently (docs/backends.md, "Friction
        combination"): Bullet multiplies them, PhysX averages them. URDF links get
        :attr:`PhysicsConfig.default_friction`, a body its ``friction`` (or the default).
        """

    # -- bodies --------------------------------------------------------------
    @abc.abstractmethod
    def add_ground(self, height: float = 0.0, friction: float | None = None) -> BodyId:
        """A static infinite plane (or a large static slab) with its top at ``height``."""

    @abc.abstractmethod
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
        """A rigid body made of one or more primitive shapes.

        Mass is spread uniformly by volume unless ``com`` / ``inertia_diag``
        (principal moments about the COM, in the body frame) are given.

        ``visuals`` are render-only shapes moving with the body (e.g. a
        Rubik's cube's stickers): they have no mass, never collide and rays
        pass through them; a backend with a camera draws them (and each
        shape, collision or visual, in its ``rgba``), one without ignores
        them. The physics of a body is the same with or without them.
        """

    @abc.abstractmethod
    def load_urdf(
        self,
        path: str | Path,
        base_pose: Pose,
        *,
        fixed_base: bool = True,
        name: str | None = None,
    ) -> BodyId:
        """An articulated body from a URDF: its ``<collision>`` elements are the physics.

        ``<visual>`` elements (primitive geometry with an inline
        ``<material><color rgba=.../></material>``) are render-only, as
        :meth:`add_body`'s ``visuals``: a backend with a camera draws them,
        one without ignores them; a link without ``<visual>`` is drawn as its
        collision geometry.
        """

    @abc.abstractmethod
    def remove_body(self, body: BodyId) -> None:
        """Remove a body; its handle becomes invalid (used to swap cube models in place)."""

    @abc.abstractmethod
    def get_pose(self, body: BodyId) -> Pose:
        """The base (root link) pose of a body in the world."""

    @abc.abstractmethod
    def set_pose(self, body: BodyId, pose: Pose) -> None:
        """Teleport a body's base; velocities are kept."""

    @abc.abstractmethod
    def get_velocity(self, body: BodyId) -> tuple[np.ndarray, np.ndarray]:
        """Linear (m/s) and angular (rad/s) velocity of the base, in the world frame."""

    @abc.abstractmethod
    def set_velocity(
        self,
        body: BodyId,
        linear: Sequence[float] | np.ndarray,
        angular: Sequence[float] | np.ndarray,
    ) -> None:
        """Set the base's linear (of its centre of mass) and angular velocity, world frame."""

    @abc.abstractmethod
    def get_link_pose(self, body: BodyId, link: str | None) -> Pose:
        """World pose of a link frame (the URDF link frame, not its COM)."""

    @abc.abstractmethod
    def get_mass(self, body: BodyId) -> float:
        """Total mass of a body (all links), kg."""

    # -- joints --------------------------------------------------------------
    @abc.abstractmethod
    def joint_info(self, body: BodyId) -> list[JointInfo]:
        """Movable joints of an articulated body, in a fixed order."""

    def joint_names(self, body: BodyId) -> list[str]:
        return [j.name for j in self.joint_info(body)]

    @abc.abstractmethod
    def link_names(self, body: BodyId) -> list[str]: ...

    @abc.abstractmethod
    def get_joint_state(self, body: BodyId) -> JointState: ...

    def get_joint_motion(self, body: BodyId) -> tuple[np.ndarray, np.ndarray]:
        """``(positions, velocities)`` of :meth:`get_joint_state`, without the efforts.

        Controllers read joint positions and velocities several times a physics
        step; an engine that must compute efforts (PhysX reports none) can
        skip that here. Fresh arrays each call, like :meth:`get_joint_state`.
        """
        st = self.get_joint_state(body)
        return st.positions, st.velocities

    @abc.abstractmethod
    def set_joint_positions(
        self, body: BodyId, positions: Sequence[float], joints: Sequence[str] | None = None
    ) -> None:
        """Teleport joints (zero velocity); for resets, not for control."""

    @abc.abstractmethod
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
        """Drive joints with a PD law ``tau = k (q* - q) + d (qd* - qd)``, capped at ``force_limit``.

        ``stiffness``/``damping`` are physical gains (N·m/rad, N·m·s/rad) with
        the same meaning on every backend; ``force_limit`` defaults to the
        URDF effort limit. Targets persist until changed.
        """

    def retarget_joints(
        self,
        body: BodyId,
        positions: Sequence[float],
        velocities: Sequence[float],
        *,
        joints: Sequence[str],
        stiffness: Sequence[float],
        damping: Sequence[float],
        force_limit: Sequence[float],
    ) -> None:
        """:meth:`set_joint_targets` for a controller that re-aims the same joints every physics step.

        Same arguments and the same effect (one value per joint, no
        defaults). Why a second call: a fingertip linkage is re-aimed after
        every physics step while a finger moves (~78,000 calls in a Rubiks-1-5
        trial), and normalising the arguments cost more than the engine's
        setters. A backend may therefore send only the targets when the
        joints are already driven with exactly these gains and caps
        (:meth:`_retarget_driven`); otherwise this is :meth:`set_joint_targets`.
        """
        if not self._retarget_driven(
            body, positions, velocities, joints, stiffness, damping, force_limit
        ):
            self.set_joint_targets(
                body,
                positions,
                velocities,
                joints=joints,
                stiffness=stiffness,
                damping=damping,
                force_limit=force_limit,
            )

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
        """Engine hook of :meth:`retarget_joints`: set only the targets if the joints are driven with
        exactly these gains and caps, and say so (False: nothing done, the full call follows)."""
        return False

    def gravity_torques(self, body: BodyId) -> np.ndarray:
        """Joint torques/forces (:meth:`joint_names` order) that hold the body still against gravity.

        The inverse dynamics of the current configuration with zero joint
        velocities and accelerations and the base held where it is (for a
        free base: zero base acceleration), from the engine's own masses and
        inertial frames, with gravity in the world frame whatever the base's
        orientation: ``tau = G(q)``, positive in each joint's positive
        direction, i.e. the torque a drive must add to hold the pose. Only
        the body's own links count (not attached or touching bodies).

        Why in the interface: a robot feeds ``G(q)`` forward every control
        tick; the engines compute it in microseconds, a Python model of the
        URDF takes milliseconds. Backends without it raise
        :class:`CapabilityError` (``capabilities.gravity_torques`` is False)
        and callers use :class:`benchharness.robots.gravity.GravityModel`.
        """
        raise CapabilityError(f"backend {self.name!r} cannot compute gravity torques")

    @abc.abstractmethod
    def set_joint_friction(
        self, body: BodyId, torques: float | Sequence[float], joints: Sequence[str] | None = None
    ) -> None:
        """A constant Coulomb friction torque (N·m) at passive joints.

        Both engines model it as a velocity drive with target 0 capped at the
        torque; a joint that also has a position target keeps that target.
        """

    # -- interaction -------------------------------------------------------------
    @abc.abstractmethod
    def contacts(self, body_a: BodyId | None = None, body_b: BodyId | None = None) -> list[Contact]:
        """Contact points after the last step, optionally filtered to bodies A and B.

        With ``body_a`` given, every contact returned has that body as A (the
        pair is flipped, normal negated, when the engine reports it as B).
        Between a body's removal and the next step: the last step's contacts
        without the removed body's.
        """

    @abc.abstractmethod
    def ray_cast(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        max_distance: float | np.ndarray,
        *,
        ignore_bodies: Sequence[BodyId] = (),
        ignore_links: Sequence[tuple[BodyId, str | None]] = (),
    ) -> RayHits:
        """Batched ray casts (origins, unit directions: (n, 3)) against all bodies.

        Rays pass through every body in ``ignore_bodies`` and through the
        links named in ``ignore_links`` as ``(body, link)`` pairs (``None`` or
        the root link's name for the base), e.g. a robot's own fingertip
        carrying a time-of-flight sensor, while the rest of the robot still
        blocks the ray.
        """

    @abc.abstractmethod
    def attach(
        self,
        parent: BodyId,
        parent_link: str | None,
        child: BodyId,
        child_link: str | None,
        child_in_parent: Pose,
    ) -> int:
        """A fixed constraint holding ``child`` at ``child_in_parent``; returns its handle."""

    @abc.abstractmethod
    def detach(self, constraint: int) -> None: ...

    def couple_joints(
        self, body: BodyId, follower: str, leader: str, multiplier: float = 1.0
    ) -> None:
        """Tie two one-degree-of-freedom joints of ``body``: ``q_follower = multiplier * q_leader``.

        A mechanism's coupling (a URDF ``<mimic>``) as an engine constraint
        that lasts as long as the body: forces on either joint act on both,
        and each joint's own drive still applies. Backends without it
        (``capabilities.joint_coupling`` False) raise :class:`CapabilityError`.
        """
        raise CapabilityError(f"{type(self).__name__} cannot couple joints (joint_coupling)")

    def render(self, camera: CameraSpec) -> np.ndarray:
        """An RGB image (height, width, 3) uint8. Backends without a renderer raise."""
        raise CapabilityError(f"backend {self.name!r} cannot render images")

    def check_finite(self, bodies: Sequence[BodyId]) -> None:
        """Raise :class:`SimulationError` if any of the bodies' states is not finite."""
        for b in bodies:
            pose = self.get_pose(b)
            lin, ang = self.get_velocity(b)
            if not (
                np.all(np.isfinite(pose.p))
                and np.all(np.isfinite(pose.q))
                and np.all(np.isfinite(lin))
                and np.all(np.isfinite(ang))
            ):
                raise SimulationError(f"body {b} has a non-finite state (simulation blew up)")
