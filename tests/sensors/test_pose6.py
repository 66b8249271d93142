"""The 6-DOF cube filter (sensors.pose6) and edge finding (sensors.sweep) on synthetic sweeps: no engine.

Ranges come from the analytic box at a known true pose plus the ToF noise, so
the filter's answer can be checked against an independent least-squares
solution of the same MAP objective (scipy, numeric Jacobians), its analytic
Jacobians against finite differences, and its covariance against the errors
it actually makes.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

pytest.importorskip("filterpy")

from benchharness.geometry import Pose
from benchharness.sensors import (
    POSE6_AXES,
    CubePose6Filter,
    PoseEstimate,
    SweepConfig,
    ToFConfig,
    find_edges,
    ray_box,
)
from benchharness.sensors.pose6 import compose, edge_model, left_jacobian, range_model
from benchharness.sensors.sweep import EdgeObservation

HALF = 0.0285
PRIOR_STD = np.array([0.006, 0.006, 0.006, *np.radians([2.0, 2.0, 3.0])])
#: a held cube: F facing the robot, tilted a little about every axis
TRUTH = Pose.from_rotation(
    [0.6, 0.0, 0.6],
    Rotation.from_rotvec([0.02, -0.03, 0.04]) * Rotation.from_euler("z", -90, degrees=True),
)


def _sweeps(truth: Pose, belief: Pose, rng: np.random.Generator, tof: ToFConfig, sw: SweepConfig):
    """The PR2's three sweeps across the +y face (beam along -y), planned from ``belief``, read at ``truth``."""
    a = np.array([0.0, -1.0, 0.0])
    base = belief.p + np.array([0.0, HALF + sw.standoff, 0.0])
    far, low, vo = HALF + sw.overshoot, HALF - sw.face_depth, sw.vertical_offset
    lines = [((-far, 0.0), (far, 0.0)), ((vo, low), (vo, far)), ((-vo, far), (-vo, low))]
    o_all, d_all, z_all, edges = [], [], [], []
    for (s0, v0), (s1, v1) in lines:
        start, end = base + [s0, 0.0, v0], base + [s1, 0.0, v1]
        n = int(np.linalg.norm(end - start) / sw.spacing) + 1
        o = start + (end - start) * np.linspace(0.0, 1.0, n)[:, None]
        d = np.tile(a, (n, 1))
        hits = ray_box(o, d, truth.p, truth.rotation.as_matrix(), HALF)
        noise = rng.standard_normal(n)
        z = np.where(hits.hit, hits.distance + noise * (tof.noise_std + tof.noise_std_per_m * np.where(hits.hit, hits.distance, 0.0)), np.inf)  # fmt: skip
        o_all.append(o)
        d_all.append(d)
        z_all.append(z)
        edges += find_edges(o, d, z, config=sw, tof=tof)
    return np.concatenate(o_all), np.concatenate(d_all), np.concatenate(z_all), edges


def _err(pose: Pose, truth: Pose) -> np.ndarray:
    return np.r_[pose.p - truth.p, (pose.rotation * truth.rotation.inv()).as_rotvec()]


def test_edges_of_a_sweep_lie_on_the_true_box_within_their_noise():
    rng = np.random.default_rng(3)
    tof, sw = ToFConfig(), SweepConfig()
    _, _, _, edges = _sweeps(TRUTH, TRUTH, rng, tof, sw)
    assert len(edges) == 4  # both side edges, the top edge twice
    for e in edges:
        h, _, var = edge_model(TRUTH, HALF, e)
        assert abs(h) < 4 * np.sqrt(var), (h, np.sqrt(var))


def test_jacobians_match_finite_differences():
    rng = np.random.default_rng(0)
    o, d, z, edges = _sweeps(TRUTH, TRUTH, rng, ToFConfig(), SweepConfig())
    x0 = np.array([0.001, -0.002, 0.0015, 0.01, -0.02, 0.015])
    pose = compose(TRUTH, x0)
    hit, rng0, jac, cos_inc, edge_d = range_model(pose, HALF, o, d)
    jl = left_jacobian(
        x0[3:]
    )  # the models' rotation columns are for a turn on the left of ``pose``
    jac = np.c_[jac[:, :3], jac[:, 3:] @ jl]
    ok = hit & (edge_d > 0.003)
    eps = 1e-7
    for k in range(6):
        dx = np.zeros(6)
        dx[k] = eps
        # the error state composes on the left of the nominal: perturb x, not the pose
        _, r1, *_ = range_model(compose(TRUTH, x0 + dx), HALF, o, d)
        np.testing.assert_allclose((r1[ok] - rng0[ok]) / eps, jac[ok, k], rtol=1e-4, atol=1e-6)
        for e in edges:
            h0, j0, _ = edge_model(pose, HALF, e)
            j0 = np.r_[j0[:3], j0[3:] @ jl]
            h1, _, _ = edge_model(compose(TRUTH, x0 + dx), HALF, e)
            assert abs((h1 - h0) / eps - j0[k]) < 1e-5, (k, (h1 - h0) / eps, j0[k])


