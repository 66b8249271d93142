"""The in-grasp planner's hand-object collision term (strategies/ingrasp/collision.py).

Checked against independent answers: the box signed distance against trimesh's exact
point-to-mesh distance, every link frame against pytorch-kinematics' generic chain walk, the
active-set distances and their Jacobian against the all-samples minimum, and the scene at the
initial grasp against the set-up placement's own clearance.
"""

from __future__ import annotations

import numpy as np
import pytest
import torch
from ingrasp_helpers import trial_context

from benchharness.strategies.ingrasp.collision import box_signed_distance, collision_scene
from benchharness.strategies.ingrasp.config import IngraspConfig
from benchharness.strategies.ingrasp.hand import (
    DTYPE,
    FINGERS,
    TIP_LINKS,
    HandKinematics,
    joint_indices,
)
from benchharness.strategies.ingrasp.placement import object_surface_arrays
from benchharness.strategies.ingrasp.planner import _Cost, plan
from benchharness.strategies.ingrasp.problem import problem_from_task
from benchharness.strategies.ingrasp.tasks import published_tasks


@pytest.fixture(scope="module")
def hand():
    return HandKinematics()


@pytest.fixture(scope="module")
def apple(hand):
    """apple-06 with our apple where a simulated trial's set-up puts it (PyBullet friction)."""
    from benchharness.objects import load_object
    from benchharness.plugin import get_manager
    from benchharness.strategies.ingrasp.execution import InGraspExecutor

    task = next(t for t in published_tasks() if t.task_id == "apple-06")
    prob = problem_from_task(task, hand)
    be = get_manager().create("backend", "pybullet")
    try:
        ctx = trial_context(task, be)
        q_touch, place, _ = InGraspExecutor(hand).nominal_setup(be, ctx.robot, prob, "apple")
    finally:
        be.close()
    return prob, object_surface_arrays(load_object("apple"))[0], place, q_touch


def test_box_signed_distance_matches_trimesh():
    trimesh = pytest.importorskip("trimesh")
    half = np.array([0.01, 0.014, 0.027])
    box = trimesh.creation.box(extents=2 * half)
    pts = np.random.default_rng(3).uniform(-0.04, 0.04, (400, 3))
    ours = box_signed_distance(torch.as_tensor(pts), torch.as_tensor(half)).numpy()
    theirs = -trimesh.proximity.signed_distance(box, pts)  # trimesh: positive inside
    assert np.abs(ours - theirs).max() < 1e-8
    assert (ours < 0).sum() > 5 and (ours > 0).sum() > 300  # both sides were measured


def test_link_poses_match_pytorch_kinematics(hand):
    fingers = ("index", "middle", "thumb")
    lo, hi = hand.limits(fingers)
    q = torch.as_tensor(np.random.default_rng(0).uniform(lo, hi, (3, 12)), dtype=DTYPE)
    ours = hand.link_poses(q, fingers)
    for i, f in enumerate(fingers):
        fk = hand.chains[f].forward_kinematics(q[:, 4 * i : 4 * i + 4], end_only=False)
        base = 4 * FINGERS.index(f)
        for j, name in enumerate([*(f"link_{base + j}" for j in range(4)), TIP_LINKS[f]]):
            assert torch.allclose(ours[:, i, j], fk[name].get_matrix(), atol=1e-12), name
    assert torch.equal(ours[:, :, 4], hand.tip_poses(q, fingers))


def test_scene_at_the_initial_grasp_keeps_the_placement_clearance(hand, apple):
    prob, v, place, q_touch = apple
    scene = collision_scene(hand, prob, v, place.pose, q_touch=q_touch, max_points=len(v))
    assert set(TIP_LINKS[f] for f in prob.fingers).isdisjoint(scene.names)
    assert "palm_link" in scene.names and "link_11_tip" in scene.names  # the unused ring tip
    with torch.no_grad():
        links = scene.hand_links(hand, torch.as_tensor(prob.q0[None], dtype=DTYPE))
        d = scene.distances(links, torch.as_tensor(prob.object_initial[None], dtype=DTYPE))[0]
    # the plan's first row is the set-point q_0; the hand stands at q_touch, where the set-up
    # keeps every other part 1 mm off the object (vertices against shapes, as here: penetration
    # is what is left inside that clearance); each shape is allowed what it has there
    np.testing.assert_allclose(
        scene.joint_offset.numpy(), prob.q0 - q_touch[joint_indices(prob.fingers)]
    )
    assert float(d.min()) >= 0.001 - place.penetration - 1e-6
    assert torch.allclose(scene.allowed, torch.clamp(d, max=0.001))


