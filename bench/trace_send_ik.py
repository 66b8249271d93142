"""Trace the arm moves of a bimanual Rubik's run whose executed IK differs from the planned one (issue 16; not a test).

Runs ``benchharness run`` in this process (give it ``--workers 0``) with the
state machine's ``send`` wrapped: for every move it solves the IK of the
*believed* target (what the planner checked) and of the target the arm is sent
(the injected calibration and tracking error added), both from the move's seed,
and prints the move when the sent one fails to converge or lands more than
``--jump`` rad (default 0.8) from the seed on some joint while the believed
one does not: the label, both IK results, the largest joint change and which
limited joints sit within 0.05 rad of their limits. Example::

    PYTHONPATH=src:plugins python bench/trace_send_ik.py run --task Rubiks-1-20 --robot pr2 \\
        --strategy sensor-aided --backend pybullet --seed 0 --workers 0 --store /tmp/x.sqlite
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from benchharness.strategies.bimanual import machine as mm

JUMP = float(os.environ.get("TRACE_JUMP", "0.8"))


def _limits(arm: Any, q: np.ndarray) -> str:
    names = list(arm.config.joints)
    out = []
    for i, (v, lo, hi) in enumerate(zip(q, arm.lower, arm.upper)):
        for side, lim in (("lo", lo), ("hi", hi)):
            if np.isfinite(lim) and abs(v - lim) < 0.05:
                out.append(f"{names[i]} {side} {v - lim:+.3f}")
    return ", ".join(out) or "none"


def _install() -> None:
    send = mm.BimanualRubiksMachine.send
    actual = mm.BimanualRubiksMachine.actual
    last: dict[str, Any] = {}

    def traced_actual(hand, target, noise):
        out = actual(hand, target, noise)
        last["sent"] = out
        return out

    def traced_send(self, hand, target, **kw):
        q_now = hand.arm.positions()
        seed = q_now if kw.get("seed_q") is None else np.asarray(kw["seed_q"], dtype=float)
        base = hand.arm.base_pose()
        err = None
        try:
            return send(self, hand, target, **kw)
        except mm.StrategyFailure as e:
            err = e
            raise
        finally:
            sent = last.pop("sent", None)
            if sent is not None:
                rb = hand.arm.ik((base.inv() * target).as_matrix()[None], seed_q=seed)
                rs = hand.arm.ik((base.inv() * sent).as_matrix()[None], seed_q=seed)
                jb = float(np.max(np.abs(rb.q[0] - seed)))
                js = float(np.max(np.abs(rs.q[0] - seed)))
                if err is not None or not rs.success[0] or (js > JUMP and jb <= JUMP):
                    print(
                        f"t={self.b.time:8.2f} {hand.side} {kw.get('label')}: believed IK "
                        f"{bool(rb.success[0])} (jump {jb:.2f}, pos err {1000 * rb.pos_error[0]:.1f} mm), "
                        f"sent IK {bool(rs.success[0])} (jump {js:.2f}, pos err "
                        f"{1000 * rs.pos_error[0]:.1f} mm); sent - believed "
                        f"{np.round(1000 * (sent.p - target.p), 1).tolist()} mm; "
                        f"dq sent {np.round(rs.q[0] - seed, 2).tolist()}; seeded={kw.get('seed_q') is not None}\n"
                        f"    near limits: believed [{_limits(hand.arm, rb.q[0])}] "
                        f"sent [{_limits(hand.arm, rs.q[0])}] seed [{_limits(hand.arm, seed)}]"
                        + (f"\n    FAILED: {err}" if err is not None else ""),
                        flush=True,
                    )

    mm.BimanualRubiksMachine.actual = staticmethod(traced_actual)  # type: ignore[method-assign]
    mm.BimanualRubiksMachine.send = traced_send  # type: ignore[method-assign]


def main() -> None:
    from _trace_cli import run_traced

    run_traced(_install)


if __name__ == "__main__":
    main()
