"""Fig. 6 / Table II style planning results of the five in-grasp variants on the published Level I tasks.

Plans every task (or every ``--every``-th) with each variant, writes one
results file per object-frame model (``write_results`` format, method =
variant, reached = planned object pose), scores it through the metric module
(err_pos, err_pos%, err_or%) and prints a Markdown table with the median
planning time beside the paper's.

    .venv/bin/python bench/bench_ingrasp.py [--out DIR] [--every N] [--object-frame fingertips reference-finger]

Timings are single-threaded (``torch.set_num_threads(1)``) wall times of
the optimisation only (the hand model is built once).
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

#: Median planning times of the paper (IV-A2), seconds.
PAPER_PLAN_TIME = {
    "point-contact": 14.8,
    "ik-rigid": 4.4,
    "relaxed-position": 0.5,
    "relaxed-position-orientation": 0.3,
    "relaxed-rigidity": 0.5,
}
#: Table II (real-robot execution, medians): err_pos (cm), err_pos%, err_or%.
PAPER_TABLE2 = {
    "point-contact": (1.69, 36.81, 9.74),
    "relaxed-position": (1.64, 30.95, 10.43),
    "relaxed-position-orientation": (1.54, 29.19, 9.84),
    "relaxed-rigidity": (1.32, 28.67, 9.86),
}


def _q(a: np.ndarray) -> str:
    a = a[np.isfinite(a)]
    if a.size == 0:
        return "-"
    q1, m, q3 = np.percentile(a, [25, 50, 75])
    return f"{m:.3g} [{q1:.3g}, {q3:.3g}]"


def main(argv=None) -> int:
    import torch

    from benchharness.inhand.fileformat import read_results
    from benchharness.inhand.scoring import score_results
    from benchharness.strategies.ingrasp.config import VARIANTS, IngraspConfig
    from benchharness.strategies.ingrasp.hand import HandKinematics
    from benchharness.strategies.ingrasp.planner import plan
    from benchharness.strategies.ingrasp.problem import problem_from_task
    from benchharness.strategies.ingrasp.results import write_plan_results
    from benchharness.strategies.ingrasp.tasks import published_tasks

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="/tmp/benchharness-ingrasp")
    ap.add_argument("--every", type=int, default=1, help="plan every N-th task (1 = all 100)")
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS))
    ap.add_argument("--object-frame", nargs="+", default=["fingertips", "reference-finger"])
    args = ap.parse_args(argv)
    torch.set_num_threads(1)

    hand = HandKinematics()
    tasks = published_tasks()[:: args.every]
    print(
        f"# in-grasp planning, {len(tasks)} published Level I tasks, T = {IngraspConfig().waypoints} waypoints"
    )
    print(f"# {platform.processor() or platform.machine()}, torch {torch.__version__}, 1 thread\n")
    for frame in args.object_frame:
        cfg = IngraspConfig(object_frame=frame)
        rows, all_tasks, all_plans = [], [], []
        for v in args.variants:
            t0 = time.perf_counter()
            plans = [plan(hand, problem_from_task(t, hand), v, cfg) for t in tasks]
            wall = time.perf_counter() - t0
            all_tasks += tasks
            all_plans += plans
            rows.append((v, plans, wall))
            print(f"  [{frame}] {v}: {wall:.1f} s for {len(plans)} plans", file=sys.stderr)
        path = write_plan_results(
            Path(args.out) / f"ingrasp_{frame}.csv", all_tasks, all_plans, cfg
        )
        scored = score_results(read_results(path))
        s = scored.scores
        method = scored.results.method
        print(f"## object frame: {frame}  (results: {path})\n")
        print(
            "| method | n | err_pos (cm) | err_pos% | err_or% | plan time (s) | paper plan time (s) | converged | max projection (rad) |"
        )
        print("|---|---|---|---|---|---|---|---|---|")
        for v, plans, _ in rows:
            m = method == v
            conv = np.mean([p.converged for p in plans]) * 100
            proj = max(p.projection_change for p in plans)
            print(
                f"| {v} | {int(m.sum())} | {_q(s.err_pos[m] * 100)} | {_q(s.err_pos_percent[m])} | {_q(s.err_or_percent[m])} "
                f"| {_q(s.plan_time_s[m])} | {PAPER_PLAN_TIME[v]} | {conv:.0f} % | {proj:.1e} |"
            )
        print()
    print(
        "Paper, Table II (real-robot execution, not planning): "
        + "; ".join(f"{k} {a} cm / {b} % / {c} %" for k, (a, b, c) in PAPER_TABLE2.items())
    )
    from benchharness.strategies.ingrasp.tasks import published_level1_path

    pub = score_results(read_results(published_level1_path())).scores
    print(
        f"Published relaxed-rigidity 'final palm pose' (dataset): err_pos {_q(pub.err_pos * 100)} cm, "
        f"err_pos% {_q(pub.err_pos_percent)}, err_or% {_q(pub.err_or_percent)}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
