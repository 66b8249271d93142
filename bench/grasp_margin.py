"""How close the published Level I grasps, on our Allegro model, stand to the edge of the friction cone (issue 14).

The published data give each initial grasp as joint angles (``grasp_*`` columns of the relaxed-rigidity
results file), not as contact points. Put on our hand model (the SimLab/Wonik description's link
lengths, 12 mm fingertip spheres) those angles fix where the three fingertip centres are: for a round
object of radius R held by three spherical tips of radius r, every tip centre lies at R + r from the
object's centre, so if the tip centres span a circle of radius rho the centre sits off their plane and
each contact normal is tilted out of that plane by acos(rho / (R + r)). A squeeze in the plane of the
tips then acts at about that angle to every normal, and the grasp holds only while it is inside the
friction cone (45 deg at the friction 1.0 we simulate).

Part 1 reads the published angles as the configuration at which the fingertips touch (the set-up's
``grasp_q0="contact"``; the default ``"command"`` touches where the squeeze holds the fingers back from
them, and ``bench/hand_models.py`` measures both). It prints, from the published file and the hand
model alone (no physics), each distinct initial
grasp's fingertip circle and, for the near-spherical scans (apple, orange: least-squares ball fitted
to the scan), the predicted tilt. Part 2 (``--store``, any number of stores written by ``run`` on
``inhand-level1``) counts each engine's and method's scored trials (set-up within the 10 % rule) and
drops by the largest angle the set-up placement measured between a fingertip's squeeze and its contact
normal (``extra["placement_grip_angles_deg"]``), and lists the drops with that angle and the plan's
largest fingertip turn (``plan_tip_rotation_deg``, the rolling of docs/ingrasp.md "Execution drops").

    python bench/grasp_margin.py
    python bench/grasp_margin.py --store t2-pybullet.sqlite --store t2-sapien.sqlite
"""

from __future__ import annotations

import argparse
import json
import math
import sqlite3
from collections import defaultdict

import numpy as np

from benchharness.objects import load_object
from benchharness.robots.descriptions.allegro import TIP_R
from benchharness.strategies.ingrasp.hand import HandKinematics
from benchharness.strategies.ingrasp.tasks import distinct_initial_grasps

ROUND = ("apple", "orange")
BINS = (30.0, 38.0, 42.0)  #: edges of the grip-angle bins (deg)


def circumradius(p: np.ndarray) -> float:
    """Radius of the circle through three points (m)."""
    a, b, c = (float(np.linalg.norm(p[i] - p[j])) for i, j in ((1, 2), (0, 2), (0, 1)))
    s = 0.5 * (a + b + c)
    area = math.sqrt(max(s * (s - a) * (s - b) * (s - c), 1e-18))
    return a * b * c / (4.0 * area)


def ball_radius(name: str) -> float:
    """Least-squares sphere fitted to the object's surface vertices (m)."""
    v = np.asarray(load_object(name).surface.vertices, float)
    a = np.c_[2.0 * v, np.ones(len(v))]
    x = np.linalg.lstsq(a, (v**2).sum(1), rcond=None)[0]
    return float(math.sqrt(x[3] + x[:3] @ x[:3]))


def published_grasps() -> None:
    r_tip = TIP_R
    kin = HandKinematics()
    balls = {name: ball_radius(name) for name in ROUND}
    print(f"fingertip sphere radius {1000 * r_tip:.1f} mm (our Allegro description)")
    print(
        "initial grasp (task)           fingers            tip-centre distances (mm)   circle rho (mm)"
        "   ball R (mm)   predicted tilt acos(rho/(R+r))"
    )
    for task in distinct_initial_grasps():
        fingers = task.hand_fingers
        tips = kin.tip_poses_np(task.q0_used, fingers)[0, :, :3, 3]
        d = [1000 * float(np.linalg.norm(tips[i] - tips[j])) for i, j in ((0, 1), (0, 2), (1, 2))]
        rho = circumradius(tips)
        row = f"{task.task_id:<30s} {'+'.join(fingers):<18s} {' / '.join(f'{x:5.1f}' for x in d):<27s} {1000 * rho:8.1f}"
        if task.object in balls:
            big_r = balls[task.object]
            tilt = math.degrees(math.acos(min(1.0, rho / (big_r + r_tip))))
            row += f"   {1000 * big_r:11.1f}   {tilt:5.1f} deg"
        print(row)


def _bin(angle: float) -> str:
    lo = 0.0
    for hi in BINS:
        if angle < hi:
            return f"{lo:.0f}-{hi:.0f}"
        lo = hi
    return f">={lo:.0f}"


def store_table(paths: list[str]) -> None:
    per: dict[tuple[str, str], list[tuple]] = defaultdict(list)
    for path in paths:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        for strategy, backend, oj in con.execute(
            "select strategy, backend, outcome_json from trials order by trial_index"
        ):
            o = json.loads(oj)
            e = o.get("extra") or {}
            if o.get("discarded") or "placement_grip_angles_deg" not in e:
                continue
            per[(backend, strategy)].append(
                (
                    o["task_id"],
                    o.get("repeat"),
                    max(e["placement_grip_angles_deg"]),
                    max(e.get("plan_tip_rotation_deg") or [0.0]),
                    bool(o.get("dropped")),
                )
            )
        con.close()
    labels = [_bin(a) for a in (0.0, *BINS)]
    print(
        "\nscored trials (set-up within 10 %): drops / trials by the largest squeeze-to-normal angle"
    )
    print(f"{'engine':<9s} {'method':<30s} " + " ".join(f"{b + ' deg':>12s}" for b in labels))
    for (backend, strategy), rows in sorted(per.items()):
        counts = {b: [0, 0] for b in labels}
        for *_, angle, _rot, dropped in rows:
            c = counts[_bin(angle)]
            c[0] += int(dropped)
            c[1] += 1
        print(
            f"{backend:<9s} {strategy:<30s} "
            + " ".join(f"{f'{d}/{n}':>12s}" for d, n in counts.values())
        )
    for (backend, strategy), rows in sorted(per.items()):
        drops = [r for r in rows if r[4]]
        if drops:
            print(
                f"\n{backend} {strategy}: {len(drops)} drops of {len(rows)} (task, repeat, angle, plan turn)"
            )
            print(
                "  "
                + ", ".join(
                    f"{t}{'' if rep is None else f'#{rep}'} {a:.1f}/{r:.0f}"
                    for t, rep, a, r, _ in drops
                )
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--store", action="append", default=[], help="results store(s) of inhand-level1 runs"
    )
    args = ap.parse_args()
    published_grasps()
    if args.store:
        store_table(args.store)


if __name__ == "__main__":
    main()
