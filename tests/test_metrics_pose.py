"""Pose metrics (eqs. 1-3) and the section II-B set-up rule against analytic answers."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.metrics.pose import err_or_percent, err_pos, err_pos_percent, setup_check


def expected_or_percent(theta):
    # Two unit quaternions whose relative rotation has angle theta have
    # q_d . q_r = cos(theta/2) (for the sign choice with positive dot product),
    # so ||q_d - q_r||^2 = 2 - 2 cos(theta/2), and eq. 3 gives
    # 100 * sqrt(2 - 2 cos(theta/2)) / sqrt(2).
    return 100.0 * np.sqrt(2.0 - 2.0 * np.cos(theta / 2.0)) / np.sqrt(2.0)


def test_err_pos_and_percent_known_values():
    s_i = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
    s_d = np.array([[0.03, 0.04, 0.0], [1.0, 1.0, 2.0]])
    s_r = np.array([[0.03, 0.04, 0.01], [1.0, 1.5, 2.0]])
    np.testing.assert_allclose(err_pos(s_d, s_r), [0.01, 0.5])
    np.testing.assert_allclose(err_pos_percent(s_d, s_r, s_i), [20.0, 50.0])
    assert err_pos([0, 0, 0], [0, 3, 4]) == pytest.approx(5.0)


def test_err_pos_percent_zero_displacement_is_nan():
    assert np.isnan(err_pos_percent([1, 2, 3], [1, 2, 3.1], [1, 2, 3]))


@pytest.mark.parametrize("theta", [0.0, 0.1, np.pi / 6, np.pi / 2, 2.0, np.pi])
@pytest.mark.parametrize("axis", [[1, 0, 0], [0, 1, 1], [-0.3, 0.2, 0.9]])
def test_err_or_percent_for_rotation_about_axis(theta, axis):
    rng = np.random.default_rng(7)
    base = Rotation.from_rotvec(rng.normal(size=3))
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    q_d = base.as_quat()
    q_r = (base * Rotation.from_rotvec(theta * axis)).as_quat()
    assert err_or_percent(q_d, q_r) == pytest.approx(expected_or_percent(theta), abs=1e-9)
    # q and -q are the same rotation and must score the same
    assert err_or_percent(q_d, -q_r) == pytest.approx(expected_or_percent(theta), abs=1e-9)
    assert err_or_percent(-q_d, q_r) == pytest.approx(expected_or_percent(theta), abs=1e-9)


def test_err_or_percent_vectorised_and_half_turn_is_100():
    q_d = np.tile([0, 0, 0, 1.0], (3, 1))
    q_r = Rotation.from_rotvec([[np.pi, 0, 0], [0, 0, 0], [0, 0, -np.pi / 2]]).as_quat()
    np.testing.assert_allclose(
        err_or_percent(q_d, q_r), [100.0, 0.0, expected_or_percent(np.pi / 2)], atol=1e-9
    )


def test_normalisation_is_a_choice_within_the_tolerance():
    # inside QUAT_NORM_TOL (rounded data) the raw value is eq. 3 on the numbers given
    q = np.array([0.0, 0.0, 0.0, 1.0])
    q_scaled = 1.001 * q
    assert err_or_percent(q, q_scaled) == pytest.approx(100 * 0.001 / np.sqrt(2))
    assert err_or_percent(q, q_scaled, normalize=True) == pytest.approx(0.0)
    # beyond it, only an explicit normalize=True scores it
    with pytest.raises(ValueError, match="q_r: row 0 is not a unit quaternion"):
        err_or_percent(q, 1.01 * q)
    assert err_or_percent(q, 1.01 * q, normalize=True) == pytest.approx(0.0)


def _setup_case(setup_offset, setup_angle):
    s_i = np.zeros(3)
    s_d = np.array([0.1, 0.0, 0.0])  # 10 cm displacement: 1 cm set-up error = 10 %
    q_i = np.array([0, 0, 0, 1.0])
    s_hat = s_i + np.asarray(setup_offset)
    q_hat = Rotation.from_rotvec([0, 0, setup_angle]).as_quat()
    return s_i, q_i, s_hat, q_hat, s_d


def test_setup_rule_constructed_cases():
    # err_or% = 10 % exactly at theta = 2 acos(1 - 0.01) (from the formula above)
    theta_10 = 2 * np.arccos(1 - 0.5 * (0.1 * np.sqrt(2)) ** 2)
    cases = [
        ((0.005, 0, 0), 0.0, False),  # 5 % position
        ((0.0, 0.0101, 0), 0.0, True),  # 10.1 % position
        ((0.0, 0.0, 0.0), theta_10 * 0.99, False),  # just under 10 % orientation
        ((0.0, 0.0, 0.0), theta_10 * 1.01, True),  # just over
        ((0.009, 0, 0), theta_10 * 0.9, False),  # both under
    ]
    rows = [_setup_case(o, a) for o, a, _ in cases]
    s_i, q_i, s_hat, q_hat, s_d = (np.array(x) for x in zip(*rows))
    check = setup_check(s_i, q_i, s_hat, q_hat, s_d)
    assert check.discard.tolist() == [c[2] for c in cases]
    np.testing.assert_allclose(check.pos_percent[:2], [5.0, 10.1])
    assert check.or_percent[2] == pytest.approx(9.9, rel=0.02)


def test_setup_rule_boundary_is_strict_and_nan_never_discards():
    s_i, q_i, s_hat, q_hat, s_d = _setup_case((0.01, 0, 0), 0.0)  # exactly 10 %
    assert not setup_check(s_i, q_i, s_hat, q_hat, s_d).discard[0]
    nan = np.full(3, np.nan)
    assert not setup_check(s_i, q_i, nan, np.full(4, np.nan), s_d).discard[0]