def test_update_is_the_least_squares_map_and_shrinks_every_observed_error():
    """One batch: the posterior mean equals scipy's solution of the MAP objective (prior + the fused
    rows, numeric Jacobians); every error component and every std shrinks, the tilts and the turn
    about the work axis included."""
    rng = np.random.default_rng(11)
    tof, sw = ToFConfig(), SweepConfig()
    x_true = rng.normal(0.0, PRIOR_STD)  # where the belief is off the truth
    belief = compose(TRUTH, -x_true)
    o, d, z, edges = _sweeps(TRUTH, belief, rng, tof, sw)
    kf = CubePose6Filter(PoseEstimate(belief, np.diag(PRIOR_STD**2), axes=POSE6_AXES))
    rep = kf.update(o, d, z, edges)
    assert rep.n_edges_used == 4 and rep.n_rays_used > 100

    fr, fe = rep.fused_rays, [e for e, f in zip(edges, rep.fused_edges) if f]
    r_var = (tof.noise_std + tof.noise_std_per_m * z[fr]) ** 2

    def residuals(x: np.ndarray) -> np.ndarray:
        pose = compose(belief, x)
        hits = ray_box(o[fr], d[fr], pose.p, pose.rotation.as_matrix(), HALF)
        out = [x / PRIOR_STD, (z[fr] - hits.distance) / np.sqrt(r_var)]
        for e in fe:
            h, _, var = edge_model(pose, HALF, e)
            out.append(np.array([-h / np.sqrt(var)]))
        return np.concatenate(out)

    # started from the filter's answer (at the belief some fused rays may miss the box), it must not move
    ls = least_squares(residuals, kf.x, xtol=1e-14, ftol=1e-14, gtol=1e-14)
    np.testing.assert_allclose(kf.x[:3], ls.x[:3], atol=2e-6)  # m
    np.testing.assert_allclose(kf.x[3:], ls.x[3:], atol=1e-4)  # rad
    # the covariance is the Gauss-Newton one at the solution
    jac = ls.jac
    np.testing.assert_allclose(kf.P, np.linalg.inv(jac.T @ jac), rtol=0.05, atol=1e-12)

    e0, e1 = np.abs(_err(belief, TRUTH)), np.abs(_err(kf.pose, TRUTH))
    post_std = np.sqrt(np.diag(kf.P))
    assert np.all(post_std < 0.75 * PRIOR_STD), post_std / PRIOR_STD
    assert np.all(e1 < np.maximum(e0, 3 * post_std)), (e0, e1)
    # along and across the work axis and the height to well under a millimetre
    assert np.all(e1[:3] < 0.001), e1[:3]


def test_covariance_is_consistent_over_many_sweeps():
    """NEES of the 6-DOF posterior over 20 priors: inside the chi-square(6) 99 % band for the mean."""
    tof, sw = ToFConfig(), SweepConfig()
    nees = []
    for seed in range(20):
        rng = np.random.default_rng(100 + seed)
        belief = compose(TRUTH, -rng.normal(0.0, PRIOR_STD))
        o, d, z, edges = _sweeps(TRUTH, belief, rng, tof, sw)
        kf = CubePose6Filter(PoseEstimate(belief, np.diag(PRIOR_STD**2), axes=POSE6_AXES))
        kf.update(o, d, z, edges)
        e = _err(kf.pose, TRUTH)
        nees.append(float(e @ np.linalg.solve(kf.P, e)))
    lo, hi = chi2.ppf([0.005, 0.995], 6 * len(nees)) / len(nees)
    assert lo < np.mean(nees) < hi, (np.mean(nees), lo, hi)


def test_a_masked_reading_is_neither_face_nor_beyond_an_edge():
    o = np.stack([np.linspace(0.0, 0.02, 21), np.zeros(21), np.zeros(21)], axis=1)
    d = np.tile([0.0, 1.0, 0.0], (21, 1))
    z = np.r_[np.full(10, 0.03), np.full(11, np.inf)]
    assert len(find_edges(o, d, z)) == 1
    z2 = z.copy()
    z2[10:13] = np.nan  # too close, or masked: no edge can be placed there
    assert find_edges(o, d, z2) == []
    excl = np.zeros(21, dtype=bool)
    excl[10:13] = True
    z3 = z.copy()
    z3[10:13] = 0.06  # the robot's own finger 30 mm behind the face: still beyond the edge
    (e,) = find_edges(o, d, z3, exclude=excl)
    assert not e.entering and abs(e.point[0] - 0.0095) < 1e-9


