"""The search: the cheapest action list for a whole sequence (A*), and the naive baseline.

The state between actions is small — the cube's orientation (24), which hand
is the rotator (2) and, for a limited wrist, the rotator's roll — so the
search runs over (position in the twist program, state) for the entire
sequence at once rather than greedily move by move. A greedy planner would
choose, say, which hand ends a hand-over as rotator without looking at the
next move; the search does.

The heuristic is a lower bound that only counts what the faces force: a
twist of another face on the same axis needs at least a shift (or a
hand-over), of a face on another axis at least a hand-over. It is
consistent, so the first time the goal is popped the plan is optimal for the
:class:`~.model.CostModel`. Ties are broken by a fixed expansion order
(twist, shift, unwind, hand-over; left before right; roll 0, -1, +1), so the
same input always gives the same plan.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable
from dataclasses import dataclass
from functools import lru_cache

from ...cube import Move
from .actions import Action, Handover, Pick, Regrasp, RegraspPlan, Release, Twist
from .executor import carry_turn
from .model import (
    GRIPPERS,
    PICK_APPROACHES,
    HandModel,
    Side,
    handover_turns,
    other,
    side_direction,
    side_layer,
)
from .orientation import INITIAL_ORIENTATION, Orientation, all_orientations
from .translate import FaceTwist, MoveTwists, logical_twists

__all__ = ["RegraspNoPlanError", "naive_plan", "plan_sequence"]

_SIDES: tuple[Side, ...] = GRIPPERS
_HANDOVER_TURNS: tuple[tuple[str, int], ...] = (("z", 1), ("z", -1), ("x", 1), ("x", -1))
_END = -1


class RegraspNoPlanError(RuntimeError):
    """The model admits no plan (cannot happen with the built-in models; guards custom ones)."""


@lru_cache(maxsize=1)
def _tables() -> tuple[
    dict[Orientation, int], list[dict[str, str]], list[dict[tuple[str, int], int]]
]:
    """Orientation index, the faces on the work axis, and every hand-over turn, per orientation."""
    orients = all_orientations()
    index = {o: i for i, o in enumerate(orients)}
    faces = [{d: o.face_along(d) for d in ("+y", "-y")} for o in orients]
    turns = [{t: index[o.rotated(*t)] for t in _HANDOVER_TURNS} for o in orients]
    return index, faces, turns


@dataclass(frozen=True)
class _Program:
    """The twists to make, as positions; alternatives (slice orders) branch at move boundaries."""

    twists: tuple[FaceTwist, ...]  #: twist at each position
    successors: tuple[
        tuple[int, ...], ...
    ]  #: positions after twisting at each position (_END = done)
    starts: tuple[int, ...]

    @classmethod
    def build(cls, moves: tuple[MoveTwists, ...]) -> _Program:
        groups = [m.alternatives for m in moves if any(m.alternatives)]
        twists: list[FaceTwist] = []
        firsts: list[list[int]] = []  # per group: first position of each alternative
        lasts: list[list[int]] = []
        for alts in groups:
            firsts.append([])
            lasts.append([])
            for alt in alts:
                firsts[-1].append(len(twists))
                twists.extend(alt)
                lasts[-1].append(len(twists) - 1)
        succ: list[tuple[int, ...]] = [()] * len(twists)
        for g in range(len(groups)):
            nxt = tuple(firsts[g + 1]) if g + 1 < len(groups) else (_END,)
            for first, last in zip(firsts[g], lasts[g]):
                for p in range(first, last):
                    succ[p] = (p + 1,)
                succ[last] = nxt
        starts = tuple(firsts[0]) if groups else (_END,)
        return cls(tuple(twists), tuple(succ), starts)


def _quarter_choices(turns: int, layer: int) -> tuple[int, ...]:
    """Signed wrist quarter turns (about +y) that turn the face ``turns`` clockwise quarters."""
    q = (-turns) % 4 if layer == 2 else turns % 4
    return {1: (1,), 3: (-1,), 2: (2, -2)}[q]


def _lower_bounds(prog: _Program, model: HandModel) -> list[int]:
    c = model.costs
    step = min(c.shift, c.handover)

    def pair(a: FaceTwist, b: FaceTwist) -> int:
        if a.face == b.face:
            return 0
        return step if b.face in a.axis_faces else c.handover

    h = [0] * len(prog.twists)
    for p in range(len(prog.twists) - 1, -1, -1):
        tw = prog.twists[p]
        own = c.twist_quarter * (2 if tw.turns == 2 else 1)
        h[p] = own + min(
            0 if s == _END else pair(tw, prog.twists[s]) + h[s] for s in prog.successors[p]
        )
    return h


def plan_sequence(
    moves: str | Iterable[Move | str],
    model: HandModel | None = None,
    initial: Orientation = INITIAL_ORIENTATION,
) -> RegraspPlan:
    """The cheapest plan for ``moves`` under ``model`` (A* over the whole sequence; deterministic)."""
    model = model or HandModel.pr2()
    mts = logical_twists(moves)
    prog = _Program.build(mts)
    index, faces, turns = _tables()
    costs, rolls = model.costs, model.rolls
    hpos = _lower_bounds(prog, model)
    step = min(costs.shift, costs.handover)

    def h(pos: int, o: int, s: int) -> int:
        if pos == _END:
            return 0
        f = prog.twists[pos].face
        fs = faces[o]
        own = fs[side_direction(_SIDES[s])]
        need = 0 if own == f else step if fs[side_direction(_SIDES[1 - s])] == f else costs.handover
        return need + hpos[pos]

    Node = tuple  # (pos, orientation index, rotator side index, roll)
    best: dict[Node, int] = {}
    pred: dict[Node, tuple[Node | None, tuple]] = {}
    heap: list[tuple[int, int, int, Node]] = []
    counter = 0

    def push(node: Node, cost: int, parent: Node | None, action: tuple) -> None:
        # ``action`` is (class, args): built into a dataclass only for the plan that wins.
        nonlocal counter
        old = best.get(node)
        if old is not None and old <= cost:
            return
        best[node] = cost
        pred[node] = (parent, action)
        counter += 1
        hn = h(node[0], node[1], node[2])
        # Among equal f, prefer the node nearer the goal (smaller h): A* then runs down one optimal
        # path instead of widening over every tie; still deterministic.
        heapq.heappush(heap, (cost + hn, hn, counter, node))

    for g in _SIDES:
        for approach in model.pick_approaches:
            where = PICK_APPROACHES[approach]
            where = side_direction(g) if where == "own" else where
            axis, q = carry_turn(where, g)
            o = initial if axis is None else initial.rotated(axis, q)
            cost = costs.pick + (costs.pick_turn if axis else 0)
            for s in range(2):
                for r in rolls:
                    pick = (Pick, (g, initial.face_along(where), approach, axis, q, _SIDES[s], r))
                    for pos in prog.starts:
                        push((pos, index[o], s, r), cost, None, pick)

    done: set[Node] = set()
    goal: Node | None = None
    while heap:
        *_, node = heapq.heappop(heap)
        if node in done:
            continue
        done.add(node)
        pos, o, s, r = node
        g_cost = best[node]
        if pos == _END:
            goal = node
            break
        tw = prog.twists[pos]
        side = _SIDES[s]
        # twist
        if faces[o][side_direction(side)] == tw.face:
            layer = side_layer(side)
            for q in _quarter_choices(tw.turns, layer):
                r2 = model.after_twist(r, q)
                if model.roll_ok(r2):
                    act = (Twist, (side, "y", layer, q, tw.face, tw.source))
                    for nxt in prog.successors[pos]:
                        push((nxt, o, s, r2), g_cost + costs.twist_quarter * abs(q), node, act)
        # shift: the holder becomes the rotator
        for r2 in rolls:
            push(
                (pos, o, 1 - s, r2),
                g_cost + costs.shift,
                node,
                (Regrasp, ("shift", _SIDES[1 - s], r2)),
            )
        # unwind
        if model.wrist_roll_limit is not None:
            for r2 in rolls:
                if r2 != r:
                    push(
                        (pos, o, s, r2),
                        g_cost + costs.unwind,
                        node,
                        (Regrasp, ("unwind", side, r2)),
                    )
        # hand-over: the holder gives, turning the cube a quarter turn about x or z (model.handover_turns)
        for t in handover_turns(other(side)):
            o2 = turns[o][t]
            for s2 in range(2):
                for r2 in rolls:
                    act = (Handover, (other(side), side, t[0], t[1], _SIDES[s2], r2))
                    push((pos, o2, s2, r2), g_cost + costs.handover, node, act)
    if goal is None:
        raise RegraspNoPlanError(f"no plan for {[m.token for m in mts]} under {model.name}")
    actions: list[Action] = [Release()]
    cur: Node | None = goal
    while cur is not None:
        parent, (cls, args) = pred[cur]
        actions.append(cls(*args))
        cur = parent
    actions.reverse()
    return RegraspPlan(
        tuple(m.token for m in mts), tuple(actions), model, best[goal], initial, "optimal"
    )


def _start_roll(q: int, model: HandModel) -> int:
    """A starting roll from which the wrist can turn ``q`` quarters, as near neutral as possible."""
    if model.wrist_roll_limit is None:
        return 0
    lim = model.wrist_roll_limit
    return min((r for r in model.rolls if abs(r + q) <= lim), key=lambda r: (abs(r), r))


def naive_plan(
    moves: str | Iterable[Move | str],
    model: HandModel | None = None,
    initial: Orientation = INITIAL_ORIENTATION,
) -> RegraspPlan:
    """The baseline: one regrasp before every twist, without looking ahead.

    Pick from the left side (no carry turn), the right hand rotator; before
    each twist, an unwind if the face is already the rotator's, a shift if it
    is the holder's, else the first hand-over (in a fixed order) that brings
    it to a hand. The first slice order is always used.
    """
    model = model or HandModel.pr2()
    mts = logical_twists(moves)
    c = model.costs
    o = initial
    rotator: Side = "right"
    actions: list[Action] = [Pick("left", initial.face_along("+y"), "side", None, 0, rotator, 0)]
    cost = c.pick
    for mt in mts:
        for tw in mt.alternatives[0]:
            if o.face_along(side_direction(rotator)) == tw.face:
                q = _quarter_choices(tw.turns, side_layer(rotator))[0]
                actions.append(Regrasp("unwind", rotator, _start_roll(q, model)))
                cost += c.unwind
            elif o.face_along(side_direction(other(rotator))) == tw.face:
                rotator = other(rotator)
                q = _quarter_choices(tw.turns, side_layer(rotator))[0]
                actions.append(Regrasp("shift", rotator, _start_roll(q, model)))
                cost += c.shift
            else:
                for t in handover_turns(other(rotator)):
                    o2 = o.rotated(*t)
                    hit = [s for s in _SIDES if o2.face_along(side_direction(s)) == tw.face]
                    if hit:
                        giver = other(rotator)
                        o, rotator = o2, hit[0]
                        q = _quarter_choices(tw.turns, side_layer(rotator))[0]
                        actions.append(
                            Handover(
                                giver, other(giver), t[0], t[1], rotator, _start_roll(q, model)
                            )
                        )
                        cost += c.handover
                        break
            q = _quarter_choices(tw.turns, side_layer(rotator))[0]
            actions.append(Twist(rotator, "y", side_layer(rotator), q, tw.face, tw.source))
            cost += c.twist_quarter * abs(q)
    actions.append(Release())
    return RegraspPlan(tuple(m.token for m in mts), tuple(actions), model, cost, initial, "naive")
