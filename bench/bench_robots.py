"""Robot performance figures (not unit tests): physics steps/s, real-time factor, batched IK.

Scene: the PR2 (both arms and grippers holding their targets) over a table
with a 5.7 cm, 94 g cube, on each backend, at the default PhysicsConfig.
Four loops per backend:

* ``physics``   — ``backend.step(n)`` with the PD targets set once (the
  engine plus the backend's own per-step work);
* ``control``   — ``robot.settle()``: the robot's Python control loop (hold
  targets + gravity feed-forward every 1/120 s) on top;
* ``physics@10it`` — ``physics`` with 10 solver iterations instead of the
  engine's default (PyBullet 50, SAPIEN 20), to show what the solver costs;
* ``engine``    — the engine's own step function in a bare Python loop
  (``pybullet.stepSimulation`` / ``sapien.Scene.step``) on the same scene,
  every layer of ours removed: the floor of ``physics``. This loop reaches
  past the Backend interface on purpose (the only place outside
  ``backends/`` that touches an engine), and on PyBullet it leaves the
  joint motors at the last drive command, so it measures the engine, not
  the same physics.

Each loop reports wall-clock and CPU-time (``time.process_time``) steps/s;
on a shared machine CPU time is the steadier figure (other jobs delay wall
time but not this process's CPU time). With ``--repeats N`` every figure
is the median of N runs.

Then IK for one PR2 arm: 1,000 random reachable targets in one batched
call from random restarts, and 200 single-target calls seeded with a
configuration 0.15 rad (std per joint) away from the answer — what a
motion's ``move_to_pose`` does.

Usage::

    python bench/bench_robots.py [--seconds 3] [--repeats 3] [--json out.json]

Torch is limited to one thread and the figures are per core (the process
runs single-threaded; other load on the machine shows up in the numbers).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from dataclasses import replace

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
import torch

torch.set_num_threads(1)

from benchharness.backends.interface import Box, PhysicsConfig  # noqa: E402
from benchharness.geometry import Pose  # noqa: E402
from benchharness.plugin import get_manager  # noqa: E402

CUBE_HALF, CUBE_MASS = 0.0285, 0.094


def build_scene(backend_name: str, config: PhysicsConfig):
    m = get_manager()
    be = m.create("backend", backend_name, config=config)
    be.add_ground()
    robot = m.create("robot", "pr2")
    robot.spawn(be)
    tcp = robot.arm("left_arm").tcp_pose()
    top = tcp.p[2] - CUBE_HALF
    be.add_body(
        [Box((0.25, 0.4, top / 2))], Pose([0.95, 0.0, top / 2]), 20.0, fixed=True, name="table"
    )
    cube = be.add_body(
        [Box((CUBE_HALF,) * 3)],
        Pose([0.85, 0.0, top + CUBE_HALF + 5e-4]),
        CUBE_MASS,
        friction=1.0,
        name="cube",
    )
    robot.settle(0.2)
    return be, robot, cube


def time_loop(fn, sim_seconds: float, dt: float, repeats: int = 1) -> dict:
    walls, cpus = [], []
    steps = 0
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        steps = fn(sim_seconds)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    wall, cpu = float(np.median(walls)), float(np.median(cpus))
    return {
        "steps": steps,
        "wall_s": wall,
        "cpu_s": cpu,
        "steps_per_s": steps / wall,
        "cpu_steps_per_s": steps / cpu,
        "real_time_factor": steps * dt / wall,
    }


def _engine_step_fn(be):
    """The engine's own step, bypassing the backend (see the module docstring)."""
    if be.name == "pybullet":
        import pybullet as pb

        cid = be._cid
        return lambda: pb.stepSimulation(physicsClientId=cid)
    scene = be._scene
    return scene.step


def bench_backend(name: str, seconds: float, repeats: int = 1) -> dict:
    out = {}
    for label, cfg in (
        ("physics", PhysicsConfig()),
        ("physics@10it", replace(PhysicsConfig(), solver_iterations=10)),
    ):
        be, robot, cube = build_scene(name, cfg)
        dt = cfg.timestep

        def physics(sim_s, be=be, dt=dt):
            n = int(round(sim_s / dt))
            be.step(n)
            return n

        out[label] = time_loop(physics, seconds, dt, repeats)
        if label == "physics":
            out[label]["cube_speed_m_s"] = float(
                np.linalg.norm(be.get_velocity(cube)[0])
            )  # at rest: ~0

            def control(sim_s, robot=robot, dt=dt):
                robot.settle(sim_s)
                return int(round(sim_s / dt))

            out["control"] = time_loop(control, seconds, dt, repeats)
            step = _engine_step_fn(be)

            def engine(sim_s, step=step, dt=dt):
                n = int(round(sim_s / dt))
                for _ in range(n):
                    step()
                return n

            out["engine"] = time_loop(engine, seconds, dt, repeats)
        be.close()
    return out


