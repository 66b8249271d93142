"""Trace how the cube turns in each holding hand's grip along a bimanual Rubik's run (issue 16; not a test).

Runs ``benchharness run`` in this process (give it ``--workers 0``) with every
primitive of the bimanual state machine wrapped: each arm motion (``send``),
each gripper ``close`` and ``open``. Before and after each, the cube's true
orientation relative to the true tool frame of every hand that holds it is
read from the backend; a primitive that turned it more than 1 degree in a grip
is printed, marked ALONE when that hand held the cube by itself, and for arm
motions with the robot links that touched the cube meanwhile (beyond the
holding hands' own fingers), the least distance of the moving tool frame from
the cube and the joint change. Example (a minute)::

    PYTHONPATH=src:plugins python bench/bench_one_hand_holds.py run --task Rubiks-5-5 \\
        --robot pr2 --strategy sensor-aided --backend pybullet --seed 0 --workers 0 --store /tmp/x.sqlite

docs/strategies.md, "One-hand holds", has what it found.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from benchharness.robots import parts
from benchharness.strategies.bimanual import machine as mm

_current: dict[str, Any] = {"machine": None, "trial": 0}


def _relative(m: Any) -> dict[str, Any]:
    """Cube orientation in each holding hand's true tool frame."""
    cube = m.cube.pose().rotation
    return {s: h.arm.tcp_pose().rotation.inv() * cube for s, h in m.hands.items() if h.holding}


def _report(label: str, before: dict, after: dict, m: Any) -> None:
    for side, r0 in before.items():
        if side not in after:
            continue
        rv = np.degrees((r0.inv() * after[side]).as_rotvec())
        if np.linalg.norm(rv) > 1.0:
            alone = "ALONE" if len(before) == 1 else "both "
            print(
                f"  trial {_current['trial']} t={m.b.time:7.2f} {label:42s} in {side} grip ({alone}) "
                f"turned {np.linalg.norm(rv):5.1f} deg {np.round(rv, 1).tolist()}",
                flush=True,
            )


def _install() -> None:
    run_trial = mm.BimanualRubiksMachine.run_trial
    send = mm.BimanualRubiksMachine.send
    close, open_ = parts.Gripper.close, parts.Gripper.open

    def traced_run_trial(self, ctx):
        _current["machine"] = self
        _current["trial"] += 1
        print(f"trial {ctx.item.trial}: {' '.join(str(x) for x in ctx.item.sequence)}", flush=True)
        return run_trial(self, ctx)

    def traced_send(self, hand, target, **kw):
        touched: dict[str, float] = {}
        nearest = [np.inf]
        q0 = hand.arm.positions()
        held = tuple(f"{s[0]}_gripper_" for s, h in self.hands.items() if h.holding)

        def after_step() -> None:
            nearest[0] = min(
                nearest[0], float(np.linalg.norm(hand.arm.tcp_pose().p - self.cube.pose().p))
            )
            for c in self.b.contacts(self.cube.body, self.robot.body):
                if c.link_b is not None and not c.link_b.startswith(held):
                    touched[c.link_b] = max(touched.get(c.link_b, 0.0), c.normal_force)

        handle = self.b.add_step_callback(after_step)
        before = _relative(self)
        try:
            return send(self, hand, target, **kw)
        finally:
            self.b.remove_step_callback(handle)
            _report(f"{hand.side} send {kw.get('label')}", before, _relative(self), self)
            if touched:
                dq = np.round(hand.arm.positions() - q0, 2).tolist()
                forces = ", ".join(f"{k} {v:.1f} N" for k, v in touched.items())
                print(
                    f"     touched the cube: {forces}; tool frame came to "
                    f"{1000 * nearest[0]:.0f} mm of its centre; joint change {dq}",
                    flush=True,
                )

    def traced(name: str, fn):
        def wrapper(self, **kw):
            m = _current["machine"]
            if m is None or not hasattr(m, "hands"):
                return fn(self, **kw)
            before = _relative(m)
            out = fn(self, **kw)
            force = f" {kw['force_limit']} N" if kw.get("force_limit") is not None else ""
            _report(f"{self.name} {name}{force}", before, _relative(m), m)
            return out

        return wrapper

    mm.BimanualRubiksMachine.run_trial = traced_run_trial  # type: ignore[method-assign]
    mm.BimanualRubiksMachine.send = traced_send  # type: ignore[method-assign]
    parts.Gripper.close = traced("close", close)  # type: ignore[method-assign]
    parts.Gripper.open = traced("open", open_)  # type: ignore[method-assign]


def main() -> None:
    from _trace_cli import run_traced

    run_traced(_install)


if __name__ == "__main__":
    main()
