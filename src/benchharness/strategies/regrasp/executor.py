"""The abstract executor: run a plan on the logical cube, checking every precondition.

It is the planner's test oracle and the reference a physical strategy
compares its measured outcome with. It shares no bookkeeping with the
search: it re-tracks the cube's orientation from the actions alone and turns
each :class:`~.actions.Twist` (gripper, workspace axis, slab, signed quarter
turns) into the face move it must be, through that orientation, then applies
it with the cube core. A planner that lost track of the orientation, or put a
gripper on the wrong slab, fails here.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...cube import SOLVED, Move, apply
from .actions import Handover, Pick, Regrasp, RegraspPlan, Release, Twist
from .model import (
    GIVER_ENDS,
    PICK_APPROACHES,
    Grip,
    HandModel,
    Side,
    handover_turns,
    other,
    side_direction,
    side_layer,
)
from .orientation import Orientation, direction_vector

__all__ = ["Execution", "PlanError", "TwistCheck", "carry_turn", "execute", "twist_move"]


class PlanError(ValueError):
    """A plan that breaks the model: names the action (1-based) and the broken rule."""


@dataclass(frozen=True)
class TwistCheck:
    """What the grips touched at one twist, for tests and physical comparison."""

    action: int  #: 0-based index into the plan's actions
    move: str  #: the face move applied, e.g. ``"U'"``
    axis: str
    layer: int
    rotator_slabs: frozenset[int]
    holder_slabs: frozenset[int]
    rotator_axis: str  #: the axis of the rotator's wrist (its grip is along it)
    holder_axis: str


@dataclass
class Execution:
    """The logical outcome of a plan."""

    state: np.ndarray  #: facelets in the centre frame (the exchange format's), uint8 (54,)
    orientation: Orientation  #: the cube in the workspace at the end
    orientations: list[Orientation] = field(default_factory=list)  #: after each action
    twists: list[TwistCheck] = field(default_factory=list)
    moves: list[str] = field(default_factory=list)  #: face moves applied, in order


def carry_turn(approach_direction: str, side: Side) -> tuple[str | None, int]:
    """The quarter turn that takes the face at ``approach_direction`` to the gripper's side, or (None, 0)."""
    a, s = direction_vector(approach_direction), direction_vector(side_direction(side))
    if np.array_equal(a, s):
        return None, 0
    if int(a @ s) != 0:
        raise ValueError(
            f"a gripper on the {side} cannot carry the face at {approach_direction} round to its side"
        )
    w = np.cross(a, s)  # a quarter turn about a × s takes a onto s
    (i,) = np.flatnonzero(w)
    return "xyz"[i], int(w[i])


def twist_move(orientation: Orientation, axis: str, layer: int, quarter_turns: int) -> Move:
    """The centre-named face move a twist makes: the +axis face turns clockwise for negative turns."""
    if layer not in (0, 2):
        raise ValueError(
            f"layer {layer}: two grippers can only turn an outer slab against the other two"
        )
    face = orientation.face_along(("+" if layer == 2 else "-") + axis)
    cw = (-quarter_turns) % 4 if layer == 2 else quarter_turns % 4
    if cw == 0:
        raise ValueError("a twist of a whole number of turns does nothing")
    return Move(face, cw)


