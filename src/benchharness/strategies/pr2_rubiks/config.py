"""Parameters of the PR2 Rubik's baselines: scene, grasp geometry and every error source.

Every magnitude is a named field with its default and why (docs/strategies.md,
"Error sources"); the fields every robot has come from
:class:`..bimanual.config.BimanualConfig`. ``zero_error()`` gives the same
configuration with every injected error set to 0 (for tests and for telling
the strategy's own mistakes from injected ones).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ...cube_physics.config import CubeConfig
from ...robots.descriptions.pr2 import PAD_SIZE, pad_setback
from ...sensors.config import SweepConfig
from ..bimanual.config import BimanualConfig
from ..error_sources import ErrorConfig

__all__ = ["ErrorConfig", "PR2RubiksConfig", "grip_offset"]


def grip_offset(inner_end: float, edge: float = CubeConfig().edge) -> float:
    """Tool-frame distance from the cube centre that puts the pads' inner end ``inner_end`` from it.

    The pads are ``PAD_SIZE[0]`` long and, on the PR2's four-bar fingers, their centre sits
    ``pad_setback(edge)`` behind the tool frame when they close on the cube (4.7 mm at 57 mm),
    so the tool frame goes that much nearer the centre than the pads' middle.
    """
    return inner_end + PAD_SIZE[0] / 2 - pad_setback(edge)


@dataclass(frozen=True, kw_only=True)
class PR2RubiksConfig(BimanualConfig):
    """Scene, grasp geometry and motion settings of the PR2 baselines (metres, seconds).

    The fields every robot has are :class:`..bimanual.config.BimanualConfig`'s
    (documented there); the PR2's values of the scene's are explained here.
    """

    #: height of the table top (m): 7 cm below the twisting pose's cube bottom, so that the pick is
    #: a straight lift (the cube centre on the table at 0.5285 m) and no finger reaches the table
    #: at the twisting pose. Low because the twisting pose is (docs/strategies.md, "Twisting pose").
    table_height: float = 0.50
    #: half extents (x, y) of the table top (m): narrow in y (a pedestal) so that a side grasp's
    #: wrist (18 cm behind the tool frame, 3.5 cm radius) passes beside it, not through it.
    table_half_size: tuple[float, float] = (0.10, 0.06)
    #: cube centre on the table in the robot base frame (x forward, y left): below the twisting pose
    #: (at x = 0.65 m the pick's stand-off is out of reach inside the soft limits).
    cube_xy: tuple[float, float] = (0.60, 0.0)
    #: where the cube is held for twisting (cube centre, robot base frame), from an IK scan
    #: (:mod:`.workspace`): every grip the planner uses, its stand-off and both hand-over turns
    #: (with the giver's retreat) stay >= 0.26 rad inside the PR2's soft limits here, and the pick
    #: directly below it >= 0.42 rad; at the former (0.60, 0, 0.80) the turn about z had no smooth
    #: solution inside them (docs/strategies.md, "Twisting pose").
    twist_position: tuple[float, float, float] = (0.60, 0.0, 0.60)
    #: distance from the cube centre to the tool frame along the work axis for a grip `depth` slabs
    #: deep, derived from where the pads' inner end must sit (:func:`grip_offset`: the 36 mm pad's
    #: centre is 4.7 mm behind the tool frame at the 57 mm grip). Holder: inner end at 0 -> 13.3 mm;
    #: the pad covers the middle slab (-9.5..9.5 mm) up to its centre line, half a cubie (9.5 mm) of
    #: margin either way, the paper's tolerance. Rotator: inner end at 16.5 mm -> 29.8 mm; 7 mm clear
    #: of the middle slab, 12 mm of the outer slab under the pad.
    rotator_offset: float = grip_offset(0.0165)
    holder_offset: float = grip_offset(0.0)
    #: stand-off of the pre-grasp pose along the approach (m).
    pregrasp_distance: float = 0.07
    #: a hand that lets go backs off to the pre-grasp stand-off (m), the way it came in.
    retreat_distance: float = 0.07
    #: the hand-over turn carries the believed cube back to ``twist_position`` (BimanualConfig, as HERB's):
    #: without it the cube wandered from the pose the stand-offs and turns were placed for (SAPIEN
    #: Rubiks-5-20 sensor-aided seed 0 trial 4: 32 mm forward, 12 mm left, 28 mm down after 9 twists) until no
    #: stand-off of a re-grip was within the arm's reach (`unreachable`); with it that trial succeeds.
    recentre_turn: bool = True
    #: the hand-over turn also brings the believed cube's orientation back to faces-level (BimanualConfig):
    #: with the position alone brought back, the believed cube's offset from faces-level grew to 26 deg by
    #: twist 33 of PyBullet Rubiks-1-50 and 21 deg by twist 82 of SAPIEN Rubiks-1-100 (sensor-aided seed 0),
    #: and each trial ended `unreachable` at a stand-off 55-61 mm, 13 deg out of reach. HERB leaves it off.
    recentre_tilt: bool = True
    #: a grip's 15 cm stand-off and a retreat's steps must stay within reach for the injected errors' 3
    #: standard deviations (BimanualConfig): a side approach's stand-off and retreat are near the arm's
    #: full stretch (measured: PyBullet Rubiks-1-20 and SAPIEN Rubiks-5-20 sensor-aided seed 0 ended
    #: `unreachable` there).
    reach_sigmas: float | None = 3.0
    #: grip force per finger (N), as in tests/cube_physics/rig.py and docs/benchmarks/cube_spike.md.
    grip_force: float = 20.0
    #: force per finger (N) of the first, gentle close when the other hand already holds the cube:
    #: the first finger to touch then pushes with 3 N, a torque of at most ~0.15 N m at the 50 mm
    #: lever to the other gripper's pad axis, below what the other pads' friction resists (they hold
    #: the cube's weight at 34 mm without turning); then the force rises to ``grip_force``. 0: one stage.
    soft_grip_force: float = 3.0
    #: largest joint change (rad) allowed between two hand-over waypoints when choosing the giver's grip.
    #: A quarter of a quarter turn moves the joints a few tenths of a rad on a smooth branch (the rolls
    #: are continuous and IK stays on the branch nearest the seed); a bigger change is the arm switching
    #: branch with the cube in hand (measured: a 3.9 s, 0.27 rad-tracking-error swing that turned the
    #: held cube 15 degrees when 2.5 rad was allowed).
    max_waypoint_jump: float = 0.8
    #: where the fingers need not cross the other hand's: "parallel" prefers closing along the other
    #: hand's pad axis (no torque about it), "crossing" prefers crossing them.
    finger_preference: str = "parallel"
    #: extra IK seeds (random self-motions of the 7-DOF arm) a giver's grip is also solved from: a
    #: hand-over turn may be smooth only from another elbow/shoulder posture. The seeds come from a
    #: generator spawned once from the trial's rng (the machine's ``plan_rng``; deterministic per trial).
    giver_seeds: int = 6
    #: when no grip solved from those seeds carries the hand-over turn and the giver's retreat smoothly:
    #: starts per finger placement, drawn over the whole joint range, from which the turn is solved
    #: backwards from the retreat's end (:meth:`..bimanual.machine.BimanualRubiksMachine.turn_postures`).
    #: The seeds near the arm's joints find only the branch it is on (measured: every one of 14 ended a
    #: turn with the upper-arm roll on its soft limit, SAPIEN Rubiks-1-20). 0: the least bad grip instead.
    giver_backward_seeds: int = 8
    #: a grip posture whose upper arm or forearm comes nearer the other (holding) arm than this (m), both
    #: modelled as 5 cm round their axes, is not chosen while another is (the arms collide in the engines:
    #: measured, a hand-over take stopped 25 mm short against the giver's elbow, PyBullet Rubiks-1-20).
    arm_clearance: float = 0.01
    #: pre-touch (sensor-aided): std of the prior handed to the filter at each re-localisation, position
    #: (m) and yaw (deg): of the order of the head camera's error (4 mm, 3 deg) that dead reckoning carries.
    pretouch_prior_pos_std: float = 0.006
    pretouch_prior_yaw_std_deg: float = 3.0
    #: pre-touch (sensor-aided): std of the prior's roll, pitch and yaw about the believed pose in the 6-DOF
    #: sweep mode (deg): the hand-over turns and grips tilt the cube by a degree or two as well as turning it.
    pretouch_prior_tilt_std_deg: float = 2.0
    #: pre-touch (sensor-aided): "sweep" (Yang et al.: the fingertip sensor swept across the face's edges
    #: before every grasp, a 6-DOF filter; docs/sensors.md, "Sweeps") or "grid" (the former simplification:
    #: one 3 x 3 ray grid along the approach from the pre-grasp, position and yaw only).
    pretouch_mode: str = "sweep"
    #: pre-touch sweeps: rate, speed, stand-off, extents and edge detection (docs/sensors.md).
    sweep: SweepConfig = field(default_factory=SweepConfig)
    #: pre-touch sweeps: whether the rays see the robot (only the emitting fingertip is transparent); False:
    #: the whole robot is transparent to its own sensors (the grid mode's simplification).
    pretouch_see_robot: bool = True
    #: pre-touch (sensor-aided): the 3 x 3 emitter grid across the tool frame (m, tool y and z), all
    #: looking along tool x: 12 mm apart, well inside the 57 mm face the hand approaches.
    pretouch_grid: tuple[float, ...] = (-0.012, 0.0, 0.012)
    #: a motion that ends farther than this from its target counts as unreachable (m).
    reach_tolerance: float = 0.01
    #: pick approaches the planner may use (only "side" is implemented physically).
    pick_approaches: tuple[str, ...] = ("side",)
