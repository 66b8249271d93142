"""Per-grasp belief error along the work axis against twists done: sensor-aided vs dead reckoning (not a test).

The work axis is the axis the hand approaches and grips along (world y for
the PR2's side grips): a belief off along it by more than half a cubie
(9.5 mm) puts a pad on the wrong slab. Reads result stores written by
``benchharness run`` and draws one panel per tier (both strategies in each,
the 9.5 mm line; a failed trial's first wrong twist (another slab turned,
jammed, misaligned; else its failure) marked at the worst of the grasps made
for it). The x axis counts the twists done before each grasp: the grasps at
k are made for twist k (from 0). Per grasp:

* sensor-aided: the ``pretouch`` event of every grasp (the work-axis error of
  the belief the grasp is made from, after the sweeps; and, faint, before
  them: the dead-reckoned belief the sweeps started from);
* dead reckoning: the ``grasp`` event of every grasp (the same quantity: the
  work-axis error of the belief the hand moves in with). Stores written
  before that event existed have only the pose estimate logged after every
  plan action; their world-y error is drawn instead (and the panel says so).

The truth is the engine's, read for the record only. Errors are against the
world, so they include the grasping arm's calibration offset (1.5 mm per
axis by default), which that arm's commands share. Points above the plot
(a belief off by more than ``Y_MAX``, 16 mm) are drawn at its top as
triangles; one off by more than ``DROP_MM`` (50 mm, the judge's drop
distance) is a cube no longer in the hands, not a belief, and is left out of
the statistics (counted apart).

One panel per tier, each from its own stores (a store may hold several
tiers: each panel reads only its task's trials)::

    python bench/plot_work_axis_error.py \\
        --tier Rubiks-5-5 sa_5_5.sqlite dr_5_5.sqlite \\
        --tier Rubiks-5-10 sa_5_10.sqlite dr_5_10.sqlite \\
        --tier Rubiks-5-20 sa_5_20.sqlite dr_5_20.sqlite \\
        --out docs/img/work_axis_error_five_trial_tiers.png --stats

or one panel, as before::

    python bench/plot_work_axis_error.py --sensor-aided sa.sqlite --dead-reckoning dr.sqlite \\
        --task Rubiks-5-5 --out work_axis_error_rubiks_5_5.png

``--stats`` also prints, per tier and strategy: trials and outcomes, the
number of grasps, the median / 95th percentile / worst work-axis error
(after the sweeps for sensor-aided; before them too), whether every grasp
stays below half a cubie, and per trial the first grasp that crosses it
(twists before it, simulated time) against the trial's first wrong twist (a
``move`` event not as intended: another slab turned, jammed, misaligned) or,
if none, its failure ("crossed before it" compares their times), with the
signed errors of the grasps made for that twist (> 0: the hand went in
deeper than it meant to; a one-slab rotator grip, "shift out", has 7 mm to
the middle slab that way, ``PR2RubiksConfig.rotator_offset``). ``--json
FILE`` writes the same as JSON.
"""

from __future__ import annotations

import argparse
import bisect
import json
import sqlite3
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

HALF_CUBIE_MM = 9.5
#: top of the y axis (mm); larger errors are drawn at it as a triangle
Y_MAX = 16.0
#: a belief off by more than this (mm: the judge's 5 cm drop distance) is a cube out of the hands
DROP_MM = 50.0
SA, DR = "sensor-aided", "dead-reckoning"
COLOURS = {SA: "tab:blue", DR: "tab:red"}


@dataclass
class Trial:
    """One stored trial's grasps: move index, |work-axis error| (mm), label; and how it ended."""

    index: int
    status: str
    cause: str | None
    twists: int
    score: float | None
    backend: str
    moves: list[int] = field(default_factory=list)  # twists done before each grasp
    errs: list[float] = field(default_factory=list)
    signed: list[float] = field(default_factory=list)  # > 0: the hand goes in deeper than meant
    before: list[float] = field(default_factory=list)  # sensor-aided: before the sweeps
    labels: list[str] = field(default_factory=list)
    hands: list[str] = field(default_factory=list)
    ts: list[float] = field(default_factory=list)  # simulated time of each grasp's record (s)
    source: str = ""  # "grasp", "pretouch" or "estimate" (world y after each action)
    #: the first thing that went wrong: a twist not as intended (wrong slab turned, jammed,
    #: misaligned) or the trial's failure, whichever came first: (move index, time, what)
    first_wrong: tuple[int, float, str] | None = None


