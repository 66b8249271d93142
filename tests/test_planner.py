"""Regrasp/twist planner (benchharness.strategies.regrasp): correctness, preconditions, optimality.

The oracle is the cube core: a plan, run by the abstract executor (which
re-derives every face from the tracked orientation), must reproduce exactly
the state ``apply(SOLVED, sequence)`` for 500 generated 20-move sequences.
"""

from __future__ import annotations

import heapq
import os
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from benchharness.cube import SOLVED, apply, generate_sequences, reorient
from benchharness.strategies.regrasp import (
    INITIAL_ORIENTATION,
    HandModel,
    Handover,
    Orientation,
    Pick,
    PlanError,
    Regrasp,
    Release,
    Twist,
    execute,
    logical_twists,
    naive_plan,
    plan_sequence,
)

MODELS = {"pr2": HandModel.pr2(), "herb": HandModel.herb()}
N_SEQUENCES = 500


@pytest.fixture(scope="module")
def sequences():
    return generate_sequences(0, "planner-test", N_SEQUENCES, 20)


@pytest.fixture(scope="module", params=sorted(MODELS))
def planned(request, sequences):
    model = MODELS[request.param]
    rows = []
    for seq in sequences:
        plan = plan_sequence(seq, model)
        rows.append((seq, plan, naive_plan(seq, model), execute(plan)))
    return model, rows


def _face_changes(seq) -> tuple[int, int]:
    """(consecutive pairs on different faces, of those the pairs on different axes)."""
    opposite = dict(zip("URFDLB", "DLBURF"))
    faces = [m.kind for m in seq]
    diff = sum(a != b for a, b in zip(faces, faces[1:]))
    axis = sum(a != b and opposite[a] != b for a, b in zip(faces, faces[1:]))
    return diff, axis


# --- the logical result -------------------------------------------------------------------------


def test_random_sequences_reproduce_the_core_state(planned):
    model, rows = planned
    for seq, _, naive, run in rows:
        want = apply(SOLVED, seq)
        assert np.array_equal(run.state, want), (model.name, seq)
        assert np.array_equal(execute(naive).state, want), (model.name, seq)


def test_every_twist_has_the_rotator_on_its_slab_and_the_holder_on_the_other_two(planned):
    _, rows = planned
    for seq, plan, _, run in rows:
        assert len(run.twists) == len(seq) == plan.twists
        for t in run.twists:
            assert t.layer in (0, 2)
            assert t.rotator_slabs == {t.layer}
            assert t.holder_slabs == {0, 1, 2} - {t.layer}
            assert t.rotator_axis == t.holder_axis == t.axis
        assert run.moves == [
            str(m) for m in seq
        ]  # each twist is the prescribed face move, in order


def test_slices_and_rotations_match_the_core_after_reorienting():
    for token in ("M", "M'", "M2", "E", "E'", "E2", "S", "S'", "S2", "x", "y'", "z2"):
        want = reorient(apply(SOLVED, token))
        twists = [t.move for alt in (logical_twists(token)[0].alternatives[0],) for t in alt]
        assert np.array_equal(apply(SOLVED, twists), want), token
        assert np.array_equal(execute(plan_sequence(token)).state, want), token
    seq = "x U M' y R S2 z' E F x2 B' M2"
    for model in MODELS.values():
        assert np.array_equal(
            execute(plan_sequence(seq, model)).state, reorient(apply(SOLVED, seq))
        )


def test_a_rotation_changes_which_face_a_letter_names():
    (twist,) = logical_twists("x U")[1].alternatives[0]
    assert (twist.face, twist.turns) == ("F", 1)  # after x the F centre is on top


# --- regrasp counts -----------------------------------------------------------------------------


