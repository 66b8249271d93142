"""Parameters of HERB's push-grasp Rubik's strategy: scene, hand pre-shapes, the push, and every error source.

Every magnitude is a named field with its default and why; the fields every
robot has come from :class:`..bimanual.config.BimanualConfig`. ``zero_error()``
gives the same configuration with every injected error 0 (tests, and telling
the strategy's own mistakes from injected ones).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..bimanual.config import BimanualConfig
from ..error_sources import ErrorConfig

__all__ = ["ErrorConfig", "HerbPushGraspConfig"]


@dataclass(frozen=True, kw_only=True)
class HerbPushGraspConfig(BimanualConfig):
    """Scene, pre-shapes, push and motion settings (metres, seconds, radians, newtons)."""

    #: table top height (m): the cube's middle at 0.9285 m, level with the WAM shoulders (j1 at
    #: 0.9126 m, herb_description).
    table_height: float = 0.90
    #: half extents (x, y) of the table top (m): narrower in y than the cube (28.5 mm) so that the
    #: picking palm and the thumb, whose flex axis is 50 mm off the palm axis, pass beside it (at
    #: 0.04 m the holder's thumb struck the table edge, folded 14 deg and shoved the cube 6 mm).
    table_half_size: tuple[float, float] = (0.10, 0.02)
    #: cube centre on the table, robot base frame (x forward, y left): between the two WAMs, 0.55 m in
    #: front of their j1 axes (x 0.351 m): nearer, the folded arms reach no side of the cube (an IK scan
    #: of the push-grasp frames on the published mount, docs/herb_push_grasp.md).
    cube_xy: tuple[float, float] = (0.90, 0.0)
    #: cube centre while twisting (robot base frame): 20 cm above the table top, where the IK scan
    #: finds push-grasps of every side but the far one (+x) for both arms (x 0.9 m, z 0.8-1.1 m).
    twist_position: tuple[float, float, float] = (0.90, 0.0, 1.10)
    #: spread of F1/F2 (rad): 90 deg puts the outer fingers face to face across the tool x axis.
    spread: float = math.pi / 2
    #: flex of the open outer fingers F1/F2 in the pre-shape (rad; 0 = flat, radially out of the palm, the
    #: published zero). 60 deg keeps their bent distal links 73 mm off the palm axis (clear of a 57 mm
    #: cube's sides during the push) without spreading the hand 17 cm wide (docs/herb_push_grasp.md).
    outer_open_flex: float = math.radians(60.0)
    #: thumb (F3, the "middle finger") flex of the rotator's pre-shape (rad). From FK of the corrected hand
    #: (docs/herb_push_grasp.md): the distal link's farthest corner stands ~35 mm beyond the tool frame, so
    #: the closing outer fingers meet the cube's sides ~2 mm deep (centred pinch), on the outer slab. The
    #: outer fingers' bent distal boxes lie along the side faces 13-17 mm past their contact: at 100 deg
    #: (contact 3-7 mm) they reached the middle slab's sides (19 mm), which the rolling fingertip then
    #: pushed round (18-37 N on the middle slab, PyBullet Rubiks-1-20: F' dragged the held slab 54 deg).
    #: Deeper still (104 deg) the rotator's fingertips struck the holder's (51 N, the layer turned 62-73 deg).
    rotator_thumb_flex: float = math.radians(98.0)
    #: thumb flex of the holder's pre-shape (rad): tip 18.9 mm beyond the tool frame; its fingers meet
    #: the sides 15-23 mm deep on SAPIEN (F1/F2 differ: the held cube sits off the pinch centre and the
    #: tips close on an arc), 17 mm on PyBullet, and their distal boxes end ~35 mm deep, 2 mm short of
    #: the rotator's. The window is narrow (docs/herb_push_grasp.md): at 17 mm only the outer slab is
    #: held (PyBullet one-move trial: the middle slab dragged 70 deg); at 122-123 deg the hand-over takes
    #: found no grip that clears the giver's fingers (Rubiks-1-5 `unreachable` on both engines); at
    #: 125-128 deg (pinch 20-28 mm) the fingertips reached 40 mm and met the rotator's in the twist.
    holder_thumb_flex: float = math.radians(121.0)
    #: thumb flex of a giver's one-slab grip for a hand-over turn (rad; None: the rotator's): the giver does
    #: not twist, so its fingertips may reach the middle slab; the rotator's 98 deg left a giver 0-3 mm deep
    #: and the cube fell in the turn (PyBullet Rubiks-1-20). 100 deg (contact 3-7 mm) is the deepest whose
    #: fingers clear a two-slab taker's (``handover_clearance``): at 101 and 103 deg a give grip found none.
    giver_thumb_flex: float | None = math.radians(100.0)
    #: the tool frame stands this far off the face's centre towards the thumb's root (m, tool +y). The
    #: corrected thumb's tip lands within 3.4 mm of the palm axis at both flexes: no offset needed.
    rotator_thumb_offset: float = 0.0
    holder_thumb_offset: float = 0.0
    #: joint torque cap of the thumb while it probes (N m): stiff enough not to fold at the stop force.
    thumb_force: float = 2.0
    #: speed of the push along the face normal (m/s): slow, so the stop overshoots < 0.5 mm.
    approach_speed: float = 0.03
    #: summed normal force between the hand and the cube that counts as contact (N).
    contact_force: float = 1.0
    #: the push starts this far before the believed contact (m): > 3 sigma of the belief's error.
    push_start: float = 0.03
    #: and gives up this far past it (m): no face there means the cube is not where believed.
    push_limit: float = 0.03
    #: in a hand-over the giver straightens its thumb once the taker's thumb is on the taker's face, before
    #: the taker closes, to clear the taker's crossing outer finger. Off: without the thumb a two-finger
    #: pinch is a hinge, and the cube swung 20-32 deg about it (measured, SAPIEN); see taker_parallel.
    giver_retracts_thumb: bool = False
    #: in a hand-over the taker pinches the same pair of faces as the giver (True) rather than crossing
    #: it (the PR2's rule): crossing puts the taker's outer finger through the giver's curled thumb.
    taker_parallel: bool = True
    #: a grip on the faces the other holding hand pinches (a parallel hand-over take) keeps its fingers this
    #: far from that hand's finger links (m), sliding across its face (tool y) until they do: with both hands
    #: on the same two faces the taker's closing fingers stalled on the giver's (2nd hand-over of Rubiks-1-5).
    handover_clearance: float = 0.003
    #: how far beyond the tool frame a closed outer finger reaches along the approach (m): the distal
    #: box's farthest corner when its inner side meets a 57 mm cube (flex ~86 deg, FK of the corrected hand).
    finger_reach: float = 0.051
    #: half width of an outer finger across the palm (m): the proximal link box is 24 mm wide.
    finger_half_width: float = 0.012
    #: such a grip may slide across its face at most this far (m) from the face centre: the finger then
    #: still covers 20 of its 24 mm on the face.
    max_lateral: float = 0.02
    #: a rotator whose grip slid farther than this (m) off its face centre lets go and grips again before
    #: the twist: the wrist rolls about the palm axis, and off the layer's axis the layer is dragged round.
    max_twist_slide: float = 0.005
    #: the thumb's tip must touch the face at least this far inside its edge (m): half the distal link's
    #: 14 mm thickness and margin, so the push stops on the face, not on its edge.
    thumb_edge_margin: float = 0.007
    #: joint torque cap of the outer fingers when closing (N m).
    grip_torque: float = 2.0
    #: closing speed of the outer fingers' command (rad/s).
    finger_speed: float = 1.5
    #: a free hand swings round the cube in Cartesian waypoints at most this many degrees apart (the
    #: machine's swing): one joint-space move from beside the cube to behind it swept the re-gripping hand
    #: through the taker's thumb and the cube fell (measured, SAPIEN).
    swing_step_deg: float = 20.0
    #: and only when its stand-off is at least two steps round the cube, the rule HERB's trials were measured
    #: with: from its home pose the second grasp's stand-off is 39 deg round, and a two-waypoint arc there
    #: moved where that grasp landed (0.6 mm) until Rubiks-1-5's first hand-over take found no grip whose
    #: fingers clear the giver's (SAPIEN, seed 0; the take had slid to its 20 mm limit before).
    swing_min_deg: float = 40.0
    #: only a hand whose tool frame is nearer the cube than this (m) swings round it; one farther away
    #: (e.g. an arm far out at its side before the pick) moves straight to its stand-off.
    swing_radius: float = 0.30
    #: check the swing's route before moving, with two-leg arcs through a via point and a wrist roll there
    #: when the direct arc leaves the arm's branch: HERB's own swing until the move onto the shared machine
    #: (Rubiks-1-5 on SAPIEN took a two-leg route at the first two hand-over re-grips and succeeded; with the
    #: direct arc only, waypoints out of reach left out, that trial jammed at twist 9).
    swing_routes: bool = True
    #: a checked swing route's waypoints keep the injected errors' 3-sigma box in reach (the machine's
    #: ``swing_reach_sigmas``; the PR2's ``reach_sigmas`` for its stand-offs and retreats, the same errors):
    #: a re-grip's arc found reachable for the believed poses only had a waypoint the arm missed by 5.1 mm,
    #: 1.5 deg with the errors, past ``ik_slack``, and SAPIEN Rubiks-5-5 seed 0 trial 3 ended `unreachable`
    #: (at ffe4661 on the development VM; docs/herb_push_grasp.md, "Arc waypoints and the injected errors").
    #: HERB's stand-offs and retreats keep no such margin (``reach_sigmas`` None).
    swing_reach_sigmas: float | None = 3.0
    #: a two-slab giver grips again one slab deep before the hand-over turn (the taker holding meanwhile):
    #: the holder's fingers reach 33 mm into the cube, 4.6 mm past its centre, so a parallel take had to slide
    #: 19.6 mm of its 20 mm limit across its face to clear them, or found no grip (SAPIEN: Rubiks-1-10's first
    #: take and 3 of Rubiks-5-5's 5 trials `unreachable`; a take slid 20 mm let the held layer slip 47 deg in
    #: PyBullet's Rubiks-1-5).
    giver_depth: int | None = 1
    #: a move whose IK did not converge goes on if the arm ended within this of its target (m; the machine's
    #: ``ik_slack``): at the edge of the WAMs' reach round the twist position a retreat and a hand-over turn
    #: ended 1.7 mm / 0.4 deg and 4.2 mm / 1.3 deg from targets IK could not meet exactly, and each failed its
    #: trial (Rubiks-5-5, PyBullet); the injected calibration and tracking errors are as large. The same 5 mm
    #: as ``reach_warning``.
    ik_slack: float | None = 0.005
    #: the hand-over turn carries the cube back to ``twist_position`` (the machine's ``recentre_turn``): over
    #: Rubiks-1-20's first 10 moves the cube wandered from (0.900, 0, 1.100) to (0.907, 0, 1.086) m and the
    #: 11th hand-over turn's IK ended 6.9 mm off (PyBullet, seed 0).
    recentre_turn: bool = True
    #: a giver that finds no grip with a smooth hand-over turn chooses again with that turn levelled (the
    #: machine's ``level_stuck_turns``; ``recentre_tilt`` stays off: levelling every turn changed every trial
    #: and, measured on this VM, did not complete more of Rubiks-1-20 or Rubiks-5-5, docs/herb_push_grasp.md).
    level_stuck_turns: bool = True
    #: when no giver grip solved from the arm's joints has a smooth hand-over turn: starts per finger
    #: placement, drawn over the whole joint range, from which the turn and the giver's retreat are solved
    #: backwards (:meth:`..bimanual.machine.BimanualRubiksMachine.turn_postures`, the PR2's value). The IK
    #: from the arm's joints finds only the branch it is on (SAPIEN Rubiks-1-20 seed 0, the hand-over after
    #: move 17: both placements' turns stepped 3.3-3.7 rad, the fallback's turn moved the cube and the take
    #: met no face). 0: the least bad grip instead.
    giver_backward_seeds: int = 8
    #: retreat along the approach after letting go (m).
    retreat_distance: float = 0.08
    #: a retreat whose straight way out fails does not slide sideways (the machine's ``side_retreat``) nor
    #: change the arm's posture in place (``retreat_posture_offsets``), the PR2's ways out: it backs off in
    #: 2 cm steps as far as they go, as before HERB's hand was checked against the cube (``hand_points``).
    #: Measured with those ways on: PyBullet Rubiks-1-20 seed 1 took a sideways retreat at its second
    #: hand-over, whose waypoint the arm then missed by 5.7 mm with the injected errors (past ``ik_slack``;
    #: HERB's retreats keep no reach margin), and the trial ended `unreachable` at 76 s.
    side_retreat: float = 0.0
    retreat_posture_offsets: tuple[float, ...] = ()
    #: the picker and a hand-over's taker grip two slabs deep whichever hand rotates next (the machine's rule,
    #: the PR2's too): a one-slab lone grip lost the cube on PyBullet (Rubiks-1-10: the pick's close turned it
    #: 9 deg and the second grasp's push met no face; Rubiks-5-5: a one-slab hold turned it 16 deg as the other
    #: hand let go). Measured with it (seed 0): Rubiks-1-5 succeeds on both engines, Rubiks-5-5 PyBullet 3/5
    #: (was 1/5), SAPIEN 4/5 (as before); it costs a push-grasp and a release per pick and take.
    lone_holder_two_slabs: bool = True
    #: a hand that closed on the cube held by the other hand centres its pinch across the pinch axis when the
    #: middle of its fingers' inner sides (FK of its joints) is farther than this off the tool frame (m;
    #: None: never): it opens, moves across and closes again. Off: at 1.5 mm PyBullet's Rubiks-5-5 fell to
    #: 1/5 (4/5 without): the FK offset after a re-centring was often no smaller (a held cube moves with the
    #: re-closing fingers; overshoots of 1.6 -> 1.8 mm, 3.2 -> 4.2 mm), and each re-close shook the cube.
    centre_tolerance: float | None = None
    #: a twist turns the tool about the layer's axis as the rotator's closed fingers measure it (``roll_offset``,
    #: the machine's ``roll_about``) instead of rolling the wrist about the palm's axis. Off: measured on
    #: PyBullet Rubiks-1-20 seed 0 it removes the cause of the fall after move 14 (a U2 rolled 4.0 mm off the
    #: layer's axis turned the cube 15 deg in the holder's pinch; turned about the measured axis at that move
    #: only, 1.0 deg, and the trial succeeded), but on for every twist R2 at move 5 slipped 14 deg short and
    #: the cube fell (docs/herb_push_grasp.md, "The fall after Rubiks-1-20's move 14").
    roll_about_fingers: bool = False
    #: the fingers' inner sides must be this close to the cube's width apart (m) to be read as its side faces.
    centre_width_tolerance: float = 0.006
    #: largest joint change (rad) allowed between two hand-over waypoints (bigger = IK flipped the arm).
    max_waypoint_jump: float = 2.5
    #: a motion that ends farther than this from its target is logged as a warning event (m).
    reach_warning: float | None = 0.005
