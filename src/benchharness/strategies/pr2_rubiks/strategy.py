"""The PR2 baselines: the bimanual state machine with the PR2's parallel-gripper grasp module.

The machine (:mod:`..bimanual.machine`: plan, pick, twist, regrasp, hand over,
release, the belief carried by commanded motion) is every robot's; what is
the PR2's is here: which of the four finger placements a side grip takes
(:meth:`PR2Grasp.choose`, by joint motion, finger crossing and, for a giver,
whether the hand-over turn can be carried), the approach (stand-off,
pre-grasp, grip) and the two-stage close of the parallel gripper.
``sensor-aided`` adds a pre-touch re-localisation at every pre-grasp
(:class:`PR2SensorAidedGrasp`).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose
from ..bimanual.frames import DIRECTIONS, along, grip_candidates, unit_box_grid
from ..bimanual.machine import (
    CUBE_HALF,
    BimanualRubiksMachine,
    GripRequest,
    Hand,
    StrategyFailure,
)
from ..regrasp import HandModel
from .config import PR2RubiksConfig

__all__ = [
    "DeadReckoningStrategy",
    "PR2Grasp",
    "PR2SensorAidedGrasp",
    "SensorAidedStrategy",
    "StrategyFailure",
]


#: radius (m) of the wrist flex link's collision sphere, centred on the wrist roll axis at the palm
#: link's origin (robots/descriptions/pr2.py): rigid with the tool frame whatever the wrist roll
WRIST_RADIUS = 0.035


#: radius (m) round the segments shoulder lift -> elbow -> wrist flex within which the PR2's arm lies
#: (the elbow flex link's sphere is 5 cm; the upper-arm and forearm boxes are 9 and 8 cm square)
ARM_RADIUS = 0.05


def _arm_points(hand: Hand, q: np.ndarray) -> np.ndarray:
    """Points (world, m) on the arm's axis from the shoulder lift through the elbow to the wrist flex at
    joints ``q`` (one row per configuration: (B, 13, 3))."""
    o = hand.arm.joint_origins(np.atleast_2d(q))
    s = np.linspace(0.0, 1.0, 7)[:, None]
    pts = np.concatenate(
        [
            o[:, None, 1] + s[None] * (o[:, None, 3] - o[:, None, 1]),
            o[:, None, 3] + s[None, 1:] * (o[:, None, 5] - o[:, None, 3]),
        ],
        axis=1,
    )
    w = hand.arm.base_pose().as_matrix()
    return np.einsum("ij,bpj->bpi", w[:3, :3], pts) + w[:3, 3]


def arm_pair_clearance(m: BimanualRubiksMachine, hand: Hand, q: np.ndarray) -> np.ndarray:
    """Distance (m) between each point of ``hand``'s arm axis at each row of ``q`` and each of the other
    arm's where it is, both arms as ``ARM_RADIUS`` round their axes: (B, 13 * 13)."""
    mine = _arm_points(hand, q)
    other = m.other(hand)
    theirs = _arm_points(other, other.arm.positions())
    d = np.linalg.norm(mine[:, :, None, :] - theirs[0][None, None, :, :], axis=-1)
    return d.reshape(len(d), -1) - 2 * ARM_RADIUS


def arm_clearance(m: BimanualRubiksMachine, hand: Hand, q: np.ndarray) -> np.ndarray:
    """Least distance (m) between ``hand``'s arm at each row of ``q`` and the other arm where it is, both
    as ``ARM_RADIUS`` round their axes."""
    return arm_pair_clearance(m, hand, q).min(axis=1)


@functools.cache
def _open_hand_points() -> np.ndarray:
    """The open hand's points (tool frame): constants of the gripper's description, so built once and
    returned read-only (every free-hand path check asks for them)."""
    from ...robots.descriptions.pr2 import GRIPPER_MAX_OPENING, PALM_BOX, TCP_X, finger_boxes

    boxes = [*finger_boxes(GRIPPER_MAX_OPENING), PALM_BOX]
    grid = unit_box_grid()
    pts = np.concatenate([np.asarray(c) + grid * np.asarray(s) for c, s in boxes])
    # the wrist flex link's sphere (the palm frame's origin): a stand-off move that changes the arm's
    # posture can swing the wrist through the cube with the hand itself well clear (measured: 52 N from
    # l_wrist_flex_link, the tool frame never nearer than 125 mm, the held cube turned 90 deg; SAPIEN
    # Rubiks-1-20 sensor-aided seed 0)
    ball = grid * 2 * WRIST_RADIUS
    ball = ball[np.linalg.norm(ball, axis=1) <= WRIST_RADIUS + 1e-9]
    out = np.concatenate([pts, ball]) - np.array([TCP_X, 0.0, 0.0])
    out.setflags(write=False)
    return out


