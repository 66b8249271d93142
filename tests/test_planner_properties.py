"""Property tests for the regrasp planner over arbitrary notation (slices and rotations included)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from benchharness.cube import ALL_MOVES, SOLVED, apply, reorient
from benchharness.strategies.regrasp import (
    HandModel,
    Handover,
    Pick,
    Regrasp,
    Release,
    Twist,
    all_orientations,
    execute,
    logical_twists,
    naive_plan,
    plan_sequence,
)

moves = st.lists(st.sampled_from([str(m) for m in ALL_MOVES]), max_size=10)
models = st.sampled_from([HandModel.pr2(), HandModel.herb()])
starts = st.sampled_from(all_orientations())


@settings(max_examples=120, deadline=None)
@given(seq=moves, model=models)
def test_plan_reproduces_the_core_state_in_the_centre_frame(seq, model):
    plan = plan_sequence(seq, model)
    want = reorient(apply(SOLVED, seq))
    assert np.array_equal(execute(plan).state, want)
    assert np.array_equal(execute(naive_plan(seq, model)).state, want)


@settings(max_examples=80, deadline=None)
@given(seq=moves, model=models, start=starts)
def test_any_table_orientation_works_and_never_costs_more_than_naive(seq, model, start):
    plan = plan_sequence(seq, model, initial=start)
    naive = naive_plan(seq, model, initial=start)
    assert np.array_equal(execute(plan).state, execute(naive).state)
    assert plan.cost <= naive.cost
    assert plan.total_regrasps <= naive.total_regrasps


@settings(max_examples=80, deadline=None)
@given(seq=moves, model=models)
def test_plan_structure_and_counts(seq, model):
    plan = plan_sequence(seq, model)
    assert isinstance(plan.actions[0], Pick) and isinstance(plan.actions[-1], Release)
    assert all(not isinstance(a, (Pick, Release)) for a in plan.actions[1:-1])
    n_twists = sum(len(mt.alternatives[0]) for mt in logical_twists(seq))
    assert plan.twists == n_twists
    assert plan.regrasps == sum(isinstance(a, Regrasp) for a in plan.actions)
    assert plan.handovers == sum(isinstance(a, Handover) for a in plan.actions)
    # every twist is an outer slab on the work axis, from the gripper's own side
    for a in plan.actions:
        if isinstance(a, Twist):
            assert a.axis == "y" and a.layer == (2 if a.gripper == "left" else 0)
            assert a.quarter_turns in (-2, -1, 1, 2)
    # sources point back at the input, in order
    sources = [a.source for a in plan.actions if isinstance(a, Twist)]
    assert sources == sorted(sources)
    assert plan == plan_sequence(seq, model)


@settings(max_examples=60, deadline=None)
@given(seq=st.lists(st.sampled_from(list("URFDLB")), min_size=1, max_size=12))
def test_one_regrasp_per_change_of_face_and_one_hand_over_per_change_of_axis(seq):
    plan = plan_sequence(seq, HandModel.pr2())
    opposite = dict(zip("URFDLB", "DLBURF"))
    pairs = list(zip(seq, seq[1:]))
    assert plan.total_regrasps == sum(a != b for a, b in pairs)
    assert plan.handovers == sum(a != b and opposite[a] != b for a, b in pairs)