def _rows(store: Path, task: str | None, strategy: str) -> list[tuple[Any, ...]]:
    con = sqlite3.connect(store)
    try:
        where, args = ["strategy = ?"], [strategy]
        if task is not None:
            where.append("task = ?")
            args.append(task)
        q = (
            "select trial_index, status, failure_cause, score, backend, diagnostics_json from trials "
            "where " + " and ".join(where) + " order by trial_index"
        )
        return list(con.execute(q, args))
    finally:
        con.close()


def sensor_aided_points(diag: dict) -> list[dict[str, Any]]:
    """One per grasp: time, hand, label, signed work-axis error after the sweeps and before them (mm)."""
    return [
        {
            "t": float(e["t"]),
            "hand": e.get("hand", ""),
            "label": str(e["label"]),
            "err": float(e["work_err_mm"]),
            "before": float(e["work_err_mm_before"]),
        }
        for e in diag["events"]
        if e["kind"] == "pretouch" and "work_err_mm" in e
    ]


def dead_reckoning_points(diag: dict) -> tuple[list[dict[str, Any]], str]:
    """One per grasp: time, hand, label, signed work-axis error (mm); and the source.

    From the ``grasp`` events where the store has them; else (older stores)
    the world-y error of every logged estimate but the camera's and the
    release's (the belief after each plan action; no hand, sign arbitrary).
    """
    ev = [e for e in diag["events"] if e["kind"] == "grasp" and "work_err_mm" in e]
    if ev:
        return [
            {
                "t": float(e["t"]),
                "hand": e.get("hand", ""),
                "label": str(e["label"]),
                "err": float(e["work_err_mm"]),
            }
            for e in ev
        ], "grasp"
    return [
        {
            "t": float(e["t"]),
            "hand": "",
            "label": str(e["label"]),
            "err": 1000.0 * (e["estimated"][1] - e["true"][1]),
        }
        for e in diag["pose_estimates"]
        if e["label"] not in ("camera", "release")
    ], "estimate"


def first_wrong(diag: dict) -> tuple[int, float, str] | None:
    """(twist index, time, what) of the first twist not as intended or else of the failure, if any."""
    n_moves = 0
    for e in diag["events"]:
        if e["kind"] == "move":
            if not e.get("as_intended", True):
                return n_moves, float(e["t"]), str(e.get("outcome", ""))
            n_moves += 1
        elif e["kind"] == "failure":
            return n_moves, float(e["t"]), f"{e.get('cause')}: {e.get('message', '')}"
    return None


def load(store: Path, task: str | None, strategy: str) -> list[Trial]:
    """Every stored trial of ``strategy`` (and ``task``) in ``store``, with its grasps.

    A grasp's x is the number of twists done before it (``move`` events
    earlier in simulated time): the grasps at x = k are made for twist k
    (counting from 0), or, at x = N, for the release.
    """
    out = []
    for index, status, cause, score, backend, dj in _rows(store, task, strategy):
        diag = json.loads(dj) if dj else {}
        if not diag:
            continue
        twists = sum(  # twists done as intended
            e["kind"] == "move" and e.get("as_intended", True) for e in diag["events"]
        )
        t = Trial(int(index), str(status), cause, twists, score, str(backend))
        if strategy == SA:
            pts = sensor_aided_points(diag)
            t.source = "pretouch"
        else:
            pts, t.source = dead_reckoning_points(diag)
        move_t = sorted(float(e["t"]) for e in diag["events"] if e["kind"] == "move")
        t.moves = [bisect.bisect_right(move_t, p["t"]) for p in pts]
        t.signed = [p["err"] for p in pts]
        t.errs = [abs(p["err"]) for p in pts]
        t.before = [abs(p["before"]) for p in pts if "before" in p]
        t.labels = [p["label"] for p in pts]
        t.hands = [p["hand"] for p in pts]
        t.ts = [p["t"] for p in pts]
        t.first_wrong = first_wrong(diag)
        out.append(t)
    return out


