"""Trace the twists of a bimanual Rubik's run step by step (issue 15; not a test).

Runs ``benchharness run`` in this process (give it ``--workers 0``) with the
state machine's ``_twist`` wrapped. During each twist (from the wrist roll to
the rotator letting go), every ``--every`` s simulated it prints the rotator's
wrist roll (WAM joint 7, measured, from where it started), the cube's layer
angles (slab 0 and 2 against the middle slab) and each slab's turn in the world
about the twist axis since the twist began, and the summed normal force between
each hand's finger links and each slab. True poses and engine contacts: a
diagnostic, nothing here changes the run. ``--moves 3,4`` traces those move
indices only (default all). Example::

    PYTHONPATH=src:plugins python bench/trace_twist.py --moves 2 run --task Rubiks-1-20 \\
        --robot herb --strategy push-grasp --backend pybullet --seed 0 --workers 0 --store /tmp/x.sqlite
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from benchharness.strategies.bimanual import machine as mm

_state: dict[str, Any] = {"every": 0.1, "moves": None}


def _install() -> None:
    twist = mm.BimanualRubiksMachine._twist

    def traced_twist(self, t, orientation, k):
        if _state["moves"] is not None and t.source not in _state["moves"]:
            return twist(self, t, orientation, k)
        b, cube = self.b, self.cube
        rot = self.hands[t.gripper]
        begin = cube.begin_twist
        info: dict[str, Any] = {}

        def traced_begin(axis, intended=None):
            begin(axis, intended=intended)
            body = cube.body
            links = sorted(
                {c.link_b for c in b.contacts(self.robot.body, body) if c.link_b}
                | {f"slab_{i}" for i in range(3)}
            )
            info.update(body=body, axis=axis, links=links, t0=b.time, last=-1.0)
            info["r0"] = {ln: _link_rot(b, body, ln) for ln in links}
            info["q0"] = float(rot.arm.positions()[-1])
            ax = np.zeros(3)
            ax["xyz".index(axis)] = 1.0
            info["ax_world"] = cube.pose().rotation.apply(ax)

            def after_step() -> None:
                now = b.time
                if now - info["last"] < _state["every"] - 1e-9:
                    return
                info["last"] = now
                _print_state(self, rot, info)

            info["cb"] = b.add_step_callback(after_step)
            print(
                f"== move {t.source} {t.face}{'' if t.quarter_turns == 1 else t.quarter_turns} "
                f"({t.gripper} rotates, {t.quarter_turns} quarter turns, body axis {axis}, intended "
                f"{intended}) at t={b.time:.2f}",
                flush=True,
            )

        end = cube.end_twist

        def traced_end():
            _print_state(self, rot, info)
            if "cb" in info:
                b.remove_step_callback(info.pop("cb"))
            out = end()
            print(f"   outcome: {out.summary()}", flush=True)
            return out

        cube.begin_twist, cube.end_twist = traced_begin, traced_end
        try:
            return twist(self, t, orientation, k)
        finally:
            del cube.begin_twist, cube.end_twist
            if "cb" in info:
                b.remove_step_callback(info.pop("cb"))

    mm.BimanualRubiksMachine._twist = traced_twist  # type: ignore[method-assign]


def _link_rot(b, body, link) -> Rotation | None:
    try:
        return b.get_link_pose(body, link).rotation
    except Exception:  # noqa: BLE001 - a name that is not a link of this body
        return None


def _print_state(m, rot, info) -> None:
    b = m.b
    body, ax = info["body"], info["ax_world"]
    turns = []
    for ln in info["links"]:
        r0, r1 = info["r0"].get(ln), _link_rot(b, body, ln)
        if r0 is None or r1 is None:
            continue
        rv = (r1 * r0.inv()).as_rotvec()
        turns.append(f"{ln} {math.degrees(float(np.dot(rv, ax))):+6.1f}")
    a0, a2 = m.cube.layer_angles_deg()
    q7 = float(rot.arm.positions()[-1]) - info["q0"]
    forces: dict[tuple[str, str], float] = {}
    for c in b.contacts(m.robot.body, body):
        la = (c.link_a or "?").replace("_link", "").replace("_bh_", ":")
        key = (la, c.link_b or "?")
        forces[key] = forces.get(key, 0.0) + float(c.normal_force)
    fs = " ".join(f"{a}-{s} {f:.1f}" for (a, s), f in sorted(forces.items()) if f > 0.2)
    print(
        f"  t={b.time - info['t0']:5.2f} wrist {math.degrees(q7):+7.1f} | layers {a0:+7.1f} {a2:+7.1f} | "
        f"world {' '.join(turns)} | {fs}",
        flush=True,
    )


def main() -> None:
    from _trace_cli import run_traced

    run_traced(
        _install,
        {
            "--every": lambda v: _state.__setitem__("every", float(v)),
            "--moves": lambda v: _state.__setitem__("moves", {int(x) for x in v.split(",")}),
        },
    )


if __name__ == "__main__":
    main()
