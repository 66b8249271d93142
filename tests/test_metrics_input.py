"""Issue 13 item 12: the metrics API refuses input that would give a wrong number.

Before, a zero quaternion scored 70.71 % (eq. 3 with q_r = 0 is
``100 * ||q_d|| / sqrt(2)``), a scaled one up to thousands of percent, and
arguments with different row counts were broadcast. Each case now raises
``ValueError`` naming the argument; the published-figure tests
(tests/test_inhand_published.py) are unchanged.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchharness.geometry import QUAT_NORM_TOL
from benchharness.metrics import (
    box_stats,
    err_or_percent,
    err_pos,
    err_pos_percent,
    score_trials,
    setup_check,
)

ID = np.array([0.0, 0.0, 0.0, 1.0])


@pytest.mark.parametrize(
    "q_r, match",
    [
        (np.zeros(4), "q_r: row 0 is a zero quaternion"),
        (1000.0 * ID, "q_r: row 0 is not a unit quaternion"),
        (0.5 * ID, "q_r: row 0 is not a unit quaternion"),
    ],
)
def test_err_or_refuses_non_unit_quaternions(q_r, match):
    with pytest.raises(ValueError, match=match):
        err_or_percent(ID, q_r)


def test_err_or_normalize_is_the_explicit_way_to_score_a_scaled_quaternion():
    q = Rotation.from_rotvec([0.3, 0.0, 0.0]).as_quat()
    want = err_or_percent(ID, q)  # unit: the reference value
    assert err_or_percent(ID, 7.0 * q, normalize=True) == pytest.approx(want, abs=1e-12)
    with pytest.raises(ValueError, match="q_d: row 0 is a zero quaternion"):
        err_or_percent(np.zeros(4), q, normalize=True)


def test_quaternion_tolerance_is_the_documented_one():
    assert err_or_percent(ID, (1 + 0.9 * QUAT_NORM_TOL) * ID) >= 0
    with pytest.raises(ValueError, match="q_r"):
        err_or_percent(ID, (1 + 1.1 * QUAT_NORM_TOL) * ID)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: err_pos(np.zeros((3, 3)), np.zeros((2, 3))), "s_r: 2 rows"),
        (lambda: err_pos(np.zeros(3), np.zeros((2, 3))), "s_r: 2 rows"),
        (lambda: err_pos_percent(np.zeros((2, 3)), np.zeros((2, 3)), np.ones((1, 3))), "s_i"),
        (lambda: err_or_percent(np.tile(ID, (2, 1)), ID), "q_r: 1 rows"),
        (lambda: err_pos(np.zeros((2, 2)), np.zeros((2, 2))), "s_d: expected shape"),
        (lambda: err_pos([0, 0, np.inf], [0, 0, 0]), "s_d: row 0 holds an infinite value"),
        (lambda: err_or_percent(ID, [0, 0, np.inf, 1]), "q_r"),
    ],
)
def test_shapes_rows_and_infinities_are_refused(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_nan_still_means_not_measured():
    assert np.isnan(err_pos([0, 0, 0], [np.nan] * 3))
    assert np.isnan(err_or_percent(ID, [np.nan] * 4))


def test_huge_finite_coordinate_gives_a_huge_error_not_inf():
    # np.linalg.norm squares first: 1e200 -> inf, which a summary then dropped
    assert err_pos([0, 0, 0], [1e200, 0, 0]) == pytest.approx(1e200)
    assert err_pos_percent([0, 0, 0], [1e200, 0, 0], [1, 0, 0]) == pytest.approx(1e202)
    with pytest.raises(ValueError, match="s_r: row 0"):
        err_pos([-1e308, 0, 0], [1e308, 0, 0])


def _poses(n):
    p = np.zeros((n, 7))
    p[:, 6] = 1.0
    return p


def test_score_trials_refuses_per_trial_arrays_of_another_length():
    ini, des, rea = _poses(3), _poses(3), _poses(3)
    des[:, 0] = 0.1
    for kw, match in (
        ({"dropped": [False, True]}, "dropped: expected 3"),
        ({"plan_time_s": [1.0]}, "plan_time_s: expected 3"),
        ({"exec_time_s": np.ones(4)}, "exec_time_s: expected 3"),
        ({"setup": _poses(2)}, "setup: expected shape"),
    ):
        with pytest.raises(ValueError, match=match):
            score_trials(ini, des, rea, **kw)
    with pytest.raises(ValueError, match="initial"):
        score_trials(np.zeros((3, 6)), des, rea)
    bad = rea.copy()
    bad[1, 3:] = 0.0
    with pytest.raises(ValueError, match="q_r: row 1 is a zero quaternion"):
        score_trials(ini, des, bad)
    # a dropped trial's reached pose is not measured, so it is not checked
    assert score_trials(ini, des, bad, dropped=[False, True, False]).err_pos[0] == 0.1


def test_setup_check_names_its_own_arguments():
    p = _poses(1)
    with pytest.raises(ValueError, match="q_setup: row 0 is a zero quaternion"):
        setup_check(p[:, :3], p[:, 3:], p[:, :3], np.zeros((1, 4)), p[:, :3] + 0.1)


def test_box_stats_refuses_inf_instead_of_dropping_it():
    with pytest.raises(ValueError, match="values: entry 1 is infinite"):
        box_stats([1.0, np.inf, 2.0])
    assert box_stats([1.0, np.nan, 3.0]).median == 2.0


def test_contact_region_error_checks_its_arguments():
    trimesh = pytest.importorskip("trimesh")
    from benchharness.metrics import contact_region_error

    box = trimesh.creation.box((0.05, 0.05, 0.05))
    top = np.array([[0.0, 0.0, 0.025]])
    for kw, match in (
        ({"contact_tol": -1.0}, "contact_tol"),
        ({"contact_tol": float("nan")}, "contact_tol"),
        ({"method": "fast"}, "method"),
    ):
        with pytest.raises(ValueError, match=match):
            contact_region_error(box, top, top, **kw)
    with pytest.raises(ValueError, match=r"reached: contact points: expected shape \(n, 3\)"):
        contact_region_error(box, top, np.zeros((3, 2)))
    with pytest.raises(ValueError, match="desired: contact points: an infinite"):
        contact_region_error(box, [[0, 0, np.inf]], top)