def test_regrasps_meet_the_lower_bound_and_beat_naive(planned):
    """Under Fig. 2's rule one grasp can turn only one face, so every change of face costs at least one
    regrasp; the pick sets up the first move for free. The plans meet that bound exactly, and on a PR2
    hand-overs are exactly the changes of axis (the one work axis)."""
    model, rows = planned
    for seq, plan, naive, _ in rows:
        changes, axis_changes = _face_changes(seq)
        assert plan.total_regrasps == changes, seq
        if model.wrist_roll_limit is None:
            assert plan.handovers == axis_changes
        assert plan.total_regrasps <= naive.total_regrasps == len(seq)
        assert plan.cost <= naive.cost


def test_mean_regrasps_per_move_over_the_random_set(planned):
    model, rows = planned
    moves = sum(len(s) for s, *_ in rows)
    mean = sum(p.total_regrasps for _, p, *_ in rows) / moves
    naive = sum(n.total_regrasps for _, _, n, _ in rows) / moves
    handovers = sum(p.handovers for _, p, *_ in rows) / moves
    print(
        f"\n{model.name}: {mean:.4f} regrasps/move ({handovers:.4f} hand-overs), naive {naive:.4f}, "
        f"mean cost {np.mean([p.cost for _, p, *_ in rows]):.1f} vs naive {np.mean([n.cost for _, _, n, _ in rows]):.1f}"
    )
    assert mean == pytest.approx(
        19 / 20
    )  # generated sequences never repeat a face: 19 face changes
    assert naive == 1.0


@pytest.mark.parametrize(
    "moves, regrasps, handovers",
    [
        ("U U U", 0, 0),  # the rotator keeps its slab; a continuous wrist just keeps turning
        ("U", 0, 0),  # a top pick brings U onto the work axis on the way
        ("D", 0, 0),  # ... and D with it, on the other hand's side
        ("B2", 0, 0),  # a front pick brings F, so also B
        ("U D", 1, 0),  # one shift: the same two faces stay gripped, the hands swap roles
        ("U D'", 1, 0),
        ("U D U' D'", 3, 0),
        ("U R", 0, 1),  # another axis: one hand-over
        ("R L R' L'", 3, 0),
        ("M", 1, 0),  # R L': two twists on one axis
        ("R M", 1, 0),  # R R L': the search orders the slice's twists to follow R
        ("x U", 0, 0),
    ],
)
def test_hand_checked_regrasp_counts_pr2(moves, regrasps, handovers):
    plan = plan_sequence(moves, HandModel.pr2())
    assert (plan.regrasps, plan.handovers) == (regrasps, handovers), plan.describe()


def test_limited_wrist_unwinds_only_when_it_must():
    herb = HandModel.herb()  # ±1 quarter turn
    assert plan_sequence("U2", herb).total_regrasps == 0  # starts at one end of the range
    assert plan_sequence("U U", herb).total_regrasps == 0
    plan = plan_sequence("U U U", herb)
    assert (plan.regrasps, plan.handovers) == (1, 0)
    assert [a.kind for a in plan.actions if isinstance(a, Regrasp)] == ["unwind"]
    # a half turn may go either way: U2 U2 goes +180° and back instead of unwinding
    qs = [a.quarter_turns for a in plan_sequence("U2 U2", herb).actions if isinstance(a, Twist)]
    assert sorted(qs) == [-2, 2] and plan_sequence("U2 U2", herb).total_regrasps == 0


# --- optimality against an independent uniform-cost search ---------------------------------------


