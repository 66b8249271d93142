"""Executing an in-grasp plan on the simulated Allegro hand (Level I, paper sections II-B and II-E).

One trial, through the :class:`~benchharness.backends.interface.Backend`
interface only (so it runs on PyBullet and SAPIEN alike):

1. **Set-up.** The hand is fixed in space, palm up by default
   (:attr:`ExecConfig.palm`; why: ``docs/ingrasp.md``, "Why palm up"). Our model of the task's object is placed where
   the fingertips touch its surface at ``q_c``, where fingers commanded to the published
   grasp ``q_0`` stop against the squeeze (:attr:`ExecConfig.grasp_q0`, :func:`touch_configuration`;
   ``q_c = q_0`` with ``"contact"``) (:mod:`.placement`), then displaced by the set-up noise (drawn
   from ``ctx.rng``), and held there by a fixed constraint to the palm (the
   "human" of the protocol) while the fingers, opened
   :attr:`ExecConfig.preshape_open` away from the surface, close onto it
   commanded to ``q_0`` (``"contact"``: ``q_0`` plus the squeeze offset). The constraint is
   removed, the grasp settles, and the achieved object pose is the set-up pose.
2. **Execution.** The planned joint trajectory, linearly interpolated
   between its waypoints over the plan's duration (1.67 s), plus the squeeze
   offset's change from ``q_0`` (``"contact"``: plus the squeeze offset), is sent as joint
   position targets every control period.
3. **Stability check.** The last target is held for
   :attr:`ExecConfig.hold_s` (5 s) with nothing but the hand touching the
   object; the object's drift over the hold is reported.

From the release on, the object counts as **dropped** when no used
fingertip has touched it for :attr:`ExecConfig.drop_no_contact_s`, when it
touches anything but the hand (the ground), or when its centre gets
:attr:`ExecConfig.drop_distance` farther from the fingertip centroid than
at the grasp.

**Squeeze.** A plan is kinematic: no force in it holds the object. Each used fingertip is
therefore given an
internal force ``f_i = s (g - p_i)`` towards the centroid ``g`` of the used
fingertip centres ``p_i``, scaled so the mean force is
:attr:`ExecConfig.squeeze_force`. These forces sum to zero and have zero
net moment about any point (``sum p_i x (g - p_i) = 3 g x g = 0``): they
grip without pushing the object anywhere. Through the hand's joint PD
stiffness ``K`` they become a joint-target offset ``dq = K^-1 J^T f``
(``J`` the fingertip's position Jacobian), recomputed at every waypoint of
the plan and interpolated with it.

**Object frame.** The dataset's ``H`` is the object's pose in the palm frame
(``docs/ingrasp.md``) and the planner places the task's object frame at
``H_i`` at ``q_0``. Our body frame ``B`` is a different frame on the object,
so the task frame is attached to the body: ``A = B_nom^-1 H_i`` with
``B_nom`` the noise-free placement; the set-up pose is ``B_setup A``. With
:attr:`ExecConfig.reanchor_setup` (default, as the paper does: "a rigid
transformation between the human setup pose and the planned initial pose to
account for the human error") the reached pose is the object's executed
displacement in the palm frame applied to ``H_i``:
``H_r = (B_final B_setup^-1) H_i``. The planner predicts
``X_o(q_T) = C(q_T) C(q_0)^-1 H_i`` (``C`` the fingertip-triangle carrier),
so if the object moves exactly with the fingertips the executed ``reached``
equals the planned one; every difference is execution (slip, rolling,
tracking error, the squeeze).
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import torch
from scipy.spatial.transform import Rotation

from .hand import DTYPE, TIP_LINKS, HandKinematics, joint_indices
from .placement import InGraspPlacement, object_surface_arrays, place_object
from .planner import PlanResult
from .problem import InGraspProblem
from .rotations import pose_vector

__all__ = [
    "ExecConfig",
    "ExecResult",
    "InGraspExecutor",
    "SetupInfeasible",
    "squeeze_offsets",
    "finger_gravity",
    "PALM_ROTATIONS",
]

#: Palm frame (``palm_link``: fingers along +z, palm facing +x) in the world, per ``ExecConfig.palm``.
PALM_ROTATIONS = {
    "down": Rotation.from_euler("y", 90, degrees=True),  # palm normal +x -> -z, fingers -> +x
    "up": Rotation.from_euler("y", -90, degrees=True),  # palm normal +x -> +z, fingers -> -x
}


@dataclass(frozen=True)
class ExecConfig:
    """Settings of a simulated Level I trial (defaults documented in ``docs/ingrasp.md``)."""

    #: ``"up"``: palm facing up, the object resting on the fingertips (our placements put its centre
    #: beyond the fingertip plane, so palm down the squeeze and gravity push it out; docs/ingrasp.md);
    #: ``"down"``: palm facing the ground, nothing but fingertip friction holds the object.
    palm: str = "up"
    hand_height: float = 0.4  #: m, palm origin above the ground
    setup_pos_std: float = 0.001  #: m, per axis, set-up noise of the object position (palm frame)
    setup_rot_std_deg: float = 0.5  #: deg, per axis, set-up noise of the object orientation
    squeeze_force: float = 3.0  #: N, mean internal fingertip force (the grip) added to the plan
    preshape_open: float = (
        0.008  #: m, fingertips backed off from the surface before the grasp closes
    )
    close_s: float = 0.4  #: s, closing onto the object held by the "human" constraint
    settle_s: float = 0.4  #: s, after the constraint is removed, before the set-up pose is taken
    hold_s: float = 5.0  #: s, stability check after execution (paper II-E)
    object_friction: float | None = (
        None  #: object's friction coefficient; None = the physics default
    )
    control_period: float = 1.0 / 120.0  #: s between joint target updates
    check_period: float = 0.02  #: s between drop checks
    drop_no_contact_s: float = (
        0.1  #: s without any used fingertip touching the object that count as a drop
    )
    #: m, how much farther than at the grasp the object's centre may get from the fingertip centroid before
    #: it counts as dropped
    drop_distance: float = 0.03
    max_speed: float = 5.0  #: m/s, object speed treated as a physics blow-up
    reanchor_setup: bool = (
        True  #: reached = executed displacement applied to H_i (paper's set-up correction)
    )
    max_placement_gap: float = 0.002  #: m, placement fit worse than this is refused (unreachable)
    #: m, deepest the best placement may leave a hand part other than the used fingertips inside the
    #: object; deeper, the published grasp does not fit our model of the object and the trial is refused
    #: before any physics (unreachable): the engines would otherwise start from an interpenetration
    #: (SAPIEN ejected the airplane toy at 7-14 m/s). 1 mm is the tolerance of "a valid grasp of the
    #: scan" in docs/objects.md; only the airplane toy's grasps exceed it (5.9, 6.5 mm)
    max_placement_penetration: float = 0.001
    #: friction cone half angle (deg) the set-up placement keeps the squeeze directions inside
    #: (``placement.place_object``). ``"friction"`` (default): ``atan(mu)`` of the fingertip-object
    #: contact's coefficient as the engine combines it (:meth:`Backend.pair_friction` of the object's
    #: friction and the hand links' ``PhysicsConfig.default_friction``; 45 deg at the defaults, 1.0);
    #: a number: that angle whatever the friction; None: contacts only (before 2026-12-02)
    placement_grip_cone_deg: float | Literal["friction"] | None = "friction"
    #: add the fingers' gravity holding torques (the engine's inverse dynamics at the measured joints,
    #: every control period) to the joint targets, as ``tau_g / K``: the PD spring's torque then goes
    #: into the squeeze instead of carrying the fingers (palm up the proximal joints of index and
    #: middle carry ~0.05 N m of finger weight against a ~0.13 N m squeeze). False: plain PD (before
    #: 2026-12-02). docs/ingrasp.md, "Execution drops"
    gravity_compensation: bool = True
    #: what the published initial grasp ``q_0`` is. ``"command"`` (default): the joint set-point the
    #: grasp was commanded at (the file types every grasp joint to at most two decimals, 97 % of them
    #: multiples of 0.1 rad, where its measured poses carry ten: set-points, not encoder readings);
    #: a PD hand squeezing an object stops short of it, so the fingertips touch the object at
    #: ``q_c = q_0 - K^-1 J^T f(q_c)`` (:func:`touch_configuration`), the object is placed there, and
    #: the set-up and the plan's first target command ``q_0`` itself. ``"contact"``: the fingertips
    #: touch at ``q_0`` and the squeeze is commanded beyond it (before 2026-12-04). docs/ingrasp.md,
    #: "What the published grasp is"
    grasp_q0: Literal["contact", "command"] = "command"

    def __post_init__(self) -> None:
        if self.palm not in PALM_ROTATIONS:
            raise ValueError(f"palm must be one of {', '.join(PALM_ROTATIONS)}, not {self.palm!r}")
        if self.grasp_q0 not in ("contact", "command"):
            raise ValueError(f"grasp_q0 must be 'contact' or 'command', not {self.grasp_q0!r}")
        for name in (
            "hand_height",
            "control_period",
            "check_period",
            "drop_distance",
            "max_speed",
            "max_placement_gap",
            "max_placement_penetration",
        ):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be positive")
        for name in (
            "setup_pos_std",
            "setup_rot_std_deg",
            "squeeze_force",
            "preshape_open",
            "close_s",
            "settle_s",
            "hold_s",
            "drop_no_contact_s",
        ):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must be >= 0")
        if self.object_friction is not None and self.object_friction < 0:
            raise ValueError("object_friction must be >= 0")
        cone = self.placement_grip_cone_deg
        if isinstance(cone, str):
            if cone != "friction":
                raise ValueError(
                    f"placement_grip_cone_deg must be a number, 'friction' or None, not {cone!r}"
                )
        elif cone is not None and not 0.0 <= float(cone) <= 90.0:
            raise ValueError("placement_grip_cone_deg must be in [0, 90] deg")


class SetupInfeasible(ValueError):
    """The task's initial grasp cannot be set up on our model of its object (found before any physics).

    The in-grasp strategy ends such a trial ``unreachable`` with this message.
    """


@dataclass
class ExecResult:
    """What one simulated execution observed (poses in the palm frame, dataset convention)."""

    setup: np.ndarray  #: (7,) achieved set-up pose of the task frame
    reached: np.ndarray  #: (7,) reached pose of the task frame after the hold (or at the drop)
    dropped: bool
    phase: str  #: where the trial ended: "setup", "execution", "hold" or "done"
    message: str
    exec_sim_s: float  #: simulated seconds of trajectory execution
    extra: dict[str, Any] = field(default_factory=dict)


class _Dropped(Exception):
    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


def _jacobians(
    hand: HandKinematics, q: np.ndarray, fingers: tuple[str, ...]
) -> tuple[np.ndarray, np.ndarray]:
    """Fingertip positions (k, 3) and position Jacobians (k, 3, 4) w.r.t. each finger's own joints."""
    qt = torch.as_tensor(np.asarray(q, float), dtype=DTYPE)
    fn = lambda z: hand.tip_poses(z[None], fingers)[0, :, :3, 3]  # noqa: E731
    jac = torch.autograd.functional.jacobian(fn, qt)  # (k, 3, 4k)
    k = len(fingers)
    blocks = np.stack([jac[i, :, 4 * i : 4 * i + 4].numpy() for i in range(k)])
    with torch.no_grad():
        pos = fn(qt).numpy()
    return pos, blocks


