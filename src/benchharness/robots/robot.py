"""A :class:`Robot`: a base, arms and grippers/hands, composed from a :class:`RobotConfig`.

The robot owns the link to the simulation (backend + body handle) after
:meth:`Robot.spawn`; its parts use it. The control loop is here, because
all parts share it: every joint that no primitive is moving holds its last
target (with gravity feed-forward), so moving one arm never drops the other
or opens a hand.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..backends.interface import Backend, BodyId, CapabilityError
from ..geometry import Pose
from .config import RobotConfig
from .description import UrdfJoint, downstream_links, read_joints, read_links
from .gravity import GravityModel
from .kinematics import IKConfig
from .parts import Gripper, RobotArm
from .trajectory import QuinticTrajectory

__all__ = ["Robot"]


class Robot:
    """A simulated (or merely kinematic) robot built from a :class:`RobotConfig`."""

    #: control ticks run every this many seconds of simulated time (targets updated, gravity re-fed)
    control_period: float = 1.0 / 120.0

    def __init__(self, config: RobotConfig, ik_config: IKConfig | None = None) -> None:
        self.config = config
        self.ik_config = ik_config or IKConfig()
        self.urdf_path = Path(config.urdf)
        if not self.urdf_path.is_file():
            raise FileNotFoundError(f"robot {config.name!r}: URDF {self.urdf_path} does not exist")
        self.urdf_text = self.urdf_path.read_text()
        joints = read_joints(self.urdf_path)
        self.urdf_joints: dict[str, UrdfJoint] = {j.name: j for j in joints}
        self.joint_names: list[str] = [j.name for j in joints]
        self.link_names: list[str] = read_links(self.urdf_path)
        missing = [j for g in config.groups().values() for j in g if j not in self.urdf_joints]
        missing += [
            k.follower
            for g in config.grippers
            for k in g.linkages
            if k.follower not in self.urdf_joints
        ]
        if missing:
            raise ValueError(
                f"robot {config.name!r}: joints {missing} are not movable joints of {self.urdf_path}"
            )
        self.arms: dict[str, RobotArm] = {a.name: RobotArm(a, self) for a in config.arms}
        self.grippers: dict[str, Gripper] = {g.name: Gripper(g, self) for g in config.grippers}
        self._gains = self._collect_gains()
        self._gravity: GravityModel | None = None
        self.backend: Backend | None = None
        self.body: BodyId | None = None
        self._base_rot = np.eye(3)
        self._gcache: tuple[np.ndarray, np.ndarray] | None = None
        self._gj: tuple[str, ...] | None = None
        self._plans: dict[tuple[str, ...], tuple] = {}
        self._index: dict[tuple[str, ...], np.ndarray] = {}  #: joint names -> indices (cached)

    # -- description -------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.config.name

    @property
    def dof(self) -> int:
        """Movable joints of the model (a linkage's fingertip joints included)."""
        return len(self.joint_names)

    @property
    def driven_dof(self) -> int:
        """Joints the robot's groups command: :attr:`dof` less the fingertips a linkage moves."""
        return len({j for names in self.groups().values() for j in names})

    def groups(self) -> dict[str, tuple[str, ...]]:
        return self.config.groups()

    def arm(self, name: str) -> RobotArm:
        return self.arms[name]

    def gripper(self, name: str) -> Gripper:
        return self.grippers[name]

    hand = gripper

    def links_below(self, joint: str) -> frozenset[str]:
        """The links ``joint`` moves: its child link and every link downstream of it (fixed joints
        included), e.g. an arm's links and its hand's from the arm's first joint."""
        return frozenset(downstream_links(ET.fromstring(self.urdf_text))[joint])

    def tcp_links(self) -> dict[str, str]:
        out = {a.name: a.config.tcp_link for a in self.arms.values()}
        out.update({g.name: g.config.tcp_link for g in self.grippers.values() if g.config.tcp_link})
        return out

    def joint_limits(self, joints: Sequence[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The position limits that IK and every motion primitive keep ``joints`` (default: all) within.

        The URDF's soft limits (``<safety_controller>``, e.g. the PR2's) when
        ``config.soft_limits``, else, and for joints without them, the hard
        ``<limit>``; continuous joints are unbounded (inf). Why soft limits:
        the real robot's safety controller resists poses beyond them, so a
        strategy that needs one would not run on it.
        """
        names = self.joint_names if joints is None else list(joints)
        js = [self.urdf_joints[n] for n in names]
        if self.config.soft_limits:
            return np.array([j.soft_lower for j in js]), np.array([j.soft_upper for j in js])
        return np.array([j.lower for j in js]), np.array([j.upper for j in js])

    def home(self) -> np.ndarray:
        """Home configuration in :attr:`joint_names` order.

        Joints the config's ``home`` does not name take their gripper's open
        position, or 0; all are clamped to :meth:`joint_limits`.
        """
        default: dict[str, float] = {}
        for g in self.grippers.values():
            default.update(zip(g.joints, g.config.joint_targets(g.config.open)))
        lo, hi = self.joint_limits()
        q = [float(self.config.home.get(n, default.get(n, 0.0))) for n in self.joint_names]
        return self.with_linkages(np.clip(np.array(q), lo, hi))

    def with_linkages(self, q: np.ndarray) -> np.ndarray:
        """``q`` with every linkage's fingertip joint where its finger's lateral joint puts it.

        Why: a linkage is rigid, so a configuration that sets the fingers (home, a
        spawn pose) must carry the fingertips along, not leave them to catch up.
        """
        q = np.array(q, dtype=float)
        for g in self.config.grippers:
            for k in g.linkages:
                q[self.joint_names.index(k.follower)] = k.target(
                    float(q[self.joint_names.index(k.leader)])
                )
        return q

    def describe(self) -> dict:
        return {
            "name": self.name,
            "dof": self.dof,
            "urdf": str(self.urdf_path),
            "groups": {k: list(v) for k, v in self.groups().items()},
            "tcp_links": self.tcp_links(),
            "summary": self.config.summary,
        }

    def _collect_gains(self) -> dict[str, tuple[float, float]]:
        g: dict[str, tuple[float, float]] = {}
        for a in self.config.arms:
            g.update({j: (k, d) for j, k, d in zip(a.joints, a.stiffness, a.damping)})
        for h in self.config.grippers:
            g.update({j: (k, d) for j, k, d in zip(h.joints, h.stiffness, h.damping)})
            g.update({k.follower: (k.stiffness, k.damping) for k in h.linkages})
        g.update(dict(self.config.extra_gains))
        for n, j in self.urdf_joints.items():
            if n not in g:
                e = j.effort if np.isfinite(j.effort) else 100.0
                g[n] = (100.0 * e, 10.0 * e)
        return g

    # -- simulation ------------------------------------------------------------------
    def spawn(
        self, backend: Backend, base_pose: Pose | None = None, *, q: Sequence[float] | None = None
    ) -> BodyId:
        """Load the robot into ``backend`` at ``base_pose`` (default: the config's), in home pose, holding it."""
        pose = base_pose or self.config.base_pose
        self.backend = backend
        self.body = backend.load_urdf(
            self.urdf_path, pose, fixed_base=self.config.fixed_base, name=self.name
        )
        names = backend.joint_names(self.body)
        if names != self.joint_names:
            raise RuntimeError(
                f"backend joint order {names} differs from the URDF's {self.joint_names}"
            )
        self._base_rot = pose.rotation.as_matrix()
        self._gravity = None  # built on first use, only for backends without gravity_torques
        self._gcache = None
        q0 = self.home() if q is None else self.with_linkages(np.asarray(q, dtype=float))
        backend.set_joint_positions(self.body, q0)
        self._couple(backend)
        self._targets = q0.copy()
        self.hold()
        for g in self.grippers.values():  # hands keep their home shape
            qg = q0[[self.joint_names.index(j) for j in g.joints]]
            g.set_command(np.linalg.lstsq(g.coupling, qg, rcond=None)[0])
        return self.body

    def _couple(self, backend: Backend) -> None:
        """Make each hand's ``mimic`` couplings engine constraints (see :class:`~.config.JointMimic`)."""
        mimics = [m for g in self.config.grippers for m in g.mimic]
        if mimics and not backend.capabilities.joint_coupling:
            raise CapabilityError(
                f"robot {self.name!r} needs joint couplings ({mimics[0].follower} mimics "
                f"{mimics[0].leader}), which backend {type(backend).__name__} cannot make"
            )
        for m in mimics:
            backend.couple_joints(self.body, m.follower, m.leader, m.multiplier)

    def _require(self) -> Backend:
        if self.backend is None or self.body is None:
            raise RuntimeError(f"robot {self.name!r} is not spawned: call spawn(backend) first")
        return self.backend

    def joint_index(self, joints: Sequence[str]) -> np.ndarray:
        """Indices of ``joints`` in :attr:`joint_names` (cached per tuple of names)."""
        key = tuple(joints)
        idx = self._index.get(key)
        if idx is None:
            idx = np.array([self.joint_names.index(j) for j in key], dtype=int)
            self._index[key] = idx
        return idx

    def joint_positions(self, joints: Sequence[str] | None = None) -> np.ndarray:
        q, _ = self._require().get_joint_motion(self.body)
        if joints is None:
            return q
        return q[self.joint_index(joints)]

    def joint_velocities(self, joints: Sequence[str] | None = None) -> np.ndarray:
        _, v = self._require().get_joint_motion(self.body)
        if joints is None:
            return v
        return v[self.joint_index(joints)]

    def joint_motion(self, joints: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities of ``joints``, read together (one engine query)."""
        q, v = self._require().get_joint_motion(self.body)
        idx = self.joint_index(joints)
        return q[idx], v[idx]

    def _gravity_joints(self) -> list[str]:
        """Every joint but the grippers' (a new list each call; the names are computed once)."""
        if self._gj is None:
            grip = {j for g in self.config.grippers for j in g.driven_joints}
            self._gj = tuple(j for j in self.joint_names if j not in grip)
        return list(self._gj)

    def _drive_plan(self, joints: tuple[str, ...]) -> tuple:
        """Per joint group, everything :meth:`drive` needs that does not change: cached.

        Why: strategies drive the same few groups every control tick; looking
        names up in lists each time cost more than the physics step.
        """
        plan = self._plans.get(joints)
        if plan is None:
            idx = np.array([self.joint_names.index(j) for j in joints], dtype=int)
            k = np.array([self._gains[j][0] for j in joints])
            d = np.array([self._gains[j][1] for j in joints])
            eff = np.array([self.urdf_joints[j].effort for j in joints])
            gj = set(self._gravity_joints())
            sel = np.array([i for i, j in enumerate(joints) if j in gj], dtype=int)
            carried = {j for a in self.config.arms if a.gravity_carried for j in a.joints}
            carried_mask = np.array([j in carried for j in joints], dtype=bool)
            plan = (
                list(joints),
                idx,
                k,
                d,
                np.maximum(k, 1e-9),  # the feed-forward's divisor
                eff,
                sel,
                idx[sel],
                carried_mask,
            )
            self._plans[joints] = plan
        return plan

    def drive(self, joints: Sequence[str], q: np.ndarray, qd: np.ndarray | None = None) -> None:
        """PD targets for ``joints`` with gravity feed-forward folded into the position target."""
        be = self._require()
        if not len(joints):  # nothing to drive
            return
        names, idx, k, d, k_floor, eff, sel, gidx, carried = self._drive_plan(tuple(joints))
        self._targets[idx] = q
        tau = np.zeros(len(names))
        if sel.size:
            tau[sel] = self._gravity_all()[gidx]
        limit = eff + np.where(carried, np.abs(tau), 0.0)
        # arrays, not lists: the backend reads each argument as an array (the plan's are not modified)
        be.set_joint_targets(
            self.body,
            q + tau / k_floor,
            np.zeros(len(names)) if qd is None else qd,
            joints=names,
            stiffness=k,
            damping=d,
            force_limit=limit,
        )

    def _gravity_torques(self, joints: list[str]) -> np.ndarray:
        """Gravity holding torques of ``joints`` (0 for hand joints)."""
        _, _, _, _, _, _, sel, gidx, _ = self._drive_plan(tuple(joints))
        tau = np.zeros(len(joints))
        if sel.size:
            tau[sel] = self._gravity_all()[gidx]
        return tau

    def _gravity_all(self) -> np.ndarray:
        """Gravity holding torques of all joints (:attr:`joint_names` order), cached while the robot is still.

        From the backend's own inverse dynamics where it has it
        (``capabilities.gravity_torques``: microseconds), else from the URDF
        :class:`GravityModel` (milliseconds; hand joints are not needed and
        stay 0 there). Why the cache: holding still is most of a benchmark's
        time, and the torques only change when the configuration does (1e-4 rad).
        """
        be = self._require()
        q, _ = be.get_joint_motion(self.body)
        if self._gcache is None or np.abs(q - self._gcache[0]).max() > 1e-4:
            if be.capabilities.gravity_torques:
                tau = np.asarray(be.gravity_torques(self.body), dtype=float)
            else:
                if self._gravity is None:
                    self._gravity = GravityModel(self.urdf_path, be.config.gravity)
                names = self._gravity_joints()
                tau = np.zeros(self.dof)
                tau[[self.joint_names.index(j) for j in names]] = self._gravity.torques(
                    dict(zip(self.joint_names, q)), names, self._base_rot
                )
            self._gcache = (q.copy(), tau)
        return self._gcache[1]

    def hold(self, joints: Sequence[str] | None = None) -> None:
        """Hold ``joints`` (default: all but the grippers') at their last targets."""
        if joints is None:
            self._gravity_joints()
            js = self._gj
        else:
            js = tuple(joints)
        if js:
            self.drive(js, self._targets[self._drive_plan(js)[1]])

    def step(self, n: int = 1) -> None:
        """Step the backend in control ticks, letting hands re-aim coupled joints each tick."""
        be = self._require()
        per = max(1, int(round(self.control_period / be.config.timestep)))
        while n > 0:
            k = min(per, n)
            be.step(k)
            n -= k
            self._tick()

    def _tick(self) -> None:
        for g in self.grippers.values():
            g.update()

    def settle(self, seconds: float) -> None:
        """Step while holding every joint, refreshing gravity feed-forward each control tick."""
        be = self._require()
        per = max(1, int(round(self.control_period / be.config.timestep)))
        ticks = max(1, int(round(seconds / (per * be.config.timestep))))
        for _ in range(ticks):
            self.hold()
            be.step(per)
            self._tick()

    def track(self, joints: Sequence[str], traj: QuinticTrajectory, *, settle: float = 0.3) -> dict:
        """Follow a joint trajectory with PD targets (position + velocity), stepping the backend."""
        be = self._require()
        dt = be.config.timestep
        per = max(1, int(round(self.control_period / dt)))
        joints = list(joints)
        idx = self.joint_index(joints)
        n_ticks = int(np.ceil(traj.duration / (per * dt)))
        max_err = 0.0
        vmax = np.array([self.urdf_joints[j].velocity for j in joints])
        peak_ratio = 0.0
        others = [j for j in self._gravity_joints() if j not in joints]
        for k in range(n_ticks + 1):
            t = k * per * dt
            q_ref, qd_ref = traj.sample(t)
            if k:
                pos, vel = be.get_joint_motion(self.body)
                max_err = max(max_err, float(np.abs(pos[idx] - q_ref).max()))
                peak_ratio = max(peak_ratio, float((np.abs(vel[idx]) / vmax).max()))
            self.drive(joints, q_ref, qd_ref)
            if others:
                self.hold(others)
            be.step(per)
            self._tick()
        self.settle(settle) if settle > 0 else None
        final = float(np.max(np.abs(self.joint_positions()[idx] - traj.q1)))
        return {
            "max_tracking_error": max_err,
            "final_error": final,
            "measured_velocity_ratio": peak_ratio,
        }

    def tcp_poses(self) -> dict[str, Pose]:
        be = self._require()
        return {k: be.get_link_pose(self.body, v) for k, v in self.tcp_links().items()}
