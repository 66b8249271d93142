"""Trace one table-supported parallel-gripper trial (DMG or pivoting) per primitive: what tips the object.

Runs trial INDEX of TASK exactly as ``benchharness run`` does (same seed streams, same physics) and
samples, every ``--every`` simulated seconds through a backend step callback, the rig's phase
(set-up, loosen, move, tighten, servo, lift), the object's tilt from its rest pose (deg), the
summed normal force of each pad on the object, and the table's support: its summed normal force
and the centre of pressure's distance inside the support polygon's nearest edge (mm; the object
tips when it reaches 0). Also prints, for each primitive, the largest tilt it caused.

    python bench/trace_table_rig.py --backend pybullet --trial 1          # on the YCB scan (the default)
    python bench/trace_table_rig.py --trial 13 --repeats 5 --strategy-option model=generated \
        --exec setup.position_std=0                                         # no set-up position noise
    python bench/trace_table_rig.py --task inhand-level1-pivoting --strategy pivoting --trial 7
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from benchharness.runner import trial as trial_mod
from benchharness.runner.recorder import TrialRecorder
from benchharness.runner.spec import RunSpec
from benchharness.strategies.pivoting import rig as rig_mod


def _support(contacts) -> tuple[float, float]:
    """Summed table normal force (N) and the centre of pressure's margin inside the contact hull (mm)."""
    if not contacts:
        return 0.0, float("nan")
    f = np.array([c.normal_force for c in contacts])
    p = np.array([c.position[:2] for c in contacts])
    if f.sum() <= 0:
        return 0.0, float("nan")
    cop = (f[:, None] * p).sum(axis=0) / f.sum()
    try:
        eq = ConvexHull(p).equations
    except (QhullError, ValueError):  # fewer than three points, or all on a line: an edge
        return float(f.sum()), 0.0
    return float(f.sum()), float(np.min(-(eq[:, :2] @ cop + eq[:, 2]))) * 1e3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--backend", default="pybullet")
    ap.add_argument("--task", default="inhand-level3-dmg")
    ap.add_argument("--strategy", default="dmg")
    ap.add_argument("--trial", type=int, required=True)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--every", type=float, default=0.05, help="sampling period (simulated s)")
    ap.add_argument(
        "--strategy-option",
        action="append",
        default=[],
        metavar="K=V",
        help="as `benchharness run --strategy-option` takes it (repeatable)",
    )
    ap.add_argument(
        "--exec",
        default="",
        metavar="PART.K=V,...",
        help="ExecutionConfig overrides for a DMG trial, e.g. grip.loose_force_ratio=0.05,"
        "setup.position_std=0 (floats)",
    )
    args = ap.parse_args()
    if args.exec:
        from dataclasses import replace

        from benchharness.strategies.dmg.execution import DMGExecConfig
        from benchharness.strategies.dmg.strategy import DMGPlanner

        base = DMGExecConfig()
        ex = base.execution
        for item in args.exec.split(","):
            key, value = item.split("=")
            part, name = key.split(".")
            ex = replace(ex, **{part: replace(getattr(ex, part), **{name: float(value)})})
        cfg = replace(base, execution=ex)
        run_trial = DMGPlanner.run_trial

        def run_trial_w(self, ctx):
            self.execution = cfg
            return run_trial(self, ctx)

        DMGPlanner.run_trial = run_trial_w
    spec = RunSpec(
        task=args.task,
        robot="pr2-gripper",
        strategy=args.strategy,
        backend=args.backend,
        repeats=args.repeats,
        strategy_options=tuple(tuple(o.split("=", 1)) for o in args.strategy_option),
    )
    st: dict = {"rig": None, "phase": "build", "next": 0.0, "prim": None, "worst": {}}
    rows: list[str] = []

    def sample() -> None:
        rig = st["rig"]
        be = rig.backend
        t = float(be.time)
        if rig.body is None or t + 1e-9 < st["next"]:
            return
        st["next"] = t + args.every
        pose = be.get_pose(rig.body)
        rest = st["rest"]  # the engine's pose when the rig built the scene
        turn = (pose.rotation * rest.rotation.inv()).as_rotvec()
        tilt = math.degrees(float(np.linalg.norm(turn)))
        try:  # the turn's axis in the hand frame (x approach, z closing), and the hand in the object
            hand = rig.hand_world()
            ax = hand.rotation.inv().apply(turn) / max(np.linalg.norm(turn), 1e-12)
            rel = rig.hand_in_object(noisy=False)
            rel0 = st.setdefault("rel0", rel)
            dh = rel0.inv() * rel
            qg = rig.robot.joint_positions(list(rig.gripper.joints))
            hand_s = (
                f" q_fingers=({qg[0] * 1e3:.1f},{qg[1] * 1e3:.1f}) mm"
                f" axis(hand)=({ax[0]:+.2f},{ax[1]:+.2f},{ax[2]:+.2f}) "
                f"hand-in-obj d=({dh.p[0] * 1e3:+5.1f},{dh.p[1] * 1e3:+5.1f},{dh.p[2] * 1e3:+5.1f}) mm "
                f"approach.z={hand.rotation.apply([1.0, 0.0, 0.0])[2]:+.2f}"
            )
        except RuntimeError:  # no grasp yet
            hand_s = ""
        dz = (pose.p[2] - rest.p[2]) * 1e3
        pads = {ln: 0.0 for ln in rig.gripper.config.finger_links}
        others: dict[str, float] = {}  # other robot links touching the object
        table = []
        for c in be.contacts(rig.body):
            if c.body_b == rig.robot.body:
                if c.link_b in pads:
                    pads[c.link_b] += c.normal_force
                else:
                    others[str(c.link_b)] = others.get(str(c.link_b), 0.0) + c.normal_force
            elif c.normal_force > 0:
                table.append(c)
        for c in be.contacts(rig.robot.body):  # the robot against anything but the object
            if c.body_b not in (rig.body, rig.robot.body) and c.normal_force > 0:
                k = f"{c.link_a}~table"
                others[k] = others.get(k, 0.0) + c.normal_force
        ft, margin = _support(table)
        if st["prim"] is not None:
            w = st["worst"]
            w[st["prim"]] = max(w.get(st["prim"], 0.0), tilt)
        rows.append(
            f"t={t:6.2f} {str(st['prim'] or '-'):>12s} {st['phase']:8s} tilt={tilt:5.1f} deg "
            f"pads N: {' '.join(f'{v:5.2f}' for v in pads.values())}  table {ft:5.2f} N, "
            f"CoP {margin:5.1f} mm inside dz={dz:+5.1f} mm"
            + hand_s
            + "".join(f" {k}={v:.2f}N" for k, v in sorted(others.items()))
        )

    build = rig_mod.TableRig.build

    def build_w(self, rest):
        build(self, rest)
        st["rig"] = self
        st["rest"] = self.backend.get_pose(self.body)
        self.backend.add_step_callback(sample)

    rig_mod.TableRig.build = build_w
    for name in ("setup_grasp", "loosen", "follow", "tighten", "servo", "lift_and_hold"):
        fn = getattr(rig_mod.TableRig, name)

        def wrapped(self, *a, _fn=fn, _name=name, **k):
            outer = st["phase"]
            st["phase"] = _name
            try:
                return _fn(self, *a, **k)
            finally:
                st["phase"] = outer

        setattr(rig_mod.TableRig, name, wrapped)

    event = TrialRecorder.event

    def event_w(self, kind, **data):
        if kind == "primitive":
            st["prim"] = f"{data['index']}:{data['primitive']}"
        return event(self, kind, **data)

    TrialRecorder.event = event_w
    rec = trial_mod.execute_trial(spec, args.trial)
    print("\n".join(rows))
    print("largest tilt per primitive (deg):", {k: round(v, 1) for k, v in st["worst"].items()})
    print("status", rec.status, rec.failure_cause, rec.message, rec.traceback[-800:])
    print("primitives", (rec.outcome.get("extra") or {}).get("primitives"))


if __name__ == "__main__":
    main()