def squeeze_offsets(
    hand: HandKinematics,
    q: np.ndarray,
    fingers: tuple[str, ...],
    force: float,
    stiffness: np.ndarray,
) -> np.ndarray:
    """Joint offsets (4 k,) that press the fingertips with internal forces ``s (g - p_i)``, mean ``force`` N."""
    pos, jac = _jacobians(hand, q, fingers)
    d = pos.mean(axis=0) - pos
    scale = force / max(float(np.mean(np.linalg.norm(d, axis=1))), 1e-9)
    tau = np.concatenate([jac[i].T @ (scale * d[i]) for i in range(len(fingers))])
    return tau / np.asarray(stiffness, float)


def touch_configuration(
    hand: HandKinematics,
    q0: np.ndarray,
    fingers: tuple[str, ...],
    force: float,
    stiffness: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    iterations: int = 8,
) -> np.ndarray:
    """Where fingers commanded to ``q0`` stop on an object they squeeze with mean ``force`` N.

    A joint PD drive of stiffness ``K`` commanded to ``q0`` holds a fingertip force ``f`` at
    ``q_c = q0 - K^-1 J(q_c)^T f(q_c)`` (the squeeze of :func:`squeeze_offsets`), solved by fixed
    point from ``q0`` (each step moves less than a milliradian after three); 16 joints in and out,
    only ``fingers``' joints changed (``stiffness`` is theirs), kept inside ``lower``..``upper``.
    """
    idx = joint_indices(fingers)
    q = np.asarray(q0, float).copy()
    for _ in range(iterations):
        q[idx] = q0[idx] - squeeze_offsets(hand, q[idx], fingers, force, stiffness)
        q = np.clip(q, lower, upper)
    return q


