"""Settings of the bimanual Rubik's state machine that every robot has: scene, motion, hand-over, error sources.

Each robot's config (``PR2RubiksConfig``, ``HerbPushGraspConfig``) is a
subclass that gives the scene its values and adds the fields of its own
grasp primitive. Fields without a default here are the ones no robot can
share (where the table is, how far its arm may jump between waypoints): a
robot's config must give them. ``zero_error()`` gives the same configuration
with every injected error set to 0.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TypeVar

from ..error_sources import ErrorConfig

__all__ = ["BimanualConfig", "ErrorConfig"]

_C = TypeVar("_C", bound="BimanualConfig")


@dataclass(frozen=True, kw_only=True)
class BimanualConfig:
    """What the state machine (:class:`.machine.BimanualRubiksMachine`) reads (metres, seconds, radians)."""

    #: height of the table top (m) the cube starts on.
    table_height: float
    #: half extents (x, y) of the table top (m).
    table_half_size: tuple[float, float]
    #: cube centre on the table in the robot base frame (x forward, y left).
    cube_xy: tuple[float, float]
    #: where the cube is held for twisting (cube centre, robot base frame): the pick lifts and carries it there.
    twist_position: tuple[float, float, float]
    #: largest joint change (rad) allowed between two hand-over waypoints, and between a free hand's joints
    #: and its retreat's IK solution: a bigger change is the arm switching branch (elbow or shoulder) with
    #: the cube in hand or round it.
    max_waypoint_jump: float
    #: how far a hand backs off along its approach after letting go (m), unless the action says otherwise.
    retreat_distance: float
    #: stand-off (m) along the approach that a free hand swings round to before it moves in to grip: the
    #: open fingers must clear the cube while the wrist turns (the PR2's open to 90 mm, and a swing of the
    #: wrist at its 7 cm pre-grasp can sweep the 57 mm cube).
    far_distance: float = 0.15
    #: a free hand's joint-space move to its stand-off, and a retreat, must keep the hand this far (m) from
    #: the believed cube and from the table all the way (one that starts nearer: at most 5 mm nearer than
    #: it starts), checked on the straight joint path with forward kinematics and the grasp module's
    #: ``hand_points``; a stand-off move that comes nearer backs out first (``detour_distances``), a
    #: retreat is cut short. The table counts since a stand-off swing checked against the cube alone
    #: drove the PR2's wrist into the table's edge (SAPIEN Rubiks-1-50 sensor-aided seed 0).
    #: Why: a stand-off
    #: whose IK solution lies on another arm branch is reached by a joint-space swing of the whole hand;
    #: measured (PR2, PyBullet, Rubiks-5-5 sensor-aided seed 0 trial 5): a shift-in stand-off move turning
    #: the wrist and forearm rolls 2.3 and 2.0 rad brought the open fingertip onto the cube held by the other
    #: hand (25 N) and turned it 32 degrees in that grip (docs/strategies.md, "One-hand holds"). 0: no check.
    sweep_clearance: float = 0.02
    #: distances (m) from the believed cube centre, tried in order, at which a free hand whose move to its
    #: stand-off would sweep the cube makes that move instead: straight back along its own approach to
    #: the distance, there to the stand-off's orientation (the joint-space swing), then straight in.
    detour_distances: tuple[float, ...] = (0.25, 0.35, 0.45)
    #: after every arm move the engine's contacts between the two arms (each arm's links and its hand's)
    #: are summed, and a summed normal force of at least this (N) is recorded as an ``arm_contact`` event
    #: (the hand that moved, the move's label, the force, the pair of links pressing hardest). Record
    #: only: nothing is planned from it. Why: the arms are checked against each other only at a grip's
    #: posture and on the moves ``arm_check`` covers, and an elbow pressing on the holding arm moved
    #: the cube 27 mm without the belief knowing (PyBullet Rubiks-1-100 sensor-aided seed 0, Intel VM:
    #: 63-160 N, found by a separate trace). None: no check.
    arm_contact_event: float | None = 5.0
    #: with the grasp module's ``arm_margin``, every move the machine solves from the arm's joints
    #: (:meth:`.machine.BimanualRubiksMachine.smooth_q`: a retreat's straight way out and its 2 cm steps,
    #: a sideways retreat's steps, the pre-touch sweeps; and, as a preference only, a detour's straight
    #: legs; a detour whose legs and turn all keep clear is taken before any that does not, its way out
    #: along the approach or any of ``machine.WAYS_OUT``: ``transit``) must keep the arm clear of the
    #: other arm on its joint path (every pair of the two arms' parts at margin >= 0 all the way; a pair
    #: that starts nearer, never nearer than it starts). The nearest IK solution that does not is replaced by the clear one of least joint
    #: change among those solved from the arm's joints with each joint moved by each of
    #: ``arm_check_offsets`` either way (the 7-DOF arm's elbow swings about the shoulder-wrist line while
    #: the hand keeps its pose); an ``arm_avoid`` event records it. With none,
    #: the move counts as one the arm cannot make smoothly (a retreat goes sideways or is cut, a sweep is
    #: skipped), except a detour's step, made as before (the event says ``found: false``: refusing it
    #: ended SAPIEN Rubiks-1-50 ``unreachable`` where the move, elbows touching, had been harmless). Every
    #: move's joints as the arm solves them for its target with the injected errors are judged the same
    #: way before it moves (``send``; an ``arm_avoid`` event whose label ends "as sent"), which covers the
    #: moves not solved step by step (a stand-off beyond its detour, an approach, a hand-over take or
    #: turn); where none is clear the solved one is made. Why: every arm contact recorded in 14 sensor-aided
    #: PR2 trials (1-50, 1-100 and 5-20, both engines, AMD VM; 20-70 N) was the giver's elbow on the
    #: taker's just after the hand-over's retreat, whose nearest solution folds the elbow inwards as the
    #: hand backs off; on the Intel VM one such contact pushed the holding arm 27 mm and ended PyBullet
    #: Rubiks-1-100 ``wrong_state``. False: no such check.
    arm_check: bool = True
    arm_check_offsets: tuple[float, ...] = (0.25, 0.5)
    #: a grip's stand-off and every step of a retreat must stay reachable (IK) with the target moved this
    #: many standard deviations of the injected per-motion position error (calibration and tracking,
    #: ``errors``) either way along each world axis, and turned as many of the calibration's rotation std
    #: either way about each (:meth:`.machine.BimanualRubiksMachine.reachable`): the arm is sent the target
    #: with those errors, and a target the planner found reachable only for the believed pose fails there.
    #: A stand-off that does not comes in along the approach in 2 cm steps (to ``retreat_distance`` at
    #: least) until one does (a ``standoff`` event); a retreat step that does not counts as one the arm
    #: cannot follow (the retreat goes sideways or is cut, as for a joint limit). None: no margin. Why:
    #: the cube's believed pose wanders over a tier (PR2, PyBullet Rubiks-1-20 sensor-aided seed 0: 13 mm
    #: forward, 15 mm left, 12 mm down and the work axis tilted 8 deg after 19 twists), and a 15 cm
    #: stand-off along the tilted approach left the stretched arm's reach (elbow flex on its limit: 18.9 mm
    #: short for the believed target, 22.2 mm for the sent one); a retreat step reachable for the believed
    #: target was 21 mm short with the errors (SAPIEN Rubiks-5-20 trial 4). Both ended `unreachable`.
    reach_sigmas: float | None = None
    #: a retreat whose straight way out fails (a joint limit, another branch beyond) may instead slide the
    #: open hand sideways, across its approach and finger axes (the pads slide along the faces they
    #: touched, away from the other hand), at most this far (m), after backing off as far as the straight
    #: way allows (:meth:`.machine.BimanualRubiksMachine.release_hand`). 0: never. Why: a hand-over giver
    #: above the cube with its shoulder lift on the soft limit could not rise at all (its first 2 cm step
    #: swung the forearm roll 2.1 rad); its retreat was cut to 0 cm and the re-grip's move knocked the
    #: cube (SAPIEN Rubiks-1-20 sensor-aided seed 0).
    side_retreat: float = 0.10
    #: a sideways retreat's step must keep the hand this far (m) from the other hand's gripper where the
    #: robot believes it (the grasp module's ``hand_boxes``: its commanded pose, closed on the cube's
    #: width while it holds), or, for a hand that starts nearer, never more than 5 mm nearer than it
    #: starts; a direction whose slide does not is given up (a ``hand_avoid`` event). 0: no check. Why:
    #: the slide was checked against the cube and the other *arm* only, and a giver above the cube slid
    #: its fingertips 6 cm along the taker's finger axis into the taker's finger (28-103 N; SAPIEN
    #: Rubiks-5-100 dead-reckoning seed 0 trial 1, 526 s).
    hand_clearance: float = 0.01
    #: a retreat that neither slides sideways nor steps straight back the whole way changes the arm's
    #: posture in place where its steps stopped, the tool held at its pose, to the IK solution from the
    #: arm's joints with one joint moved by one of these (rad, either way) whose straight retreat then
    #: goes the rest of the way (:meth:`.machine.BimanualRubiksMachine._posture_route`, a
    #: ``retreat_posture`` event); else the retreat is cut short, as before. (): never.
    retreat_posture_offsets: tuple[float, ...] = (0.25, 0.5, 0.75)
    #: a free hand swings round the cube on an arc about its believed centre in Cartesian waypoints at most
    #: this many degrees apart (:meth:`.machine.BimanualRubiksMachine._swing`): one joint-space move from
    #: one side of the cube to another sweeps the hand along whatever path the joints take.
    swing_step_deg: float = 45.0
    #: a hand whose stand-off is less than this many degrees round the cube from where it is moves straight
    #: there (so does one within one ``swing_step_deg``). 0: only the step decides.
    swing_min_deg: float = 0.0
    #: only a hand whose tool frame starts nearer the believed cube centre than this (m) swings round it;
    #: one farther away (an arm out at its side) moves straight to its stand-off. inf: every hand swings.
    swing_radius: float = float("inf")
    #: the swing's route is checked before the hand moves (:meth:`.machine.BimanualRubiksMachine._swing_route`):
    #: the direct arc, else a two-leg arc through a via point (over the top, below, diagonally) with the wrist
    #: rolled at the via, whichever first keeps the arm on its branch (IK chained from the arm's joints, no
    #: joint stepping more than ``swing_max_joint_step``); none: straight to the stand-off. False: the direct
    #: arc only, a waypoint out of reach left out.
    swing_routes: bool = False
    #: each waypoint of a checked swing route (``swing_routes``) must stay reachable (IK from its solution on
    #: the route's chain) with the target moved this many standard deviations of the injected position error
    #: either way along each world axis and turned as many of the calibration's rotation about each, the box
    #: ``reach_sigmas`` gives stand-offs and retreat steps (:meth:`.machine.BimanualRubiksMachine.reachable`):
    #: the arm is sent each waypoint with those errors. A route whose waypoint does not is passed over for the
    #: next; if every route on the arm's branch fails it, the first is taken (a warning). None: as
    #: ``reach_sigmas`` (None there too: no margin, a route found for the believed poses is taken).
    swing_reach_sigmas: float | None = None
    #: largest joint change (rad) between two waypoints of a checked swing route (bigger: IK flipped the arm).
    swing_max_joint_step: float = 1.5
    #: a twist whose grasp module measures the layer's axis (``roll_offset``) turns the tool about it in
    #: waypoints at most this many degrees apart (:meth:`.machine.BimanualRubiksMachine.roll_about`; 15 deg is
    #: what the PyBullet Rubiks-1-20 experiment in docs/herb_push_grasp.md ran); a module without it rolls the
    #: wrist in one joint move.
    roll_step_deg: float = 15.0
    #: how far the taker backs off along its approach (m) before the giver turns the cube in a hand-over:
    #: the turn carries the cube past where the taker's open fingers were.
    taker_retreat: float = 0.15
    #: how far the giver backs off along its approach after a hand-over (m). The hand-over turn's IK chain
    #: is checked to end with this retreat (:meth:`.machine.BimanualRubiksMachine._turn_travel`): a turn
    #: that ends at a joint limit leaves no straight way out, and the retreat swings through the cube.
    handover_retreat: float = 0.12
    #: a giver holding more slabs than this grips again at this depth before the hand-over turn, the taker
    #: holding two slabs from its side meanwhile (:meth:`.machine.BimanualRubiksMachine._handover`): a deep
    #: giver's fingers reach across the faces the taker's fingers close on. None: the giver gives as it holds.
    giver_depth: int | None = None
    #: the hand-over turn also carries the cube back to ``twist_position`` (the believed centre's offset from
    #: it spread evenly over the turn's waypoints): each hand-over's belief and grip errors otherwise add up,
    #: and the cube wandered 14 mm down and 7 mm out over 10 moves until a turn left the arms' reach
    #: (HERB, PyBullet Rubiks-1-20; the PR2 too, SAPIEN Rubiks-5-20). False: the turn is about the centre only.
    recentre_turn: bool = False
    #: the hand-over turn also brings the believed cube's orientation to the nearest faces-level one (its
    #: axes along the world's), the correction's rotation vector spread evenly over the turn's waypoints as
    #: ``recentre_turn``'s shift is (:meth:`.machine.BimanualRubiksMachine.turn_path`): ``recentre_turn``
    #: brings the position back but each hand-over's errors tilt the cube a little more, 26 deg off
    #: faces-level by twist 33 of PyBullet Rubiks-1-50 (PR2, sensor-aided seed 0), and the grips' stand-offs
    #: tilt with it out of the arm's reach. False: the turn keeps the orientation's drift.
    recentre_tilt: bool = False
    #: with ``recentre_tilt`` off, a giver's grip choice that finds no grip whose hand-over turn is smooth
    #: (from the arm's branch or from a posture found backwards) tries again with this one turn levelled
    #: (:meth:`.machine.BimanualRubiksMachine.level_stuck_turn`), before taking the least bad grip. Why:
    #: a believed cube 6.3 deg off faces-level left the left WAM no smooth +90 deg turn about z at the twist
    #: position (0 of 64 backward chains, 42 of 64 with the turn levelled; ``bench/scan_herb_twist_position.py``),
    #: the least bad grip's turn ended 16.6 mm from its target and HERB's SAPIEN Rubiks-1-100 seed 0 ended
    #: ``unreachable`` after 3 moves. Only a turn that had no smooth grip changes: every other trial is as
    #: without it (``recentre_tilt`` for every turn changed them all, docs/herb_push_grasp.md).
    level_stuck_turns: bool = False
    #: waypoints per quarter turn when the giver turns the cube in a hand-over.
    handover_waypoints: int = 4
    #: the hand that is about to hold the cube alone (the picker, a hand-over's taker) grips two slabs deep
    #: whichever hand rotates next, and the other hand then joins (if the lone hand rotates next, the other
    #: grips two slabs deep, crossing, and the lone hand slides out to one slab). Why: a one-slab grip holding
    #: the cube alone lets it pivot about the pad axis (PR2, measured on PyBullet: 32 degrees as the giver let
    #: go). False: the lone hand grips at the depth the plan gives it next (one slab if it rotates next).
    lone_holder_two_slabs: bool = True
    #: duration of one quarter turn of the wrist (s).
    quarter_turn_s: float = 1.0
    #: joint-speed fraction for arm motions.
    velocity_scale: float = 0.4
    #: an arm motion that ends farther than this from its target is logged as a warning event (m); None: no
    #: check. The PR2 baselines leave it off (their recorded results predate it; the events do not move the
    #: planner, whose draws come from the machine's ``plan_rng``).
    reach_warning: float | None = None
    #: a move whose IK did not converge is carried on with (a warning event) if the arm ended within this
    #: distance of its target (m), as a move with an injected error would; None: every such move fails the
    #: trial `unreachable`.
    ik_slack: float | None = None
    #: the cube counts as dropped if it ends below the table top + 1 cm and this far from the belief (m).
    drop_distance: float = 0.05
    #: stop after this many plan actions (None: the whole plan); the outcome is then the state so far.
    #: For tests and debugging (e.g. 1 = the pick only).
    max_actions: int | None = None
    errors: ErrorConfig = ErrorConfig()

    def zero_error(self: _C) -> _C:
        """The same configuration with every injected error 0."""
        return replace(self, errors=self.errors.zero())
