"""Every drop of in-grasp Table II stores, per trial, with the measured signs of its cause (issue 14).

Reads stores written by ``benchharness run --task inhand-level1`` (any methods, engines, repeats) and
prints, per engine and method:

* each drop (``task#repeat``) with: the phase it fell in (``execution``: during the plan, ``hold``: in the
  5 s unsupported hold), the set-up placement's largest squeeze-to-normal angle beside the friction
  cone's half angle (a grasp set outside its cone can only slip), the plan's largest fingertip turn
  against the object (``plan_tip_rotation_deg``: turning a fingertip whose centre the plan holds on
  the object means rolling it over the surface or sliding), and how deep the plan carries the object
  into a hand part other than the used fingertips, and which (recomputed here: the trial's plan,
  measured against our object model where the set-up put it, ``collision.collision_scene``; no
  physics);
* the median err_pos per object and method over the scored trials (the numbers behind Figure 7's
  boxes), so a difference between two methods' medians can be traced to its objects;
* with ``--compare A B``, per engine, the two methods' err_pos trial against trial (the same trial
  index has the same task, repeat and set-up noise for every method): how often A ends nearer, the
  median paired difference, a sign test, and a 95 % interval for the difference of the two
  medians from resampling whole tasks (seeded: the same figures every run); then the same counts
  split by how the two plans end against the goal (within 0.01 cm of each other, or one farther).

    python bench/ingrasp_drops.py --store t2-relaxed-rigidity-sapien.sqlite --store t2-point-contact-sapien.sqlite \
        --compare relaxed-rigidity point-contact
    python bench/ingrasp_drops.py --plans apple-04,apple-06 --methods relaxed-rigidity,point-contact

``--plans`` prints, for the given tasks, methods and engine (``--backend``), each method's plan
measured (no store needed, no physics): how deep it carries the object into the hand, its planned
error against the goal, and how far its fingertips end from the rigidly carried grasp.
"""

from __future__ import annotations

import argparse
import json
import sqlite3
from collections import defaultdict
from functools import cache

import numpy as np


def read(paths: list[str]) -> list[dict]:
    """One dict per trial of the stores: engine, method, outcome fields and the extras used here."""
    rows = []
    for path in paths:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        for index, strategy, backend, status, oj in con.execute(
            "select trial_index, strategy, backend, status, outcome_json from trials"
            " order by trial_index"
        ):
            o = json.loads(oj or "{}")
            e = o.get("extra") or {}
            rows.append(
                {
                    "index": index,
                    "backend": backend,
                    "strategy": strategy,
                    "status": status,
                    "task": o.get("task_id"),
                    "object": o.get("object"),
                    "repeat": o.get("repeat"),
                    "dropped": bool(o.get("dropped")),
                    "discarded": bool(o.get("discarded")),
                    "err_pos": (o.get("metrics") or {}).get("err_pos"),
                    "phase": e.get("phase"),
                    "angle": max(e.get("placement_grip_angles_deg") or [float("nan")]),
                    "cone": e.get("placement_grip_cone_deg"),
                    "turn": max(e.get("plan_tip_rotation_deg") or [float("nan")]),
                    "plan_err": e.get("plan_pos_error_cm"),
                }
            )
        con.close()
    return rows


@cache
def plan_facts(backend: str, strategy: str, task_id: str) -> tuple[float, str, float, float, float]:
    """The trial's plan, measured: how deep (mm) it carries our object into a hand part other than
    the used fingertips and which part ('-' if none comes nearer than at the initial grasp); its
    object's error against the goal (cm, deg); how far (mm) its last fingertips stand from where the
    initial grasp, carried rigidly to the goal, would put them (0: the grasp kept rigid)."""
    import numpy as np

    from benchharness.plugin import get_manager
    from benchharness.strategies.ingrasp.planner import _Cost
    from benchharness.strategies.ingrasp.strategy import InGraspPlanner, _published_by_id

    task = _published_by_id()[task_id]
    pl = InGraspPlanner(strategy)
    # measured against the object with a zero margin: depth below where each part starts
    probe = InGraspPlanner(strategy, w_collision=1.0, collision_margin=0.0)
    be = get_manager().create("backend", backend)
    try:
        robot = get_manager().create("robot", "allegro")
        hand = pl.hand_for(robot)
        prob = pl.problem(task, hand)
        scene = probe.trial_scene(be, robot, prob, task.object, hand)
    finally:
        be.close()
    res = pl.plan(prob, hand)  # the trial's plan: the default planner has no collision term
    cost = _Cost(hand, prob, strategy, probe.config, scene)
    short = cost.collision_shortfalls(res.q[1:]).amax(0)
    i = int(short.argmax())
    rigid = (cost.goal[None] @ cost.tip_in_obj)[:, :3, 3].numpy()
    tips = hand.tip_poses_np(res.q[-1][None], prob.fingers)[0][:, :3, 3]
    off = float(np.linalg.norm(tips - rigid, axis=1).max()) * 1e3
    return (
        float(short[i]) * 1e3,
        scene.names[i] if float(short[i]) > 0 else "-",
        res.pos_error * 100,
        float(np.degrees(res.rot_error)),
        off,
    )