def backoff_offsets(
    hand: HandKinematics, q: np.ndarray, fingers: tuple[str, ...], distance: float
) -> np.ndarray:
    """Joint offsets (4 k,) moving each fingertip ``distance`` away from the fingertip centroid (least norm)."""
    pos, jac = _jacobians(hand, q, fingers)
    d = pos - pos.mean(axis=0)
    d = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9)
    return np.concatenate([np.linalg.pinv(jac[i]) @ (distance * d[i]) for i in range(len(fingers))])


def finger_gravity(backend, robot, joints) -> np.ndarray:
    """Gravity holding torques (N m) of ``joints`` of ``robot`` at its measured configuration.

    The engine's own inverse dynamics (``Backend.gravity_torques``). Added to a PD drive's torque
    (as a target shift ``tau / K``) it carries the fingers' weight, as the authors' Allegro PD node
    does (joint PD plus KDL gravity compensation); the spring's torque is then the contact force's.
    """
    tau = np.asarray(backend.gravity_torques(robot.body), float)
    return tau[robot.joint_index(list(joints))]


def _mat(pose) -> np.ndarray:
    return pose.as_matrix()


def _random_rotation(rng: np.random.Generator, std_rad: float) -> np.ndarray:
    return (
        Rotation.from_rotvec(rng.normal(0.0, std_rad, 3)).as_matrix() if std_rad > 0 else np.eye(3)
    )


