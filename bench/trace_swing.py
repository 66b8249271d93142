"""Trace every checked swing route (``swing_routes``) of a bimanual Rubik's run: how near the reach edge its
waypoints are with the injected errors (issue 15; not a test).

Runs ``benchharness run`` in this process (give it ``--workers 0``) with the machine's ``_swing_route``
and ``send`` wrapped. For each route the machine takes it prints, per waypoint (and the stand-off): whether
IK for the believed pose succeeds (chained from the arm's joints, as the route check does) and how many
of the 12 neighbours of the margin box (moved ``--sigmas`` standard deviations of the injected position
error either way along each world axis, turned as many of the calibration's rotation about each) have an
IK solution: the box :meth:`BimanualRubiksMachine.reachable` checks with ``reach_sigmas``. Each executed
arc move then prints how far the arm's IK ended from the target it was sent (with the injected errors).
Example::

    PYTHONPATH=src:plugins python bench/trace_swing.py --sigmas 3 run --task Rubiks-5-5 --robot herb \\
        --strategy push-grasp --backend sapien --seed 0 --workers 0 --store /tmp/x.sqlite

docs/herb_push_grasp.md, "Arc waypoints and the injected errors", has what it found.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from benchharness.geometry import Pose
from benchharness.robots import parts
from benchharness.strategies.bimanual import machine as mm

_state: dict[str, Any] = {"label": "", "sigmas": 3.0, "machine": None}


def _box(m: mm.BimanualRubiksMachine, pose: Pose) -> list[tuple[str, Pose]]:
    """The 12 neighbours ``reachable`` checks, named."""
    err, k = m.config.errors, _state["sigmas"]
    dp = k * math.hypot(err.calib_pos_std, err.tracking_std)
    dr = k * math.radians(err.calib_rot_std_deg)
    out = []
    for i, axis in enumerate(np.eye(3)):
        for s in (1.0, -1.0):
            name = ("+" if s > 0 else "-") + "xyz"[i]
            out.append((f"{name} {1000 * dp:.1f} mm", Pose(pose.p + s * dp * axis, pose.q)))
            turn = Rotation.from_rotvec(s * dr * axis) * pose.rotation
            out.append(
                (f"turn {name} {math.degrees(dr):.1f} deg", Pose.from_rotation(pose.p, turn))
            )
    return out


def _install() -> None:
    route = mm.BimanualRubiksMachine._swing_route
    send = mm.BimanualRubiksMachine.send
    move = parts.RobotArm.move_to_pose
    run_trial = mm.BimanualRubiksMachine.run_trial

    def traced_run_trial(self, ctx):
        _state["machine"] = self
        print("=== trial", flush=True)
        return run_trial(self, ctx)

    def traced_route(self, hand, far, label, *a, **kw):
        poses = route(self, hand, far, label, *a, **kw)
        base = hand.arm.base_pose()
        q = hand.arm.positions()
        c = self.est.p
        print(
            f"t={self.b.time:8.2f} {hand.side} {label} (move {self.move_index}): route of "
            f"{len(poses)} waypoints, cube at {np.round(c, 3).tolist()}",
            flush=True,
        )
        for i, pose in enumerate([*poses, far]):
            res = hand.arm.ik((base.inv() * pose).as_matrix()[None], seed_q=q)
            ok = bool(res.success[0])
            box = _box(self, pose)
            mats = np.stack([(base.inv() * p).as_matrix() for _, p in box])
            seed = res.q[0] if ok else q
            fails = [
                name
                for j, (name, _) in enumerate(box)
                if not bool(np.asarray(hand.arm.ik(mats[j : j + 1], seed_q=seed).success)[0])
            ]
            n_ok = len(box) - len(fails)
            shoulder = base.apply(hand.arm.joint_origins(np.asarray(res.q[0])[None])[0][1])
            print(
                f"    {'stand-off' if i == len(poses) else f'waypoint {i + 1}'} "
                f"{np.round(pose.p, 3).tolist()}: IK {ok}, margin box {n_ok}/{len(box)} reachable, "
                f"{1000 * float(np.linalg.norm(pose.p - shoulder)):.0f} mm from the shoulder"
                + (f"; out of reach: {', '.join(fails)}" if fails else ""),
                flush=True,
            )
            if ok:
                q = res.q[0]
        return poses

    def traced_send(self, hand, target, **kw):
        _state["label"] = f"{hand.side} {kw.get('label')}"
        return send(self, hand, target, **kw)

    def traced_move(self, target, **kw):
        res = move(self, target, **kw)
        if _state["label"].endswith(" arc"):
            print(
                f"    sent {_state['label']}: IK {res.ik_success}, ended {1000 * res.pos_error:.1f} mm, "
                f"{math.degrees(res.rot_error):.2f} deg from the sent target",
                flush=True,
            )
        return res

    mm.BimanualRubiksMachine.run_trial = traced_run_trial  # type: ignore[method-assign]
    mm.BimanualRubiksMachine._swing_route = traced_route  # type: ignore[method-assign]
    mm.BimanualRubiksMachine.send = traced_send  # type: ignore[method-assign]
    parts.RobotArm.move_to_pose = traced_move  # type: ignore[method-assign]


def main() -> None:
    from _trace_cli import run_traced

    run_traced(_install, {"--sigmas": lambda v: _state.__setitem__("sigmas", float(v))})


if __name__ == "__main__":
    main()
