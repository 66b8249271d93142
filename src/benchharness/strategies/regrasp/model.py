"""The hands: work axis, grips, reach and costs (the abstraction the search runs on).

The model, in short (docs/planner.md has the reasoning):

* **Work axis.** Twists happen with the two hands facing each other along the
  workspace y axis, the left gripper on the +y side pointing -y, the right on
  the -y side pointing +y; both wrist-roll axes lie on that line. So the
  face pointing +y can be turned by the left hand, the face pointing -y by the
  right hand, and no other face can be turned without re-orienting the cube.
* **Grips** are along the work axis, from the gripper's own side, ``depth``
  slabs deep: 1 = the outer slab on that side only (a *rotator*), 2 = that
  slab and the middle one (a *holder*). Between actions both hands hold the
  cube, one as rotator and one as holder, so every state is ready to twist
  the rotator's face: the holder covers exactly the other two slabs
  (Yang et al., Fig. 2: neither under- nor over-constrained).
* **Wrist roll** of the rotator accumulates over twists; a hand with a
  limited wrist (HERB's WAM joint 7, ±172°) must re-clamp to unwind, a PR2
  wrist roll is continuous. Tracked in quarter turns from the neutral roll.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache
from typing import Literal

from .orientation import direction_name, direction_vector, quarter_rotation

__all__ = [
    "CostModel",
    "GIVER_ENDS",
    "GRIPPERS",
    "Grip",
    "HandModel",
    "PICK_APPROACHES",
    "Side",
    "handover_turns",
    "other",
    "side_direction",
    "side_layer",
]

Side = Literal["left", "right"]
#: The two grippers, in the order used for tie-breaking.
GRIPPERS: tuple[Side, ...] = ("left", "right")

#: Where a picking gripper may approach the cube on the table: its own side, from above, or from the
#: robot's side of the cube. Never from below (the table), the far side, or the other hand's side.
PICK_APPROACHES: dict[str, str] = {"side": "own", "top": "+z", "front": "-x"}


#: Where the giving hand may be after turning the cube in a hand-over: on the robot's side of the cube
#: (pointing forward) or above it (pointing down) — not below it or reaching round its far side.
GIVER_ENDS: tuple[str, ...] = ("-x", "+z")


@cache
def handover_turns(giver: Side) -> tuple[tuple[str, int], ...]:
    """The quarter turns (workspace axis, ±1) a giver on its side can give the cube: x or z, ending in :data:`GIVER_ENDS`.

    Each giver has two, and between them they bring every face off the work
    axis onto it, so the restriction costs nothing but fixes on which side a
    face lands.
    """
    out = []
    for axis in ("z", "x"):
        for q in (1, -1):
            if (
                direction_name(quarter_rotation(axis, q) @ direction_vector(side_direction(giver)))
                in GIVER_ENDS
            ):
                out.append((axis, q))
    return tuple(out)


def other(side: Side) -> Side:
    return "right" if side == "left" else "left"


def side_direction(side: Side) -> str:
    """The workspace direction from the cube towards the gripper: the face there is the one it grips."""
    return "+y" if side == "left" else "-y"


def side_layer(side: Side) -> int:
    """Slab index along the work axis of the outer slab on the gripper's side (0 = -y, 2 = +y)."""
    return 2 if side == "left" else 0


@dataclass(frozen=True)
class Grip:
    """One gripper's hold along the work axis, from its own side."""

    depth: int  #: slabs covered from the gripper's side: 1 rotator, 2 holder (3 would jam a twist)
    roll: int = 0  #: wrist roll in quarter turns from neutral (0 when the wrist is continuous)

    def slabs(self, side: Side) -> frozenset[int]:
        """Slab indices along the work axis this grip touches (0 on the -y side, 2 on +y)."""
        return (
            frozenset(range(3 - self.depth, 3)) if side == "left" else frozenset(range(self.depth))
        )


@dataclass(frozen=True)
class CostModel:
    """Integer cost units (roughly seconds of robot time): exact ties, deterministic search.

    The defaults are for a PR2: a twist is a wrist roll (fast); a *shift* is
    two re-clamps without moving the arms much; a *hand-over* is a release, an
    arm motion that turns the cube a quarter turn, a grasp by the other hand
    and a re-clamp — the expensive part of the baselines' state machine.
    """

    pick: int = 10  #: grasp on the table, lift, second hand grasps (paid once)
    pick_turn: int = 2  #: extra when the pick turns the cube during the carry (top/front approach)
    twist_quarter: int = 2  #: per quarter turn of the rotator's wrist
    shift: int = 6  #: the hands swap roles along the work axis
    unwind: int = 3  #: the rotator lets go, rolls back and re-clamps
    handover: int = 12  #: re-orientation by hand-over

    def __post_init__(self) -> None:
        for name, v in vars(self).items():
            if not isinstance(v, int) or v < 0:
                raise ValueError(f"cost {name} must be a non-negative integer, got {v!r}")


@dataclass(frozen=True)
class HandModel:
    """A robot's two hands for the planner: costs and wrist range."""

    name: str = "generic"
    costs: CostModel = field(default_factory=CostModel)
    #: Quarter turns the rotator's wrist may be from neutral, either way; ``None`` = continuous.
    wrist_roll_limit: int | None = None
    #: Pick approaches this robot may use (keys of :data:`PICK_APPROACHES`).
    pick_approaches: tuple[str, ...] = ("side", "top", "front")

    def __post_init__(self) -> None:
        if self.wrist_roll_limit is not None and self.wrist_roll_limit < 1:
            raise ValueError("a wrist that cannot roll a quarter turn cannot twist the cube")
        bad = [a for a in self.pick_approaches if a not in PICK_APPROACHES]
        if bad or not self.pick_approaches:
            raise ValueError(
                f"pick approaches must be among {sorted(PICK_APPROACHES)}, got {self.pick_approaches!r}"
            )

    @property
    def rolls(self) -> tuple[int, ...]:
        """Wrist rolls a fresh grip may start at (just 0 when the roll is not tracked)."""
        if self.wrist_roll_limit is None:
            return (0,)
        lim = self.wrist_roll_limit
        return tuple(sorted(range(-lim, lim + 1), key=lambda r: (abs(r), r)))

    def roll_ok(self, roll: int) -> bool:
        return self.wrist_roll_limit is None or abs(roll) <= self.wrist_roll_limit

    def after_twist(self, roll: int, quarter_turns: int) -> int:
        return 0 if self.wrist_roll_limit is None else roll + quarter_turns

    @classmethod
    def pr2(cls) -> HandModel:
        """PR2: parallel grippers, continuous wrist roll (``{l,r}_wrist_roll_joint``)."""
        return cls(name="pr2")

    @classmethod
    def herb(cls) -> HandModel:
        """HERB: BarrettHands on WAM arms; joint 7 ranges ±172°, so ±1 quarter turn from neutral.

        Every re-clamp is a push-grasp (Yang et al., Sec. IV-D): the hand
        approaches perpendicular to the face and pushes until the palm
        touches, which costs more than a PR2 re-clamp.
        """
        return cls(
            name="herb",
            costs=CostModel(pick=14, pick_turn=3, twist_quarter=2, shift=10, unwind=5, handover=16),
            wrist_roll_limit=1,
        )