class InGraspExecutor:
    """Runs one plan in one backend world with the Allegro robot (see the module docstring)."""

    def __init__(self, hand: HandKinematics, config: ExecConfig | None = None) -> None:
        self.hand = hand
        self.config = config or ExecConfig()

    # ----------------------------------------------------------------- set-up geometry
    def grip_cone_deg(self, friction: float) -> float | None:
        """The placement's friction cone half angle (deg) for a contact friction coefficient ``friction``.

        ``atan(mu)`` with :attr:`ExecConfig.placement_grip_cone_deg` ``"friction"``; the configured
        angle otherwise (None: no cone).
        """
        cone = self.config.placement_grip_cone_deg
        if cone == "friction":
            return float(np.degrees(np.arctan(float(friction))))
        return None if cone is None else float(cone)

    def contact_friction(self, backend) -> float:
        """The fingertip-object friction coefficient in ``backend``: the engine's combination of the
        object's (:attr:`ExecConfig.object_friction`, else the physics default) and the hand links'
        (the physics default)."""
        hand_mu = float(backend.config.default_friction)
        obj_mu = hand_mu if self.config.object_friction is None else self.config.object_friction
        return float(backend.pair_friction(obj_mu, hand_mu))

    def placement(
        self,
        problem: InGraspProblem,
        object_name: str,
        friction: float = 1.0,
        q_touch: np.ndarray | None = None,
    ) -> InGraspPlacement:
        """Where the (noise-free) object sits when the fingertips touch it at ``q_touch`` (default
        ``q_0``) for a contact friction ``friction``; cached per hand, task, object, joints and
        friction cone."""
        q = problem.q_rest if q_touch is None else q_touch
        return _cached_placement(
            self.hand,
            problem.task_id,
            object_name,
            tuple(np.round(q, 12)),
            problem.fingers,
            self.grip_cone_deg(friction),
        )

    def nominal_setup(
        self, backend, robot, problem: InGraspProblem, object_name: str
    ) -> tuple[np.ndarray, InGraspPlacement, float]:
        """Where the set-up puts the object before its noise: ``(q_touch, placement, friction)``.

        ``q_touch`` (16,): the joints at which the fingertips touch (:attr:`ExecConfig.grasp_q0`);
        the placement makes them touch there for the contact friction of ``backend``. The plan's
        collision term reads the same answer. Raises :class:`SetupInfeasible` when no pose of the
        object fits the grasp (see :meth:`run`).
        """
        cfg = self.config
        hand_grip = robot.gripper("hand")
        kp = np.asarray(hand_grip.config.stiffness, float)
        idx = joint_indices(problem.fingers)
        lo, hi = hand_grip.lower, hand_grip.upper
        q0 = problem.q_rest.copy()
        q_touch = (
            touch_configuration(self.hand, q0, problem.fingers, cfg.squeeze_force, kp[idx], lo, hi)
            if cfg.grasp_q0 == "command"
            else q0.copy()
        )
        mu = self.contact_friction(backend)
        place = self.placement(problem, object_name, mu, q_touch)
        if place.max_gap > cfg.max_placement_gap:
            raise SetupInfeasible(
                f"{problem.task_id}: no pose of our {object_name} model touches all fingertips "
                f"(best gap {place.max_gap * 1e3:.1f} mm)"
            )
        if place.penetration > cfg.max_placement_penetration:
            raise SetupInfeasible(
                f"{problem.task_id}: the published grasp does not fit our {object_name} model: at the "
                f"best placement a hand part is {place.penetration * 1e3:.1f} mm inside it "
                f"(max_placement_penetration {cfg.max_placement_penetration * 1e3:g} mm)"
            )
        return q_touch, place, mu

    # ----------------------------------------------------------------- the trial
    def run(
        self,
        backend,
        robot,
        problem: InGraspProblem,
        plan: PlanResult,
        object_name: str,
        rng: np.random.Generator,
        recorder=None,
        duration_s: float = 1.67,
    ) -> ExecResult:
        """Set up, execute ``plan`` (timed over ``duration_s``) and hold, in ``backend`` with ``robot``.

        Raises :class:`~benchharness.backends.interface.SimulationError` on a
        blow-up (non-finite state, object faster than ``max_speed``) and
        :class:`SetupInfeasible` when no placement of the object fits the grasp:
        none touches every used fingertip within ``max_placement_gap``, or the
        best leaves another hand part deeper than ``max_placement_penetration``
        inside the object.
        """
        from benchharness.geometry import Pose
        from benchharness.objects import load_object

        cfg = self.config
        hand_joints = tuple(getattr(getattr(robot, "grippers", {}).get("hand"), "joints", ()))
        if hand_joints != tuple(f"joint_{i}" for i in range(16)):
            raise ValueError(
                "in-grasp execution needs the allegro robot (a 16-joint 'hand' joint_0..joint_15), "
                f"got {getattr(robot, 'name', robot)!r}"
            )
        robot_urdf = getattr(robot, "urdf_path", None)
        if (
            self.hand.urdf_path is not None
            and robot_urdf is not None
            and Path(self.hand.urdf_path).resolve() != Path(robot_urdf).resolve()
        ):  # a plan and set-up for one hand executed on another would put the fingertips elsewhere
            raise ValueError(
                f"the planning hand model ({self.hand.urdf_path}) is not the simulated robot's "
                f"description ({robot_urdf})"
            )
        wall0 = time.perf_counter()
        q0 = problem.q_rest.copy()
        q_touch, place, mu = self.nominal_setup(backend, robot, problem, object_name)
        hand_grip = robot.gripper("hand")
        kp = np.asarray(hand_grip.config.stiffness, float)
        idx = joint_indices(problem.fingers)
        lo, hi = hand_grip.lower, hand_grip.upper
        wall_place = time.perf_counter() - wall0
        model = load_object(object_name)

        back = backoff_offsets(self.hand, q_touch[idx], problem.fingers, cfg.preshape_open)
        q_pre = q_touch.copy()
        q_pre[idx] += back
        q_pre = np.clip(q_pre, lo, hi)

        # the world: ground, hand fixed in space, object
        backend.add_ground()
        palm_rot = PALM_ROTATIONS[cfg.palm]
        base = Pose.from_rotation([0.0, 0.0, cfg.hand_height], palm_rot)
        robot.spawn(backend, base, q=q_pre)
        palm_w = _mat(backend.get_link_pose(robot.body, "palm_link"))
        # set-up noise, in the palm frame, about the object's centre of mass
        com = np.asarray(model.body_kwargs().get("com") or np.zeros(3), float)
        b_nom = place.pose
        dp = rng.normal(0.0, cfg.setup_pos_std, 3) if cfg.setup_pos_std > 0 else np.zeros(3)
        dr = _random_rotation(rng, np.radians(cfg.setup_rot_std_deg))
        c_nom = b_nom[:3, :3] @ com + b_nom[:3, 3]
        b_noisy = np.eye(4)
        b_noisy[:3, :3] = dr @ b_nom[:3, :3]
        b_noisy[:3, 3] = c_nom + dp - b_noisy[:3, :3] @ com
        kw = model.body_kwargs()
        if cfg.object_friction is not None:
            kw["friction"] = cfg.object_friction
        obj = backend.add_body(pose=Pose.from_matrix(palm_w @ b_noisy), **kw)
        if recorder is not None:
            recorder.watch_contact(obj, robot.body)
            recorder.event(
                "setup_placement",
                task=problem.task_id,
                object=object_name,
                tip_gaps_mm=(place.tip_gaps * 1e3).round(3).tolist(),
                penetration_mm=round(place.penetration * 1e3, 3),
                noise_pos_mm=(dp * 1e3).round(3).tolist(),
                noise_rot_deg=float(np.degrees(Rotation.from_matrix(dr).magnitude())),
            )
        a_task = np.linalg.inv(b_nom) @ problem.object_initial  # task frame in the body frame
        extra: dict[str, Any] = {
            "palm": cfg.palm,
            "squeeze_force_n": cfg.squeeze_force,
            "placement_gap_mm": round(place.max_gap * 1e3, 4),
            "placement_penetration_mm": round(place.penetration * 1e3, 3),
            "placement_rotation_change_deg": round(place.rotation_change_deg, 3),
            "placement_grip_angles_deg": np.round(place.grip_angles_deg, 1).tolist(),
            # how far (rad, largest joint) the fingertips touch from the published q_0 (grasp_q0)
            "touch_offset_rad": round(float(np.max(np.abs(q0 - q_touch))), 5),
            "contact_friction": round(mu, 6),
            "placement_grip_cone_deg": self.grip_cone_deg(mu),
            "setup_noise_pos_mm": (dp * 1e3).round(4).tolist(),
            "setup_noise_rot_deg": round(
                float(np.degrees(Rotation.from_matrix(dr).magnitude())), 4
            ),
            "wall_placement_s": round(wall_place, 3),
        }
        t_start = float(backend.time)
        per = max(1, int(round(cfg.control_period / backend.config.timestep)))
        tip_links = {TIP_LINKS[f] for f in problem.fingers}
        tips0 = self.hand.tip_poses_np(q_touch[idx][None], problem.fingers)[0][:, :3, 3]
        state = {
            "last_contact": float(backend.time),
            "checked": float(backend.time),
            "com_dist": float(np.linalg.norm(c_nom - tips0.mean(axis=0))),
        }

        def obj_in_palm() -> np.ndarray:
            return np.linalg.inv(palm_w) @ _mat(backend.get_pose(obj))

        def tips_centroid() -> np.ndarray:
            return np.mean(
                [
                    _mat(backend.get_link_pose(robot.body, TIP_LINKS[f]))[:3, 3]
                    for f in problem.fingers
                ],
                axis=0,
            )

        def check(active: bool) -> None:
            """Drop and blow-up checks (``active``: only once the object is free)."""
            backend.check_finite([obj, robot.body])
            lin, _ = backend.get_velocity(obj)
            if float(np.linalg.norm(lin)) > cfg.max_speed:
                from benchharness.backends.interface import SimulationError

                raise SimulationError(
                    f"object speed {np.linalg.norm(lin):.1f} m/s (> {cfg.max_speed} m/s): blow-up"
                )
            if not active:
                return
            now = float(backend.time)
            cs = backend.contacts(obj, None)
            if any(c.body_b == robot.body and c.link_b in tip_links for c in cs):
                state["last_contact"] = now
            elif now - state["last_contact"] >= cfg.drop_no_contact_s:
                raise _Dropped(f"no fingertip contact for {now - state['last_contact']:.2f} s")
            if any(c.body_b not in (robot.body, obj) for c in cs):
                raise _Dropped("object touches the ground (external support)")
            com_w = _mat(backend.get_pose(obj)) @ np.append(com, 1.0)
            dist = float(np.linalg.norm(com_w[:3] - tips_centroid()))
            if dist > state["com_dist"] + cfg.drop_distance:
                raise _Dropped(
                    f"object centre {dist * 100:.1f} cm from the fingertip centroid "
                    f"({state['com_dist'] * 100:.1f} cm at the grasp)"
                )

        grav = cfg.gravity_compensation and backend.capabilities.gravity_torques
        cap = np.asarray(hand_grip.config.force_limit, float)

        def command(q: np.ndarray) -> None:
            """Joint targets ``q``; with gravity compensation shifted by ``tau_g / K`` (cap + |tau_g|)."""
            if not grav:
                hand_grip.set_command(q)
                return
            tau = finger_gravity(backend, robot, hand_grip.joints)
            hand_grip.set_command(q + tau / kp, force_limit=cap + np.abs(tau))

        def run_for(seconds: float, target_fn, active: bool) -> None:
            n = max(1, int(round(seconds / (per * backend.config.timestep))))
            t0 = float(backend.time)
            for k in range(n):
                command(target_fn(float(backend.time) - t0))
                backend.step(per)
                if float(backend.time) - state["checked"] >= cfg.check_period - 1e-9 or k == n - 1:
                    state["checked"] = float(backend.time)
                    check(active)

        # the set-up's closing target: q_0 plus the squeeze, or (grasp_q0 "command") q_0 itself
        q_closed = q0.copy()
        if cfg.grasp_q0 == "contact":
            q_closed[idx] += squeeze_offsets(
                self.hand, q0[idx], problem.fingers, cfg.squeeze_force, kp[idx]
            )
        phase = "setup"
        exec_sim = 0.0
        reached_m = None
        setup_m = None
        try:
            # 1. set-up: the "human" holds the object against the palm frame while the fingers close
            human = backend.attach(robot.body, "palm_link", obj, None, Pose.from_matrix(b_noisy))
            run_for(
                cfg.close_s,
                lambda t: q_pre + (q_closed - q_pre) * min(1.0, t / max(cfg.close_s * 0.5, 1e-9)),
                active=False,
            )
            backend.detach(human)
            state["last_contact"] = float(backend.time)
            run_for(cfg.settle_s, lambda t: q_closed, active=True)
            b_setup = obj_in_palm()
            setup_m = b_setup @ a_task
            tips_setup = [
                lk
                for lk in tip_links
                if any(c.link_b == lk for c in backend.contacts(obj, robot.body))
            ]
            extra["setup_tip_contacts"] = sorted(tips_setup)
            forces = {lk: 0.0 for lk in sorted(tip_links)}
            for c in backend.contacts(obj, robot.body):
                if c.link_b in forces:
                    forces[c.link_b] += float(c.normal_force)
            extra["setup_tip_forces_n"] = {k: round(v, 4) for k, v in forces.items()}
            extra["setup_joint_error_rad"] = round(
                float(np.max(np.abs(robot.joint_positions()[idx] - q_touch[idx]))), 5
            )
            if recorder is not None:
                recorder.event(
                    "setup",
                    pose=pose_vector(setup_m).round(6).tolist(),
                    tip_contacts=sorted(tips_setup),
                )

            # 2. execution: planned joints (linear between waypoints) + squeeze offset, as position targets
            phase = "execution"
            traj = np.asarray(plan.q_hand, float)
            n_wp = traj.shape[0] - 1
            dur = float(duration_s)
            offs = np.array(
                [
                    squeeze_offsets(
                        self.hand, traj[w, idx], problem.fingers, cfg.squeeze_force, kp[idx]
                    )
                    for w in range(n_wp + 1)
                ]
            )
            if cfg.grasp_q0 == "command":  # the first target is q_0 itself (the squeeze's origin)
                offs = offs - offs[0]
            targets = traj.copy()
            targets[:, idx] += offs

            def along(t: float) -> np.ndarray:
                s = min(max(t / dur, 0.0), 1.0) * n_wp
                w = min(int(np.floor(s)), n_wp - 1)
                a = s - w
                return (1.0 - a) * targets[w] + a * targets[w + 1]

            t_exec = float(backend.time)
            run_for(dur, along, active=True)
            exec_sim = float(backend.time) - t_exec
            b_exec = obj_in_palm()
            # 3. stability: hold the last target, nothing else touches the object
            phase = "hold"
            run_for(cfg.hold_s, lambda t: targets[-1], active=True)
            b_final = obj_in_palm()
            phase = "done"
            dropped, message = False, ""
            drift = np.linalg.inv(b_exec) @ b_final
            extra["hold_drift_mm"] = round(float(np.linalg.norm(drift[:3, 3])) * 1e3, 4)
            extra["hold_drift_deg"] = round(
                float(np.degrees(Rotation.from_matrix(drift[:3, :3]).magnitude())), 4
            )
        except _Dropped as d:
            dropped, message = True, f"dropped during {phase}: {d.reason}"
            b_final = obj_in_palm()
            if setup_m is None:
                b_setup = b_final
                setup_m = b_final @ a_task
            if phase == "execution":
                exec_sim = float(backend.time) - t_exec
        tips_final = sorted(
            lk for lk in tip_links if any(c.link_b == lk for c in backend.contacts(obj, robot.body))
        )
        if cfg.reanchor_setup:
            reached_m = b_final @ np.linalg.inv(b_setup) @ problem.object_initial
        else:
            reached_m = b_final @ a_task
        extra.update(
            phase=phase,
            final_tip_contacts=tips_final,
            sim_total_s=round(float(backend.time) - t_start, 4),
            wall_exec_s=round(time.perf_counter() - wall0 - wall_place, 3),
            reached_unanchored=pose_vector(b_final @ a_task).round(7).tolist(),
            exec_config=asdict(cfg),
        )
        if recorder is not None:
            recorder.event("end", phase=phase, dropped=dropped, message=message)
        return ExecResult(
            pose_vector(setup_m), pose_vector(reached_m), dropped, phase, message, exec_sim, extra
        )


_PLACEMENTS: dict[tuple, InGraspPlacement] = {}


def _cached_placement(
    hand: HandKinematics,
    task_id: str,
    object_name: str,
    q_rest: tuple,
    fingers: tuple,
    grip_cone_deg: float | None = None,
) -> InGraspPlacement:
    from benchharness.objects import load_object

    key = (hand.urdf_path, task_id, object_name, q_rest, fingers, grip_cone_deg)
    if key not in _PLACEMENTS:
        v, n, c, sym = object_surface_arrays(load_object(object_name))
        _PLACEMENTS[key] = place_object(
            hand,
            np.asarray(q_rest, float),
            fingers,
            v,
            n,
            c,
            symmetric=sym,
            grip_cone_deg=grip_cone_deg,
        )
    return _PLACEMENTS[key]
