"""Trace where the true cube parts from the belief, primitive by primitive (issue 15; not a test).

Runs ``benchharness run`` in this process (give it ``--workers 0``) with the state machine's primitives
wrapped (``_twist``, ``_handover``, ``_join``, ``grip``, ``release_hand``, ``send``, ``_swing`` and the
grasp module's ``close_in`` / ``open``). From simulated time ``--ends-after`` s on (default 0) it prints, at the end of
every primitive, the true cube centre and the belief (mm apart, degrees apart), and from ``--after`` s on, every
``--every`` s simulated during them, a line whenever the true cube moved more than ``--moved`` mm or turned more than
0.5 degrees since the last line: the primitive stack, the cube's move, its layer angles, each hand's
holding state and the summed normal force between each hand link and the cube. At every twist's start
it prints, for each holding hand, where the true and the believed cube centre lie in the hand's measured
tool frame (how far its palm axis, about which the wrist rolls, passes from the layer's axis) and what its
closed fingers read across the pinch (``_pinch_sides``). True poses and engine contacts: a diagnostic,
nothing here changes the run. Example::

    PYTHONPATH=src:plugins python bench/trace_belief.py --after 600 run --task Rubiks-1-20 --robot herb \\
        --strategy push-grasp --backend pybullet --seed 0 --workers 0 --store /tmp/x.sqlite
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from benchharness.strategies.bimanual import machine as mm

_state: dict[str, Any] = {
    "after": 0.0,
    "after_end": 0.0,
    "every": 0.05,
    "moved": 0.5,
    "stack": [],
    "m": None,
}


def _err(m) -> str:
    true = m.cube.pose()
    d = 1000 * (true.p - m.est.p)
    rv = (true.rotation * m.est.rotation.inv()).as_rotvec()
    return (
        f"true {np.round(1000 * true.p, 1).tolist()} belief-err {np.round(d, 1).tolist()} "
        f"({np.linalg.norm(d):.1f} mm, {math.degrees(np.linalg.norm(rv)):.1f} deg "
        f"rotvec {np.round(np.degrees(rv), 1).tolist()})"
    )


def _forces(m) -> str:
    forces: dict[str, float] = {}
    for c in m.b.contacts(m.robot.body, m.cube.body):
        la = (c.link_a or "?").replace("_link", "").replace("_bh_", ":")
        forces[la] = forces.get(la, 0.0) + float(c.normal_force)
    return " ".join(f"{a} {f:.1f}" for a, f in sorted(forces.items()) if f > 0.2) or "-"


def _hands(m) -> str:
    return " ".join(f"{h.side[0]}:{'H' if h.holding else '-'}{h.depth}" for h in m.hands.values())


def _twist_axes(m, t) -> None:
    """At a twist's start: how far each hand's palm axis (tool z, measured joints) passes from the true
    cube centre and from the believed one, in the tool frame (x = across the pinch, y = towards the
    thumb); and the fingers' own reading across the pinch (FK of the closed fingers, ``_pinch_sides``)."""
    true = m.cube.pose()
    for h in m.hands.values():
        if not h.holding:
            continue
        tool = h.arm.tcp_pose()
        lt = tool.inv().apply(true.p)
        lb = tool.inv().apply(m.est.p)
        fingers = ""  # the pinch reading is HERB's push-grasp (the PR2's parallel jaws have none)
        if hasattr(m.grasp, "_pinch_sides"):
            try:
                x_neg, x_pos, z_neg, z_pos = m.grasp._pinch_sides(m, h)
                fingers = (
                    f"; fingers' middle x {1000 * 0.5 * (x_neg + x_pos):+.1f} "
                    f"width {1000 * (x_pos - x_neg):.1f} depths {1000 * z_neg:.1f}/{1000 * z_pos:.1f}"
                )
            except Exception as e:  # noqa: BLE001 - diagnostic
                fingers = f"; ({e})"
        role = "rotator" if h.side == t.gripper else "holder"
        print(
            f"t={m.b.time:8.2f} twist {t.source} {t.face}{t.quarter_turns} {role} {h.side} d{h.depth}: "
            f"true centre in tool x {1000 * lt[0]:+.1f} y {1000 * lt[1]:+.1f} z {1000 * lt[2]:+.1f}; "
            f"believed x {1000 * lb[0]:+.1f} y {1000 * lb[1]:+.1f} z {1000 * lb[2]:+.1f}{fingers}",
            flush=True,
        )


