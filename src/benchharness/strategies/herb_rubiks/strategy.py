"""HERB's push-grasp Rubik's strategy (Yang et al. 2020, Sec. IV-D): the bimanual state machine, every grasp a push-grasp.

Control never reads the true cube pose. The belief starts as the head
camera's one-shot estimate; it is carried by dead reckoning (the holding
hand's *commanded* tool poses) by the bimanual state machine
(:mod:`..bimanual.machine`), and every push-grasp **re-anchors it along the
approach**: the hand stops when its thumb touches the face, so the face is
where the thumb's tip is (``commanded tool pose + thumb depth``), whatever
the belief said.

What is HERB's is here (:class:`PushGrasp`, the grasp module): the
BarrettHand's pre-shapes, which of the four push-grasp frames a grip takes
(IK, wrist-roll room for the next twist, clearance from the other hand's
fingers, whether a giver's hand-over turn can be carried), the push itself
(:mod:`.push`) and the close of the outer fingers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose
from ..bimanual.machine import (
    SIDE_DIR,
    BimanualRubiksMachine,
    GripRequest,
    Hand,
    StrategyFailure,
)
from ..regrasp import HandModel
from .config import HerbPushGraspConfig
from .frames import (
    CUBE_HALF,
    DIRECTIONS,
    DIST_CORNERS,
    DIST_FILL,
    PALM_FILL,
    PROX_CORNERS,
    PROX_FILL,
    approach_axis,
    band_clear,
    finger_extent,
    pinch_axis,
    push_grip_candidates,
    reanchor_along_approach,
    thumb_face_depth,
    thumb_tip_lateral,
)
from .push import (
    OUTER_FINGER_JOINTS,
    PushUnreachable,
    _force_limits,
    close_outer_fingers,
    preshape,
    push_until_contact,
    wait_fingers,
)

__all__ = ["BarrettState", "PushGrasp", "PushGraspStrategy", "StrategyFailure"]

#: :attr:`BarrettState.shape` of a giver's one-slab pre-shape (``giver_thumb_flex``)
GIVE_SHAPE = 3


def _axis_name(v) -> str:
    """The world axis nearest ``v`` ('+x', '-z', ...), for diagnostics."""
    i = int(np.argmax(np.abs(v)))
    return ("+" if v[i] > 0 else "-") + "xyz"[i]


@dataclass
class BarrettState:
    """What the push-grasp module keeps per hand (:attr:`..bimanual.machine.Hand.state`)."""

    shape: int = 0  #: current pre-shape: 1 rotator, 2 holder, GIVE_SHAPE giver (0: none)
    face_depth: float = (
        0.0  #: thumb tip beyond the tool frame in the current pre-shape (m), measured
    )
    slide: float = 0.0  #: how far the current grip slid across its face off the nominal, to clear the other hand (m)
    thumb_lateral: float = (
        0.0  #: where across the palm (tool y, m) the thumb's tip touches, measured
    )
    #: a giver's grip: the IK solution its hand-over turn was checked from (None: not checked)
    turn_q: np.ndarray | None = None


def _st(hand: Hand) -> BarrettState:
    st = hand.state
    assert isinstance(st, BarrettState)
    return st


class PushGrasp:
    """HERB's grasp module: BarrettHand push-grasps (tool z = approach, the outer fingers pinch across tool x)."""

    approach_axis = 2
    finger_axis = 0
    gripper_name = "{side}_hand"
    robot_name: str | None = "herb"

    def __init__(self, config: HerbPushGraspConfig | None = None) -> None:
        self.config: HerbPushGraspConfig = config or HerbPushGraspConfig()

    def hand_model(self) -> HandModel:
        return replace(HandModel.herb(), pick_approaches=("side",))

    def hand_state(self) -> Any:
        return BarrettState()

    def take_relation(self) -> str | None:
        # see ``taker_parallel``: crossing puts the taker's outer finger through the giver's curled thumb
        return "parallel" if self.config.taker_parallel else "cross"

    # ------------------------------------------------------------- pre-shape and choice
    def _shape(self, req: GripRequest) -> int:
        """The pre-shape a grip takes: the holder's for two slabs, else the rotator's, or a giver's one-slab
        grip for a hand-over turn (``giver_thumb_flex``)."""
        if req.depth == 1 and req.turn is not None and self.config.giver_thumb_flex is not None:
            return GIVE_SHAPE
        return req.depth

    def _preshape(self, m: BimanualRubiksMachine, hand: Hand, depth: int) -> None:
        """Spread 90 deg, outer fingers open, thumb flexed for pre-shape ``depth`` (1, 2 or GIVE_SHAPE);
        measure how far the thumb reaches."""
        cfg = self.config
        if depth == GIVE_SHAPE:
            assert cfg.giver_thumb_flex is not None
            flex = cfg.giver_thumb_flex
        else:
            flex = cfg.rotator_thumb_flex if depth == 1 else cfg.holder_thumb_flex
        preshape(
            hand.gripper,
            cfg.spread,
            flex,
            outer_flex=cfg.outer_open_flex,
            thumb_force=cfg.thumb_force,
        )
        prefix = hand.arm.config.tcp_link.split("_")[0]
        distal = m.b.get_link_pose(m.robot.body, f"{prefix}_bh_finger_33_link")
        st = _st(hand)
        st.face_depth = thumb_face_depth(hand.arm.tcp_pose(), distal)
        st.thumb_lateral = thumb_tip_lateral(hand.arm.tcp_pose(), distal)
        st.shape = depth

    def choose(
        self, m: BimanualRubiksMachine, hand: Hand, req: GripRequest
    ) -> tuple[Pose, np.ndarray | None]:
        """Pre-shape; the push-grasp frame (of four finger placements) the arm reaches, with wrist-roll room
        for the next twist.

        ``req.relation``: "cross", the outer fingers must cross the other hand's (the two grips overlap in
        depth in a shift); "parallel", they must pinch the same pair of faces as the other hand's (a
        hand-over take, see ``taker_parallel``); None: crossing is preferred. ``req.on_table``: no
        finger may go under the cube, and the thumb comes from below (its root beside the table).
        ``req.turn``: this hand will give the cube in a hand-over, so the grip should let the arm
        carry that turn and the retreat after it without an IK flip
        (:meth:`..bimanual.machine.BimanualRubiksMachine.turn_travel`); if no grip does, one whose
        turn alone is smooth (on HERB the 12 cm retreat straight out of a turned grip often is not);
        if none, one from an arm posture found backwards (:meth:`_backward_give`); else the least bad.
        Returns the IK solution to reach the grip by when the wrist had to be re-seeded for the twist
        (see below) or for a giver's posture found backwards (:meth:`_backward_give`), else None: the
        arm moves to the stand-off from where it is. (A giver's turn is checked from the IK solution
        seeded with the arm's joints now, but the arm reaches the grip from where its swing ends and
        can arrive on another branch: PyBullet Rubiks-5-5 seed 0 trial 5, docs/herb_push_grasp.md.
        Sending every giver on its checked solution fixed that trial but cost three others.)
        """
        cfg = self.config
        st = _st(hand)
        if st.shape != self._shape(req):
            self._preshape(m, hand, self._shape(req))
        world_dir, turn, twist_delta = req.world_dir, req.turn, req.twist_delta
        perpendicular, parallel = req.relation == "cross", req.relation == "parallel"
        other = m.other(hand)
        other_x = pinch_axis(other.last_grip) if other.holding and other.last_grip else None
        other_z = approach_axis(other.last_grip) if other.holding and other.last_grip else None
        other_on_axis = (
            other_x is not None and abs(float(np.dot(other_x, DIRECTIONS[world_dir]))) > 0.7
        )
        base = hand.arm.base_pose()
        q_now = hand.arm.positions()
        lo, hi = hand.arm.lower[-1], hand.arm.upper[-1]
        # a second pass, the wrist re-seeded, only when every grip of a rotator about to twist leaves
        # the wrist short of the twist (earlier grips leave it to ``regrip_before_twist``: re-seeded
        # there, arms took other branches and a later twist dragged, SAPIEN Rubiks-5-5 trial 4)
        for reseed in (False, True):
            best: Pose | None = None
            second: Pose | None = (
                None  # a giver's grip whose turn is smooth but not the retreat after it
            )
            fallback: Pose | None = None
            best_score = second_score = fallback_score = -np.inf
            best_slide = second_slide = fallback_slide = 0.0
            best_q: np.ndarray | None = None  # the IK solution to reach ``best`` by, if re-seeded
            # a giver's: the IK solution the turn of ``best`` / ``second`` was checked from
            best_turn_q: np.ndarray | None = None
            second_turn_q: np.ndarray | None = None
            # a giver's placements that pass the other rules: (pose, score without the arm's posture, slide)
            give_places: list[tuple[Pose, float, float]] = []
            # diagnostic for the recorder: each candidate and why it was taken or not
            tried: list[str] = []
            lateral = cfg.holder_thumb_offset if st.shape == 2 else cfg.rotator_thumb_offset
            for pose in push_grip_candidates(m.est, world_dir, st.face_depth):
                fx = pinch_axis(pose)
                tag = f"pinch {_axis_name(fx)} thumb {_axis_name(pose.rotation.apply([0.0, 1.0, 0.0]))}"
                shift: float | None = lateral
                if other_x is not None and abs(float(np.dot(fx, other_x))) >= 0.7:
                    # both hands on the same faces
                    shift = self._clear_lateral(m, hand, pose, lateral)
                    if shift is None:
                        tried.append(f"{tag}: fingers cannot clear the other hand's")
                        continue
                    if abs(shift - lateral) > 1e-4:
                        tag += f" slid {1000 * (shift - lateral):+.0f} mm"
                assert shift is not None
                pose = Pose(pose.p + pose.rotation.apply([0.0, shift, 0.0]), pose.q)
                if req.on_table and (
                    abs(fx[2]) > 0.7 or pose.rotation.apply([0.0, 1.0, 0.0])[2] > -0.7
                ):
                    # on the table: no outer finger under the cube, and the thumb's root below (its tip
                    # curls up onto the face, clear of the table top)
                    continue
                crossing = other_x is None or abs(float(np.dot(fx, other_x))) < 0.3
                if other_on_axis and other_z is not None:
                    crossing = crossing and abs(float(np.dot(fx, other_z))) < 0.3
                if perpendicular and not crossing:
                    tried.append(f"{tag}: not crossing")
                    continue
                if parallel and (other_x is None or abs(float(np.dot(fx, other_x))) < 0.7):
                    tried.append(f"{tag}: not parallel")
                    continue
                res = hand.arm.ik((base.inv() * pose).as_matrix()[None], seed_q=q_now)
                if not res.success[0]:
                    tried.append(f"{tag}: no IK")
                    continue
                q7 = float(res.q[0][-1])
                margin = min(q7 - lo, hi - q7, q7 + twist_delta - lo, hi - (q7 + twist_delta))
                q_seeded: np.ndarray | None = None
                if reseed and margin < 0.0 and np.isfinite(lo) and np.isfinite(hi):
                    # seeded from where the arm is, IK spreads the grip's roll over the forearm and wrist
                    # joints and leaves the wrist no room for the twist (measured: all four grips of a
                    # half turn's re-grip 1.0-3.1 rad short, the wrist limited 177 deg short and F2 jammed,
                    # SAPIEN and PyBullet Rubiks-5-5 trial 4); seeded with the wrist in the middle of the
                    # twist's room, the arm's redundancy takes the roll instead
                    seed = np.array(q_now, dtype=float)
                    seed[-1] = 0.5 * (max(lo, lo - twist_delta) + min(hi, hi - twist_delta))
                    alt = hand.arm.ik((base.inv() * pose).as_matrix()[None], seed_q=seed)
                    if alt.success[0]:
                        a7 = float(alt.q[0][-1])
                        alt_margin = min(
                            a7 - lo, hi - a7, a7 + twist_delta - lo, hi - (a7 + twist_delta)
                        )
                        if alt_margin > margin:
                            res, q7, margin = alt, a7, alt_margin
                            q_seeded = np.asarray(alt.q[0], dtype=float)
                            tag += " (wrist re-seeded)"
                joint_move = float(np.max(np.abs(res.q[0] - q_now)))
                score = min(margin, 0.3) - 0.1 * joint_move + (0.5 if crossing else 0.0)
                if margin < 0.0:
                    score -= 10.0
                if turn is not None:
                    # the giver's pinch must not end on the work axis after the turn: its fingertip would sit
                    # on the face the taker's thumb comes to, and the taker's push would meet the finger
                    turned = Rotation.from_rotvec(DIRECTIONS[turn[0]] * turn[1])
                    if abs(float(turned.apply(fx)[1])) > 0.7:
                        tried.append(f"{tag}: pinch on the work axis after the turn")
                        continue
                    # and its thumb, curled over the face it pushed, should rise towards its root on the side
                    # away from the taker (a preference: with the root on the taker's side, the giver's fingers,
                    # 12 mm off centre towards the root, are where the taker's fingertips close)
                    taker_dir = DIRECTIONS[SIDE_DIR[other.side]]
                    if (
                        float(np.dot(turned.apply(pose.rotation.apply([0.0, 1.0, 0.0])), taker_dir))
                        > -0.7
                    ):
                        score -= 1.0
                    if score > fallback_score:
                        fallback, fallback_score, fallback_slide = pose, score, shift - lateral
                    give_places.append(
                        (pose, score + 0.1 * joint_move - min(margin, 0.3), shift - lateral)
                    )
                    travel, worst = m.turn_travel(hand, base, [pose], res.q[:1], *turn)
                    if not np.isfinite(travel[0]):
                        # the turn, or the giver's retreat after it, leaves the arm's branch; a grip whose
                        # turn alone is smooth is the second choice (the retreat is then cut short)
                        short, _ = m.turn_travel(
                            hand, base, [pose], res.q[:1], *turn, with_retreat=False
                        )
                        tried.append(
                            f"{tag}: turn + retreat not smooth (score {score:.2f}; largest joint step "
                            f"{float(worst[0]):.2f} rad; turn alone "
                            f"{'smooth' if np.isfinite(short[0]) else 'not smooth'})"
                        )
                        if np.isfinite(short[0]) and score - 0.1 * float(short[0]) > second_score:
                            second = pose
                            second_score = score - 0.1 * float(short[0])
                            second_slide = shift - lateral
                            second_turn_q = np.asarray(res.q[0], dtype=float)
                        continue
                    score -= 0.1 * float(travel[0])
                tried.append(
                    f"{tag}: score {score:.2f} (wrist margin {margin:.2f}, move {joint_move:.2f})"
                )
                if score > best_score:
                    best, best_score, best_slide = pose, score, shift - lateral
                    best_q = q_seeded
                    best_turn_q = None if turn is None else np.asarray(res.q[0], dtype=float)
            if reseed or not req.twist_now or best is None or best_score > -5.0:
                break
        if best is None and second is None and turn is not None and give_places:
            found = self._backward_give(m, hand, base, q_now, give_places, turn)
            if found is not None:
                best, best_slide, best_q = found
                tried.append("a posture found backwards from the retreat's end (giver_posture)")
        if best is None and second is None and turn is not None and m.level_stuck_turn(hand):
            # no grip has a smooth turn on the believed tilt: choose again with the turn levelled
            return self.choose(m, hand, req)
        if best is None and second is not None:
            m.ctx.recorder.event(
                "warning",
                message=f"{hand.side}: no grip lets the giver retreat straight after the hand-over turn",
            )
            best, best_slide, best_turn_q = second, second_slide, second_turn_q
        if best is None and fallback is not None:
            m.ctx.recorder.event(
                "warning", message=f"{hand.side}: no grip lets the hand-over turn run smoothly"
            )
            best, best_slide = fallback, fallback_slide
        m.ctx.recorder.event(
            "grip_choice",
            hand=hand.side,
            face=world_dir,
            candidates=tried,
            chosen=None
            if best is None
            else f"pinch {_axis_name(pinch_axis(best))} thumb {_axis_name(best.rotation.apply([0.0, 1.0, 0.0]))}",
        )
        if best is None:
            raise StrategyFailure(
                "unreachable", f"{hand.side} arm: no push-grasp from {world_dir} reachable"
            )
        st.slide = best_slide
        st.turn_q = best_turn_q if best_q is None else None
        return best, best_q

    def _backward_give(
        self,
        m: BimanualRubiksMachine,
        hand: Hand,
        base: Pose,
        q_now: np.ndarray,
        places: list[tuple[Pose, float, float]],
        turn: tuple[str, float],
    ) -> tuple[Pose, float, np.ndarray] | None:
        """A giver's grip whose hand-over turn (and the retreat after it) runs smoothly from an arm
        posture found backwards from the retreat's end, when no grip solved from the arm's joints has
        even a smooth turn (:meth:`..bimanual.machine.BimanualRubiksMachine.turn_postures`,
        ``giver_backward_seeds`` starts per placement; the PR2's giver does the same). Each chain found
        is checked forwards again (``turn_travel``) and scored as :meth:`choose` scores a giver's grip
        (the placement's preferences, the joint change from where the arm is, the turn's travel).
        Returns (grip, its slide, the posture's IK solution: the arm is sent on it) or None; recorded
        as a ``giver_posture`` event.

        Why: seeded from where the arm is, IK finds only the branch it is on; measured (SAPIEN
        Rubiks-1-20 seed 0, the hand-over after move 17, right giver, -90 deg about z): both
        placements' turns stepped 3.3-3.7 rad, the fallback grip's turn moved the cube and the take's
        push met no face.
        """
        n = self.config.giver_backward_seeds
        if n <= 0:
            return None
        owner, qs = m.turn_postures(hand, base, [p for p, _, _ in places], *turn, n_seeds=n)
        if not owner:
            m.ctx.recorder.event("giver_posture", hand=hand.side, chains=0)
            return None
        grips = [places[i][0] for i in owner]
        travel, _ = m.turn_travel(hand, base, grips, qs, *turn)
        change = np.max(np.abs(qs - q_now), axis=1)
        score = np.array([places[i][1] for i in owner]) - 0.1 * change - 0.1 * travel
        j = int(np.argmax(score)) if np.isfinite(score).any() else None
        m.ctx.recorder.event(
            "giver_posture",
            hand=hand.side,
            chains=len(owner),
            checked=int(np.isfinite(travel).sum()),
            **(
                {}
                if j is None
                else {
                    "joint_change": round(float(change[j]), 2),
                    "travel": round(float(travel[j]), 2),
                }
            ),
        )
        if j is None:
            return None
        return grips[j], places[owner[j]][2], np.asarray(qs[j], dtype=float)

    def _clear_lateral(
        self, m: BimanualRubiksMachine, hand: Hand, face_pose: Pose, nominal: float
    ) -> float | None:
        """Lateral offset (tool y, m) of a parallel take whose closing fingers clear the other hand's fingers.

        The other hand's outer finger links are placed from its own measured
        kinematics relative to its *believed* (commanded) tool pose, and seen
        from the candidate frame ``face_pose`` (tool frame on the face
        centre). The offset nearest ``nominal`` is chosen among those that
        keep the fingers on the face (``max_lateral``) and the thumb's tip
        ``thumb_edge_margin`` inside the face edge; None if none does.
        """
        cfg = self.config
        other = m.other(hand)
        prefix = other.arm.config.tcp_link.split("_")[0] + "_bh_finger_"
        links = [
            (
                m.b.get_link_pose(m.robot.body, f"{prefix}{f}{n}_link"),
                PROX_CORNERS if n == 2 else DIST_CORNERS,
            )
            for f in (1, 2)
            for n in (2, 3)
        ]
        lo, hi = finger_extent(other.cmd, other.arm.tcp_pose(), links, face_pose)
        thumb = _st(hand).thumb_lateral

        def ok(t: float) -> bool:
            return abs(t + thumb) <= CUBE_HALF - cfg.thumb_edge_margin and band_clear(
                lo, hi, t, cfg.finger_half_width, cfg.finger_reach, cfg.handover_clearance
            )

        if ok(nominal):
            return nominal
        feasible = [
            float(t)
            for t in np.arange(-cfg.max_lateral, cfg.max_lateral + 1e-9, 0.001)
            if ok(float(t))
        ]
        return min(feasible, key=lambda t: abs(t - nominal)) if feasible else None

    # ------------------------------------------------------------- the push and the close
    def ready(self, m: BimanualRubiksMachine, hand: Hand, req: GripRequest) -> None:
        """Nothing: the pre-shape (outer fingers open, thumb flexed) was set before the choice."""

    def close_in(
        self,
        m: BimanualRubiksMachine,
        hand: Hand,
        grip: Pose,
        q_plan: np.ndarray | None,
        req: GripRequest,
    ) -> None:
        """From the stand-off: push along the face normal until the thumb touches, then close F1/F2.

        On contact the belief is re-anchored along the approach: the face is
        where the thumb's tip is. This is what makes the grasp's depth, and so
        which slabs the fingers land on, independent of the belief's error
        along the approach. In a hand-over take with ``giver_retracts_thumb``
        the giver straightens its thumb before the taker closes.
        """
        cfg, rec, label = self.config, m.ctx.recorder, req.label
        z = approach_axis(grip)
        start = Pose(grip.p - cfg.push_start * z, grip.q)
        if req.turn is not None and _st(hand).turn_q is not None:
            self._keep_turn_branch(m, hand, grip, start, req.turn, label)
        m.send(hand, start, label=f"{label} push start", settle=0.1)
        noise = m.noise()
        try:
            res = push_until_contact(
                m.robot,
                hand.arm,
                hand.gripper,
                m.cube.body,
                start,
                send_offset=lambda p: m.actual(hand, p, noise),
                limit=cfg.push_start + cfg.push_limit,
                speed=cfg.approach_speed,
                force_threshold=cfg.contact_force,
            )
        except PushUnreachable as e:
            raise StrategyFailure("unreachable", f"{label}: {hand.side} arm: {e}") from None
        hand.cmd = res.commanded
        if not res.contact:
            raise StrategyFailure(
                None,
                f"{label}: {hand.side} push-grasp met no face within "
                f"{1000 * (cfg.push_start + cfg.push_limit):.0f} mm (cube not where believed)",
            )
        if not any(l.endswith(("_bh_finger_32_link", "_bh_finger_33_link")) for l in res.links):
            raise StrategyFailure(
                None,
                f"{label}: {hand.side} push stopped on {list(res.links)}, not the thumb "
                "(the cube is off to the side of where it is believed)",
            )
        # re-anchor the belief along the approach: the face is at the thumb's tip
        m.est, corr = reanchor_along_approach(m.est, res.commanded, _st(hand).face_depth)
        m.reanchor()
        true = m.cube.pose()
        rec.event(
            "push",
            hand=hand.side,
            label=label,
            depth=req.depth,
            travel_mm=1000 * res.travel,
            correction_mm=1000 * corr,
            links=list(res.links),
            force=res.force,
            true_error_along_approach_mm=1000 * float(np.dot(true.p - m.est.p, z)),
        )
        rec.pose_estimate(m.move_index, true, m.est, label="push")
        if req.take and cfg.giver_retracts_thumb:
            # the giver's thumb, curled over its face, is where the taker's outer finger closes (measured:
            # the taker's finger 2 stopped on it): once the taker's thumb is on its face, it straightens
            self._straighten_thumb(m.other(hand))
        close_outer_fingers(hand.gripper, cfg.grip_torque, speed=cfg.finger_speed)
        if not self._outer_touching(m, hand):
            raise StrategyFailure(
                None, f"{label}: {hand.side} outer fingers closed on nothing (grasp missed)"
            )
        if cfg.centre_tolerance is not None and m.other(hand).holding:
            self._centre_pinch(m, hand, label)

    def _keep_turn_branch(
        self,
        m: BimanualRubiksMachine,
        hand: Hand,
        grip: Pose,
        start: Pose,
        turn: tuple[str, float],
        label: str,
    ) -> None:
        """At a giver's stand-off: if the grip the arm would push to from here (IK chained from its
        joints through the push's start) cannot carry the hand-over turn smoothly while the solution
        :meth:`choose` checked it from can, change to that branch here, at the stand-off, before moving
        in (a ``give_branch`` event). Otherwise nothing moves.

        Why: the turn is checked from the grip's IK solution seeded with the arm's joints at choice time,
        but the arm reaches the stand-off from where its swing ends, and IK there can pick another
        branch. Measured (PyBullet Rubiks-5-5 seed 0 trial 5, first hand-over, right giver one slab
        deep, -90 deg about z): checked from q7 = 2.15 rad, every step <= 0.57 rad; the arm arrived at
        q7 = -3.00 on its limit, the turn's 3rd waypoint moved q1/q5/q6/q7 by 1.2/2.6/2.5/4.6 rad and
        the cube fell. (Sending every giver on its checked solution fixed that trial but changed the
        others' postures, and three of the five then failed downstream.)
        """
        st = _st(hand)
        assert st.turn_q is not None
        base = hand.arm.base_pose()
        q = hand.arm.positions()
        q_start = m.ik_q(hand, start, q)
        q_grip = None if q_start is None else m.ik_q(hand, grip, q_start)
        if q_grip is None:
            return
        here, worst = m.turn_travel(hand, base, [grip], q_grip[None], *turn, with_retreat=False)
        if np.isfinite(here[0]):
            return
        checked, _ = m.turn_travel(hand, base, [grip], st.turn_q[None], *turn, with_retreat=False)
        if not np.isfinite(checked[0]):
            return
        q_far = m.ik_q(hand, hand.cmd, st.turn_q)
        if q_far is None:
            return
        m.ctx.recorder.event(
            "give_branch",
            hand=hand.side,
            label=label,
            largest_step_here=round(float(worst[0]), 2),
            joint_change=round(float(np.max(np.abs(q_far - q))), 2),
        )
        m.send(hand, hand.cmd, label=f"{label} give branch", settle=0.1, seed_q=q_far)

    def hand_points(self, m: BimanualRubiksMachine, hand: Hand) -> np.ndarray:
        """Points (tool frame, m) filling ``hand``'s palm and the proximal and distal boxes of its three
        fingers where its own joint readings put them now; the machine keeps them clear of the cube
        along a free hand's moves (``sweep_clearance``: stand-offs, swings, retreats).

        Read from the joints, not fixed as the PR2's open gripper is: a free BarrettHand moves in the
        pre-shape of its next grip (spread 90 deg, outer fingers open, the thumb flexed ahead of the
        palm to where the face will be), and the flexed thumb is what reaches the cube. Why: without
        these points HERB's moves were not checked at all; a re-gripping hand's 3.4 rad joint-space
        move to its give-grip stand-off swept its thumb into the cube held by the other hand (93 N),
        turned it 70 deg in that hand and the cube fell in the hand-over (PyBullet Rubiks-1-20 seed 1,
        t = 261.9 s; docs/herb_push_grasp.md).
        """
        prefix = hand.arm.config.tcp_link.split("_")[0] + "_bh_"
        tool = hand.arm.tcp_pose()
        inv = tool.rotation.inv()
        parts = [(f"{prefix}palm_link", PALM_FILL)] + [
            (f"{prefix}finger_{f}{n}_link", PROX_FILL if n == 2 else DIST_FILL)
            for f in (1, 2, 3)
            for n in (2, 3)
        ]
        out = []
        for name, fill in parts:
            link = m.b.get_link_pose(m.robot.body, name)
            out.append(inv.apply(link.rotation.apply(fill) + link.p - tool.p))
        return np.concatenate(out)

    def _pinch_sides(
        self, m: BimanualRubiksMachine, hand: Hand
    ) -> tuple[float, float, float, float]:
        """Where the closed outer fingers' distal boxes stand, from the hand's measured joints (FK).

        Returns (inner side of the finger on tool -x, of the finger on tool +x, their depths beyond the
        tool frame) (m, tool frame): each finger's inner side is on a side face of the cube.
        """
        prefix = hand.arm.config.tcp_link.split("_")[0]
        tool = hand.arm.tcp_pose()
        sides = []
        for f in ("1", "2"):
            link = m.b.get_link_pose(m.robot.body, f"{prefix}_bh_finger_{f}3_link")
            loc = tool.rotation.inv().apply(link.rotation.apply(DIST_CORNERS) + link.p - tool.p)
            neg = float(np.mean(loc[:, 0])) < 0.0
            x = float(np.max(loc[:, 0])) if neg else float(np.min(loc[:, 0]))
            # the corners on the inner side (within 2 mm of it) touch the face: their depth
            near = np.abs(loc[:, 0] - x) < 0.002
            sides.append((neg, x, float(np.min(loc[near, 2]))))
        sides.sort(key=lambda t: not t[0])
        (_, x_neg, z_neg), (_, x_pos, z_pos) = sides
        return x_neg, x_pos, z_neg, z_pos

    def _centre_pinch(self, m: BimanualRubiksMachine, hand: Hand, label: str) -> None:
        """Centre the pinch on the cube across the pinch axis (tool x), from the closed fingers' joints.

        The push re-anchors the belief along the approach only; across the pinch the belief keeps its
        error, and the two outer fingers' tips, closing on arcs, meet the side faces at depths that
        differ by ~1.3 mm per mm of that error (FK): the holder's pinch then lands on the outer slab on
        one side, and a rotator's deeper fingertip reaches the middle slab, which it drags round
        (measured, PyBullet Rubiks-1-20). The fingers' inner sides are the side faces: if their middle
        is more than ``centre_tolerance`` off the tool frame, the hand opens, moves across by that much
        (the belief is re-anchored across the pinch) and closes again.
        """
        cfg = self.config
        assert cfg.centre_tolerance is not None
        x_neg, x_pos, z_neg, z_pos = self._pinch_sides(m, hand)
        off = 0.5 * (x_neg + x_pos)
        width = x_pos - x_neg
        event: dict[str, Any] = {
            "hand": hand.side,
            "label": label,
            "offset_mm": 1000 * off,
            "width_mm": 1000 * width,
            "depths_mm": [
                1000 * (z_neg - _st(hand).face_depth),
                1000 * (z_pos - _st(hand).face_depth),
            ],
        }
        if (
            abs(off) <= cfg.centre_tolerance
            or abs(width - 2 * CUBE_HALF) > cfg.centre_width_tolerance
        ):
            event["moved"] = False
            m.ctx.recorder.event("centre", **event)
            return
        x = pinch_axis(hand.cmd)
        self.open(m, hand)
        m.send(hand, Pose(hand.cmd.p + off * x, hand.cmd.q), label=f"{label} centre", settle=0.1)
        m.est = Pose(m.est.p + (float(np.dot(hand.cmd.p - m.est.p, x))) * x, m.est.q)
        m.reanchor()
        close_outer_fingers(hand.gripper, cfg.grip_torque, speed=cfg.finger_speed)
        if not self._outer_touching(m, hand):
            raise StrategyFailure(
                None, f"{label}: {hand.side} outer fingers closed on nothing after centring"
            )
        x_neg, x_pos, z_neg, z_pos = self._pinch_sides(m, hand)
        event.update(
            moved=True,
            offset_after_mm=500 * (x_neg + x_pos),
            depths_after_mm=[
                1000 * (z_neg - _st(hand).face_depth),
                1000 * (z_pos - _st(hand).face_depth),
            ],
        )
        m.ctx.recorder.event("centre", **event)

    def _outer_touching(self, m: BimanualRubiksMachine, hand: Hand) -> bool:
        links = {
            m.robot.urdf_joints[j].child
            for j in hand.gripper.joints
            if j.endswith(OUTER_FINGER_JOINTS)
        }
        return any(c.link_a in links for c in m.b.contacts(m.robot.body, m.cube.body))

    def open(self, m: BimanualRubiksMachine, hand: Hand) -> None:
        """Open the outer fingers to the pre-shape's flex (the spread and the thumb stay)."""
        u = hand.gripper.command.copy()
        u[1] = u[2] = self.config.outer_open_flex
        hand.gripper.set_command(u)
        wait_fingers(hand.gripper, 0.3)

    def _straighten_thumb(self, hand: Hand) -> None:
        """Open the thumb straight along the approach (the outer fingers keep their grip).

        Why, in a hand-over: curled over its face the giver's thumb is where the
        taker's open outer finger hangs (measured: the taker's finger 2 stopped
        on the giver's thumb). Why not always: a two-finger pinch is a hinge,
        and the thumb on the face is what keeps the cube from swinging about it
        while an arm moves; after a hand-over turn the giver's pinch axis is
        vertical (giver in front) or the cube hangs below it (giver above).
        """
        u = hand.gripper.command.copy()
        u[3] = math.pi / 2  # along the approach (0 is flat, radially out of the palm)
        hand.gripper.set_command(u, _force_limits(hand.gripper))
        wait_fingers(hand.gripper, 0.4)
        _st(hand).shape = 0

    # ------------------------------------------------------------- the twist
    def regrip_before_twist(self, m: BimanualRubiksMachine, rot: Hand, delta: float) -> bool:
        """Whether the rotator lets go and grips again (a fresh choice, with wrist room) before the twist.

        When a hand-over take left it where the wrist (WAM joint 7, limited)
        cannot roll the twist (its fingers had to clear the giver's), or slid
        off its face centre: the wrist would roll the layer about an axis off
        the cube's, and the layer orbits and drags the held one (measured: D2
        after a 15 mm slide dragged it 27 deg, SAPIEN).
        """
        q7 = float(rot.arm.positions()[-1]) + delta
        slide = _st(rot).slide
        again = (
            rot.depth != 1
            or not rot.arm.lower[-1] <= q7 <= rot.arm.upper[-1]
            or abs(slide) > self.config.max_twist_slide
        )
        if again:
            m.ctx.recorder.event(
                "rotator_regrip",
                hand=rot.side,
                depth=rot.depth,
                q7_after_twist=q7,
                slide_mm=1000 * slide,
            )
        return again

    def roll_offset(self, m: BimanualRubiksMachine, hand: Hand) -> float | None:
        """The gripped layer's axis from the tool's approach axis along the pinch (m), from the closed outer
        fingers: the middle of their inner sides (FK of the hand's joints, :meth:`_pinch_sides`); None when
        the two are not a cube's width apart (``centre_width_tolerance``). Relative to the hand itself: no
        belief, no calibration. The machine's twist turns the tool about it (``roll_about``). None whenever
        ``roll_about_fingers`` is off (the default: see there)."""
        if not self.config.roll_about_fingers:
            return None
        x_neg, x_pos, _, _ = self._pinch_sides(m, hand)
        if abs(x_pos - x_neg - 2 * CUBE_HALF) > self.config.centre_width_tolerance:
            return None
        return 0.5 * (x_neg + x_pos)

    def twist_diagnostics(self, m: BimanualRubiksMachine, body_axis: str) -> dict | None:
        """Which slabs each hand's links touch (engine contacts): a diagnostic for the recorder."""
        out: dict[str, Any] = {}
        true_inv = m.cube.pose().inv()
        for side, h in m.hands.items():
            prefix = h.arm.config.tcp_link.split("_")[0] + "_bh_"
            contacts = [
                c
                for c in m.b.contacts(m.robot.body, m.cube.body)
                if c.link_a and c.link_a.startswith(prefix) and c.normal_force > 0.1
            ]
            out[side] = sorted({m.cube.layer_of(c.position.tolist(), body_axis) for c in contacts})
            # how deep each outer finger touches the cube, from this hand's face (true poses: recorder only)
            z = true_inv.rotation.apply(approach_axis(h.arm.tcp_pose()))
            depths: dict[str, list[float]] = {}
            for c in contacts:
                link = (c.link_a or "")[len(prefix) :].removesuffix("_link")
                if link.startswith("finger_3"):
                    continue
                d = 1000 * (CUBE_HALF + float(np.dot(true_inv.apply(c.position), z)))
                depths.setdefault(link, []).append(round(d, 1))
            out[f"{side}_depth_mm"] = {k: [min(v), max(v)] for k, v in sorted(depths.items())}
        return out


class PushGraspStrategy(BimanualRubiksMachine):
    """HERB push-grasp Rubik's strategy; see the module docstring and docs/herb_push_grasp.md."""

    name = "push-grasp"

    def __init__(self, config: HerbPushGraspConfig | None = None) -> None:
        super().__init__(PushGrasp(config))
