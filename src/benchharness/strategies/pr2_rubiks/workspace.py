"""Where to twist: an IK scan of the PR2 arm's soft-limit margin over the grips the Rubik's planner uses.

Why: the real PR2's safety controller keeps every arm joint inside soft
limits (``RobotConfig.soft_limits``), and IK and the primitives respect them.
At the former twisting pose (0.60, 0, 0.80) m the giver's hand-over turn
about z (ending with the hand on the robot's side of the cube, pointing
forward) had no chain of IK solutions inside them: the shoulder lift and
wrist flex pinned on their lower limits, retreats were cut short and
re-grips missed. This scan measures, at a candidate cube centre, for the
left arm (the right mirrors it, the robot being symmetric about y = 0):

* ``hold_v``/``hold_h``, ``rot_v``/``rot_h``: the side grips from +y two slabs
  (holder offset) and one slab (rotator offset) deep, fingers vertical or
  horizontal (the best of either way round), and ``far_v``/``far_h``: the
  stand-off ``far_distance`` behind the rotator's grip, where every approach
  starts;
* ``turn_z``/``turn_x``: each hand-over turn the left giver can give
  (:func:`regrasp.model.handover_turns`) from its two-slab grip, in
  ``handover_waypoints`` steps and then ``handover_retreat`` back along the
  approach, as :meth:`..bimanual.machine.BimanualRubiksMachine.turn_travel`
  checks it: a chain
  whose solutions follow each other (no joint step over ``max_waypoint_jump``);

each as the *margin*: the smallest distance (rad) of any limited joint from
its soft limit, the best over ``seeds`` IK starts (for a turn: the smallest
along the chain, the best over starts), ``-inf`` where unreachable. Run::

    PYTHONPATH=src:plugins python -m benchharness.strategies.pr2_rubiks.workspace 0.60,0,0.80 0.65,0,0.60

It reads nothing but the robot description and writes nothing.
"""

from __future__ import annotations

import math
import sys

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose
from ..bimanual.frames import grip_candidates, rotate_about_point
from .config import PR2RubiksConfig

__all__ = ["margins"]


def _left_arm():
    from ...backends.interface import PhysicsConfig
    from ...plugin import get_manager

    m = get_manager()
    b = m.create("backend", "pybullet", config=PhysicsConfig(seed=0))
    robot = m.create("robot", "pr2")
    robot.spawn(b)
    return b, robot.arm("left_arm")


def margins(
    arm, centre, cfg: PR2RubiksConfig | None = None, seeds: int = 24, rng_seed: int = 0
) -> dict[str, tuple[float, str]]:
    """Soft-limit margin (rad) and the joint that sets it, per grip family, at cube centre ``centre``."""
    cfg = cfg or PR2RubiksConfig()
    rng = np.random.default_rng(rng_seed)
    base = arm.base_pose()
    lo, hi, lim = arm.lower, arm.upper, ~arm.continuous
    names = np.array([j.split("_", 1)[1] for j in arm.joints])[lim]
    q0 = arm.positions()
    lo_f, hi_f = np.where(np.isfinite(lo), lo, -np.pi), np.where(np.isfinite(hi), hi, np.pi)
    starts = np.stack(
        [q0] + [np.clip(q0 + rng.normal(0.0, 0.8, q0.shape), lo_f, hi_f) for _ in range(seeds - 1)]
    )

    def margin(q):
        d = np.minimum(q[:, lim] - lo[lim], hi[lim] - q[:, lim])
        return d.min(1), names[d.argmin(1)]

    def solve(poses, seed_rows):
        return arm.ik(np.stack([(base.inv() * p).as_matrix() for p in poses]), seed_q=seed_rows)

    c = np.asarray(centre, dtype=float)
    cube = Pose.from_rotation(c, Rotation.from_euler("z", -90, degrees=True))
    out: dict[str, tuple[float, str]] = {}
    for name, off in (
        ("hold", cfg.holder_offset),
        ("rot", cfg.rotator_offset),
        ("far", cfg.rotator_offset + cfg.far_distance),
    ):
        grips = grip_candidates(cube, "+y", off)
        res = solve([g for g in grips for _ in range(seeds)], np.concatenate([starts] * len(grips)))
        mg, joint = margin(res.q)
        mg = np.where(res.success, mg, -np.inf).reshape(len(grips), seeds)
        joint = joint.reshape(len(grips), seeds)
        for fam, vertical in (("v", True), ("h", False)):
            rows = [
                i
                for i, g in enumerate(grips)
                if (abs(g.rotation.apply([0.0, 1.0, 0.0])[2]) > 0.7) == vertical
            ]
            i, k = max(((i, int(mg[i].argmax())) for i in rows), key=lambda t: mg[t[0], t[1]])
            out[f"{name}_{fam}"] = (float(mg[i, k]), str(joint[i, k]))
    grips = grip_candidates(cube, "+y", cfg.holder_offset)
    n = max(1, cfg.handover_waypoints)
    for ax, vec in (("z", (0.0, 0.0, 1.0)), ("x", (1.0, 0.0, 0.0))):
        for s in (1, -1):
            end = Rotation.from_rotvec(np.array(vec) * s * math.pi / 2).apply([0.0, 1.0, 0.0])
            if not (end[0] < -0.7 or end[2] > 0.7):  # regrasp.model.GIVER_ENDS: -x or +z
                continue
            angle = s * math.pi / 2
            start = [g for g in grips for _ in range(seeds)]
            res = solve(start, np.concatenate([starts] * len(grips)))
            q, ok = res.q, np.asarray(res.success, dtype=bool)
            worst, joint = margin(q)
            worst = np.where(ok, worst, -np.inf)
            for i in range(1, n + 2):
                poses = [rotate_about_point(p, c, ax, angle * min(i, n) / n) for p in start]
                if i > n:
                    poses = [
                        Pose(p.p - p.rotation.apply([cfg.handover_retreat, 0.0, 0.0]), p.q)
                        for p in poses
                    ]
                res = solve(poses, q)
                ok &= np.asarray(res.success, dtype=bool) & (
                    np.max(np.abs(res.q - q), 1) <= cfg.max_waypoint_jump
                )
                mg, jn = margin(res.q)
                joint = np.where(mg < worst, jn, joint)
                worst = np.where(ok, np.minimum(worst, mg), -np.inf)
                q = res.q
            k = int(worst.argmax())
            out[f"turn_{ax}"] = (float(worst[k]), str(joint[k]) if np.isfinite(worst[k]) else "-")
    return out


def main(argv: list[str]) -> int:
    try:
        points = [tuple(float(v) for v in a.split(",")) for a in argv]
        if not points or any(len(p) != 3 for p in points):
            raise ValueError
    except ValueError:
        print(f"expected cube centres as x,y,z (m), got {' '.join(argv)!r}", file=sys.stderr)
        return 2
    b, arm = _left_arm()
    try:
        for p in points:
            m = margins(arm, p)
            worst = min(v for v, _ in m.values())
            cells = " ".join(f"{k}={v:.3f}({j})" for k, (v, j) in m.items())
            print(f"{p}: min {worst:.3f}  {cells}")
    finally:
        b.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
