"""The composable parts of a robot: :class:`RobotArm` (a chain with a tool frame) and :class:`Gripper`.

Parts hold kinematics and motion primitives; they act on the simulated
robot only through the :class:`~benchharness.robots.robot.Robot` they belong
to, which owns the backend handle. Every physical effect goes through the
Backend interface: IK and trajectory timing are computed here, the motion
itself is PD targets and backend steps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..backends.interface import BodyId
from ..geometry import Pose
from .config import ArmConfig, GripperConfig
from .kinematics import (
    IKConfig,
    IKResult,
    KinematicChain,
    UniformStream,
    pose_error,
    restart_stream,
)
from .trajectory import QuinticTrajectory

if TYPE_CHECKING:
    import torch

    from .robot import Robot

__all__ = ["GraspResult", "Gripper", "MotionResult", "RobotArm", "RobotHand"]

#: KinematicChains built in this process, by (URDF text, root, tip, limits). A chain is immutable once
#: built (IK draws from the generator it is given), and building one parses the whole URDF: a worker
#: running many trials, or a strategy that makes a new robot, builds each chain once.
_CHAINS: dict[tuple, KinematicChain] = {}


def _chain(
    urdf_text: str, root: str, tip: str, limits: dict[str, tuple[float, float]]
) -> KinematicChain:
    key = (urdf_text, root, tip, tuple(sorted(limits.items())))
    chain = _CHAINS.get(key)
    if chain is None:
        chain = _CHAINS[key] = KinematicChain(urdf_text, root, tip, limits=limits)
    return chain


@dataclass(frozen=True)
class MotionResult:
    """What a motion primitive achieved, measured on the backend."""

    ik_success: bool  #: IK converged for the goal (the motion runs anyway, to the best solution)
    q_goal: np.ndarray
    duration: float  #: s of simulated time for the trajectory (without settling)
    max_tracking_error: float  #: rad (or m), max over joints and control ticks of |q_ref - q|
    final_joint_error: float  #: rad, max |q_goal - q| after settling
    pos_error: float  #: m, tool frame vs target (backend pose) after settling; nan for joint goals
    rot_error: float  #: rad, same
    peak_velocity_ratio: float  #: max over joints of planned peak speed / URDF velocity limit
    measured_velocity_ratio: float = float(
        "nan"
    )  #: max over joints and control ticks of measured speed / limit

    @property
    def success(self) -> bool:
        return bool(self.ik_success)


@dataclass(frozen=True)
class GraspResult:
    contact: bool  #: a finger link touches the object (or anything, if no object was named)
    closed: bool  #: the grasp joints reached the fully closed command (nothing in between)
    actuators: np.ndarray  #: actuator values measured at the end (mean of coupled joints, rescaled)
    joint_positions: np.ndarray
    time: float  #: s simulated until the fingers came to rest


class RobotArm:
    """A serial chain ending in a tool frame: an arm, or one finger of a dexterous hand."""

    def __init__(self, config: ArmConfig, robot: Robot) -> None:
        self.config = config
        self.robot = robot
        self._chain: KinematicChain | None = None
        jl = robot.urdf_joints
        #: the limits IK and the primitives respect: soft limits where the robot has them (Robot.joint_limits)
        self.lower, self.upper = robot.joint_limits(config.joints)
        self.max_velocity = np.array([jl[j].velocity for j in config.joints])
        self.effort = np.array([jl[j].effort for j in config.joints])
        #: URDF ``continuous`` joints (e.g. the PR2's forearm and wrist roll): no limits, any 2*pi-branch
        self.continuous = np.array([jl[j].type == "continuous" for j in config.joints], dtype=bool)

    @property
    def name(self) -> str:
        return self.config.name

    @property
    def joints(self) -> tuple[str, ...]:
        return self.config.joints

    @property
    def chain(self) -> KinematicChain:
        if self._chain is None:
            c = _chain(
                self.robot.urdf_text, self.config.base_link, self.config.tcp_link, self._limits()
            )
            if tuple(c.joint_names) != tuple(self.config.joints):
                raise ValueError(
                    f"{self.robot.name}.{self.name}: URDF chain {self.config.base_link} -> {self.config.tcp_link} "
                    f"has joints {c.joint_names}, config says {list(self.config.joints)}"
                )
            self._chain = c
        return self._chain

    def _limits(self) -> dict[str, tuple[float, float]]:
        """Joint -> (lower, upper) for the IK chain: this arm's limits (soft where the robot has them)."""
        return {
            j: (float(lo), float(hi))
            for j, lo, hi, c in zip(self.joints, self.lower, self.upper, self.continuous)
            if not c
        }

    # -- kinematics (no backend needed) ---------------------------------------
    def fk(self, q) -> np.ndarray:
        """Tool frame(s) in the arm's base-link frame, (B, 4, 4)."""
        return self.chain.fk(q)

    def jacobian(self, q) -> np.ndarray:
        return self.chain.jacobian(q)

    def joint_origins(self, q) -> np.ndarray:
        """Origins of the arm's movable joints (B, K, 3) in its base-link frame."""
        return self.chain.joint_origins(q)

    def ik(
        self,
        targets: np.ndarray,
        *,
        seed_q=None,
        generator: UniformStream | torch.Generator | None = None,
        seed: int = 0,
        config: IKConfig | None = None,
    ) -> IKResult:
        """Batched IK for tool-frame targets in the base-link frame (see :meth:`KinematicChain.ik`).

        With ``seed_q``, continuous joints come back on the 2*pi-branch nearest
        the seed (see :meth:`_ik_continuous`), so that a motion from the
        current configuration never unwinds a full turn.
        """
        cfg = config or self.robot.ik_config
        if self.config.position_only:
            from dataclasses import replace

            cfg = replace(cfg, rot_tolerance=float("inf"))
            return self._ik_position(targets, seed_q, generator, seed, cfg)
        if seed_q is not None and self.continuous.any():
            return self._ik_continuous(targets, seed_q, generator, seed, cfg)
        return self.chain.ik(targets, seed_q=seed_q, generator=generator, seed=seed, config=cfg)

    def _ik_continuous(self, targets, seed_q, generator, seed, cfg) -> IKResult:
        """IK with continuous joints, returned on the 2*pi-branch nearest ``seed_q``.

        Why: :class:`KinematicChain` searches a continuous joint over [-pi, pi]
        (it needs finite bounds to sample and clamp), but the joint itself may
        be anywhere, e.g. 3.5 rad after a twist, and a solution just past the
        window's edge is unreachable from a seed near it (the descent is
        clamped there and a restart on another arm branch wins: measured as a
        2.5 rad swing of three joints in one hand-over waypoint). So the
        problem is re-centred on the seed first:

        * the *last* joint, if continuous: turning it by ``c`` is a fixed
          transform of the tip, ``G(c) = FK(q|last=0)^-1 FK(q|last=c)``, so
          the solver gets the target ``T G(-c)`` with the seed's last joint
          at 0, and ``c`` (the seed's value) is added back;
        * any other continuous joint: its window is moved by pi when the
          seed lies in the outer half of [-pi, pi], by solving on a copy of
          the chain whose joint origin is turned by pi about the joint axis
          (``origin * Rot(axis, pi) * Rot(axis, q') = origin * Rot(axis, q' + pi)``).

        Each solution is then unwrapped by the multiple of 2*pi that brings it
        nearest the seed.
        """
        from .kinematics import IKResult

        t = np.asarray(targets, dtype=float).reshape(-1, 4, 4)
        b, dof = t.shape[0], len(self.joints)
        ref = np.broadcast_to(np.asarray(seed_q, dtype=float).reshape(-1, dof), (b, dof)).copy()
        c = self.continuous
        mid = np.flatnonzero(c[:-1])
        shift = np.zeros((b, dof))
        if c[-1]:
            shift[:, -1] = ref[:, -1]
        wrapped_mid = (ref[:, mid] + np.pi) % (2 * np.pi) - np.pi
        shift[:, mid] = np.where(np.abs(wrapped_mid) > np.pi / 2, np.pi, 0.0)
        if c[-1]:
            q0 = ref.copy()
            q0[:, -1] = 0.0
            qc = ref.copy()
            qc[:, -1] = -shift[:, -1]
            m = self.chain.fk(np.concatenate([q0, qc]))
            t = t @ (np.linalg.inv(m[:b]) @ m[b:])  # G(-c), in the tip frame
        local = ref - shift
        local[:, c] = (local[:, c] + np.pi) % (2 * np.pi) - np.pi
        q = np.zeros((b, dof))
        ok, dp, dr = np.zeros(b, dtype=bool), np.zeros(b), np.zeros(b)
        keys = [tuple(bool(x) for x in shift[i, mid] != 0.0) for i in range(b)]
        for key in sorted(set(keys)):
            rows = np.array([i for i in range(b) if keys[i] == key])
            chain = self._recentred_chain(tuple(int(j) for j, on in zip(mid, key) if on))
            res = chain.ik(t[rows], seed_q=local[rows], generator=generator, seed=seed, config=cfg)
            q[rows], ok[rows], dp[rows], dr[rows] = res.q, res.success, res.pos_error, res.rot_error
        q = q + shift
        q[:, c] += 2 * np.pi * np.round((ref[:, c] - q[:, c]) / (2 * np.pi))
        return IKResult(q, ok, dp, dr)

    def _recentred_chain(self, turned: tuple[int, ...]) -> KinematicChain:
        """The arm's chain with the origins of joints ``turned`` (indices) turned by pi about their axes."""
        if not turned:
            return self.chain
        cache = self.__dict__.setdefault("_recentred", {})
        if turned not in cache:
            import xml.etree.ElementTree as ET

            from scipy.spatial.transform import Rotation

            root = ET.fromstring(self.robot.urdf_text)
            names = {self.joints[i] for i in turned}
            for j in root.findall("joint"):
                if j.get("name") not in names:
                    continue
                origin = j.find("origin")
                if origin is None:
                    origin = ET.SubElement(j, "origin")
                rpy = [float(x) for x in (origin.get("rpy") or "0 0 0").split()]
                axis_el = j.find("axis")
                axis = np.array(
                    [
                        float(x)
                        for x in (axis_el.get("xyz") if axis_el is not None else "1 0 0").split()
                    ]
                )
                r = Rotation.from_euler("xyz", rpy) * Rotation.from_rotvec(
                    np.pi * axis / np.linalg.norm(axis)
                )
                origin.set("rpy", " ".join(repr(float(x)) for x in r.as_euler("xyz")))
            cache[turned] = _chain(
                ET.tostring(root, encoding="unicode"),
                self.config.base_link,
                self.config.tcp_link,
                self._limits(),
            )
        return cache[turned]

    def _ik_position(self, targets, seed_q, generator, seed, cfg) -> IKResult:
        """Position-only IK: the target orientation is replaced by the one the chain reaches.

        A 4-DOF finger cannot meet a 6-D pose; pytorch-kinematics' solver
        weighs orientation, so we iterate on position with a damped
        Jacobian-transpose-pseudoinverse of the position rows only.
        """
        t = np.asarray(targets, dtype=float).reshape(-1, 4, 4)
        gen = restart_stream(generator, seed)
        b = t.shape[0]
        best_q = np.zeros((b, self.chain.dof))
        best_e = np.full(b, np.inf)
        starts = (
            [None]
            if seed_q is None
            else [np.broadcast_to(np.asarray(seed_q, float), (b, self.chain.dof))]
        )
        starts += [self.chain.sample(b, gen) for _ in range(max(cfg.num_retries, 1))]
        for q in starts:
            q = self.chain.sample(b, gen) if q is None else np.array(q, dtype=float)
            for _ in range(cfg.max_iterations):
                m = self.chain.fk(q)
                e = t[:, :3, 3] - m[:, :3, 3]
                j = self.chain.jacobian(q)[:, :3, :]
                jt = np.transpose(j, (0, 2, 1))
                lam = 1e-4 + cfg.lm_damping * np.sum(e * e, axis=1)[:, None, None]
                dq = jt @ np.linalg.solve(j @ jt + lam * np.eye(3), e[:, :, None])
                q = np.clip(q + cfg.lr * dq[:, :, 0], self.chain.lower, self.chain.upper)
            err = np.linalg.norm(t[:, :3, 3] - self.chain.fk(q)[:, :3, 3], axis=1)
            better = err < best_e
            best_q[better], best_e[better] = q[better], err[better]
            if np.all(best_e < cfg.pos_tolerance):
                break
        return IKResult(best_q, best_e <= cfg.pos_tolerance, best_e, np.zeros(b))

    # -- world frames (needs a spawned robot) -------------------------------------
    def base_pose(self) -> Pose:
        return self.robot.backend.get_link_pose(self.robot.body, self.config.base_link)

    def tcp_pose(self) -> Pose:
        """Tool frame in the world, as the backend reports it."""
        return self.robot.backend.get_link_pose(self.robot.body, self.config.tcp_link)

    def positions(self) -> np.ndarray:
        return self.robot.joint_positions(self.joints)

    # -- motion primitives -----------------------------------------------------------
    def solve_pose(
        self,
        target: Pose,
        *,
        generator: UniformStream | torch.Generator | None = None,
        seed: int = 0,
        seed_q: np.ndarray | None = None,
    ) -> IKResult:
        """The IK solution (one row) :meth:`move_to_pose` would move to for the world pose ``target``:
        seeded with the current joints or ``seed_q``. Solved apart so a caller can judge the joints
        before the arm moves and hand them on (``move_to_pose(solution=...)``)."""
        base = self.base_pose()
        local = (base.inv() * target).as_matrix()
        q_now = self.positions() if seed_q is None else np.asarray(seed_q, dtype=float)
        return self.ik(local[None], seed_q=q_now, generator=generator, seed=seed)

    def move_to_pose(
        self,
        target: Pose,
        *,
        duration: float | None = None,
        velocity_scale: float | None = None,
        settle: float = 0.3,
        generator: UniformStream | torch.Generator | None = None,
        seed: int = 0,
        seed_q: np.ndarray | None = None,
        move_unsolved: bool = True,
        solution: IKResult | None = None,
    ) -> MotionResult:
        """Move the tool frame to a world pose: IK for the goal, then a tracked joint trajectory.

        The IK is seeded with the current joint positions, so the arm takes
        the solution nearest to where it is; or with ``seed_q``, a
        configuration planned ahead (e.g. the start of a chain of solutions
        checked for a later motion), so that the arm ends on that branch.

        ``move_unsolved=False``: if the IK does not converge the arm does not move (the result has
        ``ik_success`` False, no duration, and the IK's own position and rotation errors). With the
        default the arm moves to the IK's best attempt, which for a target just out of reach can be
        a random restart on another arm branch (measured: upper-arm and forearm rolls swung -2.84 /
        +2.86 rad for a target 2 mm out of reach, PR2 on SAPIEN).

        ``solution``: the IK of ``target`` already solved (:meth:`solve_pose`, possibly replaced by
        the caller with another solution of the same target); the seeds are then not used.
        """
        res = (
            solution
            if solution is not None
            else self.solve_pose(target, generator=generator, seed=seed, seed_q=seed_q)
        )
        if not move_unsolved and not res.success[0]:
            return MotionResult(
                False,
                np.asarray(res.q[0], dtype=float),
                0.0,
                0.0,
                float("nan"),
                float(res.pos_error[0]),
                float(res.rot_error[0]),
                0.0,
            )
        motion = self.move_to_joints(
            res.q[0], duration=duration, velocity_scale=velocity_scale, settle=settle
        )
        reached = self.tcp_pose()
        dp, dr = pose_error(reached.as_matrix(), target.as_matrix())
        if self.config.position_only:
            dr = np.array([np.nan])
        return MotionResult(
            bool(res.success[0]),
            motion.q_goal,
            motion.duration,
            motion.max_tracking_error,
            motion.final_joint_error,
            float(dp[0]),
            float(dr[0]),
            motion.peak_velocity_ratio,
            motion.measured_velocity_ratio,
        )

    def move_to_joints(
        self,
        q_goal: Sequence[float],
        *,
        duration: float | None = None,
        velocity_scale: float | None = None,
        settle: float = 0.3,
    ) -> MotionResult:
        """Track a quintic joint trajectory to ``q_goal`` within the velocity limits."""
        q_goal = np.clip(np.asarray(q_goal, dtype=float), self.lower, self.upper)
        # Start from the measured joints brought inside the limits: an arm held at a soft limit sits a few
        # mrad past it (PD tracking error), and a trajectory from there would command targets outside
        # (measured: up to 3.5 mrad in 257 of ~1e6 arm targets of a Rubiks-5-10 run).
        q0 = np.clip(self.positions(), self.lower, self.upper)
        traj = QuinticTrajectory.plan(
            q0,
            q_goal,
            self.max_velocity,
            velocity_scale=self.config.velocity_scale if velocity_scale is None else velocity_scale,
            duration=duration,
        )
        track = self.robot.track(self.joints, traj, settle=settle)
        return MotionResult(
            True,
            q_goal,
            traj.duration,
            track["max_tracking_error"],
            track["final_error"],
            float("nan"),
            float("nan"),
            float(np.max(traj.peak_velocity() / self.max_velocity)) if q0.size else 0.0,
            track["measured_velocity_ratio"],
        )


