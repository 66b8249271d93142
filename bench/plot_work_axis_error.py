"""Per-grasp belief error along the work axis against move index: sensor-aided vs dead reckoning (not a test).

The work axis is the axis the hands grip along (world y for the PR2's side
grips): a belief off along it by more than half a cubie (9.5 mm) puts a pad
on the wrong slab. Reads result stores written by ``benchharness run``:

* sensor-aided: the ``pretouch`` event of every grasp (the work-axis error of
  the belief the grasp is made from, after the sweeps; and before them, the
  dead-reckoned belief the sweeps started from, drawn faint);
* dead reckoning: the pose estimate logged after every plan action (its world
  y error), which is the belief the next grasp is made from.

The truth is the engine's, read for the record only. Errors are against the
world, so they include the grasping arm's calibration offset (1.5 mm per
axis by default), which that arm's commands share::

    python bench/plot_work_axis_error.py --sensor-aided sa.sqlite --dead-reckoning dr.sqlite \\
        --task Rubiks-5-5 --out docs/img/work_axis_error_rubiks_5_5.png
"""

from __future__ import annotations

import argparse
import json
import sqlite3
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

HALF_CUBIE_MM = 9.5
#: top of the y axis (mm); larger errors (a dropped cube) are drawn at it as a triangle
Y_MAX = 14.0


def _clip(ys: list[float]) -> list[float]:
    return [min(y, Y_MAX) for y in ys]


def _trials(store: Path, task: str | None, strategy: str) -> list[tuple[str, dict]]:
    con = sqlite3.connect(store)
    try:
        cols = {r[1] for r in con.execute("pragma table_info(trials)")}
        where, args = (
            ["strategy = ?"] if "strategy" in cols else [],
            [strategy] if "strategy" in cols else [],
        )
        if task is not None and "task" in cols:
            where.append("task = ?")
            args.append(task)
        q = "select status, diagnostics_json from trials"
        if where:
            q += " where " + " and ".join(where)
        return [(s, json.loads(d)) for s, d in con.execute(q + " order by rowid", args) if d]
    finally:
        con.close()


def sensor_aided_points(diag: dict) -> tuple[list[int], list[float], list[float]]:
    """(move index, |work-axis error| after the sweeps, before them) in mm, one per grasp."""
    ev = [e for e in diag["events"] if e["kind"] == "pretouch" and "work_err_mm" in e]
    return (
        [int(e["move_index"]) for e in ev],
        [abs(float(e["work_err_mm"])) for e in ev],
        [abs(float(e["work_err_mm_before"])) for e in ev],
    )


def dead_reckoning_points(diag: dict) -> tuple[list[int], list[float]]:
    """(move index, |world-y error| in mm) of every logged estimate but the camera's and the release's."""
    xs, ys = [], []
    for e in diag["pose_estimates"]:
        if e["label"] in ("camera", "release"):
            continue
        xs.append(int(e["move_index"]))
        ys.append(abs(1000.0 * (e["estimated"][1] - e["true"][1])))
    return xs, ys


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sensor-aided", type=Path, required=True)
    ap.add_argument("--dead-reckoning", type=Path, required=True)
    ap.add_argument("--task", default=None)
    ap.add_argument("--title", default=None)
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args(argv)

    fig = Figure(figsize=(6.4, 3.6), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    jitter = 0.12
    worst: dict[str, dict[int, float]] = {"dr": {}, "sa": {}}
    for k, (status, d) in enumerate(_trials(a.dead_reckoning, a.task, "dead-reckoning")):
        xs, ys = dead_reckoning_points(d)
        off = -jitter + 0.02 * k
        ax.plot([x + off for x in xs], _clip(ys), "o", ms=3, color="tab:red", alpha=0.6,
                label="dead reckoning (after each action)" if k == 0 else None)  # fmt: skip
        for x, y in zip(xs, ys):
            if y <= Y_MAX:
                worst["dr"][x] = max(worst["dr"].get(x, 0.0), y)
        if status != "success" and xs:
            ax.plot([xs[-1] + off], [min(ys[-1], Y_MAX)], "x", ms=9, mew=2, color="tab:red")
    for k, (status, d) in enumerate(_trials(a.sensor_aided, a.task, "sensor-aided")):
        xs, after, before = sensor_aided_points(d)
        off = jitter + 0.02 * k
        ax.plot([x + off for x in xs], _clip(before), ".", ms=3, color="tab:blue", alpha=0.25,
                label="sensor-aided, dead-reckoned before the sweeps" if k == 0 else None)  # fmt: skip
        ax.plot([x + off for x in xs], _clip(after), "o", ms=3, color="tab:blue",
                label="sensor-aided, after the sweeps (each grasp)" if k == 0 else None)  # fmt: skip
        big = [(x, y) for x, y in zip(xs, after) if y > Y_MAX]
        if big:
            ax.plot([x + off for x, _ in big], [Y_MAX] * len(big), "^", ms=7, color="tab:blue")
        for x, y in zip(xs, after):
            if (
                y <= Y_MAX
            ):  # an off-scale point is a dropped cube, not a belief: drawn, not in the line
                worst["sa"][x] = max(worst["sa"].get(x, 0.0), y)
        if status != "success" and xs:
            ax.plot([xs[-1] + off], [min(after[-1], Y_MAX)], "x", ms=9, mew=2, color="tab:blue")
    for key, colour, off in (("dr", "tab:red", -jitter), ("sa", "tab:blue", jitter)):
        pts = sorted(worst[key].items())
        if pts:
            ax.plot([x + off for x, _ in pts], _clip([y for _, y in pts]), "-", lw=1, color=colour,
                    label="worst per move (on scale)" if key == "sa" else None)  # fmt: skip
    ax.axhline(HALF_CUBIE_MM, color="k", ls="--", lw=1)
    ax.text(-0.2, HALF_CUBIE_MM + 0.3, "half a cubie (9.5 mm)", fontsize=8)
    ax.set_xlabel("move index (twists done)")
    ax.set_ylabel("|belief error| along work axis (mm)")
    ax.set_title(
        a.title
        or f"{a.task or ''} work-axis belief error per grasp (x: failed trial, ^: off scale)"
    )
    ax.set_ylim(0, Y_MAX + 0.5)
    ax.legend(fontsize=7, loc="center right", framealpha=0.9)
    fig.tight_layout()
    a.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(a.out)
    print(f"written {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