def _pct(xs: list[float], q: float) -> float | None:
    return round(float(np.percentile(xs, q)), 2) if xs else None


def stats(trials: list[Trial]) -> dict[str, Any]:
    """The tier's grasps for one strategy: counts, median / p95 / worst, and each trial's first crossing."""
    held = [e for t in trials for e in t.errs if e <= DROP_MM]
    per_trial = []
    for t in trials:
        first = next(
            (k for k, e in enumerate(t.errs) if HALF_CUBIE_MM <= e <= DROP_MM), None
        )  # a dropped cube is not a crossing
        per_trial.append(
            {
                "trial": t.index,
                "status": t.status,
                "cause": t.cause,
                "score": round(t.score, 2) if t.score is not None else None,
                "twists_done": t.twists,
                "grasps": len(t.errs),
                "worst_mm": round(max((e for e in t.errs if e <= DROP_MM), default=0.0), 2),
                "dropped_points": sum(e > DROP_MM for e in t.errs),
                "first_crossing": None
                if first is None
                else {
                    "grasp": first + 1,
                    "label": t.labels[first],
                    "twists_before": t.moves[first],
                    "t": round(t.ts[first], 2),
                    "err_mm": round(t.errs[first], 2),
                },
                "crossings": sum(HALF_CUBIE_MM <= e <= DROP_MM for e in t.errs),
                "first_wrong": None
                if t.first_wrong is None
                else {
                    "twist": t.first_wrong[0],
                    "t": round(t.first_wrong[1], 2),
                    "what": t.first_wrong[2],
                },
                "crossed_before_first_wrong": None
                if t.first_wrong is None or first is None
                else bool(t.ts[first] < t.first_wrong[1]),
                # the grasps made for the first wrong twist (after the twist before it), signed
                "grasps_for_first_wrong": []
                if t.first_wrong is None
                else [
                    {"label": lb, "hand": h, "err_mm": round(e, 2)}
                    for x, tt, lb, h, e in zip(t.moves, t.ts, t.labels, t.hands, t.signed)
                    if x == t.first_wrong[0] and tt < t.first_wrong[1]
                ],
            }
        )
    out: dict[str, Any] = {
        "trials": len(trials),
        "successes": sum(t.status == "success" for t in trials),
        "grasps": sum(len(t.errs) for t in trials),
        "dropped_points": sum(e > DROP_MM for t in trials for e in t.errs),
        "median_mm": _pct(held, 50),
        "p95_mm": _pct(held, 95),
        "worst_mm": round(max(held), 2) if held else None,
        "all_below_half_cubie": all(e < HALF_CUBIE_MM for e in held),
        "source": sorted({t.source for t in trials}),
        "per_trial": per_trial,
    }
    before = [e for t in trials for e in t.before if e <= DROP_MM]
    if before:
        out["before_sweeps"] = {
            "median_mm": _pct(before, 50),
            "p95_mm": _pct(before, 95),
            "worst_mm": round(max(before), 2),
        }
    return out


def _clip(ys: list[float]) -> list[float]:
    return [min(y, Y_MAX) for y in ys]


