"""The cube filter re-localises a real 5.7 cm box from pre-touch sweeps on both engines.

The truth is the engine's body pose; the filter sees only the head-camera
prior and the ToF readings (their believed rays and ranges), never which
body a ray hit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

pytest.importorskip("filterpy")

from sensor_rig import (
    BACKENDS,
    CUBE_CENTRE,
    HALF,
    cube_rig,
    errors,
    new_backend,
    offset_prior,
    two_face_scan,
)

from benchharness.backends import Box
from benchharness.geometry import Pose
from benchharness.sensors import FILTER_AXES, CubePoseFilter, HeadCamera

pytestmark = pytest.mark.sim


@pytest.fixture(params=BACKENDS)
def backend(request):
    b = new_backend(request.param)
    yield b
    b.close()


@pytest.mark.parametrize("yaw_deg", [10.0, 42.0])  # 42° + 5° error crosses the ±45° wrap
def test_two_face_sweep_relocalises_the_cube(backend, yaw_deg):
    rig = cube_rig(backend, yaw_deg)
    truth = rig.truth
    worst_p = worst_y = 0.0
    for seed in range(3):
        rng = np.random.default_rng(100 + seed)
        prior = offset_prior(truth, rng)  # 8 mm / 5° off
        p0_err, y0_err, _ = errors(prior, truth)
        assert p0_err == pytest.approx(0.008) and math.degrees(y0_err) == pytest.approx(5.0)
        kf = CubePoseFilter(initial=prior)
        prior_cov = kf.P
        s = two_face_scan(rig, prior, rng)
        rep = kf.update_reading(s)
        est = kf.estimate
        p_err, y_err, e = errors(est, truth)
        worst_p, worst_y = max(worst_p, p_err), max(worst_y, y_err)
        assert p_err < 0.003, f"seed {seed}: position error {p_err * 1e3:.2f} mm"
        assert math.degrees(y_err) < 2.0, f"seed {seed}: yaw error {math.degrees(y_err):.2f}°"
        # the covariance shrinks on every axis, and the truth is inside it
        assert np.all(np.diag(est.covariance) < 0.1 * np.diag(prior_cov))
        assert np.all(np.abs(e) <= 3.5 * np.sqrt(np.diag(est.covariance)))
        assert rep.n_used >= 60 and est.n_measurements == 1 + rep.n_used
        assert est.time == pytest.approx(backend.time)
    print(
        f"{backend.name} yaw {yaw_deg}: worst position error {worst_p * 1e3:.2f} mm, "
        f"yaw {math.degrees(worst_y):.2f}°"
    )


def test_a_body_in_the_way_is_gated(backend):
    """A thin plate 1 cm in front of part of a face returns short ranges: gated, not fused."""
    rig = cube_rig(backend, 10.0)
    truth = rig.truth
    face_pt = truth.apply([-HALF - 0.01, -0.015, 0.0])
    plate = backend.add_body(
        [Box((0.001, 0.006, 0.02))], Pose(face_pt, truth.q), 0.01, fixed=True, name="finger"
    )
    rng = np.random.default_rng(7)
    prior = offset_prior(truth, rng, pos_err=0.005, yaw_err_deg=3.0)
    kf = CubePoseFilter(initial=prior)
    s = two_face_scan(rig, prior, rng)
    rep = kf.update_reading(s)
    on_plate = s.body == plate
    assert on_plate.sum() >= 6
    assert not rep.fused[on_plate].any()  # decided from innovations: the filter never saw s.body
    p_err, y_err, _ = errors(kf.estimate, truth)
    assert p_err < 0.003 and math.degrees(y_err) < 2.0


def test_filter_is_consistent_over_seeded_runs(backend):
    """Head-camera priors drawn from its own noise: NEES is χ²(4)-distributed if the filter is honest."""
    rig = cube_rig(backend, 25.0)
    truth = rig.truth
    cam = HeadCamera()
    runs = 24
    nees = np.empty(runs)
    inside = 0
    for k in range(runs):
        rng = np.random.default_rng(1000 + k)
        prior = cam.estimate(truth, rng)
        kf = CubePoseFilter(initial=prior)
        kf.update_reading(two_face_scan(rig, prior, rng))
        est = kf.estimate
        _, _, e = errors(est, truth)
        nees[k] = e @ np.linalg.solve(est.covariance, e)
        inside += bool(np.all(np.abs(e) <= 3 * np.sqrt(np.diag(est.covariance))))
    lo, hi = chi2.ppf([0.005, 0.995], 4 * runs) / runs  # 99 % interval of the mean NEES
    print(
        f"{backend.name}: mean NEES {nees.mean():.2f} (99 % interval {lo:.2f}-{hi:.2f}), within 3σ {inside}/{runs}"
    )
    assert lo <= nees.mean() <= hi
    assert inside >= 0.95 * runs - 1e-9 or inside >= runs - 1


def test_predict_then_rescan_after_a_carry(backend):
    """Dead reckoning through a commanded 10 cm carry, then a sweep: covariance grows, then shrinks."""
    rig = cube_rig(backend, 5.0)
    rng = np.random.default_rng(3)
    prior = HeadCamera().estimate(rig.truth, rng)
    kf = CubePoseFilter(initial=prior)
    kf.update_reading(two_face_scan(rig, prior, rng))
    settled = kf.P
    # the robot commands a 10 cm carry; the cube really lands 4 mm short of it (slip)
    commanded = np.array([0.0, 0.10, 0.0])
    backend.set_pose(rig.cube, Pose(rig.truth.p + commanded - [0.0, 0.004, 0.0], rig.truth.q))
    kf.predict(commanded)
    assert np.all(np.diag(kf.P)[:3] > np.diag(settled)[:3])
    p_err, _, _ = errors(kf.estimate, rig.truth)
    assert p_err > 0.003  # dead reckoning carries the slip
    kf.update_reading(two_face_scan(rig, kf.estimate, rng))
    p_err, y_err, _ = errors(kf.estimate, rig.truth)
    assert p_err < 0.002 and math.degrees(y_err) < 2.0
    assert kf.estimate.axes == FILTER_AXES
    assert np.allclose(CUBE_CENTRE[:2] + [0.0, 0.096], rig.truth.p[:2])


@pytest.mark.slow
def test_relocalisation_holds_across_yaws(backend):
    """120 priors 8 mm / 5° off, at 12 true yaws spanning the ±45° wrap: every one re-localised."""
    worst_p = worst_y = 0.0
    for yaw_deg in np.linspace(-44.0, 44.0, 12):
        b = new_backend(backend.name)
        try:
            rig = cube_rig(b, float(yaw_deg))
            truth = rig.truth
            for k in range(10):
                rng = np.random.default_rng(20_000 + int(round(yaw_deg * 10)) * 10 + k)
                prior = offset_prior(truth, rng)
                kf = CubePoseFilter(initial=prior)
                kf.update_reading(two_face_scan(rig, prior, rng))
                p_err, y_err, _ = errors(kf.estimate, truth)
                worst_p, worst_y = max(worst_p, p_err), max(worst_y, y_err)
        finally:
            b.close()
    print(f"{backend.name}: worst of 120: {worst_p * 1e3:.2f} mm, {math.degrees(worst_y):.2f}°")
    assert worst_p < 0.003 and math.degrees(worst_y) < 2.0