def bench_ik(n: int = 1000, n_seeded: int = 200) -> dict:
    robot = get_manager().create("robot", "pr2")
    arm = robot.arm("left_arm")
    q = arm.chain.sample(n, torch.Generator().manual_seed(0))
    targets = arm.fk(q)
    arm.ik(targets[:10], seed=1)  # warm-up
    t0 = time.perf_counter()
    res = arm.ik(targets, seed=1)
    wall = time.perf_counter() - t0
    ok = (res.pos_error <= 1e-3) & (res.rot_error <= np.radians(1.0))
    out = {
        "targets": n,
        "wall_s": wall,
        "ms_per_target": 1e3 * wall / n,
        "converged_0.1mm": float(res.success.mean()),
        "within_1mm_1deg": float(ok.mean()),
    }
    # seeded single-target calls, as in a motion: seed 0.15 rad (std) from the answer
    rng = np.random.default_rng(0)
    goal = arm.chain.sample(n_seeded, torch.Generator().manual_seed(1), margin=0.2)
    seeds = np.clip(goal + rng.normal(0.0, 0.15, goal.shape), arm.lower, arm.upper)
    tg = arm.fk(goal)
    t0 = time.perf_counter()
    rows = [arm.ik(tg[i : i + 1], seed_q=seeds[i], seed=i) for i in range(n_seeded)]
    wall = time.perf_counter() - t0
    dp = np.array([r.pos_error[0] for r in rows])
    dr = np.array([r.rot_error[0] for r in rows])
    out["seeded"] = {
        "calls": n_seeded,
        "wall_s": wall,
        "ms_per_call": 1e3 * wall / n_seeded,
        "within_1mm_1deg": float(np.mean((dp <= 1e-3) & (dr <= np.radians(1.0)))),
        "max_pos_error_m": float(dp.max()),
        "max_rot_error_rad": float(dr.max()),
    }
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3.0, help="simulated seconds per loop")
    ap.add_argument("--json", default=None, help="also write the figures here")
    ap.add_argument("--backends", default="pybullet,sapien")
    ap.add_argument(
        "--repeats", type=int, default=1, help="runs per figure; the median is reported"
    )
    ap.add_argument("--no-ik", action="store_true", help="skip the IK figures")
    args = ap.parse_args()
    results = {
        "machine": {
            "cpu_count": os.cpu_count(),
            "python": platform.python_version(),
            "load_avg_1min": os.getloadavg()[0],
        },
        "timestep": PhysicsConfig().timestep,
        "repeats": args.repeats,
        "backends": {},
    }
    for b in args.backends.split(","):
        results["backends"][b] = bench_backend(b, args.seconds, args.repeats)
    if not args.no_ik:
        results["ik"] = bench_ik()
    results["machine"]["load_avg_after"] = os.getloadavg()[0]
    print(
        f"{'loop':14s} "
        + " ".join(
            f"{b + ' steps/s':>17s} {b + ' CPU steps/s':>21s} {b + ' RTF':>13s}"
            for b in results["backends"]
        )
    )
    for loop in ("physics", "control", "physics@10it", "engine"):
        row = []
        for r in results["backends"].values():
            row.append(
                f"{r[loop]['steps_per_s']:17.0f} {r[loop]['cpu_steps_per_s']:21.0f} {r[loop]['real_time_factor']:13.2f}"
            )
        print(f"{loop:14s} " + " ".join(row))
    if not args.no_ik:
        ik = results["ik"]
        print(
            f"IK batched: {ik['targets']} targets in {ik['wall_s']:.2f} s ({ik['ms_per_target']:.2f} ms each), "
            f"{ik['within_1mm_1deg']:.1%} within 1 mm / 1 deg"
        )
        sd = ik["seeded"]
        print(
            f"IK seeded: {sd['calls']} single-target calls, {sd['ms_per_call']:.2f} ms each, "
            f"{sd['within_1mm_1deg']:.1%} within 1 mm / 1 deg (max {sd['max_pos_error_m'] * 1e3:.3g} mm)"
        )
    print(
        f"load average {results['machine']['load_avg_1min']:.2f} -> {results['machine']['load_avg_after']:.2f} "
        f"on {results['machine']['cpu_count']} CPUs"
    )
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=2)


if __name__ == "__main__":
    main()
