"""Per-step CPU cost of the PR2 + cube scene, robust to a shared machine (not a test).

On a 2-core machine shared with other jobs, wall-clock rates swing by ±50 %
and even CPU time inflates when a sibling hyper-thread is busy. This script
times many short blocks (120 steps each) of CPU time (``time.process_time``)
and reports the **minimum** per block, which approximates the cost of a
step when nothing else interferes. Loops (same scene as
``bench_robots.py``):

* ``physics`` — ``backend.step(120)``, PD targets set once;
* ``engine``  — the engine's own step in a bare loop (see ``bench_robots.py``);
* ``control`` — ``robot.settle(0.5)``: the robot's 120 Hz control loop on top.

Usage::

    python bench/bench_step_cost.py [--backends pybullet,sapien] [--blocks 12]

To compare two versions of the code, run it under each source tree
(``PYTHONPATH=/path/to/other/src python bench/bench_step_cost.py``),
alternating, a few times.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import torch

torch.set_num_threads(1)

from bench_robots import _engine_step_fn, build_scene  # noqa: E402

from benchharness.backends.interface import PhysicsConfig  # noqa: E402


def measure(name: str, blocks: int) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        be, robot, _ = build_scene(name, PhysicsConfig())
    eng = _engine_step_fn(be)
    res: dict[str, list[float]] = {"physics": [], "engine": [], "control": []}
    for _ in range(blocks):
        c0 = time.process_time()
        be.step(120)
        res["physics"].append(time.process_time() - c0)
        c0 = time.process_time()
        for _ in range(120):
            eng()
        res["engine"].append(time.process_time() - c0)
        c0 = time.process_time()
        robot.settle(120 * be.config.timestep)
        res["control"].append(time.process_time() - c0)
    be.close()
    return {k: round(1e6 * min(v) / 120, 1) for k, v in res.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--backends", default="pybullet,sapien")
    ap.add_argument("--blocks", type=int, default=12)
    args = ap.parse_args()
    out = {b: measure(b, args.blocks) for b in args.backends.split(",")}
    out["load_avg_1min"] = os.getloadavg()[0]
    print(json.dumps(out))


if __name__ == "__main__":
    main()
