"""The bookkeeping both backends share: the body table, each body's record and its drive state.

Both engines must read ``set_joint_targets`` arguments identically (per-joint
broadcasting, URDF effort limits as the default cap, a pure velocity drive
when only velocities are given), resolve joint names with the same errors,
hand out handles the same way (never reused) and remember the same drive
settings, so all of that lives here once. Each backend subclasses
:class:`BodyRecord` with its engine's own handles and applies drive commands
in its engine; nothing here imports an engine.
"""

from __future__ import annotations

import os
from collections.abc import Callable, ItemsView, Iterator, Sequence, ValuesView
from dataclasses import dataclass, field
from typing import Generic, NamedTuple, TypeVar

import numpy as np

from ._urdf import ParsedUrdf
from .interface import BackendError, BodyId, JointInfo

__all__ = [
    "UNLIMITED_FORCE",
    "BodyRecord",
    "BodyTable",
    "DriveCommand",
    "DriveState",
    "as_array",
    "contact_side",
    "drive_command",
    "remove_files",
]

#: stand-in for an unlimited force cap (engines want finite numbers)
UNLIMITED_FORCE = 1.0e9


def remove_files(paths: Sequence[str]) -> None:
    """Delete the temporary files a body was built from (hull meshes the engine read); gone ones are fine."""
    for f in paths:
        try:
            os.unlink(f)
        except OSError:
            pass


def contact_side(a: BodyId, b: BodyId, body_a: BodyId | None, body_b: BodyId | None) -> bool | None:
    """How an engine contact between bodies ``a`` and ``b`` answers ``contacts(body_a, body_b)``.

    False: as the engine gives it; True: flipped (``b`` first, the normal negated), so that a given
    ``body_a`` is always A and, with only ``body_b`` given, that body is B; None: not asked for.
    """
    flip = (body_a is not None and a != body_a) or (
        body_a is None and body_b is not None and b != body_b
    )
    first, second = (b, a) if flip else (a, b)
    if (body_a is not None and first != body_a) or (body_b is not None and second != body_b):
        return None
    return flip


def as_array(v: float | Sequence[float], n: int, what: str) -> np.ndarray:
    """A scalar broadcast to ``n`` values, or exactly ``n`` values (else a named error)."""
    a = np.asarray(v, dtype=float)
    if a.ndim == 0:
        return np.full(n, float(a))
    if a.ndim != 1:
        a = a.reshape(-1)
    if a.shape[0] != n:
        raise BackendError(f"{what}: expected {n} values, got {a.shape[0]}")
    return a


class DriveCommand(NamedTuple):
    """Per-joint PD drive settings for the selected joints (a named tuple: built every control tick)."""

    q: np.ndarray  #: position targets
    v: np.ndarray  #: velocity targets
    k: np.ndarray  #: stiffness (0 for a pure velocity drive)
    d: np.ndarray  #: damping
    f: np.ndarray  #: force/torque caps (finite)


def drive_command(
    joints: Sequence[JointInfo],
    sel: np.ndarray,
    positions: Sequence[float] | None,
    velocities: Sequence[float] | None,
    stiffness: float | Sequence[float],
    damping: float | Sequence[float],
    force_limit: float | Sequence[float] | None,
    current_positions: Callable[[], np.ndarray],
) -> DriveCommand:
    """Normalise ``Backend.set_joint_targets`` arguments for the joints ``sel``.

    Without ``positions`` the drive holds the current positions, or, when
    velocities are given, becomes a pure velocity drive (stiffness 0).
    """
    n = len(sel)
    k = as_array(stiffness, n, "stiffness")
    d = as_array(damping, n, "damping")
    if force_limit is None:
        f = np.array([joints[i].max_effort for i in sel], dtype=float)
    else:
        f = as_array(force_limit, n, "force_limit")
    if not np.isfinite(f).all():  # (checked first: caps are nearly always finite)
        f = np.where(np.isfinite(f), f, UNLIMITED_FORCE)
    if positions is None:
        q = np.asarray(current_positions(), dtype=float)[sel]
        if velocities is not None:
            k = np.zeros(n)
    else:
        q = as_array(positions, n, "positions")
    v = np.zeros(n) if velocities is None else as_array(velocities, n, "velocities")
    return DriveCommand(q, v, k, d, f)


