"""The PR2 dead-reckoning baseline: plan, pick the cube up, twist, regrasp, hand over, release.

Control never reads the true cube pose. The cube's pose is *believed*: the
head camera's one-shot estimate on the table, then carried by whichever hand
holds it alone, through that hand's *commanded* tool poses (``Hand.cmd``).
Every arm target is a grip computed from the believed pose
(:mod:`.frames`). The injected errors (:class:`.config.ErrorConfig`) sit
between the command and the arm: the arm is sent ``calibration * noise *
commanded``, which the strategy never learns. The true pose is read only for
the recorder's true-vs-believed diagnostics and to tell a dropped cube from
a wrong state when a trial has already failed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ...backends.interface import Box, CameraSpec
from ...geometry import Pose
from ...runner.contract import TrialContext, TrialOutcome
from ...runner.video import rubiks_camera
from ..regrasp import (
    HandModel,
    Handover,
    Pick,
    Regrasp,
    Release,
    Twist,
    execute,
    plan_sequence,
    twist_move,
)
from .config import PR2RubiksConfig
from .frames import DIRECTIONS, grip_candidates, rotate_about_point, turned_about_approach

__all__ = ["DeadReckoningStrategy", "SensorAidedStrategy", "StrategyFailure"]

CUBE_HALF = 0.0285
SIDE_DIR = {"left": "+y", "right": "-y"}
BODY_AXIS_OF_FACE = {"U": "z", "D": "z", "R": "x", "L": "x", "F": "y", "B": "y"}


class StrategyFailure(Exception):
    """A failure the strategy detected itself: ``cause`` is a runner FailureCause value or None."""

    def __init__(self, cause: str | None, message: str) -> None:
        super().__init__(message)
        self.cause = cause


@dataclass
class Hand:
    """One arm + gripper and what the strategy believes about it."""

    side: str
    arm: Any
    gripper: Any
    calibration: Pose  #: injected, never read by control: actual = calibration * commanded
    cmd: Pose | None = None  #: the last commanded (believed) tool pose
    holding: bool = False
    cube_in_tcp: Pose | None = None  #: believed cube pose in the commanded tool frame
    grip_dir: str | None = None  #: world direction the hand grips from ("+y", "-x", ...)
    last_grip: Pose | None = (
        None  #: the commanded tool pose of the last grip (retreats go back from it)
    )
    depth: int = 0
    log: list = field(default_factory=list)


class DeadReckoningStrategy:
    """PR2 Rubik's baseline trusting commanded poses (Yang et al. 2020, Sec. IV-A)."""

    benchmarks = ("rubiks",)
    name = "dead-reckoning"
    #: where the fingers need not cross the other hand's: "crossing" prefers crossing them,
    #: "parallel" prefers closing along the other hand's pad axis (no torque about it)
    finger_preference = "parallel"
    #: extra IK seeds (random self-motions of the arm) a giver's grip is also solved from
    giver_seeds = 6

    def __init__(self, config: PR2RubiksConfig | None = None) -> None:
        self.config = config or PR2RubiksConfig()

    # ------------------------------------------------------------------ trial

    def video_camera(self, view: str, size: tuple[int, int]) -> CameraSpec:
        """The trial video's camera (``run --video-view``): ``close`` frames both hands at the
        twisting pose above the table and the cube on it, ``wide`` the robot (runner/video.py)."""
        cfg = self.config
        x, y = cfg.cube_xy
        return rubiks_camera((x, y, cfg.table_height + 0.08), view, size)

    def run_trial(self, ctx: TrialContext) -> TrialOutcome:
        from ...cube_physics import PhysicalCube

        cfg = self.config
        b = ctx.backend
        self.ctx = ctx
        self.b = b
        b.add_ground()
        h = cfg.table_height
        tx, ty = cfg.table_half_size
        b.add_body(
            [Box((tx, ty, h / 2), rgba=(0.55, 0.40, 0.26, 1.0))],  # wood, in a video
            Pose([cfg.cube_xy[0], cfg.cube_xy[1], h / 2]),
            1.0,
            fixed=True,
            name="table",
        )
        # protocol: top face up, F facing the robot (body -y -> world -x: yaw -90 deg)
        true0 = Pose.from_rotation(
            [cfg.cube_xy[0], cfg.cube_xy[1], h + CUBE_HALF + 5e-4],
            Rotation.from_euler("z", -90, degrees=True),
        )
        self.cube = PhysicalCube(b, true0)
        robot = ctx.robot
        robot.spawn(b)
        self.robot = robot
        return self._run(ctx)  # the cube keeps its own detents current (a step callback)

    def _run(self, ctx: TrialContext) -> TrialOutcome:
        cfg, rec, b = self.config, ctx.recorder, self.b
        err = cfg.errors
        rng = ctx.rng
        self.hands = {}
        for side in ("left", "right"):
            dp = rng.normal(0.0, err.calib_pos_std, 3) if err.calib_pos_std else np.zeros(3)
            dr = (
                rng.normal(0.0, math.radians(err.calib_rot_std_deg), 3)
                if err.calib_rot_std_deg
                else np.zeros(3)
            )
            self.hands[side] = Hand(
                side,
                self.robot.arm(f"{side}_arm"),
                self.robot.gripper(f"{side}_gripper"),
                Pose.from_rotation(dp, Rotation.from_rotvec(dr)),
            )
        for hnd in self.hands.values():
            hnd.cmd = hnd.arm.tcp_pose()
        self.robot.settle(0.2)
        rec.watch_contact(self.cube.body, self.robot.body)
        self.est = self._camera_estimate(ctx)
        rec.pose_estimate(0, self.cube.pose(), self.est, label="camera")

        model = HandModel(name="pr2", pick_approaches=tuple(cfg.pick_approaches))
        plan = plan_sequence(ctx.item.sequence, model)
        trace = execute(plan).orientations
        rec.event(
            "plan",
            actions=len(plan.actions),
            twists=plan.twists,
            regrasps=plan.regrasps,
            handovers=plan.handovers,
            text=plan.describe(),
        )
        self.plan, self.trace = plan, trace
        move_index = 0
        try:
            for k, action in enumerate(plan.actions):
                if cfg.max_actions is not None and k >= cfg.max_actions:
                    rec.event("stopped", after_actions=k)
                    self.t_release = b.time
                    break
                before = trace[k - 1] if k > 0 else plan.initial
                rec.event("action", index=k, action=type(action).__name__, detail=repr(action))
                if isinstance(action, Pick):
                    self._pick(action, k)
                elif isinstance(action, Twist):
                    move_index = max(action.source, 0)
                    self._move_index = move_index
                    self._twist(action, before, k)
                elif isinstance(action, Regrasp):
                    self._shift(action, k)
                elif isinstance(action, Handover):
                    self._handover(action, k)
                elif isinstance(action, Release):
                    self._release()
                if not isinstance(action, Release):
                    self._check_drop(k)
                    # after the release the cube lies on the table and nothing believes where:
                    # logging that estimate would plot as a 7 cm "error" at the last move
                    rec.pose_estimate(
                        move_index, self.cube.pose(), self.est, label=type(action).__name__.lower()
                    )
        except StrategyFailure as e:
            rec.event("failure", cause=e.cause, message=str(e))
            t_end = b.time
            if e.cause is None:
                return TrialOutcome(
                    final_state=self.cube.state_string,
                    termination_s=t_end,
                    message=str(e),
                    extra=self._extra(),
                )
            return TrialOutcome(
                failure=e.cause,
                message=str(e),
                termination_s=t_end,
                final_state=None,
                extra=self._extra(),
            )
        return TrialOutcome(
            final_state=self.cube.state_string, termination_s=self.t_release, extra=self._extra()
        )

    def _extra(self) -> dict:
        return {
            "twists": [o.summary() for o in self.cube.history],
            "misaligned": self.cube.misaligned,
            "errors": {s: h.calibration.as_array().tolist() for s, h in self.hands.items()},
        }

    # ------------------------------------------------------------- sensing
    def _camera_estimate(self, ctx: TrialContext) -> Pose:
        err = self.config.errors
        true = self.cube.pose()
        if not err.camera:
            return true
        slot = ctx.sensors.get("head-camera") if ctx.sensors else None
        try:
            from ...sensors import HeadCamera
        except ImportError:  # sensors package absent: a documented Gaussian from ctx.rng
            p = true.p + ctx.rng.normal(0.0, err.camera_pos_std, 3)
            yaw = Rotation.from_euler(
                "z", ctx.rng.normal(0.0, err.camera_yaw_std_deg), degrees=True
            )
            return Pose.from_rotation(p, yaw * true.rotation)
        cam = slot.create() if slot is not None else HeadCamera()
        rng = slot.rng if slot is not None else ctx.rng
        return cam.estimate(true, rng, time=self.b.time).pose

    def _check_drop(self, k: int) -> None:
        """Judge's check (not control): the cube far from where it is believed and below the hands."""
        true = self.cube.pose()
        if (
            true.p[2] < self.config.table_height + CUBE_HALF + 0.01
            and np.linalg.norm(true.p - self.est.p) > self.config.drop_distance
        ):
            raise StrategyFailure(
                "dropped", f"action {k + 1}: the cube fell (at {np.round(true.p, 3).tolist()})"
            )

    def _judge(self, label: str, hand: Hand | None = None) -> None:
        """Diagnostic event (not control): how far the true cube is from the belief right now.

        Recorded after every grasp and at the steps of a hand-over, so that a
        failure's record says at which step the cube moved in a grip.
        """
        true = self.cube.pose()
        rv = (true.rotation * self.est.rotation.inv()).as_rotvec()
        data = {
            "label": label,
            "err_mm": round(float(1000 * np.linalg.norm(true.p - self.est.p)), 2),
            "rot_deg": np.round(np.degrees(rv), 1).tolist(),
        }
        if hand is not None and hand.cmd is not None:
            data["hand"] = hand.side
            data["fingers"] = np.round(hand.cmd.rotation.apply([0.0, 1.0, 0.0]), 2).tolist()
        self.ctx.recorder.event("check", **data)

    # ------------------------------------------------------------- motion
    def _send(
        self,
        hand: Hand,
        target: Pose,
        *,
        label: str,
        duration: float | None = None,
        settle: float = 0.2,
        seed_q: np.ndarray | None = None,
    ) -> None:
        """Command ``hand`` to ``target`` (believed); the arm receives it with the injected errors."""
        err = self.config.errors
        noise = self.ctx.rng.normal(0.0, err.tracking_std, 3) if err.tracking_std else np.zeros(3)
        cal = hand.calibration
        actual = Pose.from_rotation(target.p + cal.p + noise, cal.rotation * target.rotation)
        res = hand.arm.move_to_pose(
            actual,
            duration=duration,
            velocity_scale=self.config.velocity_scale,
            settle=settle,
            seed_q=seed_q,
        )
        hand.cmd = target
        if hand.holding:
            hand.last_grip = target
        if not res.ik_success:
            raise StrategyFailure(
                "unreachable",
                f"{hand.side} arm: no IK solution for {label} "
                f"(target {np.round(target.p, 3).tolist()})",
            )
        if hand.holding and not self._other(hand).holding and hand.cube_in_tcp is not None:
            self.est = target * hand.cube_in_tcp  # dead reckoning: the cube moved with the command

    def _other(self, hand: Hand) -> Hand:
        return self.hands["right" if hand.side == "left" else "left"]

    def _offset(self, depth: int) -> float:
        return self.config.rotator_offset if depth == 1 else self.config.holder_offset

    def _choose_grip(
        self,
        hand: Hand,
        world_dir: str,
        depth: int,
        vertical_fingers: bool = True,
        turn: tuple[str, float] | None = None,
        perpendicular: bool = False,
    ) -> tuple[Pose, np.ndarray]:
        """The grip (of four finger placements) the arm reaches with the least joint motion, and its IK solution.

        The PR2's forearm and wrist rolls are continuous and IK returns them on
        the branch nearest the current configuration, so any placement leaves
        room for any twist; placements differ only in how far the arm must
        move and whether the fingers clear the other hand's.
        ``turn`` = (world axis, angle): this hand will give the cube in a hand-over from this grip;
        the grip must also let the arm carry that turn through IK solutions that follow each other
        (a waypoint whose nearest solution jumps more than ``max_waypoint_jump`` is a change of arm
        branch — elbow or shoulder — with the cube in hand), and the one with the least joint travel
        over the turn is preferred.
        ``perpendicular``: the fingers must cross the other hand's (in a shift both hands are two slabs
        deep and overlap along the work axis; in a hand-over the giver's finger lies on the face the
        taker comes to, and only crossing fingers pass it); otherwise crossing is preferred.
        All placements are solved in one batched IK call (and the turn's waypoints in one call each).
        """
        other = self._other(hand)
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
        for pose in grip_candidates(self.est, world_dir, self._offset(depth)):
            fy = pose.rotation.apply([0.0, 1.0, 0.0])
            if not vertical_fingers and abs(fy[2]) > 0.7:
                continue  # on the table a finger would go under the cube
            cross = other_y is None or abs(float(np.dot(fy, other_y))) < 0.3
            if other_on_axis:
                cross = cross and abs(float(np.dot(fy, other_x))) < 0.3
            if perpendicular and not cross:
                continue
            parallel = other_y is not None and abs(float(np.dot(fy, other_y))) > 0.7
            poses.append(pose)
            if self.finger_preference == "parallel" and not perpendicular:
                bonus.append(0.5 if parallel else 0.0)
            else:
                bonus.append(0.5 if cross else 0.0)
        if not poses:
            raise StrategyFailure(
                "unreachable",
                f"{hand.side} arm: no finger placement from {world_dir} clears the other hand",
            )
        seeds = [q_now]
        if turn is not None and self.giver_seeds > 0:
            # a giver also tries other arm configurations (the 7-DOF arm's self-motion) for each
            # placement: the turn may only be smooth from another elbow/shoulder posture
            rng = np.random.default_rng(len(self.ctx.recorder.events))  # deterministic per trial
            lo = np.where(np.isfinite(hand.arm.lower), hand.arm.lower, -np.inf)
            hi = np.where(np.isfinite(hand.arm.upper), hand.arm.upper, np.inf)
            seeds += [
                np.clip(q_now + rng.normal(0.0, 0.6, q_now.shape), lo, hi)
                for _ in range(self.giver_seeds)
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
            travel, worst = self._turn_travel(
                hand, base, [poses[i] for i in np.flatnonzero(ok)], res.q[ok], *turn
            )
            turned = score.copy()
            turned[np.flatnonzero(ok)] -= (
                0.1 * travel
            )  # inf travel: the turn cannot be carried from there
            if np.isfinite(turned).any():
                score = turned
            else:  # the least bad: the smallest largest jump on the way
                score[np.flatnonzero(ok)] -= worst
                self.ctx.recorder.event(
                    "warning",
                    message=f"{hand.side}: no grip lets the hand-over turn run smoothly "
                    f"(largest joint step {float(np.min(worst)):.2f} rad)",
                )
        best = int(np.argmax(score))
        return poses[best], np.array(res.q[best], dtype=float)

    def _turn_travel(
        self, hand: Hand, base: Pose, grips: list[Pose], q: np.ndarray, axis: str, angle: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Joint travel of carrying the cube from each of ``grips`` through the hand-over turn (inf: not
        smooth), and the largest joint step on the way (inf: a waypoint out of reach).

        The chain ends with the giver's retreat from the turned grip (``handover_retreat`` back along
        its approach): a turn that ends at a joint limit leaves no straight way out, and the arm's
        retreat then swings through the cube on another branch.
        """
        n = max(1, self.config.handover_waypoints) * max(1, round(abs(angle) / (math.pi / 2)))
        q = np.array(q, dtype=float)
        total = np.zeros(len(grips))
        worst = np.zeros(len(grips))
        for i in range(1, n + 2):
            live = np.flatnonzero(np.isfinite(worst))
            if live.size == 0:
                break
            poses = [
                rotate_about_point(grips[k], self.est.p, axis, angle * min(i, n) / n) for k in live
            ]
            if i > n:  # the retreat
                poses = [
                    Pose(p.p - p.rotation.apply([self.handover_retreat, 0.0, 0.0]), p.q)
                    for p in poses
                ]
            targets = [(base.inv() * p).as_matrix() for p in poses]
            res = hand.arm.ik(np.stack(targets), seed_q=q[live])
            jump = np.max(np.abs(res.q - q[live]), axis=1)
            reached = np.asarray(res.success, dtype=bool)
            bad = ~reached | (jump > self.config.max_waypoint_jump)
            total[live] = np.where(bad, np.inf, total[live] + jump)
            worst[live] = np.where(reached, np.maximum(worst[live], jump), np.inf)
            q[live] = res.q
        return total, worst

    def _next_turn(self, k: int, side: str) -> tuple[str, float] | None:
        """If ``side``'s next regrasp after action ``k`` is giving the cube in a hand-over: (axis, angle)."""
        for a in self.plan.actions[k + 1 :]:
            if isinstance(a, Handover):
                return (a.axis, a.quarter_turns * math.pi / 2) if a.giver == side else None
            if isinstance(a, Regrasp):
                return None
        return None

    def _approach(
        self, hand: Hand, grip: Pose, label: str, q_plan: np.ndarray | None = None
    ) -> None:
        """Open, go to the pre-grasp stand-off along the approach, move in, close.

        ``q_plan``: the grip's IK solution the choice was made with (and a
        hand-over turn checked from); the stand-off, pre-grasp and grip are
        solved from it, so that the arm arrives on that branch rather than
        wherever the seeds along the way would lead (measured: a giver that
        arrived on another branch met a joint limit in the turn's first
        waypoint and swung the cube 15 degrees).
        """
        hand.gripper.open(wait=0.3)
        cfg = self.config
        far = Pose(grip.p - grip.rotation.apply([cfg.far_distance, 0, 0]), grip.q)
        if (
            np.linalg.norm(far.p - hand.cmd.p) > 0.01
            or abs(float(np.dot(far.q, hand.cmd.q))) < 0.999
        ):
            # swing round to the far stand-off first, so that the swing clears the cube
            self._swing(hand, far, label=f"{label} stand-off", seed_q=q_plan)
        back = Pose(grip.p - grip.rotation.apply([cfg.pregrasp_distance, 0, 0]), grip.q)
        self._send(hand, back, label=f"{label} pre-grasp", settle=0.1, seed_q=q_plan)
        grip = self._relocalise(hand, grip, label)
        self._send(hand, grip, label=label, settle=0.2, seed_q=q_plan)

    def _swing(self, hand: Hand, far: Pose, label: str, seed_q: np.ndarray | None = None) -> None:
        """Carry a free hand round the cube to the stand-off ``far`` on an arc about the believed centre.

        Why: one joint-space move from where the hand let go (often above or
        below the cube after a hand-over turn) to a stand-off on another side
        sweeps the tool frame along whatever path the joints take, and was
        measured knocking the held cube 12 degrees (SAPIEN, Rubiks-1-20). Here
        the tool frame moves in Cartesian waypoints (at most 45 degrees apart)
        on an arc round the cube, its distance from the centre and its
        orientation interpolated between the two ends, so it never comes
        nearer the cube than where it started or ends. A waypoint the arm
        cannot reach is left out.
        """
        from scipy.spatial.transform import Slerp

        c = self.est.p
        d0, d1 = hand.cmd.p - c, far.p - c
        r0, r1 = float(np.linalg.norm(d0)), float(np.linalg.norm(d1))
        u0, u1 = d0 / max(r0, 1e-9), d1 / max(r1, 1e-9)
        angle = math.acos(float(np.clip(np.dot(u0, u1), -1.0, 1.0)))
        n = max(1, math.ceil(angle / (math.pi / 4)))
        if n == 1 or r0 < 0.05 or r1 < 0.05:
            self._send(hand, far, label=label, settle=0.05, seed_q=seed_q)
            return
        axis = np.cross(u0, u1)
        if np.linalg.norm(axis) < 1e-6:  # opposite sides: go over the top
            axis = np.cross(u0, [0.0, 0.0, 1.0])
            if np.linalg.norm(axis) < 1e-6:
                axis = np.array([1.0, 0.0, 0.0])
        axis = axis / np.linalg.norm(axis)
        slerp = Slerp([0.0, 1.0], Rotation.from_quat(np.stack([hand.cmd.q, far.q])))
        base = hand.arm.base_pose()
        for i in range(1, n):
            f = i / n
            u = Rotation.from_rotvec(axis * angle * f).apply(u0)
            way = Pose.from_rotation(c + ((1 - f) * r0 + f * r1) * u, slerp([f])[0])
            if hand.arm.ik(
                (base.inv() * way).as_matrix()[None], seed_q=hand.arm.positions()
            ).success[0]:
                self._send(hand, way, label=f"{label} arc", settle=0.02)
        self._send(hand, far, label=label, settle=0.05, seed_q=seed_q)

    def _relocalise(self, hand: Hand, grip: Pose, label: str) -> Pose:
        """Hook before a hand moves in to grip (dead reckoning: nothing; sensor-aided: pre-touch)."""
        return grip

    def _close(self, hand: Hand, world_dir: str, depth: int, label: str) -> None:
        """Close on the cube; when the other hand holds it, first softly, then with the full grip force.

        Why two stages: a cube held by one parallel gripper pivots about that
        gripper's pad axis, resisted only by the pads' torsional friction. The
        closing gripper's first-touching finger pushes the cube with the
        closing force at a lever of 17-50 mm from that axis; at the full 20 N
        that out-torques the friction (measured on PyBullet: the cube turned
        11 degrees at a hand-over take). At ``soft_grip_force`` it does not;
        once both pads touch, raising the force squeezes symmetrically.
        """
        cfg = self.config
        if self._other(hand).holding and cfg.soft_grip_force > 0:
            hand.gripper.close(force_limit=cfg.soft_grip_force, obj=self.cube.body)
        g = hand.gripper.close(force_limit=cfg.grip_force, obj=self.cube.body)
        if g.closed or not g.contact:
            raise StrategyFailure(
                None, f"{label}: {hand.side} gripper closed on nothing (grasp missed)"
            )
        hand.holding = True
        hand.last_grip = hand.cmd
        hand.cube_in_tcp = hand.cmd.inv() * self.est
        hand.grip_dir, hand.depth = world_dir, depth
        self._judge(label, hand)

    #: how far the giver backs off along its approach after a hand-over (m)
    handover_retreat = 0.12

    def _release_hand(self, hand: Hand, retreat: float | None = None) -> None:
        """Open (if holding) and stand off ``retreat`` along the approach from the last grip.

        The open hand is still round the cube, so the retreat must be a
        straight move: if the stand-off's IK solution is more than
        ``max_waypoint_jump`` from the arm's joints (a joint limit on the way
        out, another branch beyond), it backs off in 2 cm steps only as far
        as the arm follows smoothly and logs a warning.
        """
        if hand.holding:
            hand.gripper.open(wait=0.3)
        hand.holding, hand.cube_in_tcp, hand.grip_dir, hand.depth = False, None, None, 0
        d = self.config.pregrasp_distance if retreat is None else retreat
        ref = hand.last_grip or hand.cmd
        back = Pose(ref.p - ref.rotation.apply([d, 0, 0]), ref.q)
        if not (
            np.linalg.norm(back.p - hand.cmd.p) > 2e-3
            or not Pose(hand.cmd.p, back.q).allclose(Pose(hand.cmd.p, hand.cmd.q), 1, 1e-3)
        ):
            return
        if self._smooth(hand, back):
            self._send(hand, back, label="retreat", settle=0.05)
            return
        step = 0.02
        dist = float(
            np.dot(ref.p - hand.cmd.p, ref.rotation.apply([1.0, 0.0, 0.0]))
        )  # already backed off
        while dist + step <= d + 1e-9:
            nxt = Pose(ref.p - ref.rotation.apply([dist + step, 0, 0]), ref.q)
            if not self._smooth(hand, nxt):
                break
            self._send(hand, nxt, label="retreat step", settle=0.02)
            dist += step
        self.ctx.recorder.event(
            "warning",
            message=f"{hand.side}: retreat cut to {100 * dist:.0f} cm "
            f"(the straight way out leaves the arm's branch)",
        )

    def _smooth(self, hand: Hand, target: Pose) -> bool:
        """Whether the arm reaches ``target`` from its joints without any joint moving > max_waypoint_jump."""
        base = hand.arm.base_pose()
        q = hand.arm.positions()
        res = hand.arm.ik((base.inv() * target).as_matrix()[None], seed_q=q)
        return (
            bool(res.success[0])
            and float(np.max(np.abs(res.q[0] - q))) <= self.config.max_waypoint_jump
        )

    def _grip(
        self,
        hand: Hand,
        world_dir: str,
        depth: int,
        label: str,
        vertical_fingers: bool = True,
        k: int | None = None,
        perpendicular: bool = False,
    ) -> None:
        turn = self._next_turn(k, hand.side) if (k is not None and depth == 2) else None
        grip, q_plan = self._choose_grip(
            hand, world_dir, depth, vertical_fingers, turn, perpendicular
        )
        self._approach(hand, grip, label, q_plan)
        self._close(hand, world_dir, depth, label)

    @staticmethod
    def _roll_delta(t: Twist) -> float:
        """Wrist-roll change for a twist: ``quarter_turns`` right-handed about +y; left tool x is -y."""
        phi = t.quarter_turns * math.pi / 2
        return -phi if t.gripper == "left" else phi

    # ------------------------------------------------------------- actions
    def _pick(self, a: Pick, k: int) -> None:
        if a.approach != "side":
            raise StrategyFailure(
                None, f"pick approach {a.approach!r} is not implemented (side only)"
            )
        cfg = self.config
        picker = self.hands[a.gripper]
        other = self._other(picker)
        # the picker carries the cube alone: two slabs deep (see _handover), then slides out if it rotates
        self._grip(picker, SIDE_DIR[picker.side], 2, "pick", vertical_fingers=False)
        lift = np.asarray(cfg.twist_position) - self.est.p
        up = Pose(picker.cmd.p + [0, 0, lift[2] + 0.03], picker.cmd.q)
        self._send(picker, up, label="lift")
        there = Pose(picker.cmd.p + [lift[0], lift[1], -0.03], picker.cmd.q)
        self._send(picker, there, label="carry")
        self._join(picker, other, a.rotator, "second grasp", "pick shift out", k)

    def _join(
        self, alone: Hand, free: Hand, rotator: str, label: str, shift_label: str, k: int
    ) -> None:
        """The free hand joins the hand holding alone (two slabs deep) so that the next rotator holds one slab.

        If the lone holder rotates next, the free hand grips two slabs deep, fingers crossing (it
        becomes the holder), and the lone hand lets go and slides out to one slab; otherwise the free
        hand grips one slab deep.
        """
        if rotator == alone.side:
            self._grip(free, SIDE_DIR[free.side], 2, label, k=k, perpendicular=True)
            self._release_hand(alone)
            self._grip(alone, SIDE_DIR[alone.side], 1, shift_label)
        else:
            self._grip(free, SIDE_DIR[free.side], 1, label, k=k)

    def _twist(self, t: Twist, orientation, k: int) -> None:
        cube, rec = self.cube, self.ctx.recorder
        rot, hold = self.hands[t.gripper], self._other(self.hands[t.gripper])
        if not (rot.holding and hold.holding and rot.depth == 1 and hold.depth == 2):
            # after a twist the rotator stands off: a twist right after a twist re-takes its slab
            if hold.holding and hold.depth == 2 and not rot.holding:
                self._grip(rot, SIDE_DIR[rot.side], 1, "re-grip")
        if not (rot.holding and hold.holding and rot.depth == 1 and hold.depth == 2):
            raise StrategyFailure(None, f"twist {k + 1}: hands not in twisting grips")
        move = twist_move(orientation, t.axis, t.layer, t.quarter_turns)
        # the body axis along the work axis, from the *believed* pose
        local = self.est.rotation.inv().apply([0.0, 1.0, 0.0])
        body_axis = "xyz"[int(np.argmax(np.abs(local)))]
        intended = str(move) if BODY_AXIS_OF_FACE[move.kind] == body_axis else None
        reason = cube.block_reason(body_axis)
        if reason is not None:
            rec.blocked_rotation(t.source, str(move), reason)
            raise StrategyFailure("jammed", f"twist {k + 1} ({move}): {reason}")
        cube.begin_twist(body_axis, intended=intended)
        delta = self._roll_delta(t)
        # from the measured joints, which track a goal on a soft limit to within ~1e-4 rad of either
        # side: the goal is kept on the limit (measured: one goal 1e-4 rad past the upper-arm roll's)
        q = np.clip(rot.arm.positions(), rot.arm.lower, rot.arm.upper)
        q[-1] += delta  # the wrist roll is continuous: any twist runs in full
        rot.arm.move_to_joints(
            q, duration=self.config.quarter_turn_s * abs(t.quarter_turns), settle=0.2
        )
        rot.cmd = rot.last_grip = turned_about_approach(rot.cmd, delta)
        rot.gripper.open(wait=0.3)
        out = cube.end_twist()
        rec.move(
            t.source,
            str(move),
            outcome=out.summary(),
            moves=out.moves,
            layer_angles_deg=list(out.layer_angles_deg),
            jammed=out.jammed,
            misaligned=out.misaligned,
            as_intended=out.as_intended,
            body_axis=body_axis,
        )
        if out.unintended_rotation:
            rec.unintended_rotation(
                t.source, str(move), out.moves or "misaligned", dragged_deg=out.dragged_deg
            )
        if out.jammed:
            rec.blocked_rotation(t.source, str(move), "the turning layer did not turn (jammed)")
            raise StrategyFailure("jammed", f"twist {k + 1} ({move}) jammed: {out.summary()}")
        self._release_hand(
            rot
        )  # the rotator backs off; the next regrasp or hand-over takes it from there

    def _shift(self, a: Regrasp, k: int) -> None:
        if a.kind != "shift":
            raise StrategyFailure(None, f"regrasp {a.kind!r} is not implemented")
        new_rot = self.hands[a.gripper]
        new_hold = self._other(new_rot)
        # the old rotator slides in to two slabs, then the old holder slides out to one
        self._release_hand(new_hold)
        self._grip(new_hold, SIDE_DIR[new_hold.side], 2, "shift in", k=k, perpendicular=True)
        self._release_hand(new_rot)
        self._grip(new_rot, SIDE_DIR[new_rot.side], 1, "shift out")

    def _handover(self, a: Handover, k: int) -> None:
        giver, taker = self.hands[a.giver], self.hands[a.taker]
        cfg = self.config
        self._release_hand(taker, retreat=0.15)
        centre = self.est.p.copy()
        n = max(1, cfg.handover_waypoints) * abs(a.quarter_turns)
        angle = a.quarter_turns * math.pi / 2
        start = giver.cmd
        for i in range(1, n + 1):
            self._send(
                giver,
                rotate_about_point(start, centre, a.axis, angle * i / n),
                label="hand-over turn",
                settle=0.05 if i < n else 0.2,
            )
        self._judge("hand-over turned", giver)
        # The taker takes two slabs deep, whichever hand rotates next: it then holds the cube alone
        # while the giver comes round, and a one-slab grip (12 mm of pad on the face, the weight 34 mm
        # out) let the cube pivot about its pad axis there (measured on PyBullet: 32 degrees as the
        # giver let go). If the taker is the next rotator, the giver re-grips two slabs deep as well
        # (fingers crossing, as in a shift) and the taker then slides out to one slab.
        self._grip(taker, SIDE_DIR[taker.side], 2, "hand-over take", k=k, perpendicular=True)
        self._release_hand(giver, retreat=self.handover_retreat)
        self._judge("hand-over given", taker)
        self._join(taker, giver, a.rotator, "hand-over re-grip", "hand-over shift out", k)

    def _release(self) -> None:
        for hand in self.hands.values():
            hand.gripper.open(wait=0.3)
            hand.holding = False
        self.t_release = self.b.time


class SensorAidedStrategy(DeadReckoningStrategy):
    """Dead reckoning plus pre-touch re-localisation before every grasp (Yang et al. 2020, Sec. IV-B).

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

    name = "sensor-aided"
    #: prior std handed to the filter at each re-localisation: (position m, yaw deg)
    prior_pos_std = 0.006
    prior_yaw_std_deg = 3.0
    #: emitter grid across the tool frame (m), all looking along tool x
    grid = (-0.012, 0.0, 0.012)

    def _sensor(self, hand: Hand):
        from ...sensors import Emitter, PreTouchSensor

        cache = self.__dict__.setdefault("_sensors", {})
        if hand.side not in cache:
            emitters = [Emitter((0.0, y, z), (1.0, 0.0, 0.0)) for y in self.grid for z in self.grid]
            link = hand.arm.config.tcp_link
            slot = self.ctx.sensors.get("pretouch-tof") if self.ctx.sensors else None
            if slot is not None:
                sensor = slot.create(
                    backend=self.b, body=self.robot.body, link=link, emitters=emitters
                )
                rng = slot.rng
            else:
                sensor = PreTouchSensor(self.b, self.robot.body, link, emitters)
                rng = np.random.default_rng(self.ctx.rng.integers(2**63))
            cache[hand.side] = (sensor, rng)
        return cache[hand.side]

    def _relocalise(self, hand: Hand, grip: Pose, label: str) -> Pose:
        from ...sensors import CubePoseFilter, PoseEstimate, cube_yaw, yaw_error

        sensor, rng = self._sensor(hand)
        std = np.array([self.prior_pos_std] * 3 + [math.radians(self.prior_yaw_std_deg)])
        prior = PoseEstimate(self.est, np.diag(std**2), n_measurements=1, time=self.b.time)
        kf = CubePoseFilter(initial=prior)
        reading = sensor.read(rng, believed_link_pose=hand.cmd)
        report = kf.update_reading(reading)
        before = self.est
        if report.n_used >= 3:
            post = kf.estimate
            dyaw = yaw_error(post.yaw, cube_yaw(before.rotation))
            self.est = Pose.from_rotation(
                post.pose.p, Rotation.from_euler("z", dyaw) * before.rotation
            )
            for h in self.hands.values():  # re-anchor what the holding hand believes it carries
                if h.holding and h.cmd is not None:
                    h.cube_in_tcp = h.cmd.inv() * self.est
        self.ctx.recorder.event(
            "pretouch",
            hand=hand.side,
            label=label,
            rays=report.n_rays,
            used=report.n_used,
            correction_mm=float(1000 * np.linalg.norm(self.est.p - before.p)),
        )
        self.ctx.recorder.pose_estimate(
            getattr(self, "_move_index", 0), self.cube.pose(), self.est, label="pretouch"
        )
        if self.est is before:
            return grip
        # the same finger placement, recomputed from the corrected belief
        local = before.inv() * grip
        return self.est * local
