"""Which hand, and which reading of its joint angles, do the published Level I grasps fit? (issue 14)

The relaxed-rigidity results file gives each initial grasp as 16 Allegro joint angles. Put on a hand
description, the used fingertips must be able to touch our scan of the object at once with no other
hand part inside it (the set-up placement, ``strategies.ingrasp.placement``), and a grasp that the
real hand held should squeeze inside the friction cone (45 deg at friction 1.0). For each of the 20
distinct grasps this solves the placement on:

* ``v4``: our ``robots/allegro`` (SimLab description, 12 mm fingertip spheres);
* ``v4 + LL4MA thumb``: v4 with the LL4MA lab description's joint ranges (thumb rotation to 1.62
  rad, the published maximum) and thumb base (turned 8.75 deg, moved 3 mm);
* ``BioTac tips``: v4 with the LL4MA description's BioTac fingertips (its pad sphere, 22.7 mm longer);
* ``LL4MA BioTac``: the whole LL4MA description (``robots.descriptions.allegro.LL4MA_BIOTAC``);

each with the fingertips touching at the published angles (``grasp_q0="contact"``) and, for v4, where
a PD drive commanded to them stops against a 3 N squeeze (``"command"``,
``execution.touch_configuration``). It prints, per hand and reading, how many grasps can be placed
(gap <= 2 mm, penetration <= 1 mm) and their largest squeeze-to-normal angle, then the per-grasp
angles. No physics; about 3 CPU-minutes.

    python bench/hand_models.py
"""

from __future__ import annotations

import dataclasses
import tempfile
import time
from pathlib import Path

import numpy as np

from benchharness.objects import load_object
from benchharness.robots.allegro import KP
from benchharness.robots.descriptions import allegro as descriptions
from benchharness.strategies.ingrasp.execution import ExecConfig, touch_configuration
from benchharness.strategies.ingrasp.hand import FINGERS, HandKinematics
from benchharness.strategies.ingrasp.placement import object_surface_arrays, place_object
from benchharness.strategies.ingrasp.problem import clamp_grasp
from benchharness.strategies.ingrasp.tasks import distinct_initial_grasps

V4, BT = descriptions.V4, descriptions.LL4MA_BIOTAC
#: the LL4MA description's figures that make its thumb, and those that make its BioTac fingertips
THUMB_FIELDS = ("limits", "thumb_limits", "thumb_xyz", "thumb_rpy")
TIP_FIELDS = ("tip_centre", "thumb_tip_centre", "tip_r", "distal_box", "thumb_distal_box")
HANDS = {
    "v4": V4,
    "v4 + LL4MA thumb": dataclasses.replace(V4, **{f: getattr(BT, f) for f in THUMB_FIELDS}),
    "BioTac tips": dataclasses.replace(V4, **{f: getattr(BT, f) for f in TIP_FIELDS}),
    "LL4MA BioTac": BT,
}
CASES = [(h, "contact") for h in HANDS] + [("v4", "command")]
CONE_DEG = 45.0  #: atan(1.0): the default fingertip-object friction


def main() -> None:
    cfg = ExecConfig()  # the set-up's squeeze and refusals (max_placement_gap / _penetration)
    squeeze = cfg.squeeze_force
    surfaces = {}
    results: dict[tuple[str, str], list[tuple[str, bool, float]]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        hands = {}
        for name, spec in HANDS.items():
            path = Path(tmp) / f"{len(hands)}.urdf"
            path.write_text(descriptions.build(spec).to_xml())
            hands[name] = HandKinematics(path)
        for hand_name, reading in CASES:
            hand = hands[hand_name]
            lo, hi = hand.limits(FINGERS)
            t0 = time.process_time()
            rows = []
            for task in distinct_initial_grasps():
                if task.object not in surfaces:
                    surfaces[task.object] = object_surface_arrays(load_object(task.object))
                v, n, c, sym = surfaces[task.object]
                q, _ = clamp_grasp(task.q0_published, hand)
                if reading == "command":
                    stiffness = np.full(4 * len(task.hand_fingers), KP)
                    q = touch_configuration(hand, q, task.hand_fingers, squeeze, stiffness, lo, hi)
                p = place_object(
                    hand, q, task.hand_fingers, v, n, c, symmetric=sym, grip_cone_deg=CONE_DEG
                )
                fits = (
                    p.max_gap <= cfg.max_placement_gap
                    and p.penetration <= cfg.max_placement_penetration
                )
                rows.append((task.task_id, fits, float(np.max(p.grip_angles_deg))))
            results[(hand_name, reading)] = rows
            placed = [a for _, ok, a in rows if ok]
            print(
                f"{hand_name:<18s} {reading:<8s} placeable {len(placed):2d}/20, "
                f"squeeze-to-normal angle of those: median {np.median(placed):5.1f} deg, "
                f"within {CONE_DEG:.0f} deg: {sum(a <= CONE_DEG for a in placed):2d}   "
                f"({time.process_time() - t0:.0f} CPU-s)"
            )
    print("\nlargest squeeze-to-normal angle per grasp (deg; x: cannot be placed)")
    print(f"{'grasp':<30s}" + "".join(f"{h[:12] + ' ' + r[:3]:>17s}" for h, r in CASES))
    for i, task in enumerate(distinct_initial_grasps()):
        cells = []
        for case in CASES:
            _, ok, a = results[case][i]
            cells.append(f"{a:5.1f}{' ' if ok else 'x'}")
        print(f"{task.task_id:<30s}" + "".join(f"{c:>17s}" for c in cells))


if __name__ == "__main__":
    main()