def draw_panel(ax: Any, task: str, sa: list[Trial], dr: list[Trial], legend: bool) -> None:
    """One tier: every trial's grasps of both strategies, the per-move worst, failures and the line."""
    jitter = 0.14
    for strategy, trials, side in ((DR, dr, -1), (SA, sa, +1)):
        colour = COLOURS[strategy]
        worst: dict[int, float] = {}
        n = max(len(trials), 1)
        for k, t in enumerate(trials):
            off = side * jitter + side * 0.05 * (k - (n - 1) / 2) / n
            xs = [x + off for x in t.moves]
            if strategy == SA:
                ax.plot(xs, _clip(t.before), ".", ms=2.5, color=colour, alpha=0.25,
                        label="sensor-aided, before the sweeps" if k == 0 else None)  # fmt: skip
            ax.plot(xs, _clip(t.errs), "o", ms=2.8, color=colour, alpha=0.7, mew=0,
                    label=("sensor-aided, after the sweeps" if strategy == SA
                           else "dead reckoning, each grasp") if k == 0 else None)  # fmt: skip
            big = [(x, y) for x, y in zip(xs, t.errs) if y > Y_MAX]
            if big:
                ax.plot([x for x, _ in big], [Y_MAX] * len(big), "^", ms=6, color=colour)
            for x, y in zip(t.moves, t.errs):
                if y <= DROP_MM:
                    worst[x] = max(worst.get(x, 0.0), y)
            if t.status != "success" and t.moves:
                # the first wrong twist (or the failure), at the worst of the grasps made for it
                k = t.first_wrong[0] if t.first_wrong else t.moves[-1]
                cut = t.first_wrong[1] if t.first_wrong else float("inf")
                mine = [i for i, (x, tt) in enumerate(zip(t.moves, t.ts)) if x == k and tt < cut]
                i = max(mine, key=lambda i: t.errs[i]) if mine else len(t.errs) - 1
                x, y = (xs[i], min(t.errs[i], Y_MAX)) if mine else (k + off, 0.0)
                ax.plot([x], [y], "x", ms=9, mew=2, color=colour)
                ax.annotate(f"T{t.index}", (x, y), xytext=(3, 4), textcoords="offset points",
                            fontsize=7, color=colour)  # fmt: skip
        pts = sorted(worst.items())
        if pts:
            ax.plot([x + side * jitter for x, _ in pts], _clip([y for _, y in pts]), "-", lw=1,
                    color=colour, label=("sensor-aided" if strategy == SA else "dead reckoning")
                    + ", worst per move")  # fmt: skip
    ax.axhline(HALF_CUBIE_MM, color="k", ls="--", lw=1,
               label=f"half a cubie ({HALF_CUBIE_MM} mm)" if legend else None)  # fmt: skip
    ok = {s: sum(t.status == "success" for t in ts) for s, ts in ((SA, sa), (DR, dr))}
    engines = ", ".join(sorted({t.backend for t in sa + dr}))
    ax.set_title(
        f"{task} ({engines}): sensor-aided {ok[SA]}/{len(sa)}, dead reckoning {ok[DR]}/{len(dr)}"
        " trials in the expected state",
        fontsize=9,
    )
    ax.set_ylim(0, Y_MAX + 0.8)
    last = max([x for t in sa + dr for x in t.moves] or [0])
    if task.count("-") == 2 and task.rsplit("-", 1)[1].isdigit():  # Rubiks-M-N: twists 0..N-1
        last = max(last, int(task.rsplit("-", 1)[1]) - 1)
    ax.set_xlim(-0.6, last + 0.6)
    ax.set_xticks(range(0, last + 1, 1 if last <= 10 else 2))
    ax.set_xlabel(
        "twists done before the grasp (the grasps at k are made for twist k, from 0)", fontsize=8
    )
    ax.set_ylabel("|belief error| along\nthe work axis (mm)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(axis="y", lw=0.3, alpha=0.5)
    if any(t.source == "estimate" for t in dr):
        ax.text(0.99, 0.97, "dead reckoning: world y after each action (older store)",
                transform=ax.transAxes, ha="right", va="top", fontsize=6)  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--tier", nargs=3, action="append", default=[],
                    metavar=("TASK", "SA_STORE", "DR_STORE"),
                    help="one panel: the task and the stores of its sensor-aided and dead-reckoning "
                    "runs (repeatable, top to bottom)")  # fmt: skip
    ap.add_argument("--sensor-aided", type=Path, help="one panel: the sensor-aided store")
    ap.add_argument("--dead-reckoning", type=Path, help="one panel: the dead-reckoning store")
    ap.add_argument("--task", default=None, help="one panel: only this task's trials")
    ap.add_argument("--title", default=None, help="figure title")
    ap.add_argument("--out", type=Path, required=True, help="the figure (.png, .svg)")
    ap.add_argument("--stats", action="store_true", help="print the statistics per tier")
    ap.add_argument("--json", type=Path, default=None, help="write the statistics as JSON here")
    a = ap.parse_args(argv)

    panels: list[tuple[str | None, Path, Path]] = [(t, Path(s), Path(d)) for t, s, d in a.tier]
    if a.sensor_aided or a.dead_reckoning:
        if not (a.sensor_aided and a.dead_reckoning):
            ap.error("--sensor-aided and --dead-reckoning go together")
        panels.append((a.task, a.sensor_aided, a.dead_reckoning))
    if not panels:
        ap.error(
            "give --tier TASK SA_STORE DR_STORE (repeatable) or --sensor-aided/--dead-reckoning"
        )

    fig = Figure(figsize=(7.5, 1.3 + 2.7 * len(panels)), dpi=110)
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0]
    report: dict[str, Any] = {}
    for i, (task, sa_store, dr_store) in enumerate(panels):
        sa, dr = load(sa_store, task, SA), load(dr_store, task, DR)
        draw_panel(axes[i], task or "", sa, dr, legend=i == 0)
        report[task or f"panel {i + 1}"] = {SA: stats(sa), DR: stats(dr)}
    fig.suptitle(
        a.title
        or "PR2: belief error along the work axis at every grasp\n"
        "(x: a failed trial's first wrong twist, at the worst grasp made for it; T: the trial)",
        fontsize=9.5,
    )
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.42 / fig.get_figheight(), 1, 1))
    a.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(a.out)
    print(f"written {a.out}")
    if a.json is not None:
        a.json.write_text(json.dumps(report, indent=1))
    if a.stats:
        for task, by in report.items():
            for strategy, s in by.items():
                head = (
                    f"{task} {strategy}: {s['successes']}/{s['trials']} ok, {s['grasps']} grasps, "
                    f"median {s['median_mm']} / p95 {s['p95_mm']} / worst {s['worst_mm']} mm, "
                    f"all < {HALF_CUBIE_MM} mm: {s['all_below_half_cubie']}"
                )
                if s["dropped_points"]:
                    head += f" ({s['dropped_points']} dropped-cube points left out)"
                if "before_sweeps" in s:
                    b = s["before_sweeps"]
                    head += (
                        f"; before the sweeps {b['median_mm']} / {b['p95_mm']} / {b['worst_mm']}"
                    )
                print(head)
                for t in s["per_trial"]:
                    fc = t["first_crossing"]
                    cross = (
                        "never crosses"
                        if fc is None
                        else f"first crosses at grasp {fc['grasp']} ({fc['label']}, before twist "
                        f"{fc['twists_before']}, {fc['err_mm']} mm; {t['crossings']} grasps over)"
                    )
                    fw = t["first_wrong"]
                    wrong = (
                        ""
                        if fw is None
                        else f"; first wrong: twist {fw['twist']} (t {fw['t']} s): {fw['what']}"
                        f"; crossed before it: {t['crossed_before_first_wrong']}; its grasps: "
                        + ", ".join(
                            f"{g['label']} ({g['hand']}) {g['err_mm']:+.2f}"
                            for g in t["grasps_for_first_wrong"]
                        )
                    )
                    print(
                        f"  T{t['trial']}: {t['status']}{' (' + t['cause'] + ')' if t['cause'] else ''}"
                        f", {t['twists_done']} twists as intended, score {t['score']}, {t['grasps']} "
                        f"grasps, worst {t['worst_mm']} mm, {cross}{wrong}"
                    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