def _brute_force_cost(moves: str, model: HandModel) -> int:
    """Dijkstra without a heuristic over (twists done, cube orientation, rotator, roll), written here from
    the rules in docs/planner.md; slices offer both orders. Shares only the translation and geometry."""
    c = model.costs
    rolls = (
        [0]
        if model.wrist_roll_limit is None
        else list(range(-model.wrist_roll_limit, model.wrist_roll_limit + 1))
    )
    lim = model.wrist_roll_limit
    programs = [[]]
    for mt in logical_twists(moves):
        programs = [p + list(alt) for p in programs for alt in mt.alternatives]
    best = None
    for prog in programs:
        heap, seen, k = [], set(), 0
        for _g, where in [("left", "+y"), ("right", "-y")]:
            for _approach, d in (("side", where), ("top", "+z"), ("front", "-x")):
                o = INITIAL_ORIENTATION
                extra = 0
                if d != where:
                    v = np.cross(_vec(d), _vec(where))
                    (i,) = np.flatnonzero(v)
                    o, extra = o.rotated("xyz"[i], int(v[i])), c.pick_turn
                for rot in ("left", "right"):
                    for r in rolls:
                        k += 1
                        heapq.heappush(heap, (c.pick + extra, k, 0, o.matrix, rot, r))
        while heap:
            cost, _, i, m, rot, r = heapq.heappop(heap)
            if (i, m, rot, r) in seen:
                continue
            seen.add((i, m, rot, r))
            if i == len(prog):
                best = cost if best is None else min(best, cost)
                break
            o = Orientation(m)
            nxt = []
            tw = prog[i]
            where = "+y" if rot == "left" else "-y"
            if o.face_along(where) == tw.face:
                qmod = (-tw.turns) % 4 if rot == "left" else tw.turns % 4
                for q in {1: [1], 3: [-1], 2: [2, -2]}[qmod]:
                    r2 = r + q if lim is not None else 0
                    if lim is None or abs(r2) <= lim:
                        nxt.append((cost + c.twist_quarter * abs(q), i + 1, m, rot, r2))
            other = "right" if rot == "left" else "left"
            for r2 in rolls:
                nxt.append((cost + c.shift, i, m, other, r2))
                if lim is not None:
                    nxt.append((cost + c.unwind, i, m, rot, r2))
                # the holder gives; it may end on the robot's side (-x) or above (+z) only
                for axis, q in {"left": [("z", 1), ("x", 1)], "right": [("z", -1), ("x", -1)]}[
                    other
                ]:
                    if True:
                        for rot2 in ("left", "right"):
                            nxt.append((cost + c.handover, i, o.rotated(axis, q).matrix, rot2, r2))
            for item in nxt:
                k += 1
                heapq.heappush(heap, (item[0], k) + item[1:])
    return best


def _vec(d: str) -> np.ndarray:
    v = np.zeros(3, dtype=np.int64)
    v["xyz".index(d[1])] = 1 if d[0] == "+" else -1
    return v


@pytest.mark.parametrize("name", sorted(MODELS))
def test_cost_is_optimal_against_brute_force_on_short_sequences(name):
    model = MODELS[name]
    rng = np.random.default_rng(7)
    kinds = list("URFDLB") * 3 + list("MESxyz")
    for _ in range(40 if model.wrist_roll_limit is None else 15):
        n = int(rng.integers(1, 5 if model.wrist_roll_limit is None else 4))
        seq = " ".join(str(rng.choice(kinds)) + str(rng.choice(["", "'", "2"])) for _ in range(n))
        assert plan_sequence(seq, model).cost == _brute_force_cost(seq, model), seq


# --- the plan object ----------------------------------------------------------------------------


def test_plan_shape_counts_and_determinism():
    seq = "R U R' U' F2 D L' B M y S'"
    a, b = plan_sequence(seq), plan_sequence(seq)
    assert a == b
    assert isinstance(a.actions[0], Pick) and isinstance(a.actions[-1], Release)
    assert (
        a.twists == sum(isinstance(x, Twist) for x in a.actions) == 12
    )  # M and S' are two twists each
    assert a.regrasps + a.handovers == a.total_regrasps
    assert a.reclamps == 2 * a.regrasps + 2 * a.handovers