#: Recorded in PyBullet Rubiks-1-100, sensor-aided, seed 0 (the right hand's "shift out" sweeps before
#: move 87, at 8a73476): the true and believed cube, and the two edges the up/down sweeps found on the
#: face the beam ranged (-y face, beam along +y). Both are the top edge. The first is a plain exit; the
#: second is an entry whose step (the emitter's motion between its two readings) is mostly along world
#: x, because the arm was still moving from the previous sweep's end. Associated by its step with a side
#: edge it moved the belief 17 mm along x and the next grip jammed.
_TRUE_SHIFT_OUT = Pose(
    np.array([0.597965021286057, -0.0022973097940557187, 0.6027575698672842]),
    np.array([0.475057916865649, 0.5154523461049252, -0.5123371412822425, -0.49612448859226654]),
)
_BELIEF_SHIFT_OUT = Pose(
    np.array([0.5957645249916173, 0.00010719889680592767, 0.6020042127994657]),
    np.array([-0.4800263740368852, -0.5149762732688824, 0.5076744416266072, 0.49662941869990584]),
)
_EDGES_SHIFT_OUT = [
    EdgeObservation(
        point=np.array([0.6092764222962589, -0.0339168018419095, 0.6310797237197376]),
        step=np.array([0.009462282447160013, -0.05516836952507898, 0.9984322291547056]),
        direction=np.array([-0.048211129053205695, 0.9986330371327363, 0.020192676456131837]),
        entering=False,
        std_along=0.0007160853922582927,
        std_range=0.0010115423678776173,
        index=15,
    ),
    EdgeObservation(
        point=np.array([0.586953961354957, -0.03348691906954742, 0.630355678148118]),
        step=np.array([0.7888562957859224, -0.42451799248580485, -0.44439871585630775]),
        direction=np.array([-0.03829166388537142, 0.9989914533661222, 0.02344833849833806]),
        entering=True,
        std_along=0.0005551841233086639,
        std_range=0.0010171151866617365,
        index=8,
    ),
]


def test_an_edge_is_the_border_it_lies_on_not_the_one_its_step_points_at():
    """Both recorded edges lie 28-29 mm above the believed centre, 9-14 mm off it sideways: the top
    border. The exit is associated with it and agrees with the truth within its noise; the entry, whose
    step crosses the top border at under 0.5, is not associated at all (never with a side border)."""
    for pose in (_TRUE_SHIFT_OUT, _BELIEF_SHIFT_OUT):
        exit_, entry = (edge_model(pose, HALF, e) for e in _EDGES_SHIFT_OUT)
        assert entry is None
        assert exit_ is not None
        h, jac, var = exit_
        up = pose.rotation.as_matrix()[:, int(np.argmax(np.abs(pose.rotation.as_matrix()[2])))]
        assert (
            abs(abs(float(jac[:3] @ up)) - 1.0) < 1e-12
        )  # d h / d centre = -m, m the top face's normal
    h, _, var = edge_model(_TRUE_SHIFT_OUT, HALF, _EDGES_SHIFT_OUT[0])
    assert abs(h) < 2 * np.sqrt(var)


def test_the_recorded_shift_out_edges_do_not_move_the_belief_sideways():
    """The prior the PR2's sweeps use (6 mm, 2/2/3 degrees); the edges alone (its rays aside) observe
    the top face's height only, so the belief along world x must stay within 1 mm of where it was
    (it moved 17.4 mm with the entry taken for a side edge)."""
    kf = CubePose6Filter(PoseEstimate(_BELIEF_SHIFT_OUT, np.diag(PRIOR_STD**2), axes=POSE6_AXES))
    rep = kf.update(edges=_EDGES_SHIFT_OUT)
    assert rep.n_edges_used == 1 and rep.n_edges_unassociated == 1
    assert abs(kf.pose.p[0] - _BELIEF_SHIFT_OUT.p[0]) < 0.001
    # and the height moves towards the truth
    assert abs(kf.pose.p[2] - _TRUE_SHIFT_OUT.p[2]) < abs(
        _BELIEF_SHIFT_OUT.p[2] - _TRUE_SHIFT_OUT.p[2]
    )
