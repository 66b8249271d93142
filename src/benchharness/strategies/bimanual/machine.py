"""The one bimanual Rubik's state machine: plan, pick the cube up, twist, regrasp, hand over, release.

Control never reads the true cube pose. The cube's pose is *believed*: the
head camera's one-shot estimate on the table, then carried by whichever hand
holds it alone, through that hand's *commanded* tool poses (``Hand.cmd``),
and corrected by whatever a robot's grasp primitive measures (a pre-touch
reading, a push-grasp's contact). The injected errors
(:class:`..error_sources.ErrorConfig`) sit between the command and the arm:
the arm is sent ``calibration * noise * commanded``, which the strategy never
learns. The true pose is read only for the recorder's true-vs-believed
diagnostics and the judge's dropped-cube check.

What is the machine's (every robot's): the scene, the injected errors, the
plan and its dispatch, the camera estimate, the drop check, the hand-over
(the giver's turn, the take, the re-grip), the twist and its bookkeeping,
the swing round the cube to a stand-off, the check that a hand-over turn can
be carried smoothly (with the giver's retreat), and the retreat after letting
go. What is a robot's: a :class:`GraspModule` (its candidate grips and their
scoring, how it moves in and closes, how it opens), and its config (a
subclass of :class:`.config.BimanualConfig`). A new two-armed robot is a new
grasp module, not a new state machine (docs/strategies.md, "Adding a robot").
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

import numpy as np
from scipy.spatial.transform import Rotation

from ...backends.interface import Backend, BodyId, Box, CameraSpec
from ...geometry import Pose
from ...robots.kinematics import IKResult, row_norm
from ...runner.contract import RubiksItem, TrialContext, TrialOutcome
from ..regrasp import (
    HandModel,
    Handover,
    Pick,
    Regrasp,
    RegraspPlan,
    Release,
    Twist,
    execute,
    plan_sequence,
    twist_move,
)
from .config import BimanualConfig
from .frames import DIRECTIONS, along, rotate_about_point

__all__ = [
    "BODY_AXIS_OF_FACE",
    "CUBE_HALF",
    "SIDE_DIR",
    "BimanualRubiksMachine",
    "GraspModule",
    "GripRequest",
    "Hand",
    "StrategyFailure",
    "TurnPath",
    "level_correction",
]

CUBE_HALF = 0.0285
#: the world direction each hand grips from (the planner's grips are all side grips)
SIDE_DIR = {"left": "+y", "right": "-y"}
BODY_AXIS_OF_FACE = {"U": "z", "D": "z", "R": "x", "L": "x", "F": "y", "B": "y"}


class StrategyFailure(Exception):
    """A failure the strategy detected itself: ``cause`` is a runner FailureCause value or None."""

    def __init__(self, cause: str | None, message: str) -> None:
        super().__init__(message)
        self.cause = cause


@dataclass
class Hand:
    """One arm + hand and what the strategy believes about it."""

    side: str
    arm: Any
    gripper: Any
    calibration: Pose  #: injected, never read by control: actual = calibration * commanded
    cmd: Pose  #: the last commanded (believed) tool pose
    holding: bool = False
    cube_in_tcp: Pose | None = None  #: believed cube pose in the commanded tool frame
    grip_dir: str | None = None  #: world direction the hand grips from ("+y", "-x", ...)
    last_grip: Pose | None = (
        None  #: the commanded tool pose of the last grip (retreats go back from it)
    )
    depth: int = 0  #: slabs the current grip covers (0: not holding)
    #: the grip just chosen is on another arm branch (a posture found backwards from a hand-over turn):
    #: its stand-off is reached by the detour, the posture changed away from the cube (:meth:`transit`)
    far_posture: bool = False
    state: Any = None  #: the grasp module's own per-hand state (:meth:`GraspModule.hand_state`)
    log: list = field(default_factory=list)


#: a detour's ways out other than back along the hand's approach, in the order tried
#: (:meth:`BimanualRubiksMachine._way_out`). "side-up" since 2026-12-04: a hand in front of the cube
#: going to a stand-off at its side, whose way back along the approach met the other arm's elbow and
#: whose turns from straight up or straight sideways swept the cube (SAPIEN Rubiks-1-50 sensor-aided
#: seed 0, 1385.6 s; the diagonal clears both). "slide+" / "slide-" (the same day): along the hand's own
#: axis across its approach and finger axes, either way, so that open pads still round the cube slide
#: along the faces they were on, as a sideways retreat does: a giver above the cube whose retreat was cut
#: to 2 cm (the way up left the arm's branch, a 0.61 rad step) had no other way out that cleared the
#: cube, and the trial ended ``unreachable`` (SAPIEN Rubiks-1-100 sensor-aided seed 0 at 0361275,
#: 2506.7 s, after 84 moves)
WAYS_OUT = ("up", "side", "side-up", "slide+", "slide-")


@dataclass
class _Detour:
    """A planned detour of :meth:`BimanualRubiksMachine.transit` (nothing moved yet), ``distance`` from
    the believed cube: the straight way out (poses with their IK solutions; empty: none, the turn starts
    where the hand is), the joint-space turn from ``qa`` to ``turned`` (solution ``qb``), the straight
    way in, which way out (None: along the approach), and the ``arm_avoid`` events its planning kept
    back."""

    distance: float
    leg_out: list[tuple[Pose, np.ndarray]]
    qa: np.ndarray
    turned: Pose
    qb: np.ndarray
    leg_in: list[tuple[Pose, np.ndarray]]
    way_out: str | None
    notes: list[dict]


def _shifted(pose: Pose, shift: np.ndarray) -> Pose:
    """``pose`` translated by ``shift`` (m, world)."""
    return Pose(pose.p + shift, pose.q)


#: the 24 rotations that keep a cube's axes along the world's (faces-level orientations)
_FACES_LEVEL = Rotation.create_group("O")


def level_correction(orientation: Rotation) -> np.ndarray:
    """Rotation vector (world frame, rad) that turns ``orientation`` to the nearest faces-level one (the
    nearest of the 24 axis-aligned rotations). Exactly zero for an orientation that is one of them."""
    c = _FACES_LEVEL * orientation.inv()
    return np.asarray(c[int(np.argmin(c.magnitude()))].as_rotvec(), dtype=float)


@dataclass(frozen=True)
class TurnPath:
    """A hand-over turn as the giver carries it: the believed cube's rotation of ``angle`` rad about world
    ``axis`` through ``centre``, plus the ``shift`` of its centre (``recentre_turn``) and the ``level``
    rotation about it (``recentre_tilt``, world rotation vector) that brings it faces-level, both spread
    evenly over the turn (fraction i/n at waypoint i of n). One object for every place a turn is planned,
    scored or made (:meth:`BimanualRubiksMachine.turn_path`), so that the scored path is the executed one.
    """

    centre: np.ndarray
    axis: str
    angle: float
    shift: np.ndarray
    level: np.ndarray

    def at(self, pose: Pose, i: int, n: int) -> Pose:
        """``pose`` (held rigidly with the cube) at waypoint ``i`` of ``n`` of the turn."""
        turned = rotate_about_point(pose, self.centre, self.axis, self.angle * i / n)
        if np.any(self.level):  # the centre is where the turn left it: level the cube about it
            turned = rotate_about_point(turned, self.centre, self.level, i / n)
        return _shifted(turned, self.shift * (i / n))


@dataclass(frozen=True)
class GripRequest:
    """What the machine asks of a grasp module's grip.

    ``relation`` to the other hand's fingers if it holds the cube: "cross"
    (the fingers must cross the other hand's: the grips overlap along the
    work axis), "parallel" (they must pinch the same pair of faces), or None
    (a preference only, the module's).
    """

    world_dir: str  #: the world direction the hand grips from
    depth: int  #: 1 = the rotator's one slab, 2 = the holder's two
    label: str  #: for events and messages
    turn: tuple[str, float] | None = (
        None  #: this hand gives the cube next: the hand-over turn (axis, rad)
    )
    twist_delta: float = 0.0  #: wrist-roll change of this hand's next twist (rad; 0: none planned)
    on_table: bool = False  #: the cube is on the table: no finger may go under it
    relation: str | None = None
    take: bool = False  #: a hand-over's take (the other hand is the giver)
    twist_now: bool = (
        False  #: the hand twists right after this grip (the rotator's re-grip before a twist)
    )


class GraspModule(Protocol):
    """A robot's grasp primitives: all the machine needs that differs between robots.

    Tool-frame layout (every hand's tool frame is ``{side}_arm``'s): ``approach_axis`` and ``finger_axis`` are the tool
    axes (0 = x, 1 = y, 2 = z) along which the hand approaches the face it
    grips and across which its fingers close; the wrist's last joint rolls
    about the approach axis.

    Optional: ``hand_points(m, hand) -> np.ndarray`` (N x 3, tool frame, m), points filling ``hand``
    with its fingers open (as they are when it moves free: a fixed shape, or the hand's pre-shape
    from its own joint readings); with it the machine keeps a free hand's moves to its stand-offs
    and its retreats from sweeping through the cube (:meth:`BimanualRubiksMachine.transit`,
    :meth:`BimanualRubiksMachine.release_hand`). A module without it is not checked.

    Optional: ``arm_margin(m, hand, q) -> np.ndarray``: how far (m) each part of ``hand``'s arm at each row
    of joints ``q`` stays beyond the robot's required clearance from each part of the other arm where it
    is (negative: nearer), one column per pair of parts (or one column: the arm as a whole); with it
    every move's joints as sent, and the moves solved from the arm's joints (retreats, the pre-touch
    sweeps; a detour's straight legs as a preference, and the choice of a detour's way out), keep the
    arms apart (``arm_check``). A module without it is not checked.

    Optional: ``roll_offset(m, hand) -> float | None``: where the gripped layer's axis lies from the
    rotator's approach axis along its finger axis (m), as the hand's own closed fingers measure it (None:
    no reading); with it a twist turns the tool about that axis (:meth:`BimanualRubiksMachine.roll_about`)
    instead of rolling the wrist about the palm's. A module without it rolls the wrist.
    """

    approach_axis: int
    finger_axis: int
    #: the robot's hand per arm, by side: ``robot.gripper(gripper_name.format(side=side))``
    gripper_name: str
    #: the only robot (plugin name) the module's hands exist on; None: any robot with the arms and hands
    robot_name: str | None

    @property
    def config(self) -> BimanualConfig:
        """The robot's config: a :class:`.config.BimanualConfig` with the module's own fields added."""
        ...

    def hand_model(self) -> HandModel:
        """The regrasp planner's model of this robot's hands."""
        ...

    def hand_state(self) -> Any:
        """A fresh per-hand state for :attr:`Hand.state` (None if the module keeps none)."""
        ...

    def take_relation(self) -> str | None:
        """The :attr:`GripRequest.relation` of a hand-over's take."""
        ...

    def choose(
        self, m: BimanualRubiksMachine, hand: Hand, req: GripRequest
    ) -> tuple[Pose, np.ndarray | None]:
        """The grip (commanded tool pose) to take, among the robot's candidate grips by its own scoring,
        and the IK solution the choice was made with (None: the arm moves there from where it is).

        May move the fingers (a pre-shape) but not the arm; raises :class:`StrategyFailure` if no grip fits.
        """
        ...

    def ready(self, m: BimanualRubiksMachine, hand: Hand, req: GripRequest) -> None:
        """Ready the hand to approach (open it), after :meth:`choose`, before the swing to the stand-off."""
        ...

    def close_in(
        self,
        m: BimanualRubiksMachine,
        hand: Hand,
        grip: Pose,
        q_plan: np.ndarray | None,
        req: GripRequest,
    ) -> None:
        """From the stand-off: move in to ``grip`` and close; raise :class:`StrategyFailure` on a miss.

        The machine then records the hand as holding at its commanded pose.
        """
        ...

    def open(self, m: BimanualRubiksMachine, hand: Hand) -> None:
        """Open the hand (let go of the cube), the arm where it is."""
        ...

    def regrip_before_twist(self, m: BimanualRubiksMachine, rot: Hand, delta: float) -> bool:
        """Whether the rotator, holding with the holder, must let go and grip again before rolling ``delta``."""
        ...

    def twist_diagnostics(self, m: BimanualRubiksMachine, body_axis: str) -> dict | None:
        """Diagnostic recorded before a twist as a ``twist_contacts`` event (None: no event)."""
        ...


def arm_contact_forces(
    backend: Backend, body: BodyId, left: frozenset[str], right: frozenset[str]
) -> dict[tuple[str, str], float]:
    """Summed normal force (N) per pair of links (one of ``left``, one of ``right``) of the robot
    ``body`` pressing on each other after the last step, from the engine's contacts."""
    out: dict[tuple[str, str], float] = {}
    for c in backend.contacts(body, body):
        a, b = c.link_a, c.link_b
        if a in right and b in left:
            a, b = b, a
        elif not (a in left and b in right):
            continue
        key = (str(a), str(b))
        out[key] = out.get(key, 0.0) + c.normal_force
    return out


def _avoid_note(
    hand: Hand, label: str, q: np.ndarray, nearest: np.ndarray, other: np.ndarray | None
) -> dict:
    """An ``arm_avoid`` event's fields: the move from ``q`` whose ``nearest`` solution was not clear of
    the other arm, and how far the clear ``other`` one moves the joints (``found: False``: none)."""
    return dict(
        hand=hand.side,
        label=label,
        nearest_change=round(float(np.max(np.abs(nearest - q))), 2),
        **(
            {"joint_change": round(float(np.max(np.abs(other - q))), 2)}
            if other is not None
            else {"found": False}
        ),
    )


#: configurations at which a straight joint path is checked (:meth:`BimanualRubiksMachine.sweep_clearance`)
SWEEP_SAMPLES = 16


def _box_gap(local: np.ndarray, half: np.ndarray | float) -> float:
    """Least distance (m) of ``local`` points (N x 3, in a box's frame) from that box (half extents)."""
    return float(_box_dist(local, half).min())


def _box_dist(local: np.ndarray, half: np.ndarray | float) -> np.ndarray:
    """Distance (m) of each of ``local`` points (N x 3, in a box's frame) from that box (half extents).

    ``row_norm``: ``np.linalg.norm(axis=1)``'s bits without its dispatch (the sweep checks run this
    thousands of times a trial)."""
    return row_norm(np.maximum(np.abs(local) - half, 0.0))


def _keeps_clear(start: float, least: float, clearance: float) -> bool:
    """Whether a path whose least distance from something is ``least`` (m), starting ``start`` from it,
    keeps clear: never nearer than ``clearance`` or, for a path that starts nearer, than it starts
    less 5 mm (at most half of it). The rule of the sweep check against the cube and of the hand check."""
    return least >= min(start - min(5e-3, 0.5 * start), clearance)


class BimanualRubiksMachine:
    """Rubik's strategy for a two-armed robot; its grasp primitives are ``grasp``'s (see the module docstring).

    A robot's strategy is this class with its grasp module and a name: a
    subclass may set ``name`` and build its grasp module in ``__init__``, and
    nothing else (tests/strategies/test_bimanual.py checks).
    """

    benchmarks: ClassVar[tuple[str, ...]] = ("rubiks",)
    name: ClassVar[str] = "bimanual"

    def __init__(self, grasp: GraspModule) -> None:
        self.grasp = grasp
        #: the hand-over turn being planned is levelled although ``recentre_tilt`` is off
        #: (:meth:`level_stuck_turn`); cleared when the hand-over's turn is made
        self.level_turn = False

    @property
    def config(self) -> BimanualConfig:
        return self.grasp.config

    # ------------------------------------------------------------------ trial
    def video_camera(self, view: str, size: tuple[int, int]) -> CameraSpec:
        """The trial video's camera (``run --video-view``): ``close`` frames both hands at the
        twisting pose above the table and the cube on it, ``wide`` the robot (runner/video.py)."""
        from ...runner.video import rubiks_camera

        cfg = self.config
        x, y = cfg.cube_xy
        return rubiks_camera((x, y, cfg.table_height + 0.08), view, size)

    def run_trial(self, ctx: TrialContext) -> TrialOutcome:
        from ...cube_physics import PhysicalCube

        want = self.grasp.robot_name
        got = getattr(ctx.robot, "name", None)
        if want is not None and got != want:
            raise ValueError(
                f"strategy {self.name!r} drives robot {want!r} (grasp module "
                f"{type(self.grasp).__name__}); got robot {got!r}"
            )
        cfg = self.config
        b = ctx.backend
        self.ctx = ctx
        self.b = b
        b.add_ground()
        h = cfg.table_height
        centre, (tx, ty, tz) = self.table_box()
        wood = (0.55, 0.40, 0.26, 1.0)  # in a video
        b.add_body(
            [Box((float(tx), float(ty), float(tz)), rgba=wood)],
            Pose(centre),
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
        #: the planner's own stream (IK restarts, alternative arm postures): spawned once from the
        #: trial's rng, so its draws neither shift the error draws nor depend on how many events or
        #: measurements the trial has logged (spawning does not advance ``rng``)
        self.plan_rng: np.random.Generator = rng.spawn(1)[0]
        self.hands: dict[str, Hand] = {}
        for side in ("left", "right"):
            dp = rng.normal(0.0, err.calib_pos_std, 3) if err.calib_pos_std else np.zeros(3)
            dr = (
                rng.normal(0.0, math.radians(err.calib_rot_std_deg), 3)
                if err.calib_rot_std_deg
                else np.zeros(3)
            )
            arm = self.robot.arm(f"{side}_arm")
            self.hands[side] = Hand(
                side,
                arm,
                self.robot.gripper(self.grasp.gripper_name.format(side=side)),
                Pose.from_rotation(dp, Rotation.from_rotvec(dr)),
                arm.tcp_pose(),
                state=self.grasp.hand_state(),
            )
        self.robot.settle(0.2)
        #: each arm's links and its hand's (``arm_contact_event``)
        self.arm_links = {
            side: self.robot.links_below(h.arm.joints[0]) for side, h in self.hands.items()
        }
        rec.watch_contact(self.cube.body, self.robot.body)
        self.est = self._camera_estimate(ctx)
        rec.pose_estimate(0, self.cube.pose(), self.est, label="camera")

        if not isinstance(ctx.item, RubiksItem):
            raise ValueError(f"strategy {self.name!r} runs Rubik's tasks, not {ctx.item!r}")
        plan = plan_sequence(ctx.item.sequence, self.grasp.hand_model())
        trace = execute(plan).orientations
        rec.event(
            "plan",
            actions=len(plan.actions),
            twists=plan.twists,
            regrasps=plan.regrasps,
            handovers=plan.handovers,
            text=plan.describe(),
        )
        self.plan: RegraspPlan = plan
        self.trace = trace
        self.t_release: float | None = None
        self.level_turn = False
        #: the plan's move the latest twist made (0 before the first): the x of pose-estimate records
        self.move_index = 0
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
                    self.move_index = max(action.source, 0)
                    self._twist(action, before, k)
                elif isinstance(action, Regrasp):
                    self._regrasp(action, k)
                elif isinstance(action, Handover):
                    self._handover(action, k)
                elif isinstance(action, Release):
                    self._release()
                if not isinstance(action, Release):
                    self._check_drop(k)
                    # after the release the cube lies on the table and nothing believes where:
                    # logging that estimate would plot as a 7 cm "error" at the last move
                    rec.pose_estimate(
                        self.move_index,
                        self.cube.pose(),
                        self.est,
                        label=type(action).__name__.lower(),
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
        t_release = self.t_release if self.t_release is not None else b.time
        return TrialOutcome(
            final_state=self.cube.state_string, termination_s=t_release, extra=self._extra()
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
        data: dict[str, Any] = {
            "label": label,
            "err_mm": round(float(1000 * np.linalg.norm(true.p - self.est.p)), 2),
            "rot_deg": np.round(np.degrees(rv), 1).tolist(),
        }
        if hand is not None:
            data["hand"] = hand.side
            fingers = hand.cmd.rotation.apply(along(self.grasp.finger_axis, 1.0))
            data["fingers"] = np.round(fingers, 2).tolist()
        self.ctx.recorder.event("check", **data)

    # ------------------------------------------------------------- motion
    def noise(self) -> np.ndarray:
        """One draw of the actuator tracking error (m, world), from the trial's rng."""
        err = self.config.errors
        return self.ctx.rng.normal(0.0, err.tracking_std, 3) if err.tracking_std else np.zeros(3)

    @staticmethod
    def actual(hand: Hand, target: Pose, noise: np.ndarray) -> Pose:
        """What the arm is sent for the commanded ``target``: the injected calibration and ``noise`` added."""
        cal = hand.calibration
        return Pose.from_rotation(target.p + cal.p + noise, cal.rotation * target.rotation)

    def back_off(self, pose: Pose, distance: float) -> Pose:
        """``pose`` moved ``distance`` back along its own approach axis."""
        return Pose(pose.p - pose.rotation.apply(along(self.grasp.approach_axis, distance)), pose.q)

    def send(
        self,
        hand: Hand,
        target: Pose,
        *,
        label: str,
        duration: float | None = None,
        settle: float = 0.2,
        seed_q: np.ndarray | None = None,
        slack: float | None = None,
        skip_unreached: bool = False,
    ) -> bool:
        """Command ``hand`` to ``target`` (believed); the arm receives it with the injected errors.
        True when the arm was sent.

        ``skip_unreached``: a target whose IK with the errors does not converge (and has no slack) is
        not sent and the call returns False instead of failing the trial: for a swing's arc waypoint,
        which the swing leaves out when the arm cannot reach it (:meth:`_swing`).

        ``slack``: for this move, as ``ik_slack`` (the larger of the two applies): a via point in free
        space that the arm may miss by that much. Without a slack, a target whose IK does not converge
        fails `unreachable` before the arm moves: the IK's best attempt for a target just out of reach
        can be a restart on another arm branch (measured, SAPIEN Rubiks-5-20 sensor-aided seed 0 trial
        5: a pre-touch sweep's start 2 mm out of reach with the injected errors, the elbow straight,
        swung the upper-arm and forearm rolls -2.84 / +2.86 rad into the cube held by the other hand
        alone, 72 N; the sweep, which catches the failure and skips, had already moved)."""
        slack = max((v for v in (self.config.ik_slack, slack) if v is not None), default=None)
        sent = self.actual(hand, target, self.noise())
        res = hand.arm.move_to_pose(
            sent,
            duration=duration,
            velocity_scale=self.config.velocity_scale,
            settle=settle,
            seed_q=seed_q,
            move_unsolved=slack is not None,
            solution=self._sent_solution(hand, sent, seed_q, label),
        )
        if not res.ik_success and slack is None:
            if skip_unreached:
                return False
            raise StrategyFailure(
                "unreachable",
                f"{hand.side} arm: no IK solution for {label} "
                f"(target {np.round(target.p, 3).tolist()}; the IK's best is "
                f"{1000 * res.pos_error:.1f} mm, {math.degrees(res.rot_error):.1f}° from it; not moved)",
            )
        hand.cmd = target
        if hand.holding:
            hand.last_grip = target
        warn = self.config.reach_warning
        if warn is not None and res.ik_success and res.pos_error > warn:
            self.ctx.recorder.event(
                "warning",
                message=f"{hand.side} arm ended {1000 * res.pos_error:.1f} mm from "
                f"its {label} target (joint error {res.final_joint_error:.3f} rad)",
            )
        if not res.ik_success and slack is not None and res.pos_error <= slack:
            self.ctx.recorder.event(
                "warning",
                message=f"{hand.side} arm: IK did not converge for {label} (target "
                f"{np.round(target.p, 3).tolist()}); the arm ended {1000 * res.pos_error:.1f} mm, "
                f"{math.degrees(res.rot_error):.1f}° from it: carried on",
            )
        elif not res.ik_success:
            raise StrategyFailure(
                "unreachable",
                f"{hand.side} arm: no IK solution for {label} "
                f"(target {np.round(target.p, 3).tolist()}; the arm ended "
                f"{1000 * res.pos_error:.1f} mm, {math.degrees(res.rot_error):.1f}° from it)",
            )
        if hand.holding and not self.other(hand).holding and hand.cube_in_tcp is not None:
            self.est = target * hand.cube_in_tcp  # dead reckoning: the cube moved with the command
        self._arm_contact(hand, label)
        return True

    def _sent_solution(
        self, hand: Hand, sent: Pose, seed_q: np.ndarray | None, label: str
    ) -> IKResult | None:
        """The joints the arm moves to for the target it is ``sent`` (the injected errors in it), judged
        against the other arm before it moves (with ``arm_check`` and the grasp module's
        ``arm_margin``; else None: :meth:`RobotArm.move_to_pose` solves as it always did).

        Why: the planner checks the joints it solved for the *believed* target, but the arm solves the
        sent target again, so those are the joints that reach the other arm or not (in the one case
        traced, SAPIEN Rubiks-1-20 at 536.1 s, they were within 9 mrad of the planned ones; that
        contact came from the check's least-margin rule, :meth:`_arm_clears`). Moves planned without a
        check (a hand-over take's approach, a grip's approach) are judged here too. Where the
        solved path does not keep the arm clear (:meth:`_arm_clears`) the clear solution of the same
        target with least joint change is taken instead (an ``arm_avoid`` event, its label ending
        "as sent"); where there is none, the solved one (the event says ``found: false``). A path
        that is clear is moved exactly as before: the check draws no random number."""
        if self._arm_margin_hook() is None:
            return None
        sol = hand.arm.solve_pose(sent, seed_q=seed_q)
        if not bool(sol.success[0]):
            return sol
        q = hand.arm.positions()
        q1 = np.asarray(sol.q[0], dtype=float)
        if self._arm_clears(hand, q, q1):
            return sol
        row = self._arm_clear_row(hand, sent, q)
        other = None if row is None else np.asarray(row.q[0], dtype=float)
        self.ctx.recorder.event("arm_avoid", **_avoid_note(hand, f"{label} as sent", q, q1, other))
        return sol if row is None else row

    def _arm_contact(self, hand: Hand, label: str) -> None:
        """An ``arm_contact`` event where the arms press on each other after ``hand``'s move to
        ``label`` (``arm_contact_event``; record only)."""
        least = self.config.arm_contact_event
        if least is None:
            return
        forces = arm_contact_forces(
            self.b, self.robot.body, self.arm_links["left"], self.arm_links["right"]
        )
        total = sum(forces.values())
        if total >= least:
            links = max(forces, key=lambda k: forces[k])
            self.ctx.recorder.event(
                "arm_contact",
                hand=hand.side,
                label=label,
                force_n=round(total, 1),
                links=list(links),
            )

    def other(self, hand: Hand) -> Hand:
        return self.hands["right" if hand.side == "left" else "left"]

    def reanchor(self) -> None:
        """After the belief was corrected by a measurement: what each holding hand believes it carries."""
        for h in self.hands.values():
            if h.holding:
                h.cube_in_tcp = h.cmd.inv() * self.est

    def smooth_q(self, hand: Hand, target: Pose, label: str = "") -> np.ndarray | None:
        """The IK solution by which the arm reaches ``target`` from its joints without any joint moving
        more than ``max_waypoint_jump``, or None. Send the move seeded with it (``send(seed_q=...)``):
        solved again from the injected-error target, the arm can take another branch (measured: a
        pre-touch sweep judged smooth swung the upper-arm and forearm rolls 3.1 rad, SAPIEN).

        With the grasp module's ``arm_margin`` (``arm_check``), the joint path must also keep the arm
        clear of the other arm (:meth:`_arms_apart`): if the nearest solution does not, the clear one of
        least joint change (an ``arm_avoid`` event naming ``label``), else None."""
        base = hand.arm.base_pose()
        q = hand.arm.positions()
        res = hand.arm.ik((base.inv() * target).as_matrix()[None], seed_q=q)
        ok = (
            bool(res.success[0])
            and float(np.max(np.abs(res.q[0] - q))) <= self.config.max_waypoint_jump
        )
        if not ok:
            return None
        return self._arms_apart(hand, target, q, np.asarray(res.q[0], dtype=float), label)

    def _arms_apart(
        self,
        hand: Hand,
        target: Pose,
        q: np.ndarray,
        q1: np.ndarray,
        label: str,
        veto: bool = True,
        notes: list[dict] | None = None,
    ) -> np.ndarray | None:
        """``q1`` (an IK solution of ``target`` near ``q``) if its joint path from ``q`` keeps the arm clear
        of the other arm (:meth:`_arm_clears`), else :meth:`_arm_clear_solution` (an ``arm_avoid`` event
        naming ``label``), else None, or ``q1`` if
        not ``veto`` (a preference only: the event says ``found: false`` and the move is made as it was).
        ``notes``: a plan not yet made keeps its events there instead (recorded if it is made)."""
        if self._arm_clears(hand, q, q1):
            return q1
        other = self._arm_clear_solution(hand, target, q)
        note = _avoid_note(hand, label, q, q1, other)
        if notes is None:
            self.ctx.recorder.event("arm_avoid", **note)
        else:
            notes.append(note)
        if other is not None:
            return other
        return None if veto else q1

    def turn_path(self, axis: str, angle: float) -> TurnPath:
        """The hand-over turn of the cube as believed now: ``angle`` rad about world ``axis`` through the
        believed centre; with ``recentre_turn`` the centre is also carried back to ``twist_position``, with
        ``recentre_tilt`` (or for this hand-over, :meth:`level_stuck_turn`) the turned orientation is
        also brought to the nearest faces-level one.

        The level correction is computed for the orientation before the turn and carried through it (the
        turn by a multiple of 90 degrees about a world axis maps faces-level orientations onto each other,
        so the nearest one to the turned orientation is the turned nearest one): its rotation vector
        turned by the full turn. Why: each hand-over's belief and grip errors tilt the believed cube a
        little and nothing brought it back: its offset from faces-level reached 26 deg by twist 33 of
        PyBullet Rubiks-1-50 and 21 deg by twist 82 of SAPIEN Rubiks-1-100 (sensor-aided seed 0), its
        grips' stand-offs tilted with it out of the arm's reach (docs/strategies.md, "Edge of reach").
        """
        cfg = self.config
        shift = (
            np.asarray(cfg.twist_position, dtype=float) - self.est.p
            if cfg.recentre_turn
            else np.zeros(3)
        )
        level = np.zeros(3)
        if cfg.recentre_tilt or self.level_turn:
            v = level_correction(self.est.rotation)
            if np.any(v):
                level = Rotation.from_rotvec(DIRECTIONS[axis] * angle).apply(v)
        return TurnPath(self.est.p.copy(), axis, angle, shift, level)

    def level_stuck_turn(self, hand: Hand) -> bool:
        """Level this hand-over's turn (``level_stuck_turns``), for a giver's grip choice that found no
        grip whose turn is smooth: True if the choice should be made again with the turn levelled
        (the option is on, the turns are not levelled already and the belief is off faces-level by
        more than 0.1 deg); records a ``turn_levelled`` event."""
        cfg = self.config
        if not cfg.level_stuck_turns or cfg.recentre_tilt or self.level_turn:
            return False
        tilt = float(np.linalg.norm(level_correction(self.est.rotation)))
        if tilt < math.radians(0.1):
            return False
        self.level_turn = True
        self.ctx.recorder.event(
            "turn_levelled", hand=hand.side, tilt_deg=round(math.degrees(tilt), 2)
        )
        return True

    def turn_travel(
        self,
        hand: Hand,
        base: Pose,
        grips: list[Pose],
        q: np.ndarray,
        axis: str,
        angle: float,
        with_retreat: bool = True,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Joint travel of carrying the cube from each of ``grips`` through the hand-over turn (inf: not
        smooth), and the largest joint step on the way (inf: a waypoint out of reach).

        ``q`` holds each grip's IK solution (one row a grip); all grips are solved in one batched IK
        call per waypoint, each seeded with its own previous solution. The chain ends with the giver's
        retreat from the turned grip (``handover_retreat`` back along its approach): a turn that ends
        at a joint limit leaves no straight way out, and the arm's retreat then swings through the cube.
        With the grasp module's ``hand_points`` the retreat is checked as :meth:`release_hand` makes
        it: in 2 cm steps, each smooth and its joint path clear of the cube (:meth:`_clears`); a grip
        whose retreat is not gets inf travel (its largest step stays that of its joints). Why:
        checked as one IK step, a retreat that met the shoulder-lift limit half-way passed (0.68 rad)
        while the executed retreat's 2 cm steps switched the upper-arm roll by 0.6 rad, swept the
        open hand to 5 mm of the cube and were cut to 4 cm; the re-grip's stand-off move then found
        no detour and knocked the cube out of the taker's hand (SAPIEN Rubiks-5-5 sensor-aided seed 0,
        trial 5). ``with_retreat=False``: the turn's waypoints only (a robot's fallback when no grip
        passes).
        """
        cfg = self.config
        n = max(1, cfg.handover_waypoints) * max(1, round(abs(angle) / (math.pi / 2)))
        points = self._hand_points(hand) if with_retreat else None
        # (waypoint of the turn, of n; retreat distance) of each step
        steps = [(i, 0.0) for i in range(1, n + 1)]
        if with_retreat and points is None:
            steps.append((n, cfg.handover_retreat))
        elif with_retreat:
            m = max(1, math.ceil(cfg.handover_retreat / 0.02 - 1e-9))
            steps += [(n, cfg.handover_retreat * j / m) for j in range(1, m + 1)]
        path = self.turn_path(axis, angle)
        q = np.array(q, dtype=float)
        total = np.zeros(len(grips))
        worst = np.zeros(len(grips))
        for i, back in steps:
            live = np.flatnonzero(np.isfinite(worst))
            if live.size == 0:
                break
            poses = [path.at(grips[k], i, n) for k in live]
            if back > 0:  # the retreat
                poses = [self.back_off(p, back) for p in poses]
            targets = [(base.inv() * p).as_matrix() for p in poses]
            res = hand.arm.ik(np.stack(targets), seed_q=q[live])
            jump = np.max(np.abs(res.q - q[live]), axis=1)
            reached = np.asarray(res.success, dtype=bool)
            bad = ~reached | (jump > cfg.max_waypoint_jump)
            if back > 0 and points is not None:
                for j, k in enumerate(live):
                    if not bad[j] and np.isfinite(total[k]):
                        bad[j] = not self._clears(hand, q[k], res.q[j], points)
            total[live] = np.where(bad, np.inf, total[live] + jump)
            worst[live] = np.where(reached, np.maximum(worst[live], jump), np.inf)
            q[live] = res.q
        return total, worst

    def turn_postures(
        self, hand: Hand, base: Pose, grips: list[Pose], axis: str, angle: float, n_seeds: int
    ) -> tuple[list[int], np.ndarray]:
        """Arm postures from which each of ``grips`` carries the hand-over turn, found backwards.

        For every grip, ``n_seeds`` starts drawn uniformly over the arm's joint range (a continuous
        joint over one turn about where it is) from ``plan_rng`` are solved for the end of the giver's retreat
        (``handover_retreat`` back from the turned grip); from each solution the chain is solved
        backwards, each pose seeded with the last solution: the retreat's 2 cm steps (each joint
        path checked clear of the cube with the grasp module's ``hand_points``, as made forwards),
        then the turn's waypoints back to the grip. A chain with every step smooth
        (``max_waypoint_jump``) gives the grip's IK solution at its start. Returns (index into
        ``grips``, solution) of every chain that passed.

        Why: :meth:`turn_travel` solves the turn forwards from postures near the arm's joints, so
        it only finds the branch the arm is near. Measured (SAPIEN Rubiks-1-20 sensor-aided seed 0,
        the right hand's take before a -90 deg turn about x): all 14 grips (2 placements x 7 seeds
        near the joints, upper-arm roll at -3.3 rad) ended the turn with the upper-arm roll on its
        soft limit (-3.75 rad) and the retreat's 6 cm step switched the forearm roll 1.7 rad; the
        giver slid out 2 cm, its re-grip found no clear way round and turned the cube 41 deg.
        Solved backwards from starts over the whole range, 299 of 300 chains passed, their grips
        near an upper-arm roll of -1.1 rad.
        """
        cfg = self.config
        n = max(1, cfg.handover_waypoints) * max(1, round(abs(angle) / (math.pi / 2)))
        points = self._hand_points(hand)
        m = max(1, math.ceil(cfg.handover_retreat / 0.02 - 1e-9))
        # a continuous joint over the turn centred on where it is (IK keeps it on the seed's branch:
        # drawn over [-pi, pi], a wrist roll wound to 12 rad by the twists was unwound 9.7 rad)
        q_now = hand.arm.positions()
        lo = np.where(np.isfinite(hand.arm.lower), hand.arm.lower, q_now - math.pi)
        hi = np.where(np.isfinite(hand.arm.upper), hand.arm.upper, q_now + math.pi)
        owner = np.repeat(np.arange(len(grips)), n_seeds)
        q = lo + self.plan_rng.random((len(owner), lo.size)) * (hi - lo)
        live = np.ones(len(owner), dtype=bool)
        # (waypoint of the turn, retreat distance) of each pose, from the retreat's end back to the grip
        steps = [(n, cfg.handover_retreat * j / m) for j in range(m, 0, -1)]
        steps += [(i, 0.0) for i in range(n, -1, -1)]
        path = self.turn_path(axis, angle)
        for s, (i, back) in enumerate(steps):
            rows = np.flatnonzero(live)
            if rows.size == 0:
                break
            poses = [path.at(grips[owner[r]], i, n) for r in rows]
            if back > 0:
                poses = [self.back_off(p, back) for p in poses]
            res = hand.arm.ik(
                np.stack([(base.inv() * p).as_matrix() for p in poses]), seed_q=q[rows]
            )
            bad = ~np.asarray(res.success, dtype=bool)
            if s > 0:
                bad |= np.max(np.abs(res.q - q[rows]), axis=1) > cfg.max_waypoint_jump
                if points is not None and steps[s - 1][1] > 0:  # a retreat step, made forwards
                    for j, r in enumerate(rows):
                        if not bad[j]:
                            bad[j] = not self._clears(hand, res.q[j], q[r], points)
            q[rows] = res.q
            live[rows[bad]] = False
        keep = np.flatnonzero(live)
        return [int(owner[r]) for r in keep], q[keep]

    def _swing(self, hand: Hand, far: Pose, label: str, seed_q: np.ndarray | None = None) -> None:
        """Carry a free hand round the cube to the stand-off ``far`` on an arc about the believed centre.

        Why: one joint-space move from where the hand let go (often above or
        below the cube after a hand-over turn) to a stand-off on another side
        sweeps the tool frame along whatever path the joints take, and was
        measured knocking the held cube 12 degrees (PR2, SAPIEN, Rubiks-1-20)
        and sweeping a re-gripping hand through the taker's thumb (HERB,
        SAPIEN). Here the tool frame moves in Cartesian waypoints (at most
        ``swing_step_deg`` apart) on an arc round the cube, its distance from
        the centre and its orientation interpolated between the two ends, so
        it never comes nearer the cube than where it started or ends. A
        waypoint the arm cannot reach is left out. A hand farther than
        ``swing_radius`` from the cube, or whose stand-off is less than
        ``swing_min_deg`` round it, moves straight to the stand-off.

        With ``swing_routes`` the route is checked instead (:meth:`_swing_route`): the direct arc
        or a two-leg arc through a via point, whichever first keeps the arm on its branch all the
        way; no waypoint is left out.
        """
        cfg = self.config
        c = self.est.p
        d0, d1 = hand.cmd.p - c, far.p - c
        r0, r1 = float(np.linalg.norm(d0)), float(np.linalg.norm(d1))
        u0, u1 = d0 / max(r0, 1e-9), d1 / max(r1, 1e-9)
        angle = math.acos(float(np.clip(np.dot(u0, u1), -1.0, 1.0)))
        n = max(1, math.ceil(angle / math.radians(cfg.swing_step_deg)))
        if (
            n == 1
            or r0 < 0.05
            or r1 < 0.05
            or r0 > cfg.swing_radius
            or math.degrees(angle) < cfg.swing_min_deg
        ):
            self.transit(hand, far, label=label, seed_q=seed_q)
            return
        if cfg.swing_routes:
            for way in self._swing_route(hand, far, label, u0, u1, r0, r1):
                self.send(hand, way, label=f"{label} arc", settle=0.02)
            self.send(hand, far, label=label, settle=0.05, seed_q=seed_q)
            return
        base = hand.arm.base_pose()
        points = self._hand_points(hand)
        for way in self._arc(c, [u0, u1], [hand.cmd.q, far.q], r0, r1):
            q_now = hand.arm.positions()
            res = hand.arm.ik((base.inv() * way).as_matrix()[None], seed_q=q_now)
            if not res.success[0]:
                continue
            if points is not None and not self._clears(hand, q_now, res.q[0], points):
                # the joint path to the next waypoint sweeps the cube (measured: a giver's re-grip arc
                # from above the cube, 45 degrees a waypoint, brought the tool frame to 41 mm of the
                # centre and a fingertip onto the cube at 93 N, SAPIEN Rubiks-1-20 sensor-aided seed
                # 0): the arc ends here, and the checked move (with its detours) takes the rest
                self.ctx.recorder.event(
                    "swing_cut",
                    hand=hand.side,
                    label=label,
                    clearance_mm=round(
                        1000 * self.sweep_clearance(hand, q_now, res.q[0], points), 1
                    ),
                )
                break
            # the waypoint was solved for the believed pose; the arm is sent it with the injected errors,
            # which can put it just out of reach: it is left out then, as an unreachable believed one
            # is (measured: PyBullet Rubiks-1-10 sensor-aided seed 0, a re-grip stand-off's arc
            # waypoint 1.4 mm, 0.4 deg out of reach with the errors ended the trial `unreachable`)
            if not self.send(
                hand,
                way,
                label=f"{label} arc",
                settle=0.02,
                seed_q=None if points is None else res.q[0],
                skip_unreached=True,
            ):
                self.ctx.recorder.event(
                    "swing_skip", hand=hand.side, label=label, waypoint=np.round(way.p, 3).tolist()
                )
        self.transit(hand, far, label=label, seed_q=seed_q)

    def ik_q(self, hand: Hand, pose: Pose, seed: np.ndarray) -> np.ndarray | None:
        """The arm's IK solution for the (believed) tool pose ``pose`` from ``seed``; None if unreachable.
        (Public: grasp modules chain their own solves with it.)"""
        base = hand.arm.base_pose()
        res = hand.arm.ik((base.inv() * pose).as_matrix()[None], seed_q=seed)
        return np.asarray(res.q[0], dtype=float) if bool(res.success[0]) else None

    def table_box(self) -> tuple[np.ndarray, np.ndarray]:
        """The table (a fixed box from the floor to ``table_height``, world axes): centre and half extents (m)."""
        cfg = self.config
        h = cfg.table_height
        tx, ty = cfg.table_half_size
        return np.array([cfg.cube_xy[0], cfg.cube_xy[1], h / 2]), np.array([tx, ty, h / 2])

    def sweep_clearance(
        self,
        hand: Hand,
        q0: np.ndarray,
        q1: np.ndarray,
        points: np.ndarray,
        n: int = SWEEP_SAMPLES,
    ) -> float:
        """Least distance (m) of the hand's ``points`` (tool frame) along the straight joint path
        ``q0`` -> ``q1`` (the path :meth:`RobotArm.move_to_joints` tracks) from what the hand must not
        touch: the believed cube (a box) and the table (:meth:`table_box`, where the scene put it).

        Why the table: the twisting pose is 7 cm above the table top and the cube drifts down over a
        long tier; a free hand's joint-space swing to its stand-off checked clear of the cube drove the
        wrist into the table's edge at 295 N, where the arm stuck 258 mm from its target, and the
        re-grip closed on nothing (SAPIEN Rubiks-1-50 sensor-aided seed 0, move 38)."""
        cube, table = self._sweep_gaps(hand, q0, q1, points, n)
        return min(float(cube.min()), float(table.min()))

    def _sweep_gaps(
        self, hand: Hand, q0: np.ndarray, q1: np.ndarray, points: np.ndarray, n: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`sweep_clearance`'s least distances from the believed cube and from the table at each
        of the ``n`` configurations of the path, (n,) each."""
        p = self._path_points(hand, q0, q1, points, n)
        centre, half = self.table_box()
        cube = _box_dist(self.est.rotation.inv().apply(p - self.est.p), CUBE_HALF)
        table = _box_dist(p - centre, half)
        return cube.reshape(n, -1).min(axis=1), table.reshape(n, -1).min(axis=1)

    @staticmethod
    def _path_points(
        hand: Hand, q0: np.ndarray, q1: np.ndarray, points: np.ndarray, n: int
    ) -> np.ndarray:
        """The hand's ``points`` (tool frame) in the world at ``n`` configurations evenly along the straight
        joint path ``q0`` -> ``q1`` (forward kinematics), stacked ((n x N) x 3)."""
        s = np.linspace(0.0, 1.0, n)[:, None]
        t = np.asarray(hand.arm.fk(q0 + s * (q1 - q0)), dtype=float)
        w = hand.arm.base_pose().as_matrix() @ t
        # the rotations copied out first: einsum runs ~3x faster on contiguous blocks, same bits
        rot = np.ascontiguousarray(w[:, :3, :3])
        return (np.einsum("nij,pj->npi", rot, points) + w[:, None, :3, 3]).reshape(-1, 3)

    def hand_gap(
        self, hand: Hand, q0: np.ndarray, q1: np.ndarray, points: np.ndarray, n: int = 16
    ) -> float:
        """Least distance (m) of ``hand``'s ``points`` along the straight joint path ``q0`` -> ``q1`` from
        the other hand's gripper where the robot believes it (the grasp module's ``hand_boxes``); inf
        without that hook."""
        boxes_of = getattr(self.grasp, "hand_boxes", None)
        if boxes_of is None:
            return float("inf")
        p = self._path_points(hand, q0, q1, points, n)
        return min(
            _box_gap((p - c) @ rot, half) for c, rot, half in boxes_of(self, self.other(hand))
        )

    def _hands_clear(self, hand: Hand, q0: np.ndarray, q1: np.ndarray, points: np.ndarray) -> bool:
        """Whether the straight joint path ``q0`` -> ``q1`` keeps ``hand`` clear of the other hand's gripper
        (:meth:`hand_gap`): never nearer than ``hand_clearance`` or, for a hand that starts nearer (a
        giver's open pads just round the taker's fingers), than it starts less 5 mm (at most half of it),
        as :meth:`_clears` judges the cube. True with ``hand_clearance`` 0 or without ``hand_boxes``."""
        if self.config.hand_clearance <= 0 or getattr(self.grasp, "hand_boxes", None) is None:
            return True
        start = self.hand_gap(hand, q0, q0, points, n=1)
        return _keeps_clear(start, self.hand_gap(hand, q0, q1, points), self.config.hand_clearance)

    def _hand_points(self, hand: Hand) -> np.ndarray | None:
        """The grasp module's points of ``hand`` with its fingers open (tool frame), or None (no sweep
        checks)."""
        points_of = getattr(self.grasp, "hand_points", None)
        if points_of is None or self.config.sweep_clearance <= 0:
            return None
        return np.asarray(points_of(self, hand), dtype=float)

    def _clears(self, hand: Hand, q0: np.ndarray, q1: np.ndarray, points: np.ndarray) -> bool:
        """Whether the straight joint path ``q0`` -> ``q1`` keeps the hand clear of the believed cube:
        never nearer than ``sweep_clearance`` or, for a hand that starts nearer (backing out from round
        the cube: open pads 16 mm from its faces), than it starts less 5 mm (at most half of it). A
        joint-space step of a few centimetres strays a few millimetres from its straight Cartesian line
        (measured: 2-3 mm for 2 cm steps of a PR2 giver's retreat); a sweep through the cube reaches 0."""
        # the path's first configuration is q0 itself: its distances are the start's (each
        # configuration's points are computed alone; tests/strategies/test_free_hand_clearance.py)
        cube, table = self._sweep_gaps(hand, q0, q1, points, SWEEP_SAMPLES)
        start = min(float(cube[0]), float(table[0]))
        return _keeps_clear(
            start, min(float(cube.min()), float(table.min())), self.config.sweep_clearance
        )

    def _arm_margin_hook(self) -> Callable[..., np.ndarray] | None:
        """The grasp module's ``arm_margin`` hook where the arm check is on (``arm_check``), else None:
        the one switch for every check of the arm against the other arm."""
        return getattr(self.grasp, "arm_margin", None) if self.config.arm_check else None

    def _arm_clears(self, hand: Hand, q0: np.ndarray, q1: np.ndarray, n: int = 11) -> bool:
        """Whether the straight joint path ``q0`` -> ``q1`` keeps ``hand``'s arm clear of the other arm where
        it is: each pair of parts' ``arm_margin`` at ``n`` points of the path never below 0 or, for a pair
        that starts below it, never below where it starts. True without the hook or with
        ``arm_check`` off.

        Per pair, not the arm's least margin: a move that starts with one pair inside the clearance (the
        model is conservative: 5 cm capsules where the engine's boxes are square and end short of the
        joints) must not bring another pair in. Judged on the least margin, a retreat whose forearm-elbow
        pair stayed at -15.7 mm let the two elbows go from -6.0 to -14.1 mm: 42 N in the engine
        (SAPIEN Rubiks-1-20 sensor-aided seed 0 at c26a79a, 536.1 s)."""
        margin_of = self._arm_margin_hook()
        if margin_of is None:
            return True
        s = np.linspace(0.0, 1.0, n)[:, None]
        margin = np.asarray(margin_of(self, hand, q0[None] + s * (q1 - q0)[None]), dtype=float)
        margin = margin.reshape(n, -1)
        return bool(np.all(margin[1:] >= np.minimum(0.0, margin[0]) - 1e-9))

    def _arm_clear_solution(self, hand: Hand, target: Pose, q: np.ndarray) -> np.ndarray | None:
        """Another IK solution of ``target``: of those solved from ``q`` with each joint moved by each of
        ``arm_check_offsets`` either way (one batched call; no random draw, so a trial's plan draws are
        untouched) that are smooth (``max_waypoint_jump`` from ``q``) and :meth:`_arm_clears`, the one of
        least joint change (the first seed on a tie); None if none is."""
        row = self._arm_clear_row(hand, target, q)
        return None if row is None else np.asarray(row.q[0], dtype=float)

    @staticmethod
    def _solve_from_offsets(
        hand: Hand, row: np.ndarray, q: np.ndarray, offsets: tuple[float, ...]
    ) -> tuple[np.ndarray, IKResult]:
        """IK solutions of ``row`` (the tool's 4x4 target in the arm's base frame) from ``q`` with each
        joint moved by each of ``offsets`` either way, in that order (joint, offset, +/-), in one
        batched call with no random draw (a trial's plan draws are untouched): the seeds and the
        result, a row per seed. The other postures of the 7-DOF arm for one hand pose (the elbow
        swings about the shoulder-wrist line)."""
        seeds = np.stack(
            [
                q + s * d * np.eye(len(q))[j]
                for j in range(len(q))
                for d in offsets
                for s in (1.0, -1.0)
            ]
        )
        return seeds, hand.arm.ik(np.repeat(row[None], len(seeds), axis=0), seed_q=seeds)

    def _arm_clear_row(self, hand: Hand, target: Pose, q: np.ndarray) -> IKResult | None:
        """:meth:`_arm_clear_solution` as a one-row IK result (with its IK errors), or None."""
        offsets = self.config.arm_check_offsets
        if not offsets:
            return None
        row = (hand.arm.base_pose().inv() * target).as_matrix()
        _, res = self._solve_from_offsets(hand, row, q, offsets)
        best: tuple[float, int] | None = None
        for i in np.flatnonzero(np.asarray(res.success, dtype=bool)):
            q1 = np.asarray(res.q[i], dtype=float)
            change = float(np.max(np.abs(q1 - q)))
            if (
                change <= self.config.max_waypoint_jump
                and (best is None or change < best[0])
                and self._arm_clears(hand, q, q1)
            ):
                best = (change, int(i))
        if best is None:
            return None
        k = slice(best[1], best[1] + 1)
        return IKResult(
            np.asarray(res.q[k], dtype=float), res.success[k], res.pos_error[k], res.rot_error[k]
        )

    def _line(
        self,
        hand: Hand,
        a: Pose,
        b: Pose,
        q: np.ndarray,
        points: np.ndarray,
        label: str,
        step: float = 0.02,
        notes: list[dict] | None = None,
    ) -> list[tuple[Pose, np.ndarray]] | None:
        """Waypoints (pose, IK solution) at most ``step`` apart on the straight line from ``a`` to ``b``
        (same orientation), each solved from the last and each joint path clear of the cube (None if
        not); of the solutions clear of the cube, one clear of the other arm where there is one
        (:meth:`_arms_apart`, not a veto; ``label`` for its event, kept in ``notes`` if given)."""
        n = max(1, math.ceil(float(np.linalg.norm(b.p - a.p)) / step))
        out = []
        for i in range(1, n + 1):
            way = Pose(a.p + (b.p - a.p) * i / n, b.q)
            q1 = self.ik_q(hand, way, q)
            if q1 is not None:
                # a preference, not a veto: a detour is the way round the cube, and one refused for a
                # posture the (conservative) capsules call unclear ended a trial that had made that
                # move with the elbows touching (45 N) and completed (SAPIEN Rubiks-1-50, 1385.6 s)
                q1 = self._arms_apart(hand, way, q, q1, label, veto=False, notes=notes)
            if q1 is None or not self._clears(hand, q, q1, points):
                return None
            out.append((way, q1))
            q = q1
        return out

    def transit(
        self,
        hand: Hand,
        target: Pose,
        *,
        label: str,
        seed_q: np.ndarray | None = None,
        detour: bool = False,
        settle: float = 0.05,
    ) -> None:
        """Move a free hand to the stand-off ``target`` without sweeping it through the cube.

        The move is one joint-space motion to the IK solution nearest ``seed_q``
        (the grip's planned branch). If that straight joint path brings the
        hand (the grasp module's ``hand_points``, open) nearer the believed
        cube than ``sweep_clearance`` (or than it starts, if it starts nearer),
        the hand instead backs straight out along its approach in 2 cm steps to
        the first of ``detour_distances`` from which the swing to the stand-off's
        orientation and the straight way back in (in 2 cm steps) stay clear (where the
        straight way out is not clear, the swing is checked from where the hand is), and
        a ``detour`` event is recorded. With the arm check (``arm_check``, the grasp module's
        ``arm_margin``) a detour that also keeps the arm clear of the other arm, out along the approach
        or any of :data:`WAYS_OUT`, comes first (:meth:`_arm_clear_detour`). If none does, the direct
        move is made and a warning recorded, unless its path enters the believed cube or the table from a start
        outside them: then the trial ends ``unreachable`` (the move would knock the cube).

        ``detour``: take the detour even if the direct move clears (a change of arm branch: the
        direct move is a swing of the whole arm, its tracking off the checked joint path; measured,
        PyBullet Rubiks-1-5 dead-reckoning-exact seed 0: a 3.7 rad stand-off move checked 23 mm
        clear put the palm on the cube at 52 N and turned it 18 deg).

        ``settle``: how long the arm settles at ``target`` (s).
        """
        cfg = self.config
        points = self._hand_points(hand)
        if points is None:
            self.send(hand, target, label=label, settle=settle, seed_q=seed_q)
            return
        q0 = hand.arm.positions()
        plan_seed = q0 if seed_q is None else seed_q
        q1 = self.ik_q(hand, target, plan_seed)
        if q1 is None or (not detour and self._clears(hand, q0, q1, points)):
            self.send(hand, target, label=label, settle=settle, seed_q=seed_q)
            return
        clear = self.sweep_clearance(hand, q0, q1, points)
        plan = self._arm_clear_detour(hand, target, q0, plan_seed, points, label)
        if plan is None:
            plan = self._first_detour(hand, target, (None,), q0, plan_seed, points, label)
        if plan is not None:
            self._make_detour(hand, plan, label, settle, clear=clear, branch_change=detour)
            return
        start = self.sweep_clearance(hand, q0, q0, points, n=1)
        if detour and clear >= min(cfg.sweep_clearance, start):  # no detour, but the move clears
            self.send(hand, target, label=label, settle=settle, seed_q=seed_q)
            return
        if clear <= 0.0 < start:
            # the straight path enters the believed cube (or the table) and no detour out along the
            # approach goes round: the other ways out (``WAYS_OUT``: straight up, then towards the
            # stand-off's side of the cube, ...; measured: PyBullet Rubiks-5-10 sensor-aided seed 0
            # trial 3, a giver that had retreated sideways in front of the cube, its wrist flex on its
            # soft limit, had no straight way back along its approach; 10 cm up, the turn and the way in all clear. SAPIEN
            # Rubiks-5-100 trial 3, a hand 13 cm in front of the cube going to a stand-off on its left:
            # only the way out 10-15 cm to the left clears. Both ended `unreachable` here before)
            plan = self._first_detour(hand, target, WAYS_OUT, q0, plan_seed, points, label)
            if plan is not None:
                self._make_detour(hand, plan, label, settle, clear=clear)
                return
            # nothing goes round: the move would knock the cube, so the trial ends here with that
            # cause. Made anyway, it put the open hand through the cube (measured: SAPIEN Rubiks-5-200
            # dead reckoning seed 0
            # trial 2, the hand-over re-grip stand-off; the re-grip then found the cube 31.6 mm and
            # 19.6 deg off, the twist turned the wrong layer, and the trial ended `dropped`).
            raise StrategyFailure(
                "unreachable",
                f"{hand.side} arm: the move to the {label} passes through the believed cube or the "
                "table and no detour clears it",
            )
        self.ctx.recorder.event(
            "warning",
            message=f"{hand.side}: the move to the {label} passes {1000 * clear:.0f} mm from the "
            f"cube and no detour clears it",
        )
        self.send(hand, target, label=label, settle=settle, seed_q=seed_q)

    def _plan_detour(
        self,
        hand: Hand,
        target: Pose,
        way_out: str | None,
        distance: float,
        q0: np.ndarray,
        plan_seed: np.ndarray,
        points: np.ndarray,
        label: str,
        notes: list[dict] | None = None,
    ) -> _Detour | None:
        """A detour of :meth:`transit` ``distance`` from the believed cube, its legs each clear of the
        cube, or None: straight out from the command by ``way_out`` (:meth:`_way_out`), a joint-space
        turn to the target backed off along its approach to ``distance``, straight in to ``target``.
        The way out along the approach (``way_out`` None) that is not clear is left out and the turn is
        checked from where the hand is; another way out must be clear. Nothing moves; the legs'
        ``arm_avoid`` events are recorded now, or kept in ``notes`` if given (:meth:`_line`)."""
        out = self._way_out(hand, target, way_out, distance)
        turned = self.back_off(
            target, max(0.0, distance - float(np.linalg.norm(target.p - self.est.p)))
        )
        leg_out = self._line(hand, hand.cmd, out, q0, points, f"{label} detour out", notes=notes)
        if leg_out is None:
            if way_out is not None:
                return None
            # no straight way out (a joint limit on it): the joint-space turn to the stand-off's
            # orientation from here, if that alone is clear (measured: a giver that had slid out
            # sideways beside the cube, its shoulder pan and upper-arm roll on their soft limits,
            # SAPIEN Rubiks-1-20 sensor-aided seed 0)
            leg_out = []
        qa = leg_out[-1][1] if leg_out else q0
        qb = self.ik_q(hand, turned, plan_seed)
        if qb is None or not self._clears(hand, qa, qb, points):
            return None
        leg_in = self._line(hand, turned, target, qb, points, f"{label} detour in", notes=notes)
        if leg_in is None:
            return None
        notes = [] if notes is None else notes
        return _Detour(distance, leg_out, qa, turned, qb, leg_in, way_out, notes)

    def _arm_clear_detour(
        self,
        hand: Hand,
        target: Pose,
        q0: np.ndarray,
        plan_seed: np.ndarray,
        points: np.ndarray,
        label: str,
    ) -> _Detour | None:
        """The first detour whose every leg is clear of the cube *and* keeps the arm clear of the other
        arm (:meth:`_arm_clears` on each step's joint path, the turn's included): out along the approach
        at each of ``detour_distances``, then each of :data:`WAYS_OUT` in turn. None without the grasp
        module's ``arm_margin``, with ``arm_check`` off, or if no detour is clear of both; :meth:`transit` then takes its detour as before. Nothing moves and no
        event is recorded here.

        Why: every arm contact left in 34 sensor-aided PR2 trials with the retreats checked (AMD VM,
        3b6e43c: 7 of 8, 16-71 N, elbow on elbow) was a hand-over's giver in front of the cube backing
        out along its approach, towards the taker's elbow, on its way to a re-grip stand-off at the
        cube's side; for 17 of the 19 steps flagged no elbow posture was clear, so only another way out
        helps (measured, SAPIEN Rubiks-5-20 seed 1 trial 3 at 277.7 s: out along the approach the
        margin falls to -44 mm at 25 and 35 cm; sideways towards the stand-off it stays 3.3 mm)."""
        if self._arm_margin_hook() is None:
            return None
        ways = (None, *WAYS_OUT)
        return self._first_detour(hand, target, ways, q0, plan_seed, points, label, arm_clear=True)

    def _first_detour(
        self,
        hand: Hand,
        target: Pose,
        ways: tuple[str | None, ...],
        q0: np.ndarray,
        plan_seed: np.ndarray,
        points: np.ndarray,
        label: str,
        arm_clear: bool = False,
    ) -> _Detour | None:
        """The first detour (:meth:`_plan_detour`) by each of ``ways`` at each of ``detour_distances`` in
        turn that is clear of the cube and, with ``arm_clear``, keeps the arm clear of the other arm on
        every joint path (its ``arm_avoid`` events kept with it, not recorded); None if none is. The
        straight legs' steps were checked as they were planned (:meth:`_line`: a step with no clear
        posture is a ``found: false`` note), so only the turn is checked here."""
        for name in ways:
            for d in self.config.detour_distances:
                notes: list[dict] | None = [] if arm_clear else None
                plan = self._plan_detour(hand, target, name, d, q0, plan_seed, points, label, notes)
                if plan is not None and (
                    not arm_clear
                    or (
                        all(n.get("found", True) for n in plan.notes)
                        and self._arm_clears(hand, plan.qa, plan.qb)
                    )
                ):
                    return plan
        return None

    def _way_out(self, hand: Hand, target: Pose, way: str | None, distance: float) -> Pose:
        """Where a detour's straight way out ends, ``distance`` from the believed cube centre (or where
        the hand is, if it is farther): back along the hand's approach (``way`` None) or one of
        :data:`WAYS_OUT` (straight up; towards the stand-off's side of the cube; between those two;
        along the hand's axis across its approach and finger axes, either way), the hand's orientation
        kept."""
        c = self.est.p
        r0 = float(np.linalg.norm(hand.cmd.p - c))
        if way is None:
            return self.back_off(hand.cmd, max(0.0, distance - r0))
        side = target.p - c
        side = side / max(np.linalg.norm(side), 1e-9)
        up = np.array([0.0, 0.0, 1.0])
        if way == "up":
            direction = up
        elif way == "side":
            direction = side
        elif way == "side-up":
            direction = (side + up) / max(np.linalg.norm(side + up), 1e-9)
        elif way in ("slide+", "slide-"):
            axis = 3 - self.grasp.approach_axis - self.grasp.finger_axis
            sign = 1.0 if way == "slide+" else -1.0
            direction = hand.cmd.rotation.apply(along(axis, sign))
        else:
            raise ValueError(f"unknown way out {way!r}; expected one of {WAYS_OUT}")
        return Pose(hand.cmd.p + max(0.0, distance - r0) * direction, hand.cmd.q)

    def _make_detour(
        self,
        hand: Hand,
        plan: _Detour,
        label: str,
        settle: float,
        *,
        clear: float,
        branch_change: bool = False,
    ) -> None:
        """Make a planned detour: its kept ``arm_avoid`` events, the ``detour`` event (with ``clear``,
        the direct move's clearance), then the moves."""
        cfg = self.config
        for note in plan.notes:
            self.ctx.recorder.event("arm_avoid", **note)
        self.ctx.recorder.event(
            "detour",
            hand=hand.side,
            label=label,
            clearance_mm=round(1000 * clear, 1),
            distance_m=plan.distance,
            straight_out=bool(plan.leg_out),
            **({"branch_change": True} if branch_change else {}),
            **({"way_out": plan.way_out} if plan.way_out is not None else {}),
        )
        # the way out and the turn are via points in free space, moving away from the cube: they
        # were solved for the believed pose; the injected calibration can put the arm's target just
        # out of reach (measured: 11.7 mm short at 25 cm, PyBullet Rubiks-1-20 sensor-aided seed 0;
        # a way-out step 0.9 mm short, seeded on its planned chain, once an unconverged move was no
        # longer made, PyBullet Rubiks-1-20 at 66b020b), which within ``sweep_clearance`` leaves the
        # detour's clearance argument intact
        for way, q in plan.leg_out:
            self.send(
                hand,
                way,
                label=f"{label} detour out",
                settle=0.02,
                seed_q=q,
                slack=cfg.sweep_clearance,
            )
        self.send(
            hand,
            plan.turned,
            label=f"{label} detour turn",
            settle=0.02,
            seed_q=plan.qb,
            slack=cfg.sweep_clearance,
        )
        for k, (way, q) in enumerate(plan.leg_in):
            last = k == len(plan.leg_in) - 1
            self.send(
                hand,
                way,
                label=label if last else f"{label} detour in",
                settle=settle if last else 0.02,
                seed_q=q,
            )

    def _arc(self, c: np.ndarray, dirs: list, quats: list, r0: float, r1: float) -> list[Pose]:
        """Waypoints (tool poses, the ends left out) on great-circle legs about ``c`` through the unit
        directions ``dirs``, at most ``swing_step_deg`` apart.

        At ``dirs[i]`` the tool has the orientation ``quats[i]`` (x, y, z, w), slerped within a leg; the distance
        from ``c`` goes linearly from ``r0`` to ``r1`` over the whole route. Two opposite directions
        are joined over the top.
        """
        from scipy.spatial.transform import Slerp

        step = math.radians(self.config.swing_step_deg)
        legs = []
        for a, b in zip(dirs[:-1], dirs[1:]):
            ang = math.acos(float(np.clip(np.dot(a, b), -1.0, 1.0)))
            axis = np.cross(a, b)
            if np.linalg.norm(axis) < 1e-6:  # opposite sides: go over the top
                axis = np.cross(a, [0.0, 0.0, 1.0])
                if np.linalg.norm(axis) < 1e-6:
                    axis = np.array([1.0, 0.0, 0.0])
            legs.append((a, ang, axis / np.linalg.norm(axis)))
        total = sum(ang for _, ang, _ in legs)
        out: list[Pose] = []
        done = 0.0
        for j, (a, ang, axis) in enumerate(legs):
            slerp = Slerp([0.0, 1.0], Rotation.from_quat(np.stack([quats[j], quats[j + 1]])))
            n = max(1, math.ceil(ang / step))
            last = j == len(legs) - 1
            for i in range(1, n if last else n + 1):
                f = i / n
                # the whole route's fraction (one leg: the leg's own, the same floats as ever)
                s = f if len(legs) == 1 else (done + ang * f) / total
                u = Rotation.from_rotvec(axis * ang * f).apply(a)
                out.append(Pose.from_rotation(c + ((1 - s) * r0 + s * r1) * u, slerp([f])[0]))
            done += ang
        return out

    def _swing_route(
        self,
        hand: Hand,
        far: Pose,
        label: str,
        u0: np.ndarray,
        u1: np.ndarray,
        r0: float,
        r1: float,
    ) -> list[Pose]:
        """The checked swing (``swing_routes``): the first route round the cube the arm can follow.

        Routes, in order: the direct arc; then two-leg arcs through a via direction (the arc's
        middle, over the top, below, and diagonally between them) with the wrist rolled 0, +-90
        or 180 deg about the approach at the via (a hand in front of the cube near the torso
        cannot turn round it directly). A route passes if every waypoint and the stand-off have
        an IK solution, each seeded with the previous one from the arm's joints, no joint moving
        more than ``swing_max_joint_step`` between two, and every waypoint is :meth:`reachable` from
        its solution with ``swing_reach_sigmas`` (default ``reach_sigmas``) of the injected errors:
        the arm is sent each waypoint with those errors. Recorded as a ``swing`` event
        (``margin_skipped``: routes on the branch passed over for the margin). If routes are on the
        branch but none keeps the margin, the first is taken (a warning; the event has
        ``margin=False``). None passes: a warning, and the hand moves straight to the stand-off (no
        waypoints).
        """
        cfg = self.config
        c = self.est.p
        start = hand.cmd
        up = np.array([0.0, 0.0, 1.0])
        routes: list[tuple[list, list]] = [([u0, u1], [start.q, far.q])]
        mid = u0 + u1
        mid = mid / np.linalg.norm(mid) if np.linalg.norm(mid) > 1e-6 else np.cross(u0, up)
        vias = [mid]
        if abs(float(np.dot(u0, up))) < 0.9 and abs(float(np.dot(u1, up))) < 0.9:
            vias += [up, mid - up, -up, mid + up]
        for via in vias:
            via = via / np.linalg.norm(via)
            axis = np.cross(u0, via)
            if np.linalg.norm(axis) < 1e-9:
                axis = np.cross(u0, up) if abs(u0[2]) < 0.9 else np.cross(u0, [1.0, 0.0, 0.0])
            ang = math.acos(float(np.clip(np.dot(u0, via), -1.0, 1.0)))
            top = Rotation.from_rotvec(axis / np.linalg.norm(axis) * ang) * start.rotation
            for roll in (0.0, math.pi / 2, -math.pi / 2, math.pi):
                rolled = top * Rotation.from_rotvec(along(self.grasp.approach_axis, roll))
                routes.append(([u0, via, u1], [start.q, rolled.as_quat(), far.q]))
        sigmas = cfg.reach_sigmas if cfg.swing_reach_sigmas is None else cfg.swing_reach_sigmas
        base = hand.arm.base_pose()
        why = ""
        # the first route on the arm's branch whose waypoints do not all keep the margin (taken, with a
        # warning, only if no route does), and how many routes were passed over for the margin
        unchecked: tuple[list[Pose], int] | None = None
        short = 0
        for dirs, quats in routes:
            poses = self._arc(c, dirs, quats, r0, r1)
            q, ok = hand.arm.positions(), True
            solved: list[np.ndarray] = []
            for pose in [*poses, far]:
                res = hand.arm.ik((base.inv() * pose).as_matrix()[None], seed_q=q)
                jump = float(np.max(np.abs(res.q[0] - q)))
                if not res.success[0] or jump > cfg.swing_max_joint_step:
                    why += (
                        f" {len(dirs) - 1}-leg arc: waypoint {np.round(pose.p, 3).tolist()} IK "
                        f"{bool(res.success[0])}, joint step {jump:.2f} rad;"
                    )
                    ok = False
                    break
                q = res.q[0]
                solved.append(q)
            if not ok:
                continue
            # each waypoint is sent with the injected errors (``send``) and must be reachable with them,
            # as a stand-off and a retreat step must (``reachable``, from its solution on the route's
            # chain); the stand-off itself was chosen by :meth:`standoff`. Why (SAPIEN Rubiks-5-5 seed 0
            # trial 3 at ffe4661 on the development VM, docs/herb_push_grasp.md): a re-grip's arc, found
            # reachable for the believed poses, had a waypoint the arm missed by 5.1 mm, 1.5 deg with the
            # errors (HERB's ``ik_slack`` 5 mm), and the trial ended `unreachable`
            out = next(
                (
                    pose
                    for pose, qi in zip(poses, solved)
                    if not self.reachable(hand, pose, qi, sigmas)
                ),
                None,
            )
            if out is None:
                self.ctx.recorder.event(
                    "swing",
                    hand=hand.side,
                    label=label,
                    legs=len(dirs) - 1,
                    waypoints=len(poses),
                    **({"margin_skipped": short} if short else {}),
                )
                return poses
            short += 1
            why += (
                f" {len(dirs) - 1}-leg arc: waypoint {np.round(out.p, 3).tolist()} out of reach with "
                f"the injected errors' margin;"
            )
            if unchecked is None:
                unchecked = (poses, len(dirs) - 1)
        if unchecked is not None:
            poses, legs = unchecked
            self.ctx.recorder.event(
                "warning",
                message=f"{hand.side}: {label}: no arc round the cube keeps the injected errors' "
                f"margin ({why.strip()}); the first on the arm's branch for the believed poses",
            )
            self.ctx.recorder.event(
                "swing",
                hand=hand.side,
                label=label,
                legs=legs,
                waypoints=len(poses),
                margin_skipped=short,
                margin=False,
            )
            return poses
        self.ctx.recorder.event(
            "warning",
            message=f"{hand.side}: {label}: no arc round the cube on the arm's branch "
            f"({why.strip()}); one joint-space move to the stand-off",
        )
        return []

    def release_hand(self, hand: Hand, retreat: float | None = None) -> None:
        """Open (if holding) and stand off ``retreat`` (default ``retreat_distance``) along the approach
        from the last grip.

        The open hand is still round the cube, so the retreat must be a
        straight move: if the stand-off's IK solution is more than
        ``max_waypoint_jump`` from the arm's joints (a joint limit on the way
        out, another branch beyond), or its joint path would bring the hand
        nearer the cube (with the grasp module's ``hand_points``: see
        :meth:`transit`), it slides sideways (:meth:`_side_route`), else backs
        off in 2 cm steps as far as the arm follows smoothly and clear; cut
        short there, it changes the arm's posture in place and backs out
        straight the rest of the way (:meth:`_posture_route`), else logs a
        warning.
        """
        if hand.holding:
            self.grasp.open(self, hand)
        hand.holding, hand.cube_in_tcp, hand.grip_dir, hand.depth = False, None, None, 0
        d = self.config.retreat_distance if retreat is None else retreat
        ref = hand.last_grip or hand.cmd
        back = self.back_off(ref, d)
        if not (
            np.linalg.norm(back.p - hand.cmd.p) > 2e-3
            or not Pose(hand.cmd.p, back.q).allclose(Pose(hand.cmd.p, hand.cmd.q), 1, 1e-3)
        ):
            return
        points = self._hand_points(hand)

        def way_out(target: Pose) -> tuple[bool, np.ndarray | None]:
            """Smooth and clear of the other arm (:meth:`smooth_q`), within reach with the injected errors'
            margin, and (with hand points) clear of the cube; the IK solution to seed the move with."""
            q1 = self.smooth_q(hand, target, label="retreat")
            if q1 is None or not self.reachable(hand, target, q1):
                return False, None
            if points is None:
                return True, None
            return self._clears(hand, hand.arm.positions(), q1, points), q1

        ok, q_back = way_out(back)
        if ok:
            self.send(hand, back, label="retreat", settle=0.05, seed_q=q_back)
            return
        step = 0.02
        approach = ref.rotation.apply(along(self.grasp.approach_axis, 1.0))
        dist = float(np.dot(ref.p - hand.cmd.p, approach))  # already backed off
        if points is not None and self.config.side_retreat > 0:
            route = self._side_route(hand, ref, dist, d, points)
            if route is not None:
                for way, q, lab in route:
                    self.send(hand, way, label=lab, settle=0.02, seed_q=q)
                return
        while dist + step <= d + 1e-9:
            nxt = self.back_off(ref, dist + step)
            ok, q_next = way_out(nxt)
            if not ok:
                break
            self.send(hand, nxt, label="retreat step", settle=0.02, seed_q=q_next)
            dist += step
        if dist < d - 1e-6 and points is not None:  # cut short: another posture, then straight on
            route = self._posture_route(hand, ref, dist, d, points)
            if route is not None:
                for way, q, lab in route:
                    self.send(hand, way, label=lab, settle=0.02, seed_q=q)
                return
        if dist < d - 1e-6:  # made in full in steps (one move was not smooth or clear): no warning
            self.ctx.recorder.event(
                "warning",
                message=f"{hand.side}: retreat cut to {100 * dist:.0f} cm "
                f"(the straight way out leaves the arm's branch)",
            )

    def _side_route(
        self, hand: Hand, ref: Pose, dist: float, d: float, points: np.ndarray
    ) -> list[tuple[Pose, np.ndarray, str]] | None:
        """A retreat when the straight one fails: back along the approach from ``ref`` in 2 cm steps as
        far as that goes (from ``dist``, towards ``d``), then sideways (the axis across the approach and
        finger axes: the open pads slide along the faces they were on) in 2 cm steps until the hand is
        ``sweep_clearance`` from the believed cube (at most ``side_retreat``), then back along the
        approach again as far as it goes up to ``d``. Every step is solved from the last and must be
        smooth (``max_waypoint_jump``) and clear (:meth:`_clears`). The sideways direction pointing
        away from the other hand (if it holds the cube) is tried first; one pointing towards it (more
        than 60 degrees from square) is not tried, and a step that brings the hand near the other
        hand's gripper gives its direction up (:meth:`_hands_clear`, a ``hand_avoid`` event). Returns the waypoints (pose, IK solution, label) or None; a ``retreat_side`` event is
        recorded for a route found."""
        step = 0.02
        c = self.est.p
        other = self.other(hand)
        side_axis = 3 - self.grasp.approach_axis - self.grasp.finger_axis
        lateral = ref.rotation.apply(along(side_axis, 1.0))
        toward = other.cmd.p - c if other.holding else np.zeros(3)
        toward = toward / max(float(np.linalg.norm(toward)), 1e-9)
        dirs = sorted((s * lateral for s in (1.0, -1.0)), key=lambda v: float(np.dot(v, toward)))
        dirs = [v for v in dirs if float(np.dot(v, toward)) <= 0.5]

        q0 = hand.arm.positions()
        n_back = max(0, math.floor((d - dist) / step + 1e-9))
        first, _, _ = self._chain(
            hand,
            q0,
            [self.back_off(ref, dist + step * (i + 1)) for i in range(n_back)],
            "retreat step",
            points,
            True,
        )
        if len(first) == n_back:
            return None  # the straight way out is clear in steps after all
        # slide out from as far back as the straight way goes, else from nearer in
        for k in range(len(first), -1, -1):
            route = self._slide(hand, ref, first[:k], dirs, points, d - dist - step * k)
            if route is not None:
                side, last, v = route
                self.ctx.recorder.event(
                    "retreat_side",
                    hand=hand.side,
                    back_cm=round(100 * (dist + step * k)),
                    side_cm=round(100 * step * len(side)),
                    then_back_cm=round(100 * step * len(last)),
                    direction=np.round(v, 2).tolist(),
                )
                return [*first[:k], *side, *last]
        return None

    def _chain(
        self,
        hand: Hand,
        q: np.ndarray,
        poses: list[Pose],
        label: str,
        points: np.ndarray,
        stop_on_fail: bool,
    ) -> tuple[list[tuple[Pose, np.ndarray, str]], np.ndarray, bool]:
        """Solve ``poses`` one after another from ``q``, each smooth (``max_waypoint_jump``), within reach
        with the injected errors' margin (:meth:`reachable`), its joint path clear of the cube (:meth:`_clears`)
        and of the other arm (:meth:`_arms_apart`: another posture if the nearest is not):
        the waypoints (pose, IK solution, ``label``) that pass, the last solution, and whether all passed
        (``stop_on_fail``: stop at the first that fails, else give up)."""
        out: list[tuple[Pose, np.ndarray, str]] = []
        for way in poses:
            q1 = self.ik_q(hand, way, q)
            if q1 is not None and float(np.max(np.abs(q1 - q))) > self.config.max_waypoint_jump:
                q1 = None
            if q1 is not None:
                q1 = self._arms_apart(hand, way, q, q1, label)
            if (
                q1 is None
                or not self.reachable(hand, way, q1)
                or not self._clears(hand, q, q1, points)
            ):
                if stop_on_fail:
                    break
                return out, q, False
            out.append((way, q1, label))
            q = q1
        return out, q, True

    def _slide(
        self,
        hand: Hand,
        ref: Pose,
        first: list[tuple[Pose, np.ndarray, str]],
        dirs: list[np.ndarray],
        points: np.ndarray,
        left: float,
    ) -> tuple[list, list, np.ndarray] | None:
        """From the end of ``first`` (or the hand's command): sideways along one of ``dirs`` in 2 cm steps
        until ``sweep_clearance`` from the cube (at most ``side_retreat``), then back along the approach
        as far as it goes, at most ``left`` (m): (sideways, back, direction) or None."""
        cfg, step = self.config, 0.02
        start = first[-1][0] if first else hand.cmd
        q_start = first[-1][1] if first else hand.arm.positions()
        for v in dirs:
            side: list[tuple[Pose, np.ndarray, str]] = []
            q, done = q_start, False
            for i in range(1, math.floor(cfg.side_retreat / step + 1e-9) + 1):
                q_from = q
                part, q, ok = self._chain(
                    hand, q, [Pose(start.p + v * step * i, start.q)], "retreat side", points, False
                )
                if not ok:
                    break
                if not self._hands_clear(hand, q_from, q, points):
                    self.ctx.recorder.event(
                        "hand_avoid",
                        hand=hand.side,
                        label="retreat side",
                        direction=np.round(v, 2).tolist(),
                        side_cm=round(100 * step * i),
                        gap_mm=round(1000 * self.hand_gap(hand, q_from, q, points), 1),
                    )
                    break
                side += part
                if self.sweep_clearance(hand, q, q, points, n=1) >= cfg.sweep_clearance:
                    done = True
                    break
            if not done:
                continue
            end = side[-1][0]
            rest = max(0, math.floor(left / step + 1e-9))
            ways = [
                Pose(
                    end.p - ref.rotation.apply(along(self.grasp.approach_axis, step * (i + 1))),
                    end.q,
                )
                for i in range(rest)
            ]
            last, _, _ = self._chain(hand, q, ways, "retreat", points, True)
            return side, last, v
        return None

    def _posture_route(
        self, hand: Hand, ref: Pose, dist: float, d: float, points: np.ndarray
    ) -> list[tuple[Pose, np.ndarray, str]] | None:
        """The rest of a retreat that neither a sideways slide nor straight steps made: the arm first changes its
        posture where the hand is (the 7-DOF arm's self-motion: the tool held at its commanded pose while
        the elbow swings), then backs off straight along the approach from ``dist`` to ``d`` in 2 cm steps.

        The postures tried are the IK solutions of the hand's pose from the arm's joints with each joint
        moved by each of ``retreat_posture_offsets`` either way (one batched call, no random draw), least
        joint change first; the way there is solved at the same pose from seeds evenly between (steps of
        at most 0.05 rad), every step smooth, clear of the cube (:meth:`_clears`) and of the other arm
        (:meth:`_arm_clears`), and the way back must go the whole way (:meth:`_chain`). Why: a giver whose
        shoulder lift was 27 mrad from its soft limit could not rise (1.8 cm up, the next step swung the
        upper-arm and forearm rolls 0.7 rad through the cube), its slide one way ran into the taker's
        finger and the other way left the branch as well, and its forearm roll turned 0.18 rad in place
        let it back straight out (SAPIEN Rubiks-5-100 dead-reckoning seed 0 trial 1, 525.6 s). Returns the waypoints (pose, IK solution, label) or None;
        a ``retreat_posture`` event records a route found."""
        offsets, step = self.config.retreat_posture_offsets, 0.02
        n_back = max(0, math.floor((d - dist) / step + 1e-9))
        if not offsets or n_back == 0:
            return None
        q0 = hand.arm.positions()
        here = hand.cmd
        row = (hand.arm.base_pose().inv() * here).as_matrix()
        seeds, res = self._solve_from_offsets(hand, row, q0, offsets)
        found = [
            (float(np.max(np.abs(np.asarray(res.q[i], dtype=float) - q0))), int(i))
            for i in np.flatnonzero(np.asarray(res.success, dtype=bool))
        ]
        backs = [self.back_off(ref, dist + step * (i + 1)) for i in range(n_back)]
        for change, i in sorted(found):
            if change < 1e-3:
                continue  # the posture the arm is in
            target = np.asarray(res.q[i], dtype=float)
            n = max(1, math.ceil(change / 0.05))
            way: list[tuple[Pose, np.ndarray, str]] = []
            q = q0
            for k in range(1, n + 1):
                r = hand.arm.ik(row[None], seed_q=q0 + (target - q0) * k / n)
                q1 = np.asarray(r.q[0], dtype=float)
                if (
                    not r.success[0]
                    or float(np.max(np.abs(q1 - q))) > 0.1
                    or not self._clears(hand, q, q1, points)
                    or not self._arm_clears(hand, q, q1)
                ):
                    break
                way.append((here, q1, "retreat posture"))
                q = q1
            if len(way) < n:
                continue
            back, _, ok = self._chain(hand, q, backs, "retreat", points, False)
            if not ok:
                continue
            j = int(i) // (2 * len(offsets))
            self.ctx.recorder.event(
                "retreat_posture",
                hand=hand.side,
                joint=j,
                offset=float(seeds[i][j] - q0[j]),
                change_rad=round(change, 3),
                back_cm=round(100 * (dist + step * n_back)),
            )
            return [*way, *back]
        return None

    def grip(
        self,
        hand: Hand,
        world_dir: str,
        depth: int,
        label: str,
        k: int | None = None,
        *,
        gives: bool = True,
        on_table: bool = False,
        relation: str | None = None,
        take: bool = False,
        twist_delta: float | None = None,
        give_turn: tuple[str, float] | None = None,
        twist_now: bool = False,
    ) -> None:
        """``hand`` grips the cube from ``world_dir``, ``depth`` slabs deep: choose, swing to the stand-off,
        move in and close (the last by the grasp module), then the bookkeeping.

        ``k``: the plan action this grip serves; with ``gives`` a two-slab grip is chosen so that the
        hand can carry its next hand-over turn, if it gives the cube next (not if it grips deeper than
        ``giver_depth``: it grips again before it gives). ``twist_delta``: the wrist
        roll of the hand's next twist (default: from the plan after action ``k``). ``give_turn``: the
        hand-over turn (axis, rad) this grip gives the cube with, whatever its depth (default: the
        plan's next one after action ``k`` for a two-slab grip with ``gives``).
        """
        gives = gives and (self.config.giver_depth is None or depth <= self.config.giver_depth)
        turn = self._next_turn(k, hand.side) if (gives and k is not None and depth == 2) else None
        if give_turn is not None:
            turn = give_turn
        if twist_delta is None:
            twist_delta = self._next_twist_delta(k, hand.side) if depth == 1 else 0.0
        req = GripRequest(
            world_dir, depth, label, turn, twist_delta, on_table, relation, take, twist_now
        )
        grasp = self.grasp
        pose, q_plan = grasp.choose(self, hand, req)
        grasp.ready(self, hand, req)
        far = self.standoff(hand, pose, q_plan, label)
        if hand.far_posture:
            # another arm branch: change posture away from the cube (the detour), not on an arc round it
            hand.far_posture = False
            self.transit(hand, far, label=f"{label} stand-off", seed_q=q_plan, detour=True)
        elif (
            np.linalg.norm(far.p - hand.cmd.p) > 0.01
            or abs(float(np.dot(far.q, hand.cmd.q))) < 0.999
        ):
            # swing round to the far stand-off first, so that the swing clears the cube
            self._swing(hand, far, label=f"{label} stand-off", seed_q=q_plan)
        grasp.close_in(self, hand, pose, q_plan, req)
        hand.holding = True
        hand.last_grip = hand.cmd
        hand.cube_in_tcp = hand.cmd.inv() * self.est
        hand.grip_dir, hand.depth = world_dir, depth
        self._judge(label, hand)

    def reach_margin(self, sigmas: float | None = None) -> tuple[float, float]:
        """How far (m, rad) a target must stay reachable either way along (about) each world axis:
        ``reach_sigmas`` (or ``sigmas``) standard deviations of the injected per-motion position error
        (calibration and tracking together) and of the calibration's rotation (0: none injected)."""
        err = self.config.errors
        k = (self.config.reach_sigmas if sigmas is None else sigmas) or 0.0
        return k * math.hypot(err.calib_pos_std, err.tracking_std), k * math.radians(
            err.calib_rot_std_deg
        )

    def reachable(
        self, hand: Hand, pose: Pose, seed: np.ndarray, sigmas: float | None = None
    ) -> bool:
        """Whether ``pose`` (believed) and its neighbours within :meth:`reach_margin` (moved either way
        along each world axis, turned either way about each) all have an IK solution from ``seed``:
        whatever the injected errors put the arm's target within that box, it stays reachable.
        ``sigmas``: the box's size in standard deviations (default ``reach_sigmas``). Without either:
        True (the caller has checked ``pose`` itself)."""
        k = self.config.reach_sigmas if sigmas is None else sigmas
        if k is None:
            return True
        dp, dr = self.reach_margin(k)
        poses = [pose]
        for axis in np.eye(3):
            for s in (1.0, -1.0):
                if dp > 0:
                    poses.append(Pose(pose.p + s * dp * axis, pose.q))
                if dr > 0:
                    turn = Rotation.from_rotvec(s * dr * axis)
                    poses.append(Pose.from_rotation(pose.p, turn * pose.rotation))
        base = hand.arm.base_pose()
        # in batches small enough that the restarts of the misses stay in the NumPy solver
        for i in range(0, len(poses), 7):
            rows = np.stack([(base.inv() * p).as_matrix() for p in poses[i : i + 7]])
            if not np.asarray(hand.arm.ik(rows, seed_q=seed).success, dtype=bool).all():
                return False
        return True

    def standoff(self, hand: Hand, grip: Pose, q_plan: np.ndarray | None, label: str) -> Pose:
        """The stand-off a free hand comes to before it moves in to ``grip``: ``far_distance`` back along
        the approach or, with ``reach_sigmas``, the farthest of that and 2 cm steps in (to
        ``retreat_distance``) that stays :meth:`reachable` from the grip's solution ``q_plan`` (a
        ``standoff`` event when it is not the first; if none is, ``far_distance`` and a warning)."""
        cfg = self.config
        far = self.back_off(grip, cfg.far_distance)
        if cfg.reach_sigmas is None:
            return far
        seed = hand.arm.positions() if q_plan is None else np.asarray(q_plan, dtype=float)
        n = max(0, math.floor((cfg.far_distance - cfg.retreat_distance) / 0.02 + 1e-9))
        for i in range(n + 1):
            d = cfg.far_distance - 0.02 * i
            cand = self.back_off(grip, d)
            if self.reachable(hand, cand, seed):
                if i > 0:
                    self.ctx.recorder.event(
                        "standoff", hand=hand.side, label=label, distance_m=round(d, 3)
                    )
                return cand
        self.ctx.recorder.event(
            "warning",
            message=f"{hand.side}: no stand-off for the {label} within the arm's reach with the "
            f"injected errors' margin; {100 * cfg.far_distance:.0f} cm",
        )
        return far

    def _next_turn(self, k: int | None, side: str) -> tuple[str, float] | None:
        """If ``side``'s next regrasp after action ``k`` is giving the cube in a hand-over: (axis, angle)."""
        if k is None:
            return None
        for a in self.plan.actions[k + 1 :]:
            if isinstance(a, Handover):
                return (a.axis, a.quarter_turns * math.pi / 2) if a.giver == side else None
            if isinstance(a, Regrasp):
                return None
        return None

    def _next_twist_delta(self, k: int | None, side: str) -> float:
        """The wrist roll of the next twist after action ``k`` if ``side`` rotates it (else 0)."""
        if k is None:
            return 0.0
        for a in self.plan.actions[k + 1 :]:
            if isinstance(a, Twist):
                return self._roll_delta(a) if a.gripper == side else 0.0
        return 0.0

    @staticmethod
    def _roll_delta(t: Twist) -> float:
        """Wrist-roll change for a twist: ``quarter_turns`` right-handed about +y; the left approach is -y."""
        phi = t.quarter_turns * math.pi / 2
        return -phi if t.gripper == "left" else phi

    def _lone_depth(self, hand: Hand, rotator: str) -> int:
        """How deep a hand that will hold the cube alone grips (see ``lone_holder_two_slabs``)."""
        if self.config.lone_holder_two_slabs:
            return 2
        return 1 if rotator == hand.side else 2

    # ------------------------------------------------------------- actions
    def _pick(self, a: Pick, k: int) -> None:
        if a.approach != "side":
            raise StrategyFailure(
                None, f"pick approach {a.approach!r} is not implemented (side only)"
            )
        cfg = self.config
        picker = self.hands[a.gripper]
        other = self.other(picker)
        depth = self._lone_depth(picker, a.rotator)
        self.grip(picker, SIDE_DIR[picker.side], depth, "pick", k, gives=False, on_table=True)
        lift = np.asarray(cfg.twist_position) - self.est.p
        up = Pose(picker.cmd.p + [0, 0, lift[2] + 0.03], picker.cmd.q)
        self.send(picker, up, label="lift")
        there = Pose(picker.cmd.p + [lift[0], lift[1], -0.03], picker.cmd.q)
        self.send(picker, there, label="carry")
        self._join(picker, other, a.rotator, "second grasp", "pick shift out", k)

    def _join(
        self, alone: Hand, free: Hand, rotator: str, label: str, shift_label: str, k: int
    ) -> None:
        """The free hand joins the hand holding alone so that the next rotator holds one slab.

        If the lone holder holds two slabs and rotates next, the free hand grips two slabs deep,
        fingers crossing (it becomes the holder), and the lone hand lets go and slides out to one
        slab; otherwise the free hand grips the depth the lone hand leaves.
        """
        if rotator == alone.side and alone.depth == 2:
            self.grip(free, SIDE_DIR[free.side], 2, label, k, relation="cross")
            self.release_hand(alone)
            self.grip(alone, SIDE_DIR[alone.side], 1, shift_label, k)
        else:
            self.grip(free, SIDE_DIR[free.side], 3 - alone.depth, label, k)

    def _twist(self, t: Twist, orientation, k: int) -> None:
        cube, rec = self.cube, self.ctx.recorder
        rot, hold = self.hands[t.gripper], self.other(self.hands[t.gripper])
        delta = self._roll_delta(t)
        if (
            rot.holding
            and hold.holding
            and hold.depth == 2
            and self.grasp.regrip_before_twist(self, rot, delta)
        ):
            self.release_hand(rot)
        if not (rot.holding and hold.holding and rot.depth == 1 and hold.depth == 2):
            # after a twist the rotator stands off: a twist right after a twist re-takes its slab
            if hold.holding and hold.depth == 2 and not rot.holding:
                self.grip(rot, SIDE_DIR[rot.side], 1, "re-grip", twist_delta=delta, twist_now=True)
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
        # diagnostic (engine contacts, not control); read before the swap: the old body's contacts go with it
        diag = self.grasp.twist_diagnostics(self, body_axis)
        if diag is not None:
            rec.event("twist_contacts", **diag)
        cube.begin_twist(body_axis, intended=intended)
        # from the measured joints, which track a goal on a soft limit to within ~1e-4 rad of either
        # side: the goal is kept on the limit (measured: one goal 1e-4 rad past the upper-arm roll's)
        lo, hi = rot.arm.lower, rot.arm.upper
        q = np.clip(rot.arm.positions(), lo, hi)
        want = q[-1] + delta
        q[-1] = np.clip(want, lo[-1], hi[-1])  # a continuous wrist roll (inf limits) runs in full
        if abs(q[-1] - want) > 1e-6:
            rec.event(
                "warning",
                message=f"twist {k + 1}: wrist roll limited to {math.degrees(q[-1]):.0f}° "
                f"({math.degrees(want - q[-1]):.0f}° short)",
            )
        duration = self.config.quarter_turn_s * abs(t.quarter_turns)
        offset_fn = getattr(self.grasp, "roll_offset", None)
        offset = offset_fn(self, rot) if offset_fn is not None else None
        if offset is None or not self.roll_about(rot, offset, q, duration, k):
            rot.arm.move_to_joints(q, duration=duration, settle=0.2)
        rolled = Rotation.from_rotvec(along(self.grasp.approach_axis, delta))
        rot.cmd = rot.last_grip = Pose.from_rotation(rot.cmd.p, rot.cmd.rotation * rolled)
        self.grasp.open(self, rot)
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
        # the rotator backs off (opening again: it still counts as holding); the next regrasp or
        # hand-over takes it from there
        self.release_hand(rot)

    def roll_waypoints(
        self, tool: Pose, offset: float, angle: float, n: int
    ) -> tuple[np.ndarray, list[Pose]]:
        """The layer's axis (a point on it, world) ``offset`` along ``tool``'s finger axis, and ``tool`` turned
        about it, parallel to its approach, by ``angle`` in ``n`` equal steps (the last at ``angle``)."""
        fingers = tool.rotation.apply(along(self.grasp.finger_axis, 1.0))
        approach = tool.rotation.apply(along(self.grasp.approach_axis, 1.0))
        centre = tool.p + offset * fingers
        return centre, [
            rotate_about_point(tool, centre, approach, angle * i / n) for i in range(1, n + 1)
        ]

    def roll_about(
        self, hand: Hand, offset: float, q_goal: np.ndarray, duration: float, k: int
    ) -> bool:
        """Twist by turning ``hand``'s tool about the layer's axis, ``offset`` (m) along its finger axis from
        its approach axis as its own fingers measure it, by the wrist roll ``q_goal`` asks for; False (nothing
        moved) when the chained IK of the waypoints does not hold the arm on its branch.

        The wrist rolls about the palm's axis; a layer whose axis is off it is carried round on a circle of
        that radius, and the holder's two-fingertip pinch, a hinge, lets the whole cube turn about its pinch
        axis (measured, PyBullet Rubiks-1-20 seed 0, U2 at move 14: the axis 4.0 mm off, the cube rolled
        15 deg about the holder's pinch axis and later fell out of a one-slab give grip;
        docs/herb_push_grasp.md). The waypoints are relative to the arm's own measured tool pose (FK of its
        joints) and solved by its own IK: no belief and no injected calibration enter, as in the joint-space
        roll they replace. Waypoints every ``roll_step_deg`` at most; each IK is seeded with the wrist
        at its share of the roll, and a step that moves any other joint more than
        ``swing_max_joint_step`` (another branch) refuses the whole roll.
        """
        arm = hand.arm
        q0 = np.clip(arm.positions(), arm.lower, arm.upper)
        angle = float(q_goal[-1] - q0[-1])
        n = max(1, math.ceil(abs(angle) / math.radians(self.config.roll_step_deg) - 1e-9))
        centre, poses = self.roll_waypoints(arm.tcp_pose(), offset, angle, n)
        qs, q = [], q0
        for i, pose in enumerate(poses, start=1):
            seed = np.array(q, dtype=float)
            seed[-1] = q0[-1] + angle * i / n
            q1 = self.ik_q(hand, pose, seed)
            if q1 is None or float(np.max(np.abs(q1[:-1] - q[:-1]))) > (
                self.config.swing_max_joint_step
            ):
                self.ctx.recorder.event(
                    "warning",
                    message=f"twist {k + 1}: no smooth roll about the layer's axis "
                    f"({1000 * offset:+.1f} mm off the palm's, waypoint {i} of {n}): the wrist rolls",
                )
                return False
            qs.append(q1)
            q = q1
        for i, qi in enumerate(qs, start=1):
            arm.move_to_joints(qi, duration=duration / n, settle=0.2 if i == n else 0.0)
        self.ctx.recorder.event(
            "roll", hand=hand.side, offset_mm=round(1000 * offset, 2), waypoints=n
        )
        return True

    def _regrasp(self, a: Regrasp, k: int) -> None:
        if a.kind == "unwind":  # the rotator lets go, rolls back (a fresh choice) and re-grips
            rot = self.hands[a.gripper]
            self.release_hand(rot)
            self.grip(rot, SIDE_DIR[rot.side], 1, "unwind", k)
            return
        if a.kind != "shift":
            raise StrategyFailure(None, f"regrasp {a.kind!r} is not implemented")
        new_rot = self.hands[a.gripper]
        new_hold = self.other(new_rot)
        # the old rotator slides in to two slabs, then the old holder slides out to one
        self.release_hand(new_hold)
        self.grip(new_hold, SIDE_DIR[new_hold.side], 2, "shift in", k, relation="cross")
        self.release_hand(new_rot)
        self.grip(new_rot, SIDE_DIR[new_rot.side], 1, "shift out", k)

    def _handover(self, a: Handover, k: int) -> None:
        giver, taker = self.hands[a.giver], self.hands[a.taker]
        cfg = self.config
        angle = a.quarter_turns * math.pi / 2
        if cfg.giver_depth is not None and giver.depth > cfg.giver_depth:
            # the giver grips again shallower (``giver_depth``) while the taker holds two slabs from its
            # side, crossing (a one-slab hold let the cube turn 16 degrees and fall, PyBullet); the taker
            # then lets go as in every hand-over
            if taker.holding and taker.depth < 2:
                self.release_hand(taker)
            if not taker.holding:
                self.grip(taker, SIDE_DIR[taker.side], 2, "hand-over hold", k, relation="cross")
            self.release_hand(giver)
            self.grip(
                giver,
                SIDE_DIR[giver.side],
                cfg.giver_depth,
                "hand-over give grip",
                k,
                twist_delta=0.0,
                give_turn=(a.axis, angle),
            )
        self.release_hand(taker, retreat=cfg.taker_retreat)
        path = self.turn_path(a.axis, angle)  # the belief before the turn: send() moves it
        n = max(1, cfg.handover_waypoints) * abs(a.quarter_turns)
        start = giver.cmd
        for i in range(1, n + 1):
            self.send(
                giver,
                path.at(start, i, n),
                label="hand-over turn",
                settle=0.05 if i < n else 0.2,
            )
        self._judge("hand-over turned", giver)
        self.level_turn = False
        # The taker holds the cube alone while the giver comes round: with ``lone_holder_two_slabs``
        # two slabs deep, whichever hand rotates next (a one-slab grip let the cube pivot about its
        # pad axis: measured on PyBullet, 32 degrees as the giver let go); if the taker is then the
        # next rotator, the giver re-grips two slabs deep as well (fingers crossing, as in a shift)
        # and the taker slides out to one slab (_join).
        depth = self._lone_depth(taker, a.rotator)
        self.grip(
            taker,
            SIDE_DIR[taker.side],
            depth,
            "hand-over take",
            k,
            relation=self.grasp.take_relation(),
            take=True,
        )
        self.release_hand(giver, retreat=cfg.handover_retreat)
        self._judge("hand-over given", taker)
        self._join(taker, giver, a.rotator, "hand-over re-grip", "hand-over shift out", k)

    def _release(self) -> None:
        for hand in self.hands.values():
            self.grasp.open(self, hand)
            hand.holding = False
        self.t_release = self.b.time