class Gripper:
    """A parallel gripper or multi-fingered hand: coupled finger joints, opened and closed with a force cap."""

    def __init__(self, config: GripperConfig, robot: Robot) -> None:
        self.config = config
        self.robot = robot
        self.coupling = np.asarray(config.coupling, dtype=float)
        self.command = np.asarray(config.open, dtype=float)
        self._force = np.asarray(config.force_limit, dtype=float)
        self._targets = config.joint_targets(self.command)
        self.lower, self.upper = robot.joint_limits(config.joints)
        self._link_sent: list[float] | None = None  # fingertip targets last sent (linkages)
        self._link_cb: tuple[object, int] | None = (
            None  # (backend, step-callback handle) while moving
        )
        self._link_plan: tuple | None = None  # see _aim_linkages
        self._aimed_at: float | None = None  # sim time of the last re-aim while moving (see update)
        self._sent_gravity: np.ndarray | None = None  # feed-forward last sent (gravity_compensated)
        self._ff = False  # the targets in force carry gravity feed-forward (see set_command)

    @property
    def name(self) -> str:
        return self.config.name

    @property
    def joints(self) -> tuple[str, ...]:
        return self.config.joints

    def set_command(
        self,
        u: Sequence[float],
        force_limit: float | Sequence[float] | None = None,
        *,
        feed_forward: bool = False,
    ) -> None:
        """Drive the joints towards the coupled targets of actuator values ``u``.

        ``feed_forward``: add gravity feed-forward (only a ``gravity_compensated`` hand; see
        :meth:`_send`) — for unsaturated spring targets such as :meth:`close`'s squeeze. Off, the
        drives get the plain targets and caps (a saturated drive pushes with its cap).
        """
        self._ff = feed_forward and self.config.gravity_compensated
        self.command = np.asarray(u, dtype=float)
        q = np.clip(self.config.joint_targets(self.command), self.lower, self.upper)
        f = self.config.force_limit if force_limit is None else force_limit
        self._force = np.broadcast_to(np.asarray(f, dtype=float), (len(q),)).copy()
        self._targets = q
        if self.config.follow:
            pos = self.robot.joint_positions(self.joints)
            for fj, lj, ratio in self.config.follow:
                i, k = self.joints.index(fj), self.joints.index(lj)
                q = q.copy()
                q[i] = np.clip(ratio * pos[k], self.lower[i], self.upper[i])
        self._sent_gravity = None
        self._send(q)
        self._link_sent = None
        self._aim_linkages()

    def _send(self, q: np.ndarray) -> None:
        """Send the joints' PD targets ``q`` with their force caps, plus gravity feed-forward if the
        targets in force take it (:meth:`set_command`'s ``feed_forward``, :meth:`close` of a
        ``gravity_compensated`` hand): the target moves by ``tau / k`` and the cap
        by ``|tau|``. Exact while a drive is unsaturated (the tracked close and the squeeze keep it so:
        it then presses with its spring force on top of carrying its finger); the engines' caps are
        symmetric, so a saturated drive (a step target, ``open()``) pushes up to ``|tau|`` harder."""
        k = np.asarray(self.config.stiffness, dtype=float)
        force = self._force
        if self._ff:
            tau = self._finger_gravity()
            self._sent_gravity = tau
            q = q + tau / np.maximum(k, 1e-9)
            force = force + np.abs(tau)
        self.robot.backend.set_joint_targets(
            self.robot.body,
            q,
            np.zeros(len(q)),
            joints=list(self.joints),
            stiffness=list(self.config.stiffness),
            damping=list(self.config.damping),
            force_limit=force.tolist(),
        )

    def _finger_gravity(self) -> np.ndarray:
        """Gravity holding force/torque of each of the hand's joints (0 where the backend cannot say)."""
        r = self.robot
        if not r.backend.capabilities.gravity_torques:
            return np.zeros(len(self.joints))
        return np.asarray(r._gravity_all()[r.joint_index(self.joints)], dtype=float)

    def _refresh_gravity(self) -> None:
        """Re-send the targets when the fingers' gravity load moved (> 0.01 N): the wrist turned."""
        if not self._ff or self.config.follow:
            return
        tau = self._finger_gravity()
        if self._sent_gravity is None or np.abs(tau - self._sent_gravity).max() > 0.01:
            self._send(self._targets)

    def _aim_linkages(self) -> None:
        """Aim each linkage's fingertip at the arc position of its finger's measured lateral joint.

        The velocity target is the arc's slope times the finger's measured
        velocity: without it the fingertip trails its finger by the PD's lag
        (measured: 5 mm at a free close on PyBullet), then catches up once the
        pads touch and drags the held object along the approach. While a
        finger moves, the fingertips are re-aimed after every physics step (a
        Backend step callback, removed once the fingers rest): re-aimed only
        each control tick, a fingertip overshot its finger's stop at contact
        by up to a tick's travel (2.4 mm). At rest nothing is sent unless a
        target moved (0.1 um): holding still is most of a trial.
        """
        links = self.config.linkages
        be = self.robot.backend
        if not links or be is None or self.robot.body is None:
            return
        # this runs after every physics step while a finger moves: names and gains are built once
        plan = self._link_plan
        if plan is None:
            names = [k.follower for k in links]
            plan = self._link_plan = (
                self.robot.joint_index(tuple(k.leader for k in links)),
                names,
                [k.stiffness for k in links],
                [k.damping for k in links],
                [self.robot.urdf_joints[n].effort for n in names],
            )
        leaders, names, stiffness, damping, force_limit = plan
        pos, vel = be.get_joint_motion(self.robot.body)  # Robot.joint_motion, its index cached
        # plain floats, not arrays: two or three values per call, NumPy's per-call cost dominated
        pl, vl = pos[leaders].tolist(), vel[leaders].tolist()
        t = [k.target(p) for k, p in zip(links, pl)]
        v = [k.rate(p) * w for k, p, w in zip(links, pl, vl)]
        moving = max(abs(w) for w in vl) > 1e-4
        if moving and (self._link_cb is None or self._link_cb[0] is not be):
            self._link_cb = (be, be.add_step_callback(self._aim_linkages))
        elif not moving and self._link_cb is not None:
            if self._link_cb[0] is be:
                be.remove_step_callback(self._link_cb[1])
            self._link_cb = None
        self._aimed_at = be.time if moving else None
        if (
            not moving
            and self._link_sent is not None
            and max(abs(a - b) for a, b in zip(t, self._link_sent)) < 1e-7
        ):
            return
        self._link_sent = None if moving else t
        be.retarget_joints(
            self.robot.body,
            t,
            v,
            joints=names,
            stiffness=stiffness,
            damping=damping,
            force_limit=force_limit,
        )

    def update(self) -> None:
        """Re-aim follower joints (called every control tick while the robot steps)."""
        cb = self._link_cb
        be = self.robot.backend
        # while the fingers move, the step callback has already re-aimed them after this very step:
        # the same measured joints would give the same targets again
        if be is None or cb is None or cb[0] is not be or self._aimed_at != be.time:
            self._aim_linkages()
        if be is not None and self.robot.body is not None:
            self._refresh_gravity()
        if not self.config.follow or self.robot.body is None:
            return
        pos = self.robot.joint_positions(self.joints)
        vel = self.robot.joint_velocities(self.joints)
        names, q, k_, d_, f_ = [], [], [], [], []
        for fj, lj, ratio in self.config.follow:
            i, k = self.joints.index(fj), self.joints.index(lj)
            stalled = abs(vel[k]) < 0.05 and abs(self._targets[k] - pos[k]) > 0.02
            target = (
                self._targets[i]
                if stalled
                else np.clip(ratio * pos[k], self.lower[i], self.upper[i])
            )
            names.append(fj)
            q.append(float(target))
            k_.append(self.config.stiffness[i])
            d_.append(self.config.damping[i])
            f_.append(float(self._force[i]))
        self.robot.backend.set_joint_targets(
            self.robot.body,
            q,
            [0.0] * len(q),
            joints=names,
            stiffness=k_,
            damping=d_,
            force_limit=f_,
        )

    def open(self, *, wait: float = 0.5) -> GraspResult:
        self.set_command(self.config.open)
        return self._wait(None, wait, self.config.open)

    def close(
        self,
        *,
        force_limit: float | Sequence[float] | None = None,
        obj: BodyId | None = None,
        timeout: float = 1.5,
    ) -> GraspResult:
        """Close the grasp actuators with joint forces capped at ``force_limit``.

        Returns when the fingers have come to rest (on an object or fully
        closed) or at ``timeout``; ``contact`` says whether a finger touches
        ``obj``. Targets persist, so the hand keeps squeezing afterwards.
        """
        u = self.command.copy()
        for k, a in enumerate(self.config.actuators):
            if a in self.config.grasp_actuators:
                u[k] = self.config.closed[k]
        cfg = self.config
        if cfg.close_speed is not None and len(cfg.finger_links) == len(self.joints):
            res = self._close_tracked(u, force_limit, obj, timeout)
        else:
            self.set_command(u, force_limit)
            res = self._wait(obj, timeout, u)
        if self.config.kind == "parallel" and res.contact and not res.closed:
            res = self._squeeze(obj, force_limit, res)
        return res

    def _close_tracked(
        self, u: np.ndarray, force_limit, obj: BodyId | None, timeout: float
    ) -> GraspResult:
        """Close with each joint's target moving at ``close_speed``; a finger stops where it touches.

        Why: a step target saturates each drive at its force cap from the
        start, so each finger accelerates freely (PR2: a 0.2 kg finger at 3 N
        reached ~0.6 m/s) and hits the object alone; with the fingers closing
        vertically, gravity adds to one and subtracts from the other (2.1 N
        each), so the upper finger arrived first and knocked a cube held by
        the other hand 2.5 degrees round that hand's pad axis (SAPIEN; see
        docs/strategies.md, "One-hand holds"). Here both targets move together
        at the published gap speed; the finger whose link touches ``obj`` (or
        anything but the robot) gets its target ``force / stiffness`` past where
        it touched, an unsaturated spring pressing with ``force``, while the
        other finger carries on until it touches too.
        """
        cfg, r = self.config, self.robot
        be = r.backend
        q_goal = np.clip(cfg.joint_targets(u), self.lower, self.upper)
        f = np.broadcast_to(
            np.asarray(cfg.force_limit if force_limit is None else force_limit, float),
            (len(self.joints),),
        ).copy()
        k = np.asarray(cfg.stiffness, dtype=float)
        names = list(self.joints)
        per = max(1, int(round(r.control_period / be.config.timestep)))
        tick = per * be.config.timestep
        step = float(cfg.close_speed) * tick
        q = r.joint_positions(names)
        tgt = q.copy()
        sign = np.sign(q_goal - q)  # the closing direction of each joint
        stopped = np.zeros(len(names), dtype=bool)
        self.command = np.asarray(u, dtype=float)
        self._ff = (
            cfg.gravity_compensated
        )  # the targets below stay unsaturated: feed-forward is exact
        self._force = 1.5 * f  # an unsaturated spring presses with f at the f / k offset below
        t, rest = 0.0, 0.0
        while t < timeout:
            free = ~stopped
            tgt[free] = np.where(
                sign[free] > 0,
                np.minimum(tgt[free] + step, q_goal[free]),
                np.maximum(tgt[free] - step, q_goal[free]),
            )
            self._targets = tgt.copy()
            self._send(tgt)
            self._aim_linkages()
            r.step(per)
            t += tick
            q, v = r.joint_motion(names)
            links = self._touching_links(obj)
            for i, link in enumerate(cfg.finger_links):
                if not stopped[i] and link in links:
                    stopped[i] = True
                    tgt[i] = q[i] + sign[i] * f[i] / k[i]
            if stopped.all():
                break
            at_goal = np.all(stopped | (np.abs(tgt - q_goal) < 1e-12))
            rest = rest + tick if at_goal and np.abs(v).max() < 0.02 else 0.0
            if rest >= 0.1:
                break
        self._targets = tgt.copy()
        self._send(tgt)
        self._aim_linkages()
        res = self._wait(obj, 0.3, u)  # the spring presses; rest
        return GraspResult(
            res.contact, res.closed, res.actuators, res.joint_positions, t + res.time
        )

    def _touching_links(self, obj: BodyId | None) -> set[str]:
        """The hand's finger links that press on ``obj`` (or anything but the robot) now.

        Pressing, not merely listed: PhysX reports contact points from ``contact_offset`` (2 mm) away,
        and a finger stopped there with a 1.5 mm spring (3 N) never touched (measured, SAPIEN).
        """
        r = self.robot
        links = set(self.config.finger_links)
        return {
            c.link_a
            for c in r.backend.contacts(r.body, obj)
            if c.link_a in links and c.body_b != r.body and c.normal_force > 0.0
        }

    def _squeeze(self, obj: BodyId | None, force_limit, first: GraspResult) -> GraspResult:
        """Re-aim both fingers at the object's middle, a spring squeeze short of it.

        Why: two fingers driven at "fully closed" with the same force cap are
        both saturated — constant forces with no centring, so the object
        drifts sideways (docs/benchmarks/cube_spike.md). Aiming each finger ``F / k`` past the
        measured mid-width makes each an unsaturated spring pressing with
        ``F`` that pushes the object back to the middle if it moves.
        """
        f = np.broadcast_to(
            np.asarray(self.config.force_limit if force_limit is None else force_limit, float),
            (len(self.joints),),
        )
        k = np.asarray(self.config.stiffness, dtype=float)
        q = first.joint_positions
        u = np.array([float(np.mean(q)) - float(np.mean(f / k))])
        self.set_command(u, 1.5 * f, feed_forward=True)
        res = self._wait(obj, 0.5, u)
        return GraspResult(
            res.contact, False, res.actuators, res.joint_positions, first.time + res.time
        )

    def _wait(self, obj: BodyId | None, timeout: float, u_target: np.ndarray) -> GraspResult:
        r = self.robot
        dt = r.backend.config.timestep
        chunk = max(1, int(round(0.02 / dt)))
        t, rest = 0.0, 0.0
        names = list(self.joints)
        while t < timeout:
            r.step(chunk)  # Robot.step re-aims follower joints
            t += chunk * dt
            v = r.joint_velocities(names)
            rest = rest + chunk * dt if np.abs(v).max() < 0.02 else 0.0
            if rest >= 0.1 and t >= 0.1:
                break
        q = r.joint_positions(names)
        q_closed = np.clip(self.config.joint_targets(u_target), self.lower, self.upper)
        closed = bool(
            np.all(np.abs(q - q_closed) < 0.01 * np.maximum(1.0, np.abs(self.upper - self.lower)))
        )
        u_meas = np.linalg.lstsq(self.coupling, q, rcond=None)[0]
        return GraspResult(self.touching(obj), closed, u_meas, q, t)

    def touching(self, obj: BodyId | None = None) -> bool:
        r = self.robot
        links = set(self.config.finger_links)
        for c in r.backend.contacts(r.body, obj):
            if c.link_a in links and c.body_b != r.body:
                return True
        return False


#: A dexterous hand is a gripper with more actuators; the name reads better in hand code.
RobotHand = Gripper
