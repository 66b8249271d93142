"""The plan's vocabulary: typed actions and the plan with its counts and text rendering.

Actions are in workspace terms (which gripper, which workspace axis, which
slab along it, signed quarter turns about the +axis) because that is what a
physical strategy executes; the logical face a twist turns is stored only as
an annotation, which the abstract executor re-derives from the tracked
orientation and checks.
"""

from __future__ import annotations

from dataclasses import dataclass

from .model import HandModel, Side
from .orientation import Orientation

__all__ = ["Action", "Handover", "Pick", "RegraspPlan", "Regrasp", "Release", "Twist"]


@dataclass(frozen=True)
class Pick:
    """Grasp the cube on the table and bring it between the hands; the other hand then grasps too.

    ``gripper`` approaches from ``approach`` (its own side, the top, or the
    robot's side of the cube) and grips ``face``; during the carry it turns
    the cube by ``turn_quarters`` about workspace ``turn_axis`` so that
    ``face`` points at it along the work axis. ``rotator`` is the hand left
    gripping one slab; the other grips two.
    """

    gripper: Side
    face: str
    approach: str  #: "side" | "top" | "front"
    turn_axis: str | None
    turn_quarters: int
    rotator: Side
    roll: int = 0  #: the rotator's starting wrist roll (quarter turns)


@dataclass(frozen=True)
class Twist:
    """The rotator turns its slab; the holder keeps the other two still.

    ``quarter_turns`` is signed, right-handed about the workspace +``axis``.
    ``face`` (the centre-named face turned) and ``source`` (index of the input
    move) are annotations for reading and checking.
    """

    gripper: Side
    axis: str
    layer: (
        int  #: slab along ``axis``: 0 on the - side, 2 on the + side (1, a slice, is never planned)
    )
    quarter_turns: int
    face: str = ""
    source: int = -1


@dataclass(frozen=True)
class Regrasp:
    """A re-clamp that keeps the cube's orientation.

    * ``shift``: the rotator slides in to two slabs, then the holder slides
      out to one: the hands swap roles and the face on the other side of the
      work axis becomes turnable (two re-clamps, the cube always held);
    * ``unwind``: the rotator lets go of its slab, rolls its wrist back and
      re-clamps (one re-clamp; only for wrists with a limited range).

    ``gripper`` is the rotator afterwards and ``roll`` its wrist roll.
    """

    kind: str  #: "shift" | "unwind"
    gripper: Side
    roll: int = 0


@dataclass(frozen=True)
class Handover:
    """Re-orient the cube so another pair of faces lies on the work axis.

    The rotator lets go; the ``giver`` (the holder) turns the cube by
    ``quarter_turns`` about workspace ``axis`` (x or z) with its arm; the
    ``taker`` grasps the face now on its side, the giver lets go and re-grasps
    the opposite face from its own side. ``rotator`` is the hand gripping one
    slab afterwards.
    """

    giver: Side
    taker: Side
    axis: str
    quarter_turns: int
    rotator: Side
    roll: int = 0


@dataclass(frozen=True)
class Release:
    """Terminate: both hands open (the protocol's "robot terminates manipulation")."""


Action = Pick | Twist | Regrasp | Handover | Release


@dataclass(frozen=True)
class RegraspPlan:
    """An action list for one move sequence, with the model it was made for and its cost."""

    moves: tuple[str, ...]  #: the input moves, as tokens
    actions: tuple[Action, ...]
    model: HandModel
    cost: int
    initial: Orientation  #: the cube's orientation on the table
    planner: str = "optimal"

    @property
    def twists(self) -> int:
        return sum(isinstance(a, Twist) for a in self.actions)

    @property
    def regrasps(self) -> int:
        """Re-clamps that keep the orientation (shifts and unwinds)."""
        return sum(isinstance(a, Regrasp) for a in self.actions)

    @property
    def handovers(self) -> int:
        return sum(isinstance(a, Handover) for a in self.actions)

    @property
    def total_regrasps(self) -> int:
        """Every grasp change between two twists: the figure the search minimises (weighted by cost)."""
        return self.regrasps + self.handovers

    @property
    def reclamps(self) -> int:
        """Finger close-on-cube events after the pick: shift 2, unwind 1, hand-over 2 (for timing models)."""
        n = 0
        for a in self.actions:
            if isinstance(a, Regrasp):
                n += 2 if a.kind == "shift" else 1
            elif isinstance(a, Handover):
                n += 2
        return n

    def describe(self) -> str:
        """A short text rendering: one line per action, then the counts."""
        from .executor import PlanError, execute  # local: the executor imports this module

        try:
            trace: list = execute(self).orientations
            problem = ""
        except PlanError as e:  # still render a broken plan, so it can be read and debugged
            trace, problem = [], f"   INVALID: {e}"
        trace += [None] * (len(self.actions) - len(trace))
        lines = [
            f"{self.planner} plan for {len(self.moves)} moves on {self.model.name}: "
            f"{self.twists} twists, {self.regrasps} regrasps, {self.handovers} hand-overs, cost {self.cost}",
            f"   table: {self.initial}",
        ]
        for k, (a, o) in enumerate(zip(self.actions, trace), start=1):
            lines.append(f"{k:3d}. {_describe(a, self.moves)}")
            if isinstance(a, (Pick, Handover)) and o is not None:
                lines.append(f"       now  {o}")
        if problem:
            lines.append(problem)
        return "\n".join(lines)


def _turns(q: int) -> str:
    return f"{90 * q:+d}°"


def _describe(a: Action, moves: tuple[str, ...]) -> str:
    if isinstance(a, Pick):
        turn = f", turning it {_turns(a.turn_quarters)} about {a.turn_axis}" if a.turn_axis else ""
        roll = f", roll {a.roll:+d}" if a.roll else ""
        return f"pick      {a.gripper} grips {a.face} ({a.approach} approach){turn}; rotator {a.rotator}{roll}"
    if isinstance(a, Twist):
        src = f"  [move {a.source + 1}: {moves[a.source]}]" if 0 <= a.source < len(moves) else ""
        return f"twist     {a.gripper} turns {a.face} (layer {a.layer} on {a.axis}) {_turns(a.quarter_turns)}{src}"
    if isinstance(a, Regrasp):
        if a.kind == "unwind":
            return f"regrasp   unwind: {a.gripper} re-clamps its slab at roll {a.roll:+d}"
        roll = f", roll {a.roll:+d}" if a.roll else ""
        return f"regrasp   shift: the hands swap roles, rotator now {a.gripper}{roll}"
    if isinstance(a, Handover):
        return (
            f"handover  {a.giver} turns the cube {_turns(a.quarter_turns)} about {a.axis}, "
            f"{a.taker} takes it; rotator {a.rotator}"
        )
    return "release   both hands open"
