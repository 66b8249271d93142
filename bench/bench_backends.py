"""Raw step rate of the gripper + cube scene on every registered backend.

Not a test: run it by hand and copy the figures into docs/benchmarks/backends.md.

    .venv/bin/python bench/bench_backends.py [--seconds 5] [--iterations 50 20]

For each backend and solver-iteration count it builds the conformance suite's
scene (a parallel gripper holding a 5.7 cm, 94 g cube 10 cm above the ground,
20 N per finger), then times:

* ``step(n)``: the engine alone, no Python between steps;
* ``control``: one ``set_joint_targets`` call per step (a Python control loop);

and prints steps/s and the real-time factor (simulated s / wall s).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "backends"))

from backend_scenes import GRASP_Z, grasp_lift_hold, gripper_scene

from benchharness.backends import PhysicsConfig
from benchharness.plugin import get_manager


def bench(name: str, iterations: int, seconds: float) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        b = get_manager().create(
            "backend", name, config=PhysicsConfig(solver_iterations=iterations)
        )
    try:
        s = gripper_scene(b)
        grasp_lift_hold(s, hold_s=0.2)  # holding the cube in the air
        n = int(seconds / b.config.timestep)
        t0, c0 = time.perf_counter(), time.process_time()
        b.step(n)
        raw, raw_cpu = time.perf_counter() - t0, time.process_time() - c0
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(n):
            s.command()
            b.step()
        ctl, ctl_cpu = time.perf_counter() - t0, time.process_time() - c0
        held = abs(b.get_pose(s.cube).p[2] - (GRASP_Z - 0.065 + 0.10)) < 0.01
        return {
            "backend": name,
            "iterations": iterations,
            "steps": n,
            "raw_steps_s": n / raw,
            "raw_rtf": n * b.config.timestep / raw,
            "ctl_steps_s": n / ctl,
            "ctl_rtf": n * b.config.timestep / ctl,
            "raw_cpu_steps_s": n / raw_cpu,
            "ctl_cpu_steps_s": n / ctl_cpu,
            "held": held,
        }
    finally:
        b.close()


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--seconds", type=float, default=5.0, help="simulated seconds per measurement")
    ap.add_argument(
        "--iterations", type=int, nargs="+", default=[50, 20], help="solver iterations to try"
    )
    ap.add_argument("--backends", nargs="+", default=None, help="default: every registered backend")
    args = ap.parse_args()
    names = args.backends or get_manager().names("backend")
    print(
        f"# {platform.processor() or platform.machine()}, Python {platform.python_version()}, "
        f"timestep 1/240 s, {args.seconds} s simulated per figure"
    )
    print(
        f"# load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; CPU = steps per CPU second (process_time)"
    )
    print(
        "| backend | solver iterations | step(n) steps/s | step(n) CPU steps/s | step(n) real-time factor | "
        "control loop steps/s | control loop CPU steps/s | control loop real-time factor | cube still held |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for name in names:
        for it in args.iterations:
            r = bench(name, it, args.seconds)
            print(
                f"| {r['backend']} | {r['iterations']} | {r['raw_steps_s']:,.0f} | {r['raw_cpu_steps_s']:,.0f} | "
                f"{r['raw_rtf']:.1f} | {r['ctl_steps_s']:,.0f} | {r['ctl_cpu_steps_s']:,.0f} | {r['ctl_rtf']:.1f} | "
                f"{'yes' if r['held'] else 'NO'} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