def compare(rows: list[dict], a: str, b: str, resamples: int = 2000) -> None:
    """Method ``a`` against ``b`` on err_pos, trial against trial, per engine (module docstring)."""
    from scipy.stats import binomtest

    def scored(backend: str, strategy: str) -> dict[int, tuple[str, float, float]]:
        return {
            r["index"]: (r["task"], r["err_pos"] * 100, r["plan_err"])
            for r in rows
            if r["backend"] == backend
            and r["strategy"] == strategy
            and r["status"] == "success"
            and not r["discarded"]
            and r["err_pos"] is not None
        }

    for backend in sorted({r["backend"] for r in rows}):
        ea, eb = scored(backend, a), scored(backend, b)
        both = sorted(set(ea) & set(eb))
        if not both:
            continue
        d = np.array([ea[i][1] - eb[i][1] for i in both])
        nearer, farther = int((d < 0).sum()), int((d > 0).sum())
        p = binomtest(nearer, nearer + farther).pvalue if nearer + farther else 1.0
        by_task: dict[str, list[int]] = defaultdict(list)
        for i in both:
            by_task[ea[i][0]].append(i)
        tasks = sorted(by_task)
        rng = np.random.default_rng(0)
        diffs = []
        for _ in range(resamples):
            ids = [i for k in rng.integers(0, len(tasks), len(tasks)) for i in by_task[tasks[k]]]
            diffs.append(np.median([ea[i][1] for i in ids]) - np.median([eb[i][1] for i in ids]))
        lo, hi = np.percentile(diffs, [2.5, 97.5])
        med_a, med_b = (
            np.median([v[1] for v in ea.values()]),
            np.median([v[1] for v in eb.values()]),
        )
        print(
            f"\n{backend}: {a} vs {b}, err_pos over {len(both)} trials scored for both: "
            f"{a} nearer in {nearer}, farther in {farther} (sign test p = {p:.2g}); median paired "
            f"difference {np.median(d):+.3f} cm; medians {med_a:.3f} / {med_b:.3f} cm (all scored), "
            f"difference 95 % interval over resampled tasks [{lo:+.3f}, {hi:+.3f}] cm"
        )
        # the same, split by how the two plans end against the goal (planned error, 0.01 cm apart)
        groups = {"plans within 0.01 cm": [], f"{a}'s plan farther": [], f"{a}'s plan nearer": []}
        names = list(groups)
        for i in both:
            gap = ea[i][2] - eb[i][2]
            groups[names[0] if abs(gap) <= 0.01 else names[1] if gap > 0 else names[2]].append(i)
        for name, ids in groups.items():
            dd = np.array([ea[i][1] - eb[i][1] for i in ids])
            n1, n2 = int((dd < 0).sum()), int((dd > 0).sum())
            pp = binomtest(n1, n1 + n2).pvalue if n1 + n2 else 1.0
            med = f"{np.median(dd):+.3f}" if len(dd) else "-"
            print(
                f"  {name:36s} {len(ids):4d} trials: {a} nearer {n1}, farther {n2} "
                f"(p = {pp:.2g}), median difference {med} cm"
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--store", action="append", default=[], help="results store (repeatable)")
    ap.add_argument("--plans", default="", help="comma-separated task ids: their plans only")
    ap.add_argument("--methods", default="relaxed-rigidity,point-contact", help="for --plans")
    ap.add_argument("--backend", default="pybullet", help="for --plans: whose friction")
    ap.add_argument(
        "--no-depth", action="store_true", help="skip the plans' hand depth (no planning)"
    )
    ap.add_argument(
        "--compare", nargs=2, metavar=("A", "B"), help="two methods, trial against trial"
    )
    args = ap.parse_args()
    if args.plans:
        print(
            "per method: planned error cm / deg, fingertips off the rigid grasp mm, depth mm part"
        )
        for task in args.plans.split(","):
            for m in args.methods.split(","):
                d, part, e_cm, e_deg, off = plan_facts(args.backend, m, task)
                print(
                    f"  {task:30s} {m:30s} {e_cm:6.3f} cm {e_deg:6.2f} deg {off:6.2f} mm "
                    f"{d:6.2f} mm {part}"
                )
        return
    if not args.store:
        ap.error("give --store (or --plans)")
    rows = read(args.store)
    groups: dict[tuple[str, str], list[dict]] = defaultdict(list)
    for r in rows:
        groups[(r["backend"], r["strategy"])].append(r)
    for (backend, strategy), rs in sorted(groups.items()):
        scored = [r for r in rs if r["status"] == "success" or r["dropped"]]
        scored = [r for r in scored if not r["discarded"]]
        drops = [r for r in scored if r["dropped"]]
        print(f"\n{backend} {strategy}: {len(drops)} drops of {len(scored)} scored trials")
        if drops:
            print(
                f"  {'trial':34s} {'phase':>9s} {'angle/cone':>11s} {'turn':>6s} {'plan depth':>19s}"
            )
        for r in drops:
            depth, part = (
                (0.0, "") if args.no_depth else plan_facts(backend, strategy, r["task"])[:2]
            )
            cone = f"{r['cone']:.0f}" if r["cone"] is not None else "-"
            print(
                f"  {r['task'] + '#' + str(r['repeat']):34s} {str(r['phase']):>9s} "
                f"{r['angle']:6.1f}/{cone:>4s} {r['turn']:6.1f} "
                f"{'' if args.no_depth else f'{depth:6.2f} mm {part:>9s}':>19s}"
            )
    objects = sorted({r["object"] for r in rows if r["object"]})
    keys = sorted(groups)
    print("\nmedian err_pos (cm) per object over scored trials (n)")
    print(f"  {'object':28s} " + " ".join(f"{b[:3] + ' ' + s[:20]:>26s}" for b, s in keys))
    for obj in objects:
        cells = []
        for k in keys:
            e = [
                r["err_pos"] * 100
                for r in groups[k]
                if r["object"] == obj and r["status"] == "success" and r["err_pos"] is not None
            ]
            cells.append(f"{np.median(e):.2f} ({len(e)})" if e else "-")
        print(f"  {obj:28s} " + " ".join(f"{c:>26s}" for c in cells))
    if args.compare:
        compare(rows, *args.compare)


if __name__ == "__main__":
    main()