def execute(
    plan: RegraspPlan, initial_state: np.ndarray = SOLVED, model: HandModel | None = None
) -> Execution:
    """Run ``plan`` from ``initial_state`` (centre frame); raises :class:`PlanError` on any broken rule."""
    model = model or plan.model
    state = np.asarray(initial_state).copy()
    orient: Orientation | None = None
    grips: dict[Side, Grip | None] = {"left": None, "right": None}
    out = Execution(state=state, orientation=plan.initial)

    def fail(k: int, why: str) -> PlanError:
        return PlanError(f"action {k + 1} ({type(plan.actions[k]).__name__}): {why}")

    def set_roles(k: int, rotator: Side, roll: int) -> None:
        if not model.roll_ok(roll):
            raise fail(
                k, f"wrist roll {roll:+d} quarter turns is outside ±{model.wrist_roll_limit}"
            )
        grips[rotator] = Grip(1, roll)
        grips[other(rotator)] = Grip(2, 0)

    for k, a in enumerate(plan.actions):
        if orient is None and not isinstance(a, Pick):
            raise fail(k, "the cube is still on the table: a plan starts with a pick")
        if isinstance(a, Pick):
            if orient is not None:
                raise fail(k, "the cube is already in hand")
            if a.approach not in model.pick_approaches:
                raise fail(k, f"approach {a.approach!r} is not available to {model.name}")
            where = PICK_APPROACHES[a.approach]
            where = side_direction(a.gripper) if where == "own" else where
            if plan.initial.face_along(where) != a.face:
                raise fail(
                    k,
                    f"the face at {where} on the table is {plan.initial.face_along(where)}, not {a.face}",
                )
            axis, q = carry_turn(where, a.gripper)
            if (axis, q) != (a.turn_axis, a.turn_quarters):
                raise fail(
                    k,
                    f"carrying {a.face} to the {a.gripper} side is a turn {axis} {q:+d}, not {a.turn_axis} {a.turn_quarters:+d}",
                )
            orient = plan.initial if axis is None else plan.initial.rotated(axis, q)
            set_roles(k, a.rotator, a.roll)
        elif isinstance(a, Twist):
            g, h = grips[a.gripper], grips[other(a.gripper)]
            if a.axis != "y":
                raise fail(k, f"twists are about the work axis y, not {a.axis}")
            if g is None or h is None:
                raise fail(k, "both hands must hold the cube")
            if a.layer != side_layer(a.gripper):
                raise fail(
                    k,
                    f"the {a.gripper} gripper can only turn slab {side_layer(a.gripper)}, not {a.layer}",
                )
            rot_slabs, hold_slabs = g.slabs(a.gripper), h.slabs(other(a.gripper))
            if rot_slabs != {a.layer}:
                raise fail(
                    k, f"the rotator touches slabs {sorted(rot_slabs)}, not just slab {a.layer}"
                )
            if hold_slabs != {0, 1, 2} - {a.layer}:
                raise fail(
                    k,
                    f"the holder touches slabs {sorted(hold_slabs)}: "
                    + ("under-constrained" if len(hold_slabs) < 2 else "over-constrained"),
                )
            new_roll = model.after_twist(g.roll, a.quarter_turns)
            if not model.roll_ok(new_roll):
                raise fail(
                    k,
                    f"the wrist would roll to {new_roll:+d} quarter turns, beyond ±{model.wrist_roll_limit}",
                )
            try:
                move = twist_move(orient, a.axis, a.layer, a.quarter_turns)
            except ValueError as e:
                raise fail(k, str(e)) from None
            if a.face and a.face != move.kind:
                raise fail(k, f"the face at that slab is {move.kind}, but the plan says {a.face}")
            state = apply(state, [move])
            grips[a.gripper] = Grip(1, new_roll)
            out.moves.append(str(move))
            out.twists.append(
                TwistCheck(k, str(move), a.axis, a.layer, rot_slabs, hold_slabs, "y", "y")
            )
        elif isinstance(a, Regrasp):
            rot = next(s for s, gr in grips.items() if gr is not None and gr.depth == 1)
            if a.kind == "shift":
                if a.gripper != other(rot):
                    raise fail(
                        k, f"a shift makes the holder ({other(rot)}) the rotator, not {a.gripper}"
                    )
            elif a.kind == "unwind":
                if a.gripper != rot:
                    raise fail(k, f"only the rotator ({rot}) unwinds")
            else:
                raise fail(k, f"unknown regrasp kind {a.kind!r}")
            set_roles(k, a.gripper, a.roll)
        elif isinstance(a, Handover):
            holder = next(s for s, gr in grips.items() if gr is not None and gr.depth == 2)
            if a.giver != holder or a.taker != other(holder):
                raise fail(k, f"the holder ({holder}) gives, the other hand takes")
            if a.axis not in ("x", "z") or a.quarter_turns not in (1, -1):
                raise fail(
                    k,
                    f"a hand-over turns the cube a quarter turn about x or z, not {a.quarter_turns:+d} about {a.axis}",
                )
            if (a.axis, a.quarter_turns) not in handover_turns(a.giver):
                raise fail(
                    k,
                    f"turning {a.quarter_turns:+d} about {a.axis} would leave the {a.giver} hand outside {GIVER_ENDS}",
                )
            orient = orient.rotated(a.axis, a.quarter_turns)
            set_roles(k, a.rotator, a.roll)
        elif isinstance(a, Release):
            if k != len(plan.actions) - 1:
                raise fail(k, "release ends the plan")
            grips = {"left": None, "right": None}
        else:  # pragma: no cover - the Action union is closed
            raise fail(k, f"unknown action {a!r}")
        out.orientations.append(orient)
    if plan.actions and not isinstance(plan.actions[-1], Release):
        raise PlanError("a plan ends with a release")
    out.state = state
    out.orientation = orient if orient is not None else plan.initial
    return out
