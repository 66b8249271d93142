"""The physical cube: a rigid body between twists, three jointed slabs during one.

Everything physical goes through :class:`~benchharness.backends.Backend`; the
logical 54-facelet state is owned by the cube core and changed only from the
joint angles the engine *measured* when a twist ends. Nothing here reads a
gripper's commanded pose: whichever slabs the grippers actually hold, the
contact forces decide what turns (docs/cube_physics.md, "Model").

Life cycle::

    cube = PhysicalCube(backend, pose)        # rigid 57 mm / 94 g box
    cube.begin_twist("z", intended="U")       # swapped in place for 3 slabs
    ... grippers act; advance with backend.step(n) ...
    outcome = cube.end_twist()                # measured, snapped, state updated, rigid again

The articulated cube's joints carry one drive each (the engines give a joint
one drive): a spring toward the nearest multiple of 90° plus a damper, capped
at ``friction + detent torque``. Moving, the damper saturates at the cap, so
the joint shows Coulomb friction; at rest, the spring pulls a loose layer into
its detent with at most the cap. The target follows the joint across ±45°,
which is why the cube must be updated after every physics step while
articulated: it registers :meth:`update` as a step callback of the backend
(:meth:`~benchharness.backends.Backend.add_step_callback`) when it swaps to
the three slabs and removes it when it goes rigid again, so whoever steps the
world keeps the detents current.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from ..backends.interface import Backend, BodyId, Box
from ..cube.facelets import SOLVED, to_array, to_string
from ..cube.moves import apply as apply_moves
from ..cube.moves import reorient
from ..geometry import Pose
from .config import CubeConfig
from .layers import IntendedTwist, SnappedAngle, intended_twist, layer_moves, snap_angle
from .model import (
    FACE_BODY_AXES,
    FACELET_BODY_POSITIONS,
    JOINT_NAMES,
    PLASTIC_RGBA,
    axis_index,
    rigid_half_extents,
    rigid_inertia,
    slab_geometry,
    stickers,
    write_articulated_urdf,
)
from .outcome import TwistBlockedError, TwistOutcome

__all__ = ["PhysicalCube"]

_QUARTER = math.pi / 2.0


class PhysicalCube:
    """A Rubik's cube whose twists are decided by contact physics on any backend.

    The handle of the body in the world changes at every swap: read
    :attr:`body` after :meth:`begin_twist` / :meth:`end_twist`, and do not
    keep ``attach`` constraints to the cube across a swap (removing a body
    removes its constraints).
    """

    def __init__(
        self,
        backend: Backend,
        pose: Pose,
        config: CubeConfig | None = None,
        *,
        state: np.ndarray | str | None = None,
        linear_velocity: Sequence[float] = (0.0, 0.0, 0.0),
        angular_velocity: Sequence[float] = (0.0, 0.0, 0.0),
        name: str = "rubiks_cube",
    ) -> None:
        self.backend = backend
        self.config = config or CubeConfig()
        self.name = name
        if state is None:
            self._state = SOLVED.copy()
        else:
            arr = (
                to_array(state)
                if isinstance(state, str)
                else np.asarray(state, dtype=np.uint8).copy()
            )
            if arr.shape != (54,):
                raise ValueError(f"a cube state has 54 facelets, got shape {arr.shape}")
            self._state = arr
        self._axis: str | None = None
        self._intent: IntendedTwist | None = None
        self._misaligned = False
        self._targets = np.zeros(2, dtype=np.int64)  # detent targets, in quarter turns
        self._gains: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self.history: list[TwistOutcome] = []
        self._callback: int | None = None  #: step-callback handle while articulated
        self._body: BodyId = self._spawn_rigid(pose, linear_velocity, angular_velocity)

    # -- read-only views ------------------------------------------------------------
    @property
    def body(self) -> BodyId:
        """The cube's current body handle (changes at every swap)."""
        return self._body

    @property
    def articulated(self) -> bool:
        return self._axis is not None

    @property
    def twist_axis(self) -> str | None:
        """Body axis of the open twist or misaligned layer, ``None`` while rigid."""
        return self._axis

    @property
    def misaligned(self) -> bool:
        """The last :meth:`end_twist` left a layer beyond the snap tolerance."""
        return self._misaligned

    @property
    def state(self) -> np.ndarray:
        """The logical state (54 colour codes, URFDLB positions in the body frame); a copy."""
        return self._state.copy()

    @property
    def state_string(self) -> str:
        return to_string(self._state)

    def pose(self) -> Pose:
        """Pose of the body frame (the middle slab's while articulated)."""
        return self.backend.get_pose(self._body)

    def velocity(self) -> tuple[np.ndarray, np.ndarray]:
        return self.backend.get_velocity(self._body)

    def mass(self) -> float:
        return self.backend.get_mass(self._body)

    # -- face tracking ----------------------------------------------------------------
    def face_world_normal(self, face: str) -> np.ndarray:
        """World direction in which ``face`` (a letter of URFDLB) points now."""
        return self.pose().rotation.apply(FACE_BODY_AXES[face].astype(float))

    def face_along(self, direction: Sequence[float]) -> str:
        """The face whose outward normal is closest to the world ``direction``."""
        d = np.asarray(direction, dtype=float)
        rot = self.pose().rotation
        return max(
            FACE_BODY_AXES,
            key=lambda f: float(np.dot(rot.apply(FACE_BODY_AXES[f].astype(float)), d)),
        )

    def facelet_world_positions(self) -> np.ndarray:
        """World centre of each of the 54 facelets (index = state position), shape (54, 3).

        While articulated, each facelet moves with the slab it belongs to.
        """
        local = FACELET_BODY_POSITIONS * self.config.edge
        if self._axis is None:
            return self.pose().apply(local)
        a = axis_index(self._axis)
        out = np.empty_like(local)
        along = local[:, a]
        slab_of = (
            np.where(np.abs(along) > 0.75 * self.config.slab_thickness, np.sign(along), 0).astype(
                int
            )
            + 1
        )
        for slab in slab_geometry(self.config, self._axis):
            sel = slab_of == slab.index
            link_pose = self.backend.get_link_pose(self._body, slab.link)
            out[sel] = link_pose.apply(local[sel] - slab.centre)
        return out

    def axis_along(self, direction: Sequence[float]) -> str:
        """The body axis (x, y, z) most nearly parallel to a world direction, e.g. a wrist's axis."""
        local = self.pose().rotation.inv().apply(np.asarray(direction, dtype=float))
        return "xyz"[int(np.argmax(np.abs(local)))]

    def layer_of(self, world_point: Sequence[float], axis: str) -> int:
        """Which slab (0, 1, 2 from -axis to +axis) a world point lies in, e.g. a contact."""
        p = self.pose().inv().apply(np.asarray(world_point, dtype=float))
        t = self.config.slab_thickness
        return int(np.clip(np.floor(p[axis_index(axis)] / t + 1.5), 0, 2))

    # -- twists -------------------------------------------------------------------------
    def block_reason(self, axis: str) -> str | None:
        """Why a twist about ``axis`` cannot start now, or ``None`` if it can."""
        axis_index(axis)
        if self._axis is None or self._axis == axis:
            return None
        return str(TwistBlockedError(axis, self._axis, self.layer_angles_deg(), self._misaligned))

    def begin_twist(self, axis: str, intended: str | None = None) -> None:
        """Make the cube twistable about body ``axis``: swap in the three slabs, in place.

        ``intended`` (one face or slice move, e.g. ``"U'"``) is recorded for the
        outcome and breaks the equal-friction tie of an under-constrained grasp
        (``CubeConfig.drag_bias``); it never moves anything itself. Calling it
        again about the same axis (e.g. to work a misaligned layer back) keeps
        the articulated body. About another axis while articulated it raises
        :class:`TwistBlockedError`.
        """
        axis_index(axis)
        intent = intended_twist(intended) if intended is not None else None
        if intent is not None and intent.axis != axis:
            raise ValueError(f"move {intent.move} turns about body axis {intent.axis}, not {axis}")
        if self._axis is not None and self._axis != axis:
            raise TwistBlockedError(axis, self._axis, self.layer_angles_deg(), self._misaligned)
        self._intent = intent
        if self._axis is None:
            self._swap_to_articulated(axis)
        self._configure_joints()

    def layer_angles_deg(self) -> tuple[float, float]:
        """Measured angles of slab 0 and slab 2 relative to the middle slab (deg)."""
        if self._axis is None:
            return (0.0, 0.0)
        q = self.backend.get_joint_state(self._body).positions
        return (math.degrees(float(q[0])), math.degrees(float(q[1])))

    def update(self) -> None:
        """Move each detent's target to the multiple of 90° nearest its joint.

        The backend calls it after every physics step while the cube is
        articulated (a step callback); calling it yourself is harmless.
        """
        if self._axis is None:
            return
        q = self.backend.get_joint_motion(self._body)[0]  # positions only (no drive efforts)
        k = np.rint(np.asarray(q, dtype=float) / _QUARTER).astype(np.int64)
        if not np.array_equal(k, self._targets):
            self._targets = k
            self._apply_detent()

    def end_twist(self) -> TwistOutcome:
        """Read the layers, snap them, update the logical state and go rigid again.

        A layer beyond the snap tolerance leaves the cube articulated and
        flagged misaligned (state unchanged); call again after working it back.
        """
        if self._axis is None:
            raise RuntimeError("end_twist() without begin_twist(): the cube is rigid")
        axis = self._axis
        a0, a2 = self.layer_angles_deg()
        s0 = snap_angle(a0, self.config.snap_tolerance_deg)
        s2 = snap_angle(a2, self.config.snap_tolerance_deg)
        before = self._state.copy()
        aligned = s0.within and s2.within
        moves = ""
        if aligned:
            moves = layer_moves(axis, s0.quarter_turns, s2.quarter_turns)
            after = apply_moves(self._state, moves) if moves else self._state
            self._snap_and_swap_to_rigid(axis, s0, s2, after)  # the rigid cube shows ``after``
            self._state = after
        self._misaligned = not aligned
        outcome = self._outcome(axis, (a0, a2), (s0, s2), moves, aligned, before)
        self.history.append(outcome)
        return outcome

    def remove(self) -> None:
        """Take the cube out of the world."""
        self._stop_updates()
        self.backend.remove_body(self._body)
        self._axis = None

    # -- internals ------------------------------------------------------------------------
    def _rendered(self) -> bool:
        """Whether to give the bodies sticker visuals (only a backend with a camera draws them)."""
        return bool(self.backend.capabilities.camera)

    def _spawn_rigid(
        self,
        pose: Pose,
        lin: Sequence[float] | np.ndarray,
        ang: Sequence[float] | np.ndarray,
        state: np.ndarray | None = None,
    ) -> BodyId:
        c = self.config
        shown = self._state if state is None else state
        visuals = (
            [Box(st.half_extents, Pose(st.centre), rgba=st.rgba) for st in stickers(c, shown)]
            if self._rendered()
            else []
        )
        body = self.backend.add_body(
            [Box(rigid_half_extents(c), rgba=PLASTIC_RGBA if visuals else None)],
            pose,
            c.mass,
            friction=c.surface_friction,
            name=self.name,
            com=(0.0, 0.0, 0.0),
            inertia_diag=tuple(rigid_inertia(c)),
            visuals=visuals,
        )
        self.backend.set_velocity(body, lin, ang)
        return body

    def _swap_to_articulated(self, axis: str) -> None:
        b = self.backend
        pose = b.get_pose(self._body)
        lin, ang = b.get_velocity(self._body)
        path = write_articulated_urdf(
            self.config, axis, state=self._state if self._rendered() else None
        )
        try:
            b.remove_body(self._body)
            self._body = b.load_urdf(path, pose, fixed_base=False, name=self.name)
        finally:
            os.unlink(path)
        b.set_pose(self._body, pose)
        b.set_velocity(self._body, lin, ang)
        self._axis = axis
        self._targets = np.zeros(2, dtype=np.int64)
        if self._callback is None:
            self._callback = b.add_step_callback(self.update)

    def _stop_updates(self) -> None:
        if self._callback is not None:
            self.backend.remove_step_callback(self._callback)
            self._callback = None

    def _configure_joints(self) -> None:
        c = self.config
        turning = self._intent.turning if self._intent is not None else None
        frictions = c.joint_frictions(turning if turning in (0, 2) else None)
        # Friction through the interface's own call; with a detent it is folded
        # into the joint's one drive (a position target overrides it otherwise).
        self.backend.set_joint_friction(self._body, list(frictions), joints=list(JOINT_NAMES))
        if c.detent_torque > 0.0:
            gains = [c.drive_gains(f) for f in frictions]
            self._gains = (
                np.array([g[0] for g in gains]),
                np.array([g[1] for g in gains]),
                np.array([c.drive_cap(f) for f in frictions]),
            )
            q = self.backend.get_joint_state(self._body).positions
            self._targets = np.rint(np.asarray(q, dtype=float) / _QUARTER).astype(np.int64)
            self._apply_detent()
        else:
            self._gains = None

    def _apply_detent(self) -> None:
        if self._gains is None:
            return
        k, d, cap = self._gains
        self.backend.set_joint_targets(
            self._body,
            positions=(self._targets * _QUARTER).tolist(),
            velocities=[0.0, 0.0],
            joints=list(JOINT_NAMES),
            stiffness=k.tolist(),
            damping=d.tolist(),
            force_limit=cap.tolist(),
        )

    def _snap_and_swap_to_rigid(
        self, axis: str, s0: SnappedAngle, s2: SnappedAngle, state: np.ndarray
    ) -> None:
        b = self.backend
        # Turn the whole set by the mean residual so no slab jumps more than needed:
        # the three slabs sit at 0, a0, a2 and end at phi, phi + 90 k0, phi + 90 k2.
        phi = math.radians((s0.residual_deg + s2.residual_deg) / 3.0)
        unit = np.zeros(3)
        unit[axis_index(axis)] = 1.0
        pose = b.get_pose(self._body)
        lin, ang = b.get_velocity(self._body)
        snapped = pose * Pose(np.zeros(3), Rotation.from_rotvec(phi * unit).as_quat())
        b.set_joint_positions(
            self._body,
            [math.radians(s0.snapped_deg), math.radians(s2.snapped_deg)],
            list(JOINT_NAMES),
        )
        b.set_pose(self._body, snapped)
        self._stop_updates()
        b.remove_body(self._body)
        self._body = self._spawn_rigid(snapped, lin, ang, state)
        self._axis = None
        self._gains = None

    def _outcome(
        self,
        axis: str,
        angles: tuple[float, float],
        snaps: tuple[SnappedAngle, SnappedAngle],
        moves: str,
        aligned: bool,
        before: np.ndarray,
    ) -> TwistOutcome:
        a0, a2 = angles
        layer = (a0, 0.0, a2)
        tol = self.config.snap_tolerance_deg
        intent = self._intent
        turned = dragged = None
        unintended = jammed = as_intended = None
        if intent is not None:
            turn = layer[intent.turning] - layer[intent.reference]
            turned = (
                abs(turn)
                if abs(intent.angle_deg) == 180.0
                else math.copysign(1.0, intent.angle_deg) * turn
            )
            if intent.turning == 1:  # a slice: the two outer layers must stay together
                dragged = a2 - a0
            else:  # a face: the middle must stay with the held outer layer
                dragged = -layer[intent.reference]
            unintended = abs(dragged) > tol
            jammed = turned < self.config.jam_threshold_deg
            if aligned:
                expected = reorient(apply_moves(before, intent.move))
                as_intended = bool(np.array_equal(reorient(self._state), expected))
            else:
                as_intended = False
        if aligned:
            self._intent = None
        return TwistOutcome(
            axis=axis,
            intended=intent.move if intent is not None else None,
            layer_angles_deg=layer,
            quarter_turns=(snaps[0].quarter_turns, 0, snaps[1].quarter_turns),
            residuals_deg=(snaps[0].residual_deg, 0.0, snaps[1].residual_deg),
            moves=moves,
            state_updated=aligned and bool(moves),
            misaligned=not aligned,
            turned_deg=turned,
            dragged_deg=dragged,
            unintended_rotation=unintended,
            jammed=jammed,
            as_intended=as_intended,
            state_before=before,
            state_after=self._state.copy(),
        )
