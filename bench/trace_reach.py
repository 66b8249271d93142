"""Trace every arm motion of a bimanual Rubik's run that ends far from its target (issue 16; not a test).

Runs ``benchharness run`` in this process (give it ``--workers 0``) with
``RobotArm.move_to_pose`` wrapped. For each motion that ends more than
``--trace-mm`` (default 10) from its target, or whose joints end more than
0.05 rad from their goal, it prints the machine's label, the IK result
(success, the forward kinematics of the goal against the target), the goal
against the arm's soft limits, the joints' end error, and every contact of
the robot (with itself, the table, the cube) while it moved. Example::

    PYTHONPATH=src:plugins python bench/trace_reach.py --trace-mm 10 run --task Rubiks-1-50 \\
        --robot pr2 --strategy sensor-aided --backend sapien --seed 0 --workers 0 --store /tmp/x.sqlite

docs/strategies.md, "An arm 141 mm from its command", has what it found.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from benchharness.robots import parts
from benchharness.robots.kinematics import pose_error
from benchharness.strategies.bimanual import machine as mm

_state: dict[str, Any] = {"label": "", "machine": None, "mm": 10.0}


def _install() -> None:
    send = mm.BimanualRubiksMachine.send
    move = parts.RobotArm.move_to_pose
    run_trial = mm.BimanualRubiksMachine.run_trial

    def traced_run_trial(self, ctx):
        _state["machine"] = self
        return run_trial(self, ctx)

    def traced_send(self, hand, target, **kw):
        _state["label"] = f"{hand.side} {kw.get('label')} (move {self.move_index})"
        return send(self, hand, target, **kw)

    def traced_move(self, target, **kw):
        m = _state["machine"]
        b = self.robot.backend
        body = self.robot.body
        touched: dict[tuple, float] = {}
        tick = [0]

        def after_step() -> None:
            tick[0] += 1
            if tick[0] % 5:
                return
            for c in b.contacts(body):
                key = (c.link_a, c.body_b, c.link_b)
                touched[key] = max(touched.get(key, 0.0), c.normal_force)

        q0 = self.positions()
        handle = b.add_step_callback(after_step)
        try:
            res = move(self, target, **kw)
        finally:
            b.remove_step_callback(handle)
        q1 = self.positions()
        bad = res.pos_error * 1000 > _state["mm"] or res.final_joint_error > 0.05
        if bad:
            base = self.base_pose()
            fk_goal = base * type(base).from_matrix(self.fk(res.q_goal[None])[0])
            dp, dr = pose_error(fk_goal.as_matrix(), target.as_matrix())
            fk_now = base * type(base).from_matrix(self.fk(q1[None])[0])
            dpn, _ = pose_error(fk_now.as_matrix(), self.tcp_pose().as_matrix())
            t = m.b.time if m is not None else float("nan")
            print(
                f"t={t:8.2f} {self.name} {_state['label']}: ended {1000 * res.pos_error:.1f} mm, "
                f"{np.degrees(res.rot_error):.1f} deg from target; ik_success={res.ik_success}; "
                f"FK(goal) vs target {1000 * float(dp[0]):.1f} mm {np.degrees(float(dr[0])):.1f} deg; "
                f"FK(joints) vs engine tool frame {1000 * float(dpn[0]):.1f} mm",
                flush=True,
            )
            print(f"    q0     {np.round(q0, 3).tolist()}", flush=True)
            print(f"    q_goal {np.round(res.q_goal, 3).tolist()}", flush=True)
            print(f"    q_end  {np.round(q1, 3).tolist()}", flush=True)
            print(f"    lower  {np.round(self.lower, 3).tolist()}", flush=True)
            print(f"    upper  {np.round(self.upper, 3).tolist()}", flush=True)
            print(
                f"    joint end error {np.round(q1 - res.q_goal, 3).tolist()} "
                f"(max tracking {res.max_tracking_error:.3f} rad, duration {res.duration:.2f} s)",
                flush=True,
            )
            for (la, bb, lb), f in sorted(touched.items(), key=lambda kv: -kv[1]):
                print(f"    contact {la} - body {bb} {lb}: {f:.1f} N", flush=True)
        return res

    mm.BimanualRubiksMachine.run_trial = traced_run_trial  # type: ignore[method-assign]
    mm.BimanualRubiksMachine.send = traced_send  # type: ignore[method-assign]
    parts.RobotArm.move_to_pose = traced_move  # type: ignore[method-assign]


def main() -> None:
    from _trace_cli import run_traced

    run_traced(_install, {"--trace-mm": lambda v: _state.__setitem__("mm", float(v))})


if __name__ == "__main__":
    main()
