"""Pose-estimate error against move index, per method, from the stored diagnostics.

This is the plot that explains Table I: dead reckoning's believed cube pose
drifts away from the true one move after move, a sensor-aided strategy's
stays bounded. Points are every logged estimate; the line is the median per
move index.

Robust axis: one wild estimate (an 800 mm belief logged as the cube fell)
would otherwise stretch the y axis until every other point lies on zero.
Points above the panel's far-out fence ``Q3 + 3 IQR`` (Tukey) are drawn as
triangles on the top edge, labelled with their trial and value, and
returned as :class:`Outlier` so the command names them; nothing is dropped.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .reports import _columns
from .store import StoredTrial

__all__ = [
    "Outlier",
    "PoseErrorPlot",
    "pose_error_series",
    "pose_error_outliers",
    "plot_pose_error",
]

#: Tukey's "far out" fence: points beyond Q3 + FENCE_IQR * IQR are off-scale.
FENCE_IQR = 3.0

_UNITS = {"pos_mm": "mm", "rot_deg": "deg"}


@dataclass(frozen=True)
class Outlier:
    """One estimate drawn off-scale: which trial, which move, how large."""

    method: str
    task: str
    seed: int
    trial: int
    move: int
    metric: str  #: "pos_mm" or "rot_deg"
    value: float

    def describe(self) -> str:
        return (
            f"{self.task} {self.method} seed {self.seed} trial {self.trial} move {self.move}: "
            f"{self.value:.0f} {_UNITS[self.metric]}"
        )

    def to_dict(self) -> dict[str, object]:
        return {
            "method": self.method,
            "task": self.task,
            "seed": self.seed,
            "trial": self.trial,
            "move": self.move,
            "metric": self.metric,
            "value": self.value,
        }


@dataclass(frozen=True)
class PoseErrorPlot:
    path: Path
    outliers: tuple[Outlier, ...]


def pose_error_series(trials: Sequence[StoredTrial]) -> dict[str, dict[str, np.ndarray]]:
    """method label -> {"move", "pos_mm", "rot_deg", "trial", "seed", "task"} over all its logged estimates."""
    _, col_of = _columns(trials)
    acc: dict[str, list[tuple[int, float, float, int, int, str]]] = defaultdict(list)
    for t in trials:
        for e in t.diagnostics.get("pose_estimates") or []:
            # an estimate logged after the release (older stores) compares a cube lying on the
            # table with a belief nobody holds: not an estimation error
            if e.get("pos_err_m") is None or e.get("label") == "release":
                continue
            acc[col_of[t.run_key].label].append(
                (
                    int(e["move_index"]),
                    1000.0 * float(e["pos_err_m"]),
                    np.nan if e.get("rot_err_deg") is None else float(e["rot_err_deg"]),
                    int(t.trial_index),
                    int(t.seed),
                    str(t.task),
                )
            )
    out = {}
    for label, rows in acc.items():
        a = np.array([r[:3] for r in rows], float)
        out[label] = {
            "move": a[:, 0].astype(int),
            "pos_mm": a[:, 1],
            "rot_deg": a[:, 2],
            "trial": np.array([r[3] for r in rows], dtype=int),
            "seed": np.array([r[4] for r in rows], dtype=np.int64),
            "task": np.array([r[5] for r in rows], dtype=object),
        }
    return out


def _fence(values: np.ndarray) -> float:
    v = values[np.isfinite(values)]
    if len(v) < 4:
        return float("inf")
    q1, q3 = np.percentile(v, [25, 75])
    iqr = q3 - q1
    return float(q3 + FENCE_IQR * iqr) if iqr > 0 else float("inf")


def pose_error_outliers(
    series: dict[str, dict[str, np.ndarray]],
) -> dict[str, tuple[float, list[Outlier]]]:
    """Per metric: the fence over all methods' points, and the estimates above it."""
    out: dict[str, tuple[float, list[Outlier]]] = {}
    for key in ("pos_mm", "rot_deg"):
        allv = np.concatenate([s[key] for s in series.values()]) if series else np.zeros(0)
        fence = _fence(allv)
        found = []
        for label, s in series.items():
            for i in np.nonzero(np.isfinite(s[key]) & (s[key] > fence))[0]:
                found.append(
                    Outlier(
                        label,
                        str(s["task"][i]),
                        int(s["seed"][i]),
                        int(s["trial"][i]),
                        int(s["move"][i]),
                        key,
                        float(s[key][i]),
                    )
                )
        out[key] = (fence, found)
    return out


def plot_pose_error(
    trials: Sequence[StoredTrial], path: str | Path, title: str = ""
) -> PoseErrorPlot:
    """Write the PNG (or any format matplotlib knows from the suffix); error if nothing was logged."""
    series = pose_error_series(trials)
    if not series:
        raise ValueError(
            "no pose estimates in the selected trials' diagnostics "
            "(strategies log them with ctx.recorder.pose_estimate)"
        )
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    off = pose_error_outliers(series)
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True, constrained_layout=True)
    colours = {label: f"C{i % 10}" for i, label in enumerate(series)}
    for label, s in series.items():
        color = colours[label]
        moves = np.unique(s["move"])
        for ax, key in zip(axes, ("pos_mm", "rot_deg")):
            fence = off[key][0]
            inside = ~(s[key] > fence)
            ax.scatter(s["move"][inside], s[key][inside], s=8, alpha=0.35, color=color)
            med = [np.nanmedian(s[key][s["move"] == m]) for m in moves]
            ax.plot(moves, med, color=color, label=label)
    for ax, key in zip(axes, ("pos_mm", "rot_deg")):
        fence, outliers = off[key]
        if not outliers:
            continue
        vals = np.concatenate([s[key] for s in series.values()])
        inliers = vals[np.isfinite(vals) & ~(vals > fence)]
        top = (float(inliers.max()) * 1.15 if len(inliers) else 0.0) or 1.0
        ax.set_ylim(top=top)
        for o in outliers:
            ax.scatter([o.move], [top], marker="^", s=40, color=colours[o.method], clip_on=False)
            ax.annotate(
                f"trial {o.trial}: {o.value:.0f} {_UNITS[key]}",
                (o.move, top),
                textcoords="offset points",
                xytext=(4, -10),
                fontsize="x-small",
                color=colours[o.method],
            )
    axes[0].set_ylabel("position error (mm)")
    axes[1].set_ylabel("rotation error (deg)")
    axes[1].set_xlabel("move index")
    axes[1].xaxis.set_major_locator(MaxNLocator(integer=True))  # moves are whole numbers
    axes[0].legend(fontsize="small")
    n_off = sum(len(v[1]) for v in off.values())
    axes[0].set_title(
        title
        or "cube pose estimate vs true pose (median per move, all logged estimates)"
        + (f"\n{n_off} off-scale estimate(s) drawn as ▲ on the top edge" if n_off else "")
    )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return PoseErrorPlot(path, tuple(o for v in off.values() for o in v[1]))
