"""Summaries of per-trial metrics: medians, quartiles, box-plot statistics,
drop rates, grouped by any columns (method, object, ...).

The box statistics follow the paper's III-C description (median line,
quartile box, whiskers at the most extreme data within 1.5 IQR of the box,
the rest outliers) and are computed exactly as matplotlib's
``cbook.boxplot_stats`` does (linear-interpolation percentiles). The plots
draw these very numbers with ``Axes.bxp``, so what is printed and what is
drawn cannot disagree.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "BoxStats",
    "box_stats",
    "group_indices",
    "GroupStats",
    "summarize_groups",
    "drops_percent",
]


@dataclass(frozen=True)
class BoxStats:
    """Five-number-plus summary of one sample (NaNs removed first)."""

    n: int
    median: float
    q1: float
    q3: float
    whisker_low: float
    whisker_high: float
    minimum: float
    maximum: float
    mean: float
    outliers: tuple[float, ...]

    @property
    def iqr(self) -> float:
        return self.q3 - self.q1

    def as_bxp(self, label: str = "") -> dict:
        """The dict ``matplotlib.axes.Axes.bxp`` draws."""
        return {
            "label": label,
            "med": self.median,
            "q1": self.q1,
            "q3": self.q3,
            "whislo": self.whisker_low,
            "whishi": self.whisker_high,
            "fliers": np.asarray(self.outliers, dtype=float),
            "mean": self.mean,
        }


def box_stats(values: Iterable[float], whis: float = 1.5) -> BoxStats:
    """Box-plot statistics; an empty sample (or all-NaN) gives NaNs and ``n=0``.

    NaN means "not measured" and is left out; an infinite value is a
    ``ValueError`` (``values``), never silently dropped from the median.
    """
    x = np.asarray(
        list(values) if not isinstance(values, np.ndarray) else values, dtype=float
    ).ravel()
    if np.isinf(x).any():
        raise ValueError(f"values: entry {int(np.argmax(np.isinf(x)))} is infinite")
    x = x[np.isfinite(x)]
    if len(x) == 0:
        nan = float("nan")
        return BoxStats(0, nan, nan, nan, nan, nan, nan, nan, nan, ())
    q1, med, q3 = np.percentile(x, [25, 50, 75])
    iqr = q3 - q1
    lo_lim, hi_lim = q1 - whis * iqr, q3 + whis * iqr
    inside_hi = x[x <= hi_lim]
    inside_lo = x[x >= lo_lim]
    whishi = float(inside_hi.max()) if len(inside_hi) and inside_hi.max() >= q3 else float(q3)
    whislo = float(inside_lo.min()) if len(inside_lo) and inside_lo.min() <= q1 else float(q1)
    out = np.sort(x[(x < whislo) | (x > whishi)])
    return BoxStats(
        n=int(len(x)),
        median=float(med),
        q1=float(q1),
        q3=float(q3),
        whisker_low=whislo,
        whisker_high=whishi,
        minimum=float(x.min()),
        maximum=float(x.max()),
        mean=float(x.mean()),
        outliers=tuple(float(v) for v in out),
    )


def group_indices(
    columns: Mapping[str, Sequence | np.ndarray], by: Sequence[str]
) -> list[tuple[tuple[str, ...], np.ndarray]]:
    """Row indices per distinct key of the ``by`` columns, in order of first appearance.

    First appearance, not sorted order, so that tables and plots follow the
    order of the results file (e.g. the dataset's object order).
    """
    if not by:
        n = len(next(iter(columns.values())))
        return [((), np.arange(n))]
    for b in by:
        if b not in columns:
            raise KeyError(f"unknown grouping column {b!r}; have {sorted(columns)}")
    keys = list(zip(*[[str(v) for v in columns[b]] for b in by]))
    groups: dict[tuple[str, ...], list[int]] = {}
    for i, k in enumerate(keys):
        groups.setdefault(k, []).append(i)
    return [(k, np.array(v, dtype=int)) for k, v in groups.items()]


def drops_percent(dropped: np.ndarray) -> float:
    d = np.asarray(dropped, dtype=bool)
    return float(100.0 * d.mean()) if len(d) else float("nan")


@dataclass(frozen=True)
class GroupStats:
    """One group's summary: its key, counts, drop rate and per-metric stats."""

    by: tuple[str, ...]
    key: tuple[str, ...]
    n_trials: int
    n_dropped: int
    n_discarded: int
    drops_percent: float
    stats: Mapping[str, BoxStats]


def summarize_groups(
    columns: Mapping[str, Sequence | np.ndarray],
    by: Sequence[str],
    values: Mapping[str, np.ndarray],
    *,
    dropped: np.ndarray,
    discarded: np.ndarray | None = None,
    error_metrics: Sequence[str] = (),
) -> list[GroupStats]:
    """Per group: drops % and box statistics of each metric in ``values``.

    Discarded trials (set-up rule) are left out of everything, drops
    included: the protocol says such an experiment "must be discarded".
    Dropped trials count in drops % and are left out of the metrics named in
    ``error_metrics`` (there is no reached grasp to measure); other metrics
    (e.g. times) keep them.
    """
    n = len(dropped)
    dropped = np.asarray(dropped, dtype=bool)
    discarded = np.zeros(n, bool) if discarded is None else np.asarray(discarded, dtype=bool)
    if discarded.shape != (n,):
        raise ValueError(f"discarded: expected {n} values, got shape {discarded.shape}")
    for name, col in columns.items():
        if len(col) != n:
            raise ValueError(f"columns[{name!r}]: {len(col)} values, dropped has {n}")
    for name, v in values.items():
        if np.shape(v) != (n,):
            raise ValueError(f"values[{name!r}]: expected {n} values, got shape {np.shape(v)}")
    out = []
    for key, idx in group_indices(columns, by):
        keep = idx[~discarded[idx]]
        kept_ok = keep[~dropped[keep]]
        stats = {}
        for name, v in values.items():
            v = np.asarray(v, dtype=float)
            stats[name] = box_stats(v[kept_ok] if name in error_metrics else v[keep])
        out.append(
            GroupStats(
                by=tuple(by),
                key=key,
                n_trials=int(len(keep)),
                n_dropped=int(dropped[keep].sum()),
                n_discarded=int(discarded[idx].sum()),
                drops_percent=drops_percent(dropped[keep]),
                stats=stats,
            )
        )
    return out