def test_active_set_gives_the_minimum_and_its_jacobian(hand, apple):
    prob, v, place, q_touch = apple
    scene = collision_scene(hand, prob, v, place.pose, q_touch=q_touch)
    cost = _Cost(hand, prob, "relaxed-rigidity", IngraspConfig(w_collision=1.0e6), scene)
    rng = np.random.default_rng(1)
    q = torch.as_tensor(prob.q0[None] + rng.normal(0, 0.05, (4, 12)), dtype=DTYPE)
    full = cost.residuals(q)
    at = cost.residuals_at(q)
    assert torch.allclose(at(q), full, atol=1e-15)
    assert float(full.abs().max()) > 0  # the perturbed fingers do come near the apple
    j_full = torch.func.jacfwd(cost.residuals)(q)
    j_at = torch.func.jacfwd(at)(q)
    assert torch.allclose(j_at, j_full, atol=1e-9)


def test_plan_keeps_the_hand_off_the_object(hand, apple):
    prob, v, place, q_touch = apple
    scene = collision_scene(hand, prob, v, place.pose, q_touch=q_touch)
    on = IngraspConfig(w_collision=1.0e6)
    free = plan(hand, prob, "relaxed-rigidity", scene=scene)  # default: the term is off
    kept = plan(hand, prob, "relaxed-rigidity", on, scene=scene)
    assert free.collision_shortfall is None
    np.testing.assert_array_equal(free.q, plan(hand, prob, "relaxed-rigidity").q)
    # the kinematic plan reaches the goal by carrying the apple ~1 cm into the middle finger's
    # proximal phalanx (measured: 10.8 mm, docs/ingrasp.md "Collision term")
    assert _Cost(hand, prob, "relaxed-rigidity", on, scene).collision_shortfall(free.q[1:]) > 0.008
    assert free.pos_error < 1e-4
    # with the term the hand stays off it (to within a fifth of the 1 mm margin), and the plan
    # stops short of that goal instead
    assert kept.collision_shortfall < 0.0002
    assert kept.pos_error > 0.01


@pytest.mark.sim
def test_a_trial_plans_around_the_hand_when_asked(hand):
    """``--strategy-option w_collision=1e6``: the trial's plan is made with the object where its
    set-up puts it and records how far it stays off the hand; the default records nothing."""
    from benchharness.plugin import get_manager
    from benchharness.strategies.ingrasp.execution import ExecConfig
    from benchharness.strategies.ingrasp.strategy import InGraspPlanner

    task = next(t for t in published_tasks() if t.task_id == "apple-06")
    extras = []
    for opts in ({}, {"w_collision": 1.0e6}):
        be = get_manager().create("backend", "pybullet")
        try:
            planner = InGraspPlanner("relaxed-rigidity", exec_config=ExecConfig(hold_s=0.5), **opts)
            out = planner.run_trial(trial_context(task, be))
        finally:
            be.close()
        assert out.failure is None, out.message
        extras.append(out.extra)
    assert "plan_collision_shortfall_mm" not in extras[0]
    assert extras[1]["plan_collision_shortfall_mm"] < 0.2
    # held back from the goal it could only reach through the hand (test above: 10.8 mm deep)
    assert extras[1]["plan_pos_error_cm"] > 1.0 > extras[0]["plan_pos_error_cm"]


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("w_collision", -1.0, "w_collision must be >= 0, not -1.0"),
        ("collision_margin", -0.001, "collision_margin must be >= 0, not -0.001"),
        ("collision_points", 0, "collision_points must be >= 1, not 0"),
    ],
)
def test_collision_settings_are_validated(field, value, message):
    with pytest.raises(ValueError, match=message):
        IngraspConfig(**{field: value})
