"""In-hand benchmark scoring over many trials: pose errors, the set-up rule,
contact-region errors, and grouped summaries.

Pure functions on arrays and meshes (no file or simulator access), so a
real-robot user can call :func:`score_trials` on their own logs directly; the
``benchharness inhand score`` command only adds file reading on top.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .contact import ContactError
from .pose import (
    SETUP_THRESHOLD_PERCENT,
    SetupCheck,
    err_or_percent,
    err_pos,
    err_pos_percent,
    setup_check,
)
from .stats import GroupStats, summarize_groups

__all__ = ["TrialScores", "score_trials", "summarize_scores", "METRICS", "MetricInfo"]


@dataclass(frozen=True)
class MetricInfo:
    """How a per-trial metric is shown: label, unit and display scale."""

    label: str
    unit: str
    scale: float
    #: Measures the reached grasp, so undefined for dropped trials.
    needs_reached: bool = True


#: Display metrics, in table/plot order: name -> info (values stored in SI).
METRICS: Mapping[str, MetricInfo] = {
    "err_pos": MetricInfo("err_pos", "cm", 100.0),
    "err_pos_percent": MetricInfo("err_pos%", "%", 1.0),
    "err_or_percent": MetricInfo("err_or%", "%", 1.0),
    "g_euc": MetricInfo("G_euc", "cm", 100.0),
    "g_geo": MetricInfo("G_geo", "cm", 100.0),
    "g_min": MetricInfo("G_min", "cm", 100.0),
    "setup_err_pos": MetricInfo("setup err_pos", "cm", 100.0, needs_reached=False),
    "setup_err_or_percent": MetricInfo("setup err_or%", "%", 1.0, needs_reached=False),
    "plan_time_s": MetricInfo("plan time", "s", 1.0, needs_reached=False),
    "exec_time_s": MetricInfo("exec time", "s", 1.0, needs_reached=False),
}


@dataclass(frozen=True)
class TrialScores:
    """Per-trial metrics (SI units; NaN where not defined or not measured)."""

    err_pos: np.ndarray
    err_pos_percent: np.ndarray
    err_or_percent: np.ndarray
    setup: SetupCheck
    discarded: np.ndarray
    g_euc: np.ndarray
    g_geo: np.ndarray
    g_min: np.ndarray
    plan_time_s: np.ndarray
    exec_time_s: np.ndarray
    contact: tuple[ContactError | None, ...] = field(default=(), repr=False)

    def values(self) -> dict[str, np.ndarray]:
        """Metric name -> per-trial values, for the metrics in :data:`METRICS`."""
        return {
            "err_pos": self.err_pos,
            "err_pos_percent": self.err_pos_percent,
            "err_or_percent": self.err_or_percent,
            "g_euc": self.g_euc,
            "g_geo": self.g_geo,
            "g_min": self.g_min,
            "setup_err_pos": self.setup.pos,
            "setup_err_or_percent": self.setup.or_percent,
            "plan_time_s": self.plan_time_s,
            "exec_time_s": self.exec_time_s,
        }


def _per_trial(a, n: int, name: str, dtype: type, fill: object) -> np.ndarray:
    """One value per trial (``fill`` when absent); a different length is an error, not a broadcast."""
    if a is None:
        return np.full(n, fill, dtype=dtype)
    arr: np.ndarray = np.asarray(a, dtype=dtype)
    if arr.shape != (n,):
        raise ValueError(f"{name}: expected {n} values (one per trial), got shape {arr.shape}")
    if dtype is float and np.isinf(arr).any():
        raise ValueError(f"{name}: trial {int(np.argmax(np.isinf(arr)))} is infinite")
    return arr


def score_trials(
    initial: np.ndarray,
    desired: np.ndarray,
    reached: np.ndarray,
    *,
    setup: np.ndarray | None = None,
    dropped: np.ndarray | None = None,
    plan_time_s: np.ndarray | None = None,
    exec_time_s: np.ndarray | None = None,
    contact: Sequence[ContactError | None] | None = None,
    normalize: bool = False,
    setup_threshold_percent: float = SETUP_THRESHOLD_PERCENT,
) -> TrialScores:
    """Score ``n`` trials from ``(n, 7)`` pose arrays ``[x, y, z, qx, qy, qz, qw]``.

    ``setup`` (the recorded initial set-up pose, NaN rows where unknown)
    drives the 10 % discard rule; ``contact`` holds each trial's
    :func:`~benchharness.metrics.contact.contact_region_error` result (or
    None) when contact metrics apply (Levels II and III). Dropped trials get
    NaN pose errors whatever their reached pose says.

    Every argument must have one row per trial (nothing is broadcast); poses
    are checked as in :mod:`benchharness.metrics.pose` (``ValueError`` naming
    the argument for an infinite value or a non-unit quaternion).
    """
    ini = np.atleast_2d(np.asarray(initial, float))
    n = len(ini)
    if ini.shape != (n, 7):
        raise ValueError(f"initial: expected shape (n, 7), got {np.shape(initial)}")
    des = np.atleast_2d(np.asarray(desired, float))
    rea = np.atleast_2d(np.asarray(reached, float)).copy()
    su = np.full((n, 7), np.nan) if setup is None else np.atleast_2d(np.asarray(setup, float))
    for name, a in (("desired", des), ("reached", rea), ("setup", su)):
        if a.shape != (n, 7):
            raise ValueError(f"{name}: expected shape ({n}, 7), got {a.shape}")
    drop = _per_trial(dropped, n, "dropped", bool, False)
    plan = _per_trial(plan_time_s, n, "plan_time_s", float, np.nan)
    exe = _per_trial(exec_time_s, n, "exec_time_s", float, np.nan)
    rea[drop] = np.nan
    check = setup_check(
        ini[:, :3],
        ini[:, 3:],
        su[:, :3],
        su[:, 3:],
        des[:, :3],
        threshold_percent=setup_threshold_percent,
        normalize=normalize,
    )
    nan = np.full(n, np.nan)
    g = {k: nan.copy() for k in ("euc", "geo", "min")}
    if contact is not None:
        if len(contact) != n:
            raise ValueError(f"contact: expected {n} entries, got {len(contact)}")
        for i, c in enumerate(contact):
            if c is not None and not drop[i]:
                g["euc"][i], g["geo"][i], g["min"][i] = c.euc, c.geo, c.g_min
    return TrialScores(
        err_pos=np.atleast_1d(err_pos(des[:, :3], rea[:, :3])),
        err_pos_percent=np.atleast_1d(err_pos_percent(des[:, :3], rea[:, :3], ini[:, :3])),
        err_or_percent=np.atleast_1d(err_or_percent(des[:, 3:], rea[:, 3:], normalize=normalize)),
        setup=check,
        discarded=check.discard,
        g_euc=g["euc"],
        g_geo=g["geo"],
        g_min=g["min"],
        plan_time_s=plan,
        exec_time_s=exe,
        contact=tuple(contact) if contact is not None else (),
    )


def summarize_scores(
    scores: TrialScores,
    columns: Mapping[str, Sequence | np.ndarray],
    by: Sequence[str],
    dropped: np.ndarray,
) -> list[GroupStats]:
    """Grouped summaries in SI units (see :func:`~benchharness.metrics.stats.summarize_groups`).

    ``columns`` are the grouping columns (e.g. ``{"method": ..., "object":
    ...}``); discarded trials are excluded, dropped ones count in drops %.
    """
    return summarize_groups(
        columns,
        by,
        scores.values(),
        dropped=dropped,
        discarded=scores.discarded,
        error_metrics=[k for k, m in METRICS.items() if m.needs_reached],
    )