def test_plan_is_the_same_under_another_hash_seed():
    code = (
        "from benchharness.strategies.regrasp import plan_sequence;"
        "print(plan_sequence(\"R U R' U' F2 D L' B M y S'\").describe())"
    )
    outs = []
    for seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        outs.append(
            subprocess.run(
                [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
            ).stdout
        )
    assert outs[0] == outs[1] == plan_sequence("R U R' U' F2 D L' B M y S'").describe() + "\n"


def test_describe_lists_every_action_and_the_counts():
    plan = plan_sequence("U R D'")
    text = plan.describe()
    assert (
        "3 twists, 1 regrasps, 1 hand-overs" in text or "3 twists, 0 regrasps, 2 hand-overs" in text
    )
    assert text.count("twist     ") == 3
    assert "[move 3: D']" in text
    assert "release" in text.splitlines()[-1]


def test_body_frame_is_the_physical_cubes():
    from benchharness.cube_physics import model as physical
    from benchharness.strategies.regrasp import orientation

    assert np.array_equal(orientation.BODY_FROM_CORE, physical.BODY_FROM_CORE)
    for face, axis in physical.FACE_BODY_AXES.items():
        assert np.array_equal(orientation.FACE_BODY_AXES[face], axis)


def test_initial_orientation_is_u_up_f_towards_the_robot():
    o = INITIAL_ORIENTATION
    assert (o.face_along("+z"), o.face_along("-x"), o.face_along("-y"), o.face_along("+y")) == (
        "U",
        "F",
        "R",
        "L",
    )


# --- the executor refuses broken plans (so the tests above can fail) ------------------------------


def _swap(plan, index, action):
    acts = list(plan.actions)
    acts[index] = action
    return replace(plan, actions=tuple(acts))


def _first(plan, cls):
    return next(i for i, a in enumerate(plan.actions) if isinstance(a, cls))


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda p, i: _swap(p, i, replace(p.actions[i], layer=1)), "only turn slab"),
        (
            lambda p, i: _swap(
                p,
                i,
                replace(
                    p.actions[i],
                    gripper="right" if p.actions[i].gripper == "left" else "left",
                    layer=2 - p.actions[i].layer,
                ),
            ),
            "touches slabs",
        ),
        (lambda p, i: _swap(p, i, replace(p.actions[i], axis="z")), "work axis"),
        (lambda p, i: _swap(p, i, replace(p.actions[i], face="B")), "plan says"),
        (lambda p, i: replace(p, actions=p.actions[1:]), "still on the table"),
        (lambda p, i: replace(p, actions=p.actions[:-1]), "ends with a release"),
        (lambda p, i: replace(p, actions=(Release(),) + p.actions), "still on the table"),
    ],
)
def test_executor_rejects_broken_twists(mutate, message):
    plan = plan_sequence("U U R")
    with pytest.raises(PlanError, match=message):
        execute(mutate(plan, _first(plan, Twist)))


def test_a_flipped_twist_without_annotation_gives_a_different_state():
    plan = plan_sequence("U R F")
    i = _first(plan, Twist)
    bad = _swap(
        plan, i, replace(plan.actions[i], quarter_turns=-plan.actions[i].quarter_turns, face="")
    )
    assert not np.array_equal(execute(bad).state, apply(SOLVED, "U R F"))


def test_executor_rejects_bad_handovers_picks_and_wrist_overruns():
    plan = plan_sequence("U R")
    i = _first(plan, Handover)
    with pytest.raises(PlanError, match="quarter turn about x or z"):
        execute(_swap(plan, i, replace(plan.actions[i], quarter_turns=2)))
    with pytest.raises(PlanError, match="would leave the"):
        execute(
            _swap(plan, i, replace(plan.actions[i], quarter_turns=-plan.actions[i].quarter_turns))
        )
    with pytest.raises(PlanError, match="gives"):
        execute(
            _swap(
                plan,
                i,
                replace(plan.actions[i], giver=plan.actions[i].taker, taker=plan.actions[i].giver),
            )
        )
    with pytest.raises(PlanError, match="on the table is"):
        execute(_swap(plan, 0, replace(plan.actions[0], face="D")))
    herb = plan_sequence("U U", HandModel.herb())
    with pytest.raises(PlanError, match="beyond"):
        execute(
            _swap(herb, 0, replace(herb.actions[0], roll=0))
            if herb.actions[0].roll
            else _swap(
                herb,
                0,
                replace(herb.actions[0], roll=-1 if herb.actions[1].quarter_turns < 0 else 1),
            )
        )
    with pytest.raises(PlanError, match="not available"):
        execute(plan, model=HandModel(pick_approaches=("side",)))
