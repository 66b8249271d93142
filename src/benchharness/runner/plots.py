"""Pose-estimate error against move index, per method, from the stored diagnostics.

This is the plot that explains Table I: dead reckoning's believed cube pose
drifts away from the true one move after move, a sensor-aided strategy's
stays bounded. Points are every logged estimate; the line is the median per
move index.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .reports import _columns
from .store import StoredTrial

__all__ = ["pose_error_series", "plot_pose_error"]


def pose_error_series(trials: Sequence[StoredTrial]) -> dict[str, dict[str, np.ndarray]]:
    """method label -> {"move": (n,), "pos_mm": (n,), "rot_deg": (n,)} over all its logged estimates."""
    _, col_of = _columns(trials)
    acc: dict[str, list[tuple[int, float, float]]] = defaultdict(list)
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
                    float(e.get("rot_err_deg") or np.nan),
                )
            )
    out = {}
    for label, rows in acc.items():
        a = np.array(rows, float)
        out[label] = {"move": a[:, 0].astype(int), "pos_mm": a[:, 1], "rot_deg": a[:, 2]}
    return out


def plot_pose_error(trials: Sequence[StoredTrial], path: str | Path, title: str = "") -> Path:
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

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True, constrained_layout=True)
    for i, (label, s) in enumerate(series.items()):
        color = f"C{i % 10}"
        moves = np.unique(s["move"])
        for ax, key in zip(axes, ("pos_mm", "rot_deg")):
            ax.scatter(s["move"], s[key], s=8, alpha=0.35, color=color)
            med = [np.nanmedian(s[key][s["move"] == m]) for m in moves]
            ax.plot(moves, med, color=color, label=label)
    axes[0].set_ylabel("position error (mm)")
    axes[1].set_ylabel("rotation error (deg)")
    axes[1].set_xlabel("move index")
    axes[1].xaxis.set_major_locator(MaxNLocator(integer=True))  # moves are whole numbers
    axes[0].legend(fontsize="small")
    axes[0].set_title(
        title or "cube pose estimate vs true pose (median per move, all logged estimates)"
    )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
