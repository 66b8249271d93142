"""Box plots in the style of the paper's Figure 7.

One panel per metric, stacked; along x one cluster per group (object), one
coloured box per method inside it. Boxes are drawn with ``Axes.bxp`` from
the statistics of :func:`benchharness.metrics.stats.box_stats`: median line,
quartile box, whiskers at the extreme inliers within 1.5 IQR, outliers as
points; a group with one sample (a box of zero height) is drawn as a
median line and a diamond in its method's colour. Uses the object-oriented matplotlib API with the Agg canvas, never
``pyplot``, so it has no global figure state and needs no display.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from .stats import BoxStats, GroupStats

__all__ = ["BoxPlot", "box_plot"]


@dataclass(frozen=True)
class BoxPlot:
    """The figure and, per metric panel, the artists ``Axes.bxp`` returned."""

    figure: Figure
    artists: Mapping[str, dict]
    groups: tuple[str, ...]
    hues: tuple[str, ...]


def _scaled(b: BoxStats, s: float) -> BoxStats:
    return BoxStats(
        b.n,
        b.median * s,
        b.q1 * s,
        b.q3 * s,
        b.whisker_low * s,
        b.whisker_high * s,
        b.minimum * s,
        b.maximum * s,
        b.mean * s,
        tuple(v * s for v in b.outliers),
    )


def box_plot(
    summaries: Sequence[GroupStats],
    metrics: Sequence[str],
    path: str | Path | None = None,
    *,
    group_col: str = "object",
    hue_col: str = "method",
    labels: Mapping[str, str] | None = None,
    scales: Mapping[str, float] | None = None,
    title: str | None = None,
) -> BoxPlot:
    """Draw (and, given ``path``, save as PNG/SVG by suffix) the box plot.

    ``summaries`` must be grouped by both ``group_col`` and ``hue_col``
    (e.g. ``summarize_scores(..., by=("object", "method"))``). Metrics with
    no data in any group are skipped. ``scales`` converts stored SI values
    for display (e.g. 100 for metres -> cm) and ``labels`` names the y axes.
    """
    if not summaries:
        raise ValueError("nothing to plot")
    by = summaries[0].by
    if group_col not in by or hue_col not in by:
        raise ValueError(f"summaries must be grouped by {group_col!r} and {hue_col!r}, got {by}")
    gi, hi = by.index(group_col), by.index(hue_col)
    groups = tuple(dict.fromkeys(s.key[gi] for s in summaries))
    hues = tuple(dict.fromkeys(s.key[hi] for s in summaries))
    cells = {(s.key[gi], s.key[hi]): s for s in summaries}
    shown = [m for m in metrics if any(s.stats[m].n for s in summaries if m in s.stats)]
    if not shown:
        raise ValueError(f"no data for any of {list(metrics)}")
    labels = labels or {}
    scales = scales or {}
    colours = [f"C{i % 10}" for i in range(len(hues))]
    width = 0.8 / max(len(hues), 1)

    fig = Figure(
        figsize=(
            min(16.0, max(6.0, 0.35 * len(groups) * max(len(hues), 1) + 2.0)),
            3.0 * len(shown) + 0.9,
        )
    )
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(shown), 1, sharex=True, squeeze=False)[:, 0]
    artists: dict[str, dict] = {}
    for ax, metric in zip(axes, shown):
        scale = scales.get(metric, 1.0)
        stats, positions, faces, flat = [], [], [], []
        for g, group in enumerate(groups):
            for h, hue in enumerate(hues):
                cell = cells.get((group, hue))
                if cell is None or cell.stats[metric].n == 0:
                    continue
                b = _scaled(cell.stats[metric], scale)
                stats.append(b.as_bxp(f"{group} / {hue}"))
                positions.append(g + (h - (len(hues) - 1) / 2) * width)
                faces.append(colours[h])
                flat.append(b.q3 <= b.q1)  # one sample (or all equal): a box of zero height
        art = ax.bxp(
            stats,
            positions=positions,
            widths=width * 0.85,
            patch_artist=True,
            showfliers=True,
            medianprops={"color": "black", "linewidth": 1.4},
            flierprops={"marker": "o", "markersize": 3, "markerfacecolor": "none"},
        )
        for patch, colour in zip(art["boxes"], faces):
            patch.set_facecolor(colour)
            patch.set_alpha(0.75)
        # A zero-height box shows no face: only its black median line would be
        # seen, with no method colour. Draw its median in the method's colour
        # with a marker, so a single sample still says which method it is.
        singles = []
        for k in (k for k, f in enumerate(flat) if f):
            art["medians"][k].set_color(faces[k])
            art["medians"][k].set_linewidth(2.5)
            singles.append(
                ax.scatter(
                    [positions[k]],
                    [stats[k]["med"]],
                    marker="D",
                    s=22,
                    color=faces[k],
                    edgecolors="black",
                    linewidths=0.6,
                    zorder=3,
                )
            )
        art["singles"] = singles
        artists[metric] = art
        ax.set_ylabel(labels.get(metric, metric))
        ax.grid(axis="y", alpha=0.3)
        ax.set_xlim(-0.6, len(groups) - 0.4)
    axes[-1].set_xticks(np.arange(len(groups)))
    axes[-1].set_xticklabels(groups, rotation=30, ha="right")
    axes[-1].set_xlabel(group_col)
    # As many legend columns as fit the figure width (long "method (robot, backend)" labels
    # would otherwise run off the canvas), and room above the panels for its rows.
    longest = max((len(str(h)) for h in hues), default=1)
    ncol = max(1, min(len(hues), 5, int(fig.get_figwidth() * 72 / (6.5 * longest + 40))))
    rows = -(-len(hues) // ncol)
    fig.legend(
        handles=[Patch(facecolor=c, alpha=0.75, label=h) for h, c in zip(hues, colours)],
        loc="upper center",
        ncol=ncol,
        frameon=False,
        title=title,
    )
    fig.tight_layout(rect=(0, 0, 1, 1 - (0.3 + 0.25 * rows) / fig.get_figheight()))
    if path is not None:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=120)
    return BoxPlot(fig, artists, groups, hues)