def _wrap(cls, name: str, label) -> None:
    orig = getattr(cls, name)

    @functools.wraps(orig)
    def wrapped(self, *a, **kw):
        m = self if isinstance(self, mm.BimanualRubiksMachine) else a[0]
        lab = label(self, *a, **kw) if callable(label) else label
        _state["stack"].append(lab)
        try:
            return orig(self, *a, **kw)
        finally:
            _state["stack"].pop()
            if m.b.time >= _state["after_end"]:
                print(
                    f"t={m.b.time:8.2f} end {lab:<40s} [{_hands(m)}] {_err(m)} | {_forces(m)}",
                    flush=True,
                )

    setattr(cls, name, wrapped)


def _install() -> None:
    M = mm.BimanualRubiksMachine
    run_trial = M.run_trial

    def traced_run_trial(self, ctx):
        _state["m"] = self
        _state["last"] = None
        _state["tlast"] = -1.0
        b = ctx.backend

        def after_step() -> None:
            m = _state["m"]
            if b.time < _state["after"] or not hasattr(m, "est"):
                return
            if b.time - _state["tlast"] < _state["every"] - 1e-9:
                return
            _state["tlast"] = b.time
            true = m.cube.pose()
            last = _state["last"]
            if last is not None:
                dp = 1000 * np.linalg.norm(true.p - last.p)
                dr = math.degrees(np.linalg.norm((true.rotation * last.rotation.inv()).as_rotvec()))
                if dp < _state["moved"] and dr < 0.5:
                    return
                a0, a2 = m.cube.layer_angles_deg()
                stack = " > ".join(_state["stack"][-3:])
                print(
                    f"  t={b.time:8.2f} cube moved {dp:4.1f} mm {dr:4.1f} deg in [{stack}] [{_hands(m)}] "
                    f"layers {a0:+.1f} {a2:+.1f} | {_err(m)} | {_forces(m)}",
                    flush=True,
                )
            _state["last"] = true

        b.add_step_callback(after_step)
        return run_trial(self, ctx)

    M.run_trial = traced_run_trial  # type: ignore[method-assign]
    twist = M._twist

    def traced_twist(self, t, orientation, k):
        begin = self.cube.begin_twist

        def traced_begin(axis, intended=None):
            _twist_axes(self, t)
            return begin(axis, intended=intended)

        self.cube.begin_twist = traced_begin
        try:
            return twist(self, t, orientation, k)
        finally:
            del self.cube.begin_twist

    M._twist = traced_twist  # type: ignore[method-assign]
    _wrap(M, "_twist", lambda s, t, o, k: f"twist move {t.source} {t.face}{t.quarter_turns}")
    _wrap(
        M, "_handover", lambda s, a, k: f"handover {a.giver}->{a.taker} {a.axis}{a.quarter_turns}"
    )
    _wrap(M, "_join", "join")
    _wrap(
        M, "grip", lambda s, hand, d, depth, label, *a, **kw: f"grip {hand.side} {label} d{depth}"
    )
    _wrap(M, "release_hand", lambda s, hand, *a, **kw: f"release {hand.side}")
    _wrap(M, "send", lambda s, hand, target, **kw: f"send {hand.side} {kw.get('label')}")
    _wrap(M, "_swing", lambda s, hand, far, label, *a, **kw: f"swing {hand.side} {label}")
    from benchharness.strategies.herb_rubiks.strategy import PushGrasp

    _wrap(PushGrasp, "close_in", lambda s, m, hand, *a, **kw: f"close_in {hand.side}")
    _wrap(PushGrasp, "open", lambda s, m, hand, *a, **kw: f"open {hand.side}")


def main() -> None:
    from _trace_cli import run_traced

    run_traced(
        _install,
        {
            "--after": lambda v: _state.__setitem__("after", float(v)),
            "--ends-after": lambda v: _state.__setitem__("after_end", float(v)),
            "--every": lambda v: _state.__setitem__("every", float(v)),
            "--moved": lambda v: _state.__setitem__("moved", float(v)),
        },
    )


if __name__ == "__main__":
    main()
