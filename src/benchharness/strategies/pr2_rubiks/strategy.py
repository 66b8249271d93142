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

import math
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose
from ..bimanual.frames import DIRECTIONS, grip_candidates
from ..bimanual.machine import (
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


def _open_hand_points() -> np.ndarray:
    from ...robots.descriptions.pr2 import GRIPPER_MAX_OPENING, PALM_BOX, TCP_X, finger_boxes

    boxes = [*finger_boxes(GRIPPER_MAX_OPENING), PALM_BOX]
    g = np.linspace(-0.5, 0.5, 5)
    grid = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    pts = np.concatenate([np.asarray(c) + grid * np.asarray(s) for c, s in boxes])
    return pts - np.array([TCP_X, 0.0, 0.0])


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

    def hand_points(self) -> np.ndarray:
        """Points (tool frame, m) filling the open hand's collision boxes: both pads and finger bars at
        the 90 mm opening and the palm (:func:`...robots.descriptions.pr2.finger_boxes`); the machine keeps
        them clear of the cube when the free hand moves to a stand-off (``sweep_clearance``)."""
        return _open_hand_points()

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
        seeds = [q_now]
        if turn is not None and cfg.giver_seeds > 0:
            # a giver also tries other arm configurations (the 7-DOF arm's self-motion) for each
            # placement: the turn may only be smooth from another elbow/shoulder posture
            rng = np.random.default_rng(len(m.ctx.recorder.events))  # deterministic per trial
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
        if turn is not None:
            travel, worst = m.turn_travel(
                hand, base, [poses[i] for i in np.flatnonzero(ok)], res.q[ok], *turn
            )
            turned = score.copy()
            # inf travel: the turn cannot be carried from there
            turned[np.flatnonzero(ok)] -= 0.1 * travel
            if np.isfinite(turned).any():
                score = turned
            else:  # the least bad: the smallest largest jump on the way
                score[np.flatnonzero(ok)] -= worst
                m.ctx.recorder.event(
                    "warning",
                    message=f"{hand.side}: no grip lets the hand-over turn run smoothly "
                    f"(largest joint step {float(np.min(worst)):.2f} rad)",
                )
        best = int(np.argmax(score))
        return poses[best], np.array(res.q[best], dtype=float)

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
        """Hook before a hand moves in to grip (dead reckoning: nothing; sensor-aided: pre-touch)."""
        return grip

    def open(self, m: BimanualRubiksMachine, hand: Hand) -> None:
        hand.gripper.open(wait=0.3)

    def regrip_before_twist(self, m: BimanualRubiksMachine, rot: Hand, delta: float) -> bool:
        return False  # the wrist roll is continuous and the grip never slides off its face centre

    def twist_diagnostics(self, m: BimanualRubiksMachine, body_axis: str) -> dict | None:
        return None


class PR2SensorAidedGrasp(PR2Grasp):
    """The PR2 grasp module plus pre-touch re-localisation before every grasp (Yang et al. 2020, Sec. IV-B).

    Simplified: at each pre-grasp stand-off the approaching hand reads a 3 x 3
    grid of time-of-flight rays fixed to its tool frame, looking along the
    approach at the face it is about to grip (``benchharness.sensors``
    ``PreTouchSensor``, rays cast from the true tool pose, reported from the
    *commanded* one); an iterated EKF (``CubePoseFilter``) started from the
    believed pose fuses them; the believed pose takes the filter's position and
    yaw correction, the holding hand's belief is re-anchored to it, and the
    grip is recomputed from the corrected belief. No sweep: one face along the
    work axis is observed, which is the axis along which a grip lands on the
    wrong slab.
    """

    def __init__(self, config: PR2RubiksConfig | None = None) -> None:
        super().__init__(config)
        self._sensors: dict[str, tuple[Any, np.random.Generator]] = {}

    def _sensor(self, m: BimanualRubiksMachine, hand: Hand) -> tuple[Any, np.random.Generator]:
        from ...sensors import Emitter, PreTouchSensor

        if hand.side not in self._sensors:
            grid = self.config.pretouch_grid
            emitters = [Emitter((0.0, y, z), (1.0, 0.0, 0.0)) for y in grid for z in grid]
            link = hand.arm.config.tcp_link
            slot = m.ctx.sensors.get("pretouch-tof") if m.ctx.sensors else None
            if slot is not None:
                sensor = slot.create(backend=m.b, body=m.robot.body, link=link, emitters=emitters)
                rng = slot.rng
            else:
                sensor = PreTouchSensor(m.b, m.robot.body, link, emitters)
                rng = np.random.default_rng(m.ctx.rng.integers(2**63))
            self._sensors[hand.side] = (sensor, rng)
        return self._sensors[hand.side]

    def relocalise(self, m: BimanualRubiksMachine, hand: Hand, grip: Pose, label: str) -> Pose:
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
