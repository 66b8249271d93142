"""Table III for our DMG planner on the four published Level III tasks.

Builds each object's graph (DMG time), plans the task (Plan time), writes the
results file (``write_results`` format, meshes beside it), scores it through
the metric module and prints a Markdown table next to the published figures.

    .venv/bin/python bench/bench_dmg.py [--out DIR] [--repeat N] [--model generated|ycb]

``--repeat`` times the graph construction and the query N times and reports
the median (the planner is deterministic, so the plans are identical).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

#: Table III of the paper (gelatin box, cracker box, spatula, potted meat can).
PUBLISHED = {
    "err_pos (cm)": (0.505, 0.267, 0.513, 0.610),
    "err_pos%": (9.9, 2.7, 8.8, 11.0),
    "err_or%": (0.016, 0.044, 0.023, 0.049),
    "G_euc (cm)": (1.125, 0.862, 0.746, 0.663),
    "G_geo (cm)": (1.127, 0.862, 1.505, 0.663),
    "G_min (cm)": (0.013, 0.057, 0.034, 0.004),
    "DMG time (s)": (10.312, 15.467, 13.406, 18.295),
    "Plan time (s)": (0.023, 0.004, 6.7e-05, 0.002),
}


def main(argv=None) -> int:
    from benchharness.inhand.fileformat import read_results, read_tasks, write_results
    from benchharness.inhand.scoring import score_results
    from benchharness.strategies.dmg.config import DMGSurface
    from benchharness.strategies.dmg.strategy import (
        DESIRED_REGION_RADIUS,
        FINGER_PAD_RADIUS,
        DMGPlanner,
        ReachedGrasp,
        results_for_grasps,
        write_dmg_results,
    )

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tasks", default=str(ROOT / "tasks/inhand/level3_dmg_tasks.csv"))
    ap.add_argument("--published", default=str(ROOT / "tasks/inhand/published/yumi_lvl3_dmg.csv"))
    ap.add_argument(
        "--out", default="/tmp/benchharness-dmg", help="folder for results.csv and meshes/"
    )
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument(
        "--model",
        choices=("generated", "ycb"),
        default="generated",
        help="object model planned on and scored (DMGSurface.model; ycb: the vendored scans)",
    )
    args = ap.parse_args(argv)

    tasks = read_tasks(args.tasks)
    graph_times: dict[str, list[float]] = {}
    plan_times: dict[str, list[float]] = {}
    plans = None
    for _ in range(max(1, args.repeat)):
        planner = DMGPlanner(surface=DMGSurface(model=args.model))
        plans = planner.plan_tasks(tasks)
        for p in plans:
            graph_times.setdefault(p.task_id, []).append(p.graph_time_s)
            # the first query also pays lazy imports; re-time it on the warm graph
            t0 = time.perf_counter()
            planner.plan_task(tasks, list(tasks.task_id).index(p.task_id))
            plan_times.setdefault(p.task_id, []).append(time.perf_counter() - t0)
    out = Path(args.out)
    path = write_dmg_results(tasks, plans, planner, out / "results.csv")
    scored = score_results(read_results(path))
    s = scored.scores

    # the paper's own final grasps, scored on our meshes with the same regions and pads
    pub = read_results(args.published)
    pub_rows = [list(pub.task_id).index(p.task_id) for p in plans]
    pub_grasps = [
        ReachedGrasp(p.task_id, p.object, pub.contacts["reached"][j, :2], pub.reached[j])
        for p, j in zip(plans, pub_rows)
    ]
    pub_path = out / "published_on_our_meshes.csv"
    write_results(
        results_for_grasps(tasks, pub_grasps, planner, out, "DMG (paper, our meshes)"), pub_path
    )
    ps = score_results(read_results(pub_path)).scores

    cols = [f"{p.object}" for p in plans]
    rows = {
        "err_pos (cm)": s.err_pos * 100,
        "err_pos%": s.err_pos_percent,
        "err_or%": s.err_or_percent,
        "G_euc (cm)": s.g_euc * 100,
        "G_geo (cm)": s.g_geo * 100,
        "G_min (cm)": s.g_min * 100,
        "DMG time (s)": np.array([statistics.median(graph_times[p.task_id]) for p in plans]),
        "Plan time (s)": np.array([statistics.median(plan_times[p.task_id]) for p in plans]),
    }
    print(
        f"results: {path}  (desired region: geodesic discs of {DESIRED_REGION_RADIUS * 1e3:.0f} mm; "
        f"finger pads: geodesic discs of {FINGER_PAD_RADIUS * 1e3:.0f} mm)"
    )
    print()
    rescored = {
        "err_pos (cm)": ps.err_pos * 100,
        "err_pos%": ps.err_pos_percent,
        "err_or%": ps.err_or_percent,
        "G_euc (cm)": ps.g_euc * 100,
        "G_geo (cm)": ps.g_geo * 100,
        "G_min (cm)": ps.g_min * 100,
    }
    print("Cells: ours / paper (Table III) / the paper's final grasps scored on our meshes.")
    print()
    print("| metric | " + " | ".join(cols) + " |")
    print("|---" * (len(cols) + 1) + "|")
    for name, vals in rows.items():
        cells = []
        for j, (v, ref) in enumerate(zip(vals, PUBLISHED[name])):
            fmt = "{:.3g}" if "time" in name else "{:.3f}"
            cell = f"{fmt.format(v)} / {ref:g}"
            if name in rescored:
                cell += f" / {fmt.format(rescored[name][j])}"
            cells.append(cell)
        print(f"| {name} | " + " | ".join(cells) + " |")
    print()
    print(
        "| task | reached goal node | primitives | translation (cm) | rotation (deg) | patches | states | edges |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for p in plans:
        g = planner.graph(p.object)
        prims = " ".join(
            f"T{q.length * 100:.1f}" if q.kind == "translate" else f"R{np.degrees(q.angle):+.1f}"
            for q in p.plan.primitives
        )
        print(
            f"| {p.task_id} | {p.plan.reached_goal} | {prims} | {p.plan.translation_length * 100:.1f} | "
            f"{np.degrees(p.plan.total_rotation):.0f} | {len(g.patches)} | {g.graph.number_of_nodes()} | {g.graph.number_of_edges()} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
