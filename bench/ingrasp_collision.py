"""Where the in-grasp plans carry the object into the hand, and what the collision term costs.

For each published Level I task, with our object model where a simulated trial's set-up puts it
(``InGraspExecutor.nominal_setup``, the engine's contact friction): how far along the straight
warm-start path (initial grasp -> IK of the goal) the hand's other parts stay off the object, how
deep the worst one goes and which it is, and the plan's goal error and planning time without and
with the collision term (``w_collision``, default 1e6 here). No physics is stepped.

    python bench/ingrasp_collision.py --backend pybullet [--variant relaxed-rigidity] [--tasks apple-06,banana-01]

Prints one row per task and a summary per object and in all (docs/ingrasp.md "Collision term").
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def main() -> None:
    from benchharness.plugin import get_manager
    from benchharness.strategies.ingrasp import planner as P
    from benchharness.strategies.ingrasp.execution import SetupInfeasible
    from benchharness.strategies.ingrasp.strategy import InGraspPlanner
    from benchharness.strategies.ingrasp.tasks import published_tasks

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--backend", default="pybullet", help="whose contact friction places the object"
    )
    ap.add_argument("--variant", default="relaxed-rigidity")
    ap.add_argument("--w-collision", type=float, default=1.0e6)
    ap.add_argument("--tasks", default="", help="comma-separated task ids (default: all 100)")
    args = ap.parse_args()

    wanted = {s for s in args.tasks.split(",") if s}
    tasks = [t for t in published_tasks() if not wanted or t.task_id in wanted]
    be = get_manager().create("backend", args.backend)
    robot = get_manager().create("robot", "allegro")
    pl = InGraspPlanner(args.variant, w_collision=args.w_collision)
    hand = pl.hand_for(robot)
    rows = []
    wall0, cpu0 = time.perf_counter(), time.process_time()
    print(
        f"{'task':32s} {'free':>5s} {'depth mm':>8s} {'worst':>11s} {'err cm':>7s} {'-> coll':>7s} "
        f"{'left mm':>7s} {'t s':>5s} {'-> coll':>7s}"
    )
    for t in tasks:
        prob = pl.problem(t, hand)
        try:
            scene = pl.trial_scene(be, robot, prob, t.object, hand)
        except SetupInfeasible:
            print(f"{t.task_id:32s} set-up infeasible")
            continue
        cost = P._Cost(hand, prob, pl.variant, pl.config, scene)
        q_goal = P.rigid_goal_joints(hand, cost, pl.config)
        q0 = cost.q0.numpy()
        free = P._free_fraction(cost, q0, q_goal, pl.config)
        s = np.linspace(0.0, 1.0, 41)[1:]
        short = cost.collision_shortfalls(q0[None] + s[:, None] * (q_goal - q0)[None])
        worst = scene.names[int(short.max(0).values.argmax())] if float(short.max()) > 0 else "-"
        r0, r1 = pl.plan(prob, hand), pl.plan(prob, hand, scene)
        row = (
            t.task_id,
            free,
            float(short.max()) * 1e3,
            worst,
            r0.pos_error * 100,
            r1.pos_error * 100,
            (r1.collision_shortfall or 0.0) * 1e3,
            r0.plan_time_s,
            r1.plan_time_s,
        )
        rows.append(row)
        print(
            f"{row[0]:32s} {row[1]:5.2f} {row[2]:8.2f} {row[3]:>11s} {row[4]:7.2f} {row[5]:7.2f} "
            f"{row[6]:7.2f} {row[7]:5.2f} {row[8]:7.2f}"
        )
    be.close()
    if not rows:
        return
    print("\nper object (medians): depth mm, plan err cm without -> with the term")
    for obj in sorted({r[0].rsplit("-", 1)[0] for r in rows}):
        sub = [r for r in rows if r[0].rsplit("-", 1)[0] == obj]
        print(
            f"  {obj:28s} {np.median([r[2] for r in sub]):5.1f}  "
            f"{np.median([r[4] for r in sub]):5.2f} -> {np.median([r[5] for r in sub]):5.2f}"
        )
    depth = np.array([r[2] for r in rows])
    print(
        f"\n{len(rows)} tasks: straight path clear of the hand {sum(r[1] == 1.0 for r in rows)}, "
        f"deeper than 1 mm {int((depth > 1.0).sum())}; depth median {np.median(depth):.2f} mm, "
        f"max {depth.max():.1f}"
    )
    worst_names: dict[str, int] = {}
    for r in rows:
        if r[2] > 0.1:
            worst_names[r[3]] = worst_names.get(r[3], 0) + 1
    print(
        "  deepest shape (depth > 0.1 mm):",
        dict(sorted(worst_names.items(), key=lambda kv: -kv[1])),
    )
    print(
        f"  plan goal error median {np.median([r[4] for r in rows]):.3f} cm -> "
        f"{np.median([r[5] for r in rows]):.3f} cm with the term; left inside the margin median "
        f"{np.median([r[6] for r in rows]):.3f} mm, max {max(r[6] for r in rows):.2f} mm"
    )
    print(
        f"  plan time median {np.median([r[7] for r in rows]):.2f} s -> "
        f"{np.median([r[8] for r in rows]):.2f} s (paper, relaxed-rigidity: 0.5 s)"
    )
    print(
        f"  {time.perf_counter() - wall0:.0f} s wall, {time.process_time() - cpu0:.0f} CPU-s",
    )


if __name__ == "__main__":
    main()