def _belief_error(est: Pose, true: Pose, approach: np.ndarray) -> tuple[float, list, list]:
    """A belief's error against the engine's truth, for the record only: along the grip's approach (the
    work axis: past half a cubie a pad lands on the wrong slab) and in full (mm), and its turn (deg).
    Dead reckoning's ``grasp`` event and sensor-aided's ``pretouch`` event report the same quantities."""
    dp = est.p - true.p
    rv = (est.rotation * true.rotation.inv()).as_rotvec()
    return (
        round(1000 * float(dp @ approach), 3),
        np.round(1000 * dp, 3).tolist(),
        np.round(np.degrees(rv), 3).tolist(),
    )


class PR2Grasp:
    """The PR2's grasp module: side grips of a parallel gripper (tool x = approach, y = fingers)."""

    approach_axis = 0
    finger_axis = 1
    gripper_name = "{side}_gripper"
    robot_name: str | None = None  # any robot with PR2-like arms and parallel grippers

    def __init__(self, config: PR2RubiksConfig | None = None) -> None:
        self.config: PR2RubiksConfig = config or PR2RubiksConfig()

    def hand_model(self) -> HandModel:
        return HandModel(name="pr2", pick_approaches=tuple(self.config.pick_approaches))

    def hand_state(self) -> Any:
        return None

    def hand_points(self, m: BimanualRubiksMachine, hand: Hand) -> np.ndarray:
        """Points (tool frame, m) filling the open hand's collision boxes: both pads and finger bars at
        the 90 mm opening, the palm (:func:`...robots.descriptions.pr2.finger_boxes`) and the wrist flex
        link's sphere behind it (rigid with the tool frame: on the wrist roll axis); the machine keeps
        them clear of the cube when the free hand moves to a stand-off (``sweep_clearance``)."""
        return _open_hand_points()

    def arm_margin(self, m: BimanualRubiksMachine, hand: Hand, q: np.ndarray) -> np.ndarray:
        """How far (m) each part of the arm at each row of ``q`` stays beyond ``arm_clearance`` from each
        part of the other arm where it is, both modelled as ``ARM_RADIUS`` round their axes
        (:func:`arm_pair_clearance`; one column per pair of axis points): the machine keeps the moves it
        solves from the arm's joints from bringing a pair below 0 (``arm_check``)."""
        return arm_pair_clearance(m, hand, np.atleast_2d(q)) - self.config.arm_clearance

    def hand_boxes(
        self, m: BimanualRubiksMachine, hand: Hand
    ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Where the robot believes ``hand``'s gripper is: its collision boxes (palm, pads and finger bars,
        :func:`...robots.descriptions.pr2.finger_boxes`) at the commanded tool pose, the pads the cube's
        width apart while it holds, fully open otherwise; each (centre (world), rotation (3 x 3), half
        extents). The pre-touch self-filter drops returns from them; the machine keeps a sliding hand off
        them (``hand_clearance``)."""
        from ...robots.descriptions.pr2 import FINGER_TRAVEL, PAD_GAP, PALM_BOX, TCP_X, finger_boxes

        opening = 2 * CUBE_HALF if hand.holding else 2 * (FINGER_TRAVEL + PAD_GAP)
        tool = hand.cmd
        rot = tool.rotation.as_matrix()
        return [
            (tool.apply(np.array(c) - [TCP_X, 0.0, 0.0]), rot, np.array(size) / 2)
            for c, size in (PALM_BOX, *finger_boxes(opening))
        ]

    def take_relation(self) -> str | None:
        # in a hand-over the giver's finger lies on the face the taker comes to: only crossing fingers pass it
        return "cross"

    def _offset(self, depth: int) -> float:
        return self.config.rotator_offset if depth == 1 else self.config.holder_offset

    def choose(
        self, m: BimanualRubiksMachine, hand: Hand, req: GripRequest
    ) -> tuple[Pose, np.ndarray | None]:
        """The grip (of four finger placements) the arm reaches with the least joint motion, and its IK solution.

        The PR2's forearm and wrist rolls are continuous and IK returns them on
        the branch nearest the current configuration, so any placement leaves
        room for any twist; placements differ only in how far the arm must
        move and whether the fingers clear the other hand's.
        ``req.turn`` = (world axis, angle): this hand will give the cube in a hand-over from this grip;
        the grip must also let the arm carry that turn through IK solutions that follow each other
        (a waypoint whose nearest solution jumps more than ``max_waypoint_jump`` is a change of arm
        branch — elbow or shoulder — with the cube in hand), and the one with the least joint travel
        over the turn is preferred (:meth:`..bimanual.machine.BimanualRubiksMachine.turn_travel`).
        ``req.relation == "cross"``: the fingers must cross the other hand's (in a shift both hands are
        two slabs deep and overlap along the work axis; in a hand-over the giver's finger lies on the
        face the taker comes to, and only crossing fingers pass it); otherwise ``finger_preference``.
        ``req.on_table``: no finger may go under the cube.
        All placements are solved in one batched IK call (and the turn's waypoints in one call each).
        """
        cfg = self.config
        world_dir, turn = req.world_dir, req.turn
        perpendicular = req.relation == "cross"
        other = m.other(hand)
        other_y = (
            other.last_grip.rotation.apply([0.0, 1.0, 0.0])
            if other.holding and other.last_grip
            else None
        )
        other_x = (
            other.last_grip.rotation.apply([1.0, 0.0, 0.0])
            if other.holding and other.last_grip
            else None
        )
        # a giver whose fingers ended on the work axis has a pad on the face this hand comes to: this
        # hand's pads must then also stay off the faces the giver approaches along
        other_on_axis = (
            other_y is not None and abs(float(np.dot(other_y, DIRECTIONS[world_dir]))) > 0.7
        )
        base = hand.arm.base_pose()
        q_now = hand.arm.positions()
        poses, bonus = [], []
        for pose in grip_candidates(m.est, world_dir, self._offset(req.depth)):
            fy = pose.rotation.apply([0.0, 1.0, 0.0])
            if req.on_table and abs(fy[2]) > 0.7:
                continue  # on the table a finger would go under the cube
            cross = other_y is None or abs(float(np.dot(fy, other_y))) < 0.3
            if other_on_axis and other_x is not None:
                cross = cross and abs(float(np.dot(fy, other_x))) < 0.3
            if perpendicular and not cross:
                continue
            parallel = other_y is not None and abs(float(np.dot(fy, other_y))) > 0.7
            poses.append(pose)
            if cfg.finger_preference == "parallel" and not perpendicular:
                bonus.append(0.5 if parallel else 0.0)
            else:
                bonus.append(0.5 if cross else 0.0)
        if not poses:
            raise StrategyFailure(
                "unreachable",
                f"{hand.side} arm: no finger placement from {world_dir} clears the other hand",
            )
        placements, place_bonus = list(poses), list(bonus)
        seeds = [q_now]
        if turn is not None and cfg.giver_seeds > 0:
            # a giver also tries other arm configurations (the 7-DOF arm's self-motion) for each
            # placement: the turn may only be smooth from another elbow/shoulder posture
            rng = m.plan_rng
            lo = np.where(np.isfinite(hand.arm.lower), hand.arm.lower, -np.inf)
            hi = np.where(np.isfinite(hand.arm.upper), hand.arm.upper, np.inf)
            seeds += [
                np.clip(q_now + rng.normal(0.0, 0.6, q_now.shape), lo, hi)
                for _ in range(cfg.giver_seeds)
            ]
        poses = [p for p in poses for _ in seeds]
        bonus = [b for b in bonus for _ in seeds]
        seed_rows = np.stack([q for _ in range(len(poses) // len(seeds)) for q in seeds])
        res = hand.arm.ik(np.stack([(base.inv() * p).as_matrix() for p in poses]), seed_q=seed_rows)
        ok = np.asarray(res.success, dtype=bool)
        if not ok.any():
            raise StrategyFailure(
                "unreachable", f"{hand.side} arm: no grip from {world_dir} reachable"
            )
        score = np.array(
            [-0.1 * float(np.max(np.abs(res.q[i] - q_now))) + bonus[i] for i in range(len(poses))]
        )
        score[~ok] = -np.inf
        if other.holding:
            # the other arm holds still meanwhile: a grip posture whose elbow or forearm meets it stops
            # short of the grip (measured: a take 25 mm short, its pads on the cube's edges, against
            # the giver's elbow at 63 N; the cube fell when the giver let go. PyBullet Rubiks-1-20)
            clash = ok & (arm_clearance(m, hand, res.q) < cfg.arm_clearance)
            if clash.any() and (ok & ~clash).any():
                m.ctx.recorder.event(
                    "arm_clash", hand=hand.side, label=req.label, rejected=int(clash.sum())
                )
                ok = ok & ~clash
                score[clash] = -np.inf
        if turn is not None:
            travel, worst = m.turn_travel(
                hand, base, [poses[i] for i in np.flatnonzero(ok)], res.q[ok], *turn
            )
            turned = score.copy()
            # inf travel: the turn cannot be carried from there
            turned[np.flatnonzero(ok)] -= 0.1 * travel
            if np.isfinite(turned).any():
                score = turned
            else:
                found = self._backward_grip(m, hand, base, placements, place_bonus, q_now, turn)
                if found is not None:
                    return found
                # the least bad: the smallest largest jump on the way
                score[np.flatnonzero(ok)] -= worst
                m.ctx.recorder.event(
                    "warning",
                    message=f"{hand.side}: no grip lets the hand-over turn run smoothly "
                    f"(largest joint step {float(np.min(worst)):.2f} rad)",
                )
        best = int(np.argmax(score))
        return poses[best], np.array(res.q[best], dtype=float)

    def _backward_grip(
        self,
        m: BimanualRubiksMachine,
        hand: Hand,
        base: Pose,
        placements: list[Pose],
        bonus: list[float],
        q_now: np.ndarray,
        turn: tuple[str, float],
    ) -> tuple[Pose, np.ndarray] | None:
        """A giver's grip whose turn and retreat run smoothly, from postures found backwards from the
        retreat's end (:meth:`..bimanual.machine.BimanualRubiksMachine.turn_postures`, ``giver_backward_seeds``
        starts per placement), when none near the arm's joints does; checked forwards again
        (``turn_travel``) and scored as :meth:`choose` scores (joint change, finger bonus, turn travel).
        None: none found. Recorded as a ``giver_posture`` event."""
        n = self.config.giver_backward_seeds
        if n <= 0:
            return None
        owner, qs = m.turn_postures(hand, base, placements, *turn, n_seeds=n)
        if owner and m.other(hand).holding:
            keep = np.flatnonzero(arm_clearance(m, hand, qs) >= self.config.arm_clearance)
            owner, qs = [owner[j] for j in keep], qs[keep]
        if not owner:
            return None
        grips = [placements[i] for i in owner]
        travel, _ = m.turn_travel(hand, base, grips, qs, *turn)
        score = np.array(
            [
                -0.1 * float(np.max(np.abs(qs[j] - q_now))) + bonus[owner[j]] - 0.1 * travel[j]
                for j in range(len(owner))
            ]
        )
        if not np.isfinite(score).any():
            return None
        best = int(np.argmax(score))
        # another branch: the stand-off move changes posture away from the cube
        hand.far_posture = True
        m.ctx.recorder.event(
            "giver_posture",
            hand=hand.side,
            chains=len(owner),
            checked=int(np.isfinite(travel).sum()),
            joint_change=round(float(np.max(np.abs(qs[best] - q_now))), 2),
            travel=round(float(travel[best]), 2),
        )
        return grips[best], np.array(qs[best], dtype=float)

    def ready(self, m: BimanualRubiksMachine, hand: Hand, req: GripRequest) -> None:
        hand.gripper.open(wait=0.3)

    def close_in(
        self,
        m: BimanualRubiksMachine,
        hand: Hand,
        grip: Pose,
        q_plan: np.ndarray | None,
        req: GripRequest,
    ) -> None:
        """From the stand-off: pre-grasp, (re-localise), grip; then close, softly first if the other hand holds.

        ``q_plan``: the grip's IK solution the choice was made with (and a
        hand-over turn checked from); the pre-grasp and grip are solved from
        it, so that the arm arrives on that branch rather than wherever the
        seeds along the way would lead (measured: a giver that arrived on
        another branch met a joint limit in the turn's first waypoint and
        swung the cube 15 degrees).

        Why two stages: a cube held by one parallel gripper pivots about that
        gripper's pad axis, resisted only by the pads' torsional friction. The
        closing gripper's first-touching finger pushes the cube with the
        closing force at a lever of 17-50 mm from that axis; at the full 20 N
        that out-torques the friction (measured on PyBullet: the cube turned
        11 degrees at a hand-over take). At ``soft_grip_force`` it does not;
        once both pads touch, raising the force squeezes symmetrically.
        """
        cfg, label = self.config, req.label
        back = m.back_off(grip, cfg.pregrasp_distance)
        m.send(hand, back, label=f"{label} pre-grasp", settle=0.1, seed_q=q_plan)
        grip = self.relocalise(m, hand, grip, label)
        m.send(hand, grip, label=label, settle=0.2, seed_q=q_plan)
        if m.other(hand).holding and cfg.soft_grip_force > 0:
            hand.gripper.close(force_limit=cfg.soft_grip_force, obj=m.cube.body)
        g = hand.gripper.close(force_limit=cfg.grip_force, obj=m.cube.body)
        if g.closed or not g.contact:
            raise StrategyFailure(
                None, f"{label}: {hand.side} gripper closed on nothing (grasp missed)"
            )

    def relocalise(self, m: BimanualRubiksMachine, hand: Hand, grip: Pose, label: str) -> Pose:
        """Hook before a hand moves in to grip (dead reckoning: the record only; sensor-aided: pre-touch).

        Dead reckoning moves in on its belief as it is. For the record only
        (the truth is read, nothing is planned from it, no random number is
        drawn) it logs that belief's error at the pre-grasp as a ``grasp``
        event: along the work axis (the grip's approach; a pad lands on the
        wrong slab past half a cubie) and in full, the same quantities as the
        sensor-aided ``pretouch`` event's ``work_err_mm_before`` and
        ``err_mm_before`` (bench/plot_work_axis_error.py).
        """
        approach = grip.rotation.apply(along(self.approach_axis, 1.0))
        work, err, _ = _belief_error(m.est, m.cube.pose(), approach)
        m.ctx.recorder.event(
            "grasp",
            hand=hand.side,
            label=label,
            move_index=m.move_index,
            work_axis=np.round(approach, 3).tolist(),
            work_err_mm=work,
            err_mm=err,
        )
        return grip

    def open(self, m: BimanualRubiksMachine, hand: Hand) -> None:
        hand.gripper.open(wait=0.3)

    def regrip_before_twist(self, m: BimanualRubiksMachine, rot: Hand, delta: float) -> bool:
        return False  # the wrist roll is continuous and the grip never slides off its face centre

    def twist_diagnostics(self, m: BimanualRubiksMachine, body_axis: str) -> dict | None:
        return None


class PR2SensorAidedGrasp(PR2Grasp):
    """The PR2 grasp module plus pre-touch re-localisation before every grasp (Yang et al. 2020, Sec. IV-B).

    ``pretouch_mode="sweep"`` (default; Yang et al., ICRA 2017): at each
    pre-grasp the hand moves a fingertip ToF sensor (one emitter in each
    fingertip, looking along the approach; each sweep uses the fingertip that
    keeps the hand nearer its pre-grasp, or the other if the arm cannot start it; ``benchharness.sensors``
    ``PreTouchSensor``, rays cast from the true fingertip and reported from the
    believed one) in three sweeps across the face it is about to grip: one
    across the face at mid-height past both side edges, two up and down over
    the top edge at either side of the centre (:meth:`_sweep_plan`). The arm
    really moves (the sweeps cost simulated time), the sensor ranges at
    ``sweep.rate_hz`` while it does, and :func:`~benchharness.sensors.find_edges`
    finds where the beam steps off the face. A 6-DOF iterated EKF
    (:class:`~benchharness.sensors.pose6.CubePose6Filter`) started from the
    believed pose fuses the face ranges (along the work axis, the two tilts)
    and the edges (across the work axis, the height, the turn about the work
    axis); the belief takes the posterior pose, the holding hand's belief is
    re-anchored to it, and the grip is recomputed from it. Recorded per grasp
    as a ``pretouch`` event (belief error against the truth, for the record
    only, and the posterior std).

    ``pretouch_mode="grid"``: the former simplification, a 3 x 3 grid of rays
    along the approach from the tool frame read once at the pre-grasp
    (position and yaw only; the robot transparent to them).
    """

    def __init__(self, config: PR2RubiksConfig | None = None) -> None:
        super().__init__(config)
        if self.config.pretouch_mode not in ("sweep", "grid"):
            raise ValueError(
                f"pretouch_mode must be 'sweep' or 'grid', got {self.config.pretouch_mode!r}"
            )
        self._sensors: dict[tuple[str, str], tuple[Any, np.random.Generator]] = {}

    def _sensor(
        self, m: BimanualRubiksMachine, hand: Hand, finger: str = "l"
    ) -> tuple[Any, np.random.Generator]:
        """The pre-touch sensor (and its random stream) of ``hand``'s ``finger`` ("l" or "r") fingertip;
        in grid mode the one tool-frame grid whatever ``finger``. Created on first use."""
        from ...sensors import Emitter, PreTouchSensor

        key = (hand.side, finger if self.config.pretouch_mode == "sweep" else "tool")
        if key not in self._sensors:
            cfg = self.config
            body = m.robot.body
            tcp = hand.arm.config.tcp_link
            kw: dict[str, Any] = {}
            if cfg.pretouch_mode == "grid":
                grid = cfg.pretouch_grid
                emitters = [Emitter((0.0, y, z), (1.0, 0.0, 0.0)) for y in grid for z in grid]
                link = tcp
            else:
                # one emitter in each fingertip, its window at the pad's front end (the pad runs
                # to x = 31.25 mm in the fingertip frame), looking along the approach (the fingertip
                # stays parallel to the palm on the four-bar)
                link = tcp.replace("gripper_tcp", f"gripper_{finger}_finger_tip_link")
                emitters = [Emitter((0.032, 0.0, 0.0), (1.0, 0.0, 0.0), "fingertip")]
                if cfg.pretouch_see_robot:
                    kw = {"ignore_bodies": (), "ignore_links": ((body, link),)}
            slot = m.ctx.sensors.get("pretouch-tof") if m.ctx.sensors else None
            if slot is not None:
                sensor = slot.create(backend=m.b, body=body, link=link, emitters=emitters, **kw)
                rng = slot.rng
            else:
                sensor = PreTouchSensor(m.b, body, link, emitters, **kw)
                rng = np.random.default_rng(m.ctx.rng.integers(2**63))
            self._sensors[key] = (sensor, rng)
        return self._sensors[key]

    def relocalise(self, m: BimanualRubiksMachine, hand: Hand, grip: Pose, label: str) -> Pose:
        if self.config.pretouch_mode == "grid":
            return self._relocalise_grid(m, hand, grip, label)
        return self._relocalise_sweep(m, hand, grip, label)

    def _relocalise_grid(
        self, m: BimanualRubiksMachine, hand: Hand, grip: Pose, label: str
    ) -> Pose:
        from ...sensors import CubePoseFilter, PoseEstimate, cube_yaw, yaw_error

        cfg = self.config
        sensor, rng = self._sensor(m, hand)
        std = np.array(
            [cfg.pretouch_prior_pos_std] * 3 + [math.radians(cfg.pretouch_prior_yaw_std_deg)]
        )
        prior = PoseEstimate(m.est, np.diag(std**2), n_measurements=1, time=m.b.time)
        kf = CubePoseFilter(initial=prior)
        reading = sensor.read(rng, believed_link_pose=hand.cmd)
        report = kf.update_reading(reading)
        before = m.est
        if report.n_used >= 3:
            post = kf.estimate
            dyaw = yaw_error(post.yaw, cube_yaw(before.rotation))
            m.est = Pose.from_rotation(
                post.pose.p, Rotation.from_euler("z", dyaw) * before.rotation
            )
            m.reanchor()  # what the holding hand believes it carries
        m.ctx.recorder.event(
            "pretouch",
            hand=hand.side,
            label=label,
            rays=report.n_rays,
            used=report.n_used,
            correction_mm=float(1000 * np.linalg.norm(m.est.p - before.p)),
        )
        m.ctx.recorder.pose_estimate(m.move_index, m.cube.pose(), m.est, label="pretouch")
        if m.est is before:
            return grip
        # the same finger placement, recomputed from the corrected belief
        local = before.inv() * grip
        return m.est * local

    @staticmethod
    def _fk_tip(hand: Hand, sensor: Any) -> Pose:
        """The fingertip pose the robot's forward kinematics reports (its joint encoders through its
        kinematic model): the true pose seen through the arm's calibration offset, which the arm's
        commands carry too (``actual = calibration * commanded``) and the strategy never learns.

        Not the commanded pose: the arm is millimetres and a degree or two from its command while it
        moves and settles (measured: 2.8 mm and a wrist tilt that read as a 6 degree face tilt).
        """
        cal = hand.calibration
        tcp = hand.arm.tcp_pose()
        model = Pose.from_rotation(tcp.p - cal.p, cal.rotation.inv() * tcp.rotation)
        return model * (tcp.inv() * sensor.link_pose())

    #: margin (m) round the other hand's believed finger boxes within which a return counts as the
    #: robot's own: the two arms' calibrations differ by ~2 mm, and a finger is believed where commanded
    self_filter_margin: float = 0.004

    def _self_filter(
        self, m: BimanualRubiksMachine, hand: Hand, o: np.ndarray, d: np.ndarray, z: np.ndarray
    ) -> np.ndarray:
        """Which returns may come from the other hand's gripper (a bool per reading).

        A robot knows where its other hand is (its commanded pose and, holding, the cube's width between
        its pads), so like any self-filter of a point cloud it drops a return whose ray meets that
        gripper's collision boxes (palm, pads and finger bars, :func:`finger_boxes`, grown by
        ``self_filter_margin``) no farther than the return. Without it, the giver's pad lying on the face
        a taker ranges read as a face tilted by 10-15 degrees (measured). Such a return is not fused,
        and is never part of a face for :func:`~benchharness.sensors.find_edges`, but still counts as
        beyond an edge when it is far behind the face (the holder's pad end 28 mm behind a side edge).
        """
        from ...sensors.raybox import ray_box

        if not self.config.pretouch_see_robot:
            return np.zeros(len(z), dtype=bool)
        out = np.zeros(len(z), dtype=bool)
        finite = np.isfinite(z)
        for c, rot, h in self.hand_boxes(m, m.other(hand)):
            hits = ray_box(o, d, c, rot, h + self.self_filter_margin)
            inside = np.all(np.abs((o - c) @ rot) <= h + self.self_filter_margin, axis=1)
            own = finite & (inside | (hits.hit & (hits.distance <= z + self.self_filter_margin)))
            out |= own
        return out

    def _sweep_plan(
        self, est: Pose, approach: np.ndarray
    ) -> list[tuple[str, np.ndarray, np.ndarray]]:
        """The three sweeps (name, start, end: the emitter window's world position), from the belief.

        The face is the believed box's face towards the hand; ``across`` is its
        in-face axis nearest horizontal, ``up`` the one nearest world z. The
        window stays ``sweep.standoff`` off the face: "across" runs at
        mid-height from ``overshoot`` past one side edge to as far past the
        other; "up" rises at ``+vertical_offset`` from ``face_depth`` below the
        top edge to ``overshoot`` above it; "down" comes back at
        ``-vertical_offset``.
        """
        sw = self.config.sweep
        half = CUBE_HALF
        rot = est.rotation.as_matrix()
        k = int(np.argmax(np.abs(rot.T @ approach)))
        normal = -np.sign(float(rot[:, k] @ approach)) * rot[:, k]  # outward, towards the hand
        rest = [j for j in range(3) if j != k]
        j_up = max(rest, key=lambda j: abs(float(rot[2, j])))
        up = rot[:, j_up] * np.sign(rot[2, j_up])
        across = np.cross(up, normal)
        base = est.p + normal * (half + sw.standoff)

        def at(s: float, v: float) -> np.ndarray:
            return base + s * across + v * up

        far, low = half + sw.overshoot, half - sw.face_depth
        vo = sw.vertical_offset
        return [
            ("across", at(-far, 0.0), at(far, 0.0)),
            ("up", at(vo, low), at(vo, far)),
            ("down", at(-vo, far), at(-vo, low)),
        ]

    def _relocalise_sweep(
        self, m: BimanualRubiksMachine, hand: Hand, grip: Pose, label: str
    ) -> Pose:
        from ...sensors import find_edges
        from ...sensors.pose6 import POSE6_AXES, CubePose6Filter
        from ...sensors.pose_estimate import PoseEstimate

        cfg, sw, b = self.config, self.config.sweep, m.b
        sensors = {f: self._sensor(m, hand, f) for f in ("l", "r")}
        t0 = b.time
        pre = hand.cmd  # the pre-grasp, where the hand comes back to
        q_pre = hand.arm.positions()
        # each fingertip's window in the tool frame, from the joint encoders (forward kinematics; the
        # hand is open)
        tcp_now = hand.arm.tcp_pose()
        windows = {
            f: (tcp_now.inv() * s.link_pose()).apply(np.asarray(s.emitters[0].origin, dtype=float))
            for f, (s, _) in sensors.items()
        }
        approach = grip.rotation.apply(along(self.approach_axis, 1.0))

        def tool_at(point: np.ndarray, f: str) -> Pose:
            return Pose(point - grip.rotation.apply(windows[f]), grip.q)

        dt = float(b.config.timestep)
        every = max(1, round(1.0 / (sw.rate_hz * dt)))
        origins, directions, ranges, edges = [], [], [], []
        done, skipped = [], []
        for name, start, end in self._sweep_plan(m.est, approach):
            # the fingertip whose sweep keeps the hand nearer the pre-grasp first, the other if the arm
            # cannot start it smoothly (a sweep to the far side of the cube can leave the arm's reach)
            order = sorted(
                ("l", "r"),
                key=lambda f: max(
                    float(np.linalg.norm(tool_at(p, f).p - pre.p)) for p in (start, end)
                ),
            )
            # each move is sent seeded with the IK solution it was judged smooth with: solved again
            # from the injected-error target it can take another branch (measured, SAPIEN Rubiks-5-5
            # sensor-aided seed 0 trial 4: a sweep judged smooth swung the upper-arm roll 3.1 rad, the
            # palm hit the cube held by the other hand alone at 25 N and turned it 31 degrees)
            finger, q_a = None, None
            for f in order:
                q_a = m.smooth_q(hand, tool_at(start, f), label=f"{label} pre-touch {name} start")
                if q_a is not None:
                    finger = f
                    break
            if finger is None:
                skipped.append(name)
                continue
            sensor, rng = sensors[finger]
            a_pose, b_pose = tool_at(start, finger), tool_at(end, finger)
            try:
                m.send(
                    hand, a_pose, label=f"{label} pre-touch {name} start", settle=0.05, seed_q=q_a
                )
            except StrategyFailure:  # the injected errors put the target just out of reach
                skipped.append(name)
                continue
            q_b = m.smooth_q(hand, b_pose, label=f"{label} pre-touch {name}")
            if q_b is None:
                skipped.append(name)
                continue
            got: list[Any] = []
            tick = [0]

            def read(
                got: list[Any] = got,
                tick: list[int] = tick,
                sensor: Any = sensor,
                rng: np.random.Generator = rng,
            ) -> None:
                tick[0] += 1
                if tick[0] % every:
                    return
                got.append(sensor.read(rng, believed_link_pose=self._fk_tip(hand, sensor)))

            handle = b.add_step_callback(read)
            try:
                m.send(
                    hand,
                    b_pose,
                    label=f"{label} pre-touch {name}",
                    duration=float(np.linalg.norm(end - start)) / sw.speed,
                    settle=0.0,
                    seed_q=q_b,
                )
            except StrategyFailure:  # as above: the sweep's end just out of reach; not used
                got.clear()
            finally:
                b.remove_step_callback(handle)
            if not got:
                skipped.append(name)
                continue
            o = np.concatenate([r.origins for r in got])
            d = np.concatenate([r.directions for r in got])
            z = np.concatenate([r.distance for r in got])
            own = self._self_filter(m, hand, o, d, z)
            origins.append(o)
            directions.append(d)
            ranges.append(np.where(own, np.nan, z))  # the robot's own returns are not fused
            edges += find_edges(o, d, z, config=sw, tof=sensor.config, exclude=own)
            done.append(f"{name}({finger})")
        # back to the pre-grasp as a checked move: the sweeps hold the tool where the sensing finger needs
        # it, and the joint path back can swing the hand through the cube (measured: PyBullet Rubiks-1-10
        # seed 0, the 9th hand-over's re-grip, upper-arm and forearm rolls +1.48 / -1.75 rad on a path
        # through the believed cube from 29 mm clear; the held cube turned 23 deg and the last twist
        # was misaligned). A move that clears is the same single move as before.
        m.transit(hand, pre, label=f"{label} pre-grasp", settle=0.1, seed_q=q_pre)
        cost = b.time - t0

        pos = cfg.pretouch_prior_pos_std
        tilt, yaw = (
            math.radians(cfg.pretouch_prior_tilt_std_deg),
            math.radians(cfg.pretouch_prior_yaw_std_deg),
        )
        std = np.array([pos, pos, pos, tilt, tilt, yaw])
        before = m.est
        kf = CubePose6Filter(
            PoseEstimate(before, np.diag(std**2), n_measurements=1, time=t0, axes=POSE6_AXES),
            tof=sensors["l"][0].config,
        )
        rep = kf.update(
            np.concatenate(origins) if origins else None,
            np.concatenate(directions) if directions else None,
            np.concatenate(ranges) if ranges else None,
            edges,
            time=b.time,
        )
        if rep.n_rays_used + rep.n_edges_used >= 3:
            m.est = kf.pose
            m.reanchor()  # what the holding hand believes it carries
        # the record (truth read for it only): belief error before and after, along the work axis too
        true = m.cube.pose()
        w0, p0, r0 = _belief_error(before, true, approach)
        w1, p1, r1 = _belief_error(m.est, true, approach)
        # the same after the sweeps against the truth as this arm's kinematic model sees it (its
        # calibration offset removed, for the record only): what its grip depends on, and what the
        # posterior std describes
        cal = hand.calibration
        dp_hand = m.est.p - (true.p - cal.p)
        post_std = np.sqrt(np.diag(kf.P))
        m.ctx.recorder.event(
            "pretouch",
            hand=hand.side,
            label=label,
            mode="sweep",
            move_index=m.move_index,
            sweeps=done,
            skipped=skipped,
            rays=rep.n_rays,
            used=rep.n_rays_used,
            edges=rep.n_edges,
            edges_used=rep.n_edges_used,
            nis=round(rep.nis, 3),
            cost_s=round(cost, 4),
            work_axis=np.round(approach, 3).tolist(),
            work_err_mm_before=w0,
            work_err_mm=w1,
            work_err_hand_mm=round(1000 * float(dp_hand @ approach), 3),
            err_hand_mm=np.round(1000 * dp_hand, 3).tolist(),
            err_mm_before=p0,
            err_mm=p1,
            rot_err_deg_before=r0,
            rot_err_deg=r1,
            std_mm=np.round(1000 * post_std[:3], 3).tolist(),
            std_deg=np.round(np.degrees(post_std[3:]), 3).tolist(),
            correction_mm=round(float(1000 * np.linalg.norm(m.est.p - before.p)), 3),
        )
        m.ctx.recorder.pose_estimate(m.move_index, true, m.est, label="pretouch")
        if m.est is before:
            return grip
        local = before.inv() * grip  # the same finger placement, from the corrected belief
        return m.est * local


class DeadReckoningStrategy(BimanualRubiksMachine):
    """PR2 Rubik's baseline trusting commanded poses (Yang et al. 2020, Sec. IV-A)."""

    name = "dead-reckoning"

    def __init__(self, config: PR2RubiksConfig | None = None) -> None:
        super().__init__(PR2Grasp(config))


class SensorAidedStrategy(BimanualRubiksMachine):
    """Dead reckoning plus pre-touch re-localisation before every grasp (:class:`PR2SensorAidedGrasp`)."""

    name = "sensor-aided"

    def __init__(self, config: PR2RubiksConfig | None = None) -> None:
        super().__init__(PR2SensorAidedGrasp(config))
