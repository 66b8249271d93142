"""How far can an object on the DMG's table tip before it topples? Scan against generated model (issue 14).

For each stored DMG trial (first trial of each task) that recorded its rest pose, this puts the
object's convex hull in that pose on the table and prints the footprint (hull points within 1 mm of
the table), the height of the centre of mass, its horizontal distance to the nearest footprint edge
and the tip angle ``atan(distance / height)``: the tilt at which the object falls over by itself.
A smaller tip angle is a rest the pads' drag during a pivot topples more easily. The model is the
one the trial ran on (``extra.dmg_surface``). No physics; reads the stores only.

    python bench/dmg_rest_footprint.py pg-sapien.sqlite ycb-sapien.sqlite
"""

from __future__ import annotations

import argparse
import json
import sqlite3

import numpy as np
from scipy.spatial import ConvexHull

from benchharness.geometry import Pose
from benchharness.runner.contact_regions import planner_for_outcome


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("stores", nargs="+")
    args = ap.parse_args()
    print(
        "model      task                  footprint (mm)   CoM height (mm)  to edge (mm)  tip angle"
    )
    for store in args.stores:
        con = sqlite3.connect(f"file:{store}?mode=ro", uri=True)
        seen: set[str] = set()
        for (oj,) in con.execute(
            "select outcome_json from trials where task = 'inhand-level3-dmg' order by trial_index"
        ):
            o = json.loads(oj or "{}")
            extra = o.get("extra") or {}
            if o.get("task_id") in seen or extra.get("rest_pose") is None:
                continue
            seen.add(o["task_id"])
            planner = planner_for_outcome(o)  # the model the trial ran on
            model = planner.surface.model
            m = planner.object_model(o["object"])
            t = Pose.from_array(extra["rest_pose"]).as_matrix()
            w = np.asarray(m.surface.convex_hull.vertices) @ t[:3, :3].T + t[:3, 3]
            z0 = w[:, 2].min()
            foot = w[w[:, 2] < z0 + 1e-3][:, :2]
            com = t[:3, :3] @ np.asarray(m.mass.com) + t[:3, 3]
            eq = ConvexHull(foot).equations
            edge = float(np.min(-(eq[:, :2] @ com[:2] + eq[:, 2])))
            ext = (foot.max(axis=0) - foot.min(axis=0)) * 1e3
            h = com[2] - z0
            print(
                f"{model:10s} {o['task_id']:21s} {ext[0]:6.1f} x {ext[1]:5.1f}   {h * 1e3:10.1f}"
                f"   {edge * 1e3:11.1f}   {np.degrees(np.arctan2(edge, h)):6.1f} deg"
            )
        con.close()


if __name__ == "__main__":
    main()