@dataclass
class DriveState:
    """What ``set_joint_targets`` and ``set_joint_friction`` last set, per movable joint."""

    target_q: np.ndarray
    target_v: np.ndarray
    kp: np.ndarray
    kd: np.ndarray
    fmax: np.ndarray
    driven: np.ndarray  #: bool: the joint has a PD drive (once driven, always driven)
    friction: np.ndarray  #: Coulomb friction torque of the joint (used while not driven)
    #: bumped by every :meth:`set_targets`: gains :meth:`retarget` verified stay verified until then
    version: int = 0
    _verified: dict = field(default_factory=dict, repr=False)

    @classmethod
    def zeros(cls, n: int) -> DriveState:
        z = np.zeros(n)
        return cls(z.copy(), z.copy(), z.copy(), z.copy(), z.copy(), np.zeros(n, dtype=bool), z)

    def __len__(self) -> int:
        return len(self.driven)

    def set_targets(self, sel: np.ndarray, cmd: DriveCommand) -> None:
        self.target_q[sel], self.target_v[sel] = cmd.q, cmd.v
        self.kp[sel], self.kd[sel], self.fmax[sel] = cmd.k, cmd.d, cmd.f
        self.driven[sel] = True
        self.version += 1

    def retarget(
        self,
        sel: np.ndarray,
        positions: Sequence[float],
        velocities: Sequence[float],
        stiffness: Sequence[float],
        damping: Sequence[float],
        force_limit: Sequence[float],
    ) -> tuple[int, ...] | None:
        """New targets for joints ``sel`` if they are driven with exactly these gains and (finite)
        caps: the joint indices set; None: nothing set (the full :meth:`set_targets` is needed). Each
        engine's ``_retarget_driven`` hook (:meth:`benchharness.backends.Backend.retarget_joints`) is
        this and whatever its engine must be told."""
        # the same joints re-aimed every physics step with the same gains: the comparison with the
        # arrays is made once per set_targets (version), then only the gain lists are compared
        key = tuple(sel.tolist())
        seen = self._verified.get(key)
        # lists compare element by element with the verified copies (no copy made per call); any other
        # sequence type (an array would compare element-wise) is simply verified again
        if (
            seen is None
            or seen[0] != self.version
            or type(stiffness) is not list
            or type(damping) is not list
            or type(force_limit) is not list
            or seen[1] != stiffness
            or seen[2] != damping
            or seen[3] != force_limit
        ):
            gains = (list(stiffness), list(damping), list(force_limit))
            if not (
                bool(self.driven[sel].all())
                and self.kp[sel].tolist() == gains[0]
                and self.kd[sel].tolist() == gains[1]
                and self.fmax[sel].tolist() == gains[2]
            ):
                return None
            self._verified[key] = (self.version, *gains)
        if len(positions) != len(key) or len(velocities) != len(key):
            raise BackendError(
                f"retarget: {len(key)} joints, {len(positions)} positions, {len(velocities)} velocities"
            )
        # element by element (two or three joints a call): the same float64 values as an array set
        tq, tv = self.target_q, self.target_v
        for i, x, w in zip(key, positions, velocities):
            tq[i] = x
            tv[i] = w
        return key

    def efforts(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The capped drive law at ``(q, v)``, ``-sign(v) friction`` for undriven joints.

        For engines that do not report drive forces (PhysX).
        """
        law = self.kp * (self.target_q - q) + self.kd * (self.target_v - v)
        return np.where(
            self.driven, np.clip(law, -self.fmax, self.fmax), -np.sign(v) * self.friction
        )


@dataclass(kw_only=True)
class BodyRecord:
    """What a backend knows about one body, engine handles aside (subclasses add those)."""

    name: str
    urdf: ParsedUrdf | None = None
    joints: list[JointInfo] = field(default_factory=list)  #: movable joints, URDF order
    fixed: bool = False  #: a fixed base (or a static body)
    drive: DriveState = field(default_factory=lambda: DriveState.zeros(0))
    temp_files: list[str] = field(default_factory=list)  #: deleted with the body
    _jmap: dict[str, int] = field(default_factory=dict, repr=False)
    _sel: dict[tuple[str, ...] | None, np.ndarray] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if len(self.drive) != len(self.joints):
            self.drive = DriveState.zeros(len(self.joints))

    def joint_indices(self, joints: Sequence[str] | None) -> list[int]:
        """Indices into :attr:`joints` of the named movable joints (all when ``joints`` is None)."""
        if joints is None:
            return list(range(len(self.joints)))
        if len(self._jmap) != len(self.joints):  # name -> index, built once per body
            self._jmap = {j.name: i for i, j in enumerate(self.joints)}
        try:
            return [self._jmap[n] for n in joints]
        except KeyError as exc:
            names = [j.name for j in self.joints]
            raise BackendError(
                f"body {self.name!r} has no movable joint {exc.args[0]!r}; joints: {names}"
            ) from None

    def joint_selection(self, joints: Sequence[str] | None) -> np.ndarray:
        """:meth:`joint_indices` as an index array, cached per tuple of names (do not modify it).

        Controllers re-target the same joint groups every control tick or physics step.
        """
        key = None if joints is None else tuple(joints)
        sel = self._sel.get(key)
        if sel is None:
            sel = self._sel[key] = np.asarray(self.joint_indices(joints), dtype=int)
        return sel

    def coupled_joints(self, follower: str, leader: str, multiplier: float) -> tuple[int, int]:
        """The two joints of a :meth:`~.interface.Backend.couple_joints`, checked the same on every
        engine (one-axis joints of this body, a non-zero multiplier): their indices into
        :attr:`joints`, follower first."""
        fi, li = self.joint_indices([follower, leader])
        for i in (fi, li):
            if self.joints[i].type not in ("prismatic", "revolute", "continuous"):
                raise BackendError(f"joint {self.joints[i].name!r} is not a one-axis joint")
        if float(multiplier) == 0.0:
            raise BackendError("a joint coupling needs a non-zero multiplier")
        return fi, li

    def delete_temp_files(self) -> None:
        remove_files(self.temp_files)
        self.temp_files = []


R = TypeVar("R", bound=BodyRecord)


class BodyTable(Generic[R]):
    """Our body handles -> records. Handles start at 1 and are never reused within a backend."""

    def __init__(self) -> None:
        self._records: dict[BodyId, R] = {}
        self._next = 1
        self.closed = False

    def new_handle(self) -> BodyId:
        """Reserve the next handle (a backend that needs it before the body exists, e.g. SAPIEN)."""
        h = self._next
        self._next += 1
        return h

    def add(self, handle: BodyId, record: R) -> BodyId:
        if not record.name:
            record.name = f"body{handle}"
        self._records[handle] = record
        return handle

    def __getitem__(self, handle: BodyId) -> R:
        """The record of a live body; a named :class:`BackendError` otherwise."""
        if self.closed:
            raise BackendError("backend is closed")
        try:
            return self._records[handle]
        except KeyError:
            raise BackendError(f"no body with handle {handle}") from None

    def __contains__(self, handle: object) -> bool:
        return handle in self._records

    def __iter__(self) -> Iterator[BodyId]:
        return iter(self._records)

    def items(self) -> ItemsView[BodyId, R]:
        return self._records.items()

    def values(self) -> ValuesView[R]:
        return self._records.values()

    def pop(self, handle: BodyId) -> R:
        """Forget a body and delete its temporary files (the engine removes the body itself)."""
        rec = self[handle]
        del self._records[handle]
        rec.delete_temp_files()
        return rec

    def close(self) -> None:
        """Delete every body's temporary files; afterwards every lookup raises."""
        for rec in self._records.values():
            rec.delete_temp_files()
        self._records.clear()
        self.closed = True
