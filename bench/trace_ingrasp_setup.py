"""Trace one in-grasp (Allegro, Level I) trial per phase: object pose and fingertip contact forces.

Runs trial INDEX of ``inhand-level1`` exactly as ``benchharness run`` does (same seed streams, same
physics), with the backend's ``step`` wrapped to sample, every control period, the object's centre of
mass in the palm frame (displacement from the noise-free placement), its speed, the summed normal
force of each used fingertip's contacts, the force on other hand links, and the gravity component
along the palm normal. Prints one line every ``--every`` seconds and the drop message.

    python bench/trace_ingrasp_setup.py --backend sapien --trial 16 [--until-s 1.5]
    python bench/trace_ingrasp_setup.py --trial 74 --others --strategy-option w_collision=1e6
    python bench/trace_ingrasp_setup.py --backend sapien --trial 431 --repeats 5   # lego_duplo-01, 5th
"""

from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np

from benchharness.runner import trial as trial_mod
from benchharness.runner.spec import RunSpec

#: the three fingertips a Level I grasp uses (index, middle, thumb)
TIPS = ("link_3_tip", "link_7_tip", "link_15_tip")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--backend", default="pybullet")
    ap.add_argument("--trial", type=int, required=True)
    ap.add_argument(
        "--repeats",
        type=int,
        default=1,
        help="as `benchharness run --repeats`: trial t + (r-1)*100 is repeat r of row t (docs/inhand.md)",
    )
    ap.add_argument("--strategy", default="relaxed-rigidity")
    ap.add_argument("--every", type=float, default=0.05)
    ap.add_argument("--until-s", type=float, default=1.2, help="stop tracing after this sim time")
    ap.add_argument("--normals", action="store_true", help="print force-weighted contact normals")
    ap.add_argument(
        "--slip",
        action="store_true",
        help="print each fingertip's slip on the object since release (mm, object frame), the "
        "fingertip distances (mm) and the largest joint tracking error of the used fingers (rad)",
    )
    ap.add_argument(
        "--others",
        action="store_true",
        help="name the other links touching the object (link@separation mm and their force)",
    )
    ap.add_argument("--since-s", type=float, default=0.0, help="start tracing at this sim time")
    ap.add_argument(
        "--exec-config", default="", help="ExecConfig overrides, k=v,k=v (floats, none, friction)"
    )
    ap.add_argument(
        "--strategy-option",
        action="append",
        default=[],
        metavar="K=V",
        help="a planner option as `benchharness run --strategy-option` takes it (repeatable)",
    )
    args = ap.parse_args()

    spec = RunSpec(
        task="inhand-level1",
        robot="allegro",
        strategy=args.strategy,
        backend=args.backend,
        repeats=args.repeats,
        strategy_options=tuple(tuple(o.split("=", 1)) for o in args.strategy_option),
    )
    rows: list[str] = []
    st: dict = {"obj": None, "phase": "close", "next": 0.0, "c0": None}
    orig_create = trial_mod.create_item

    def create_item(kind, name, plugins, **kw):
        item = orig_create(kind, name, plugins, **kw)
        if kind == "strategy" and args.exec_config:
            over = {
                k: (None if v.lower() == "none" else v if v == "friction" else float(v))
                for k, v in (p.split("=") for p in args.exec_config.split(","))
            }
            item.exec_config = replace(item.exec_config, **over)
        if kind != "backend":
            return item
        be = item
        add_body, detach, step = be.add_body, be.detach, be.step

        def add_body_w(*a, **k):
            bid = add_body(*a, **k)
            st["obj"], st["com"] = bid, np.asarray(k.get("com") or np.zeros(3), float)
            return bid

        def detach_w(h):
            detach(h)
            st["phase"] = "released"
            rows.append(f"--- released at t={be.time:.3f} s")

        def step_w(n=1):
            step(n)
            t = float(be.time)
            if (
                st["obj"] is None
                or t + 1e-9 < st["next"]
                or t > args.until_s
                or t + 1e-9 < args.since_s
            ):
                return
            st["next"] = t + args.every
            rob = st["robot"]
            palm = be.get_link_pose(rob.body, "palm_link").as_matrix()
            ob = be.get_pose(st["obj"]).as_matrix()
            c = (np.linalg.inv(palm) @ ob @ np.append(st["com"], 1.0))[:3]
            if st["c0"] is None:
                st["c0"] = c
            v, _ = be.get_velocity(st["obj"])
            f: dict[str, float] = {}
            nrm: dict[str, np.ndarray] = {}
            pen: dict[str, float] = {}
            others: dict[str, float] = {}  # every other link (or the ground) touching the object
            for ct in be.contacts(st["obj"], None):
                if ct.body_b == rob.body and ct.link_b and ct.link_b.endswith("_tip"):
                    f[ct.link_b] = f.get(ct.link_b, 0.0) + ct.normal_force
                    # normal from the tip (B) towards the object (A), in the palm frame
                    nrm[ct.link_b] = nrm.get(ct.link_b, np.zeros(3)) + ct.normal_force * (
                        palm[:3, :3].T @ np.asarray(ct.normal)
                    )
                    pen[ct.link_b] = min(pen.get(ct.link_b, 0.0), float(ct.distance))
                else:
                    name = f"{ct.link_b or 'ground'}@{1e3 * float(ct.distance):+.1f}mm"
                    others[name] = others.get(name, 0.0) + ct.normal_force
            tips = " ".join(f"{k[5:]}={f.get(k, 0.0):5.2f}" for k in TIPS)
            other = sum(others.values())
            d = (c - st["c0"]) * 1e3
            rows.append(
                f"t={t:6.3f} {st['phase']:8s} dCoM_palm[mm]=({d[0]:6.1f},{d[1]:6.1f},{d[2]:6.1f}) "
                f"|v|={np.linalg.norm(v):5.3f} N: {tips} other={other:5.2f}"
                + (
                    " (" + ", ".join(f"{k} {x:.2f}" for k, x in sorted(others.items())) + ")"
                    if args.others and others
                    else ""
                )
            )
            if args.slip or args.normals:  # fingertip centres in the world, for either report
                tips_w = {k: be.get_link_pose(rob.body, k).as_matrix()[:3, 3] for k in TIPS}
            if args.slip:
                in_obj = {k: (np.linalg.inv(ob) @ np.append(p, 1.0))[:3] for k, p in tips_w.items()}
                if st["phase"] == "released" and "tips0" not in st:
                    st["tips0"] = in_obj
                slip = " ".join(
                    f"{k[5:-4]}={np.linalg.norm(in_obj[k] - st['tips0'][k]) * 1e3:5.1f}"
                    for k in in_obj
                    if "tips0" in st
                )
                ks = list(tips_w)
                dist = " ".join(
                    f"{np.linalg.norm(tips_w[ks[i]] - tips_w[ks[j]]) * 1e3:5.1f}"
                    for i, j in ((0, 1), (0, 2), (1, 2))
                )
                hg = rob.gripper("hand")
                used = [0, 1, 2, 3, 4, 5, 6, 7, 12, 13, 14, 15]
                err = np.abs(rob.joint_positions()[used] - np.asarray(hg._targets)[used])
                rows.append(
                    f"      slip_mm: {slip}  tip_dist_mm(i-m,i-t,m-t): {dist}  "
                    f"max|q-q_target|={err.max():.3f} rad (joint {used[int(err.argmax())]})"
                )
            if args.normals:
                g = np.mean(list(tips_w.values()), axis=0)
                for k in sorted(nrm):
                    n = nrm[k] / max(np.linalg.norm(nrm[k]), 1e-12)
                    # the squeeze direction (towards the fingertip centroid) against the contact
                    # normal: outside the friction cone (45 deg at mu = 1) the squeeze slides
                    sq = palm[:3, :3].T @ (g - tips_w[k])
                    ang = np.degrees(np.arccos(np.clip(n @ sq / np.linalg.norm(sq), -1.0, 1.0)))
                    rows.append(
                        f"      {k}: normal(palm)=({n[0]:5.2f},{n[1]:5.2f},{n[2]:5.2f}) "
                        f"pen={pen[k] * 1e3:5.2f} mm squeeze-normal angle={ang:5.1f} deg"
                    )

        be.add_body, be.detach, be.step = add_body_w, detach_w, step_w
        return be

    def create_item2(kind, name, plugins, **kw):
        it = create_item(kind, name, plugins, **kw)
        if kind == "robot":
            st["robot"] = it
        return it

    trial_mod.create_item = create_item2
    rec = trial_mod.execute_trial(spec, args.trial)
    print("\n".join(rows))
    print("status", rec.status, rec.failure_cause, rec.message, rec.traceback[-800:])
    ex = rec.outcome.get("extra", {}) or {}
    for k in (
        "setup_tip_contacts",
        "setup_joint_error_rad",
        "placement_gap_mm",
        "placement_penetration_mm",
        "phase",
    ):
        print(k, ex.get(k))


if __name__ == "__main__":
    main()
