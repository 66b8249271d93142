"""Box statistics and the drawn box plot against a hand computation."""

import numpy as np
import pytest

from benchharness.metrics.plots import box_plot
from benchharness.metrics.stats import box_stats, group_indices, summarize_groups

# Hand computation for x = [1, 2, 3, 4, 5, 6, 7, 8, 100] (n = 9), linear percentiles:
#   Q1 at rank 0.25 * 8 = 2 -> 3; median at rank 4 -> 5; Q3 at rank 6 -> 7
#   IQR = 4; fences 3 - 6 = -3 and 7 + 6 = 13
#   whiskers: lowest datum >= -3 is 1, highest datum <= 13 is 8; outlier: 100
X = [8, 3, 100, 1, 5, 2, 7, 4, 6]


def test_box_stats_hand_computed():
    b = box_stats(X)
    assert (b.n, b.q1, b.median, b.q3) == (9, 3.0, 5.0, 7.0)
    assert (b.whisker_low, b.whisker_high) == (1.0, 8.0)
    assert b.outliers == (100.0,)
    assert (b.minimum, b.maximum) == (1.0, 100.0)


def test_box_stats_ignores_nan_and_empty():
    assert box_stats([np.nan, 1.0, 3.0]).median == 2.0
    assert box_stats([]).n == 0 and np.isnan(box_stats([np.nan]).median)


def test_group_indices_first_appearance_order():
    cols = {"method": ["b", "a", "b", "a"], "object": ["x", "x", "y", "x"]}
    got = group_indices(cols, ["method", "object"])
    assert [k for k, _ in got] == [("b", "x"), ("a", "x"), ("b", "y")]
    assert got[1][1].tolist() == [1, 3]


def test_summarize_groups_drops_and_discards():
    cols = {"method": ["m"] * 5}
    err = np.array([1.0, 2.0, 3.0, 99.0, 50.0])
    dropped = np.array([False, False, False, True, False])
    discarded = np.array([False, False, False, False, True])
    (g,) = summarize_groups(
        cols,
        ["method"],
        {"err": err, "t": err},
        dropped=dropped,
        discarded=discarded,
        error_metrics=["err"],
    )
    assert (g.n_trials, g.n_dropped, g.n_discarded) == (4, 1, 1)
    assert g.drops_percent == 25.0
    assert g.stats["err"].median == 2.0  # dropped and discarded excluded
    assert g.stats["t"].n == 4  # non-error metrics keep dropped trials


def test_plot_whiskers_match_hand_computation(tmp_path):
    cols = {"object": ["o"] * 9 + ["p"] * 9, "method": ["A"] * 9 + ["B"] * 9}
    values = {"err": np.array(X + X, dtype=float) / 100.0}  # stored in m, shown in cm
    summ = summarize_groups(cols, ["object", "method"], values, dropped=np.zeros(18, bool))
    out = tmp_path / "box.png"
    plot = box_plot(summ, ["err"], out, scales={"err": 100.0}, labels={"err": "err (cm)"})
    art = plot.artists["err"]
    # bxp draws two whiskers per box: [lower, upper], each a line from the box edge
    lo, hi = art["whiskers"][0].get_ydata(), art["whiskers"][1].get_ydata()
    assert list(lo) == pytest.approx([3.0, 1.0]) and list(hi) == pytest.approx([7.0, 8.0])
    assert list(art["medians"][0].get_ydata()) == pytest.approx([5.0, 5.0])
    assert list(art["fliers"][0].get_ydata()) == pytest.approx([100.0])
    assert out.stat().st_size > 1000
    assert plot.groups == ("o", "p") and plot.hues == ("A", "B")


def test_plot_svg(tmp_path):
    summ = summarize_groups(
        {"object": ["o"] * 3, "method": ["A"] * 3},
        ["object", "method"],
        {"err": np.array([1.0, 2.0, 3.0])},
        dropped=np.zeros(3, bool),
    )
    out = tmp_path / "box.svg"
    box_plot(summ, ["err"], out)
    assert out.read_text().lstrip().startswith("<?xml")
