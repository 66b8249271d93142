"""Wall time and real-time factor of whole Rubik's tiers (issue 4's performance figures; not a test).

For every (strategy, backend) it runs one tier through the runner exactly as
``benchharness run`` does (same seeding, same store code path) into a fresh
temporary store, and reports per run: trials completed, simulated seconds
(robot start to termination, summed over trials), wall seconds of the whole
sweep, and the real-time factor (simulated / wall). With ``--workers N`` the
trials run in N worker processes, as ``benchharness run --workers N``.

Targets (issue 4): a full Rubiks-5-20 run of one strategy in under 5 minutes
on the 2-core machine (the paper's robot needed 5 x 417 s)::

    python bench/bench_rubiks.py                                   # Rubiks-1-20, both baselines, both engines
    python bench/bench_rubiks.py --task Rubiks-5-20 --strategies sensor-aided --workers 2

Simulated times and outcomes are deterministic per machine; wall times move
with load (run it on a quiet machine and quote the load, printed at the end).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")


def run_one(task: str, strategy: str, backend: str, robot: str, seed: int, workers: int) -> dict:
    from benchharness.runner import ResultsStore, RunSpec, run_sweep

    spec = RunSpec(task=task, robot=robot, strategy=strategy, backend=backend, seed=seed)
    with tempfile.TemporaryDirectory() as tmp:
        store = ResultsStore(Path(tmp) / "bench.sqlite")
        t0 = time.perf_counter()
        cpu0 = os.times()
        report = run_sweep(spec, store, workers=workers)
        wall = time.perf_counter() - t0
        cpu1 = os.times()
        store.close()
    recs = report.records
    sim = sum(float(r.sim_s or 0.0) for r in recs)
    cpu = (cpu1.user - cpu0.user) + (cpu1.children_user - cpu0.children_user)
    return {
        "task": task,
        "strategy": strategy,
        "backend": backend,
        "robot": robot,
        "seed": seed,
        "workers": workers,
        "trials": len(recs),
        "successes": sum(r.status.value == "success" for r in recs),
        "causes": [r.failure_cause.value if r.failure_cause else None for r in recs],
        "sim_s": round(sim, 2),
        "wall_s": round(wall, 2),
        "cpu_user_s": round(cpu, 2),
        "rtf": round(sim / wall, 2) if wall > 0 else None,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", default="Rubiks-1-20")
    ap.add_argument("--strategies", default="sensor-aided,dead-reckoning")
    ap.add_argument("--backends", default="pybullet,sapien")
    ap.add_argument("--robot", default="pr2")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=0, help="0: in this process (one core)")
    ap.add_argument("--json", type=Path, help="also write the rows here")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    rows = []
    print("| task | strategy | backend | workers | completed | sim s | wall s | RTF | CPU user s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for strategy in a.strategies.split(","):
        for backend in a.backends.split(","):
            r = run_one(a.task, strategy, backend, a.robot, a.seed, a.workers)
            rows.append(r)
            print(
                f"| {r['task']} | {strategy} | {backend} | {r['workers']} | {r['successes']}/{r['trials']} | "
                f"{r['sim_s']:.1f} | {r['wall_s']:.1f} | {r['rtf']} | {r['cpu_user_s']:.1f} |",
                flush=True,
            )
    load = os.getloadavg()
    print(
        f"\nload average at the end: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; {os.cpu_count()} CPUs"
    )
    if a.json:
        a.json.write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
