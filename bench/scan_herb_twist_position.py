"""Where HERB can turn the cube in every hand-over the planner may ask for (issue 15; not a test).

For each candidate twist position (the believed cube centre while twisting, the
machine's ``twist_position``) this scans, with the HERB arms' own IK and the
shared machine's own planning functions:

* **hand-over turns**: for each giver (left, right) and each quarter turn the
  planner's HERB model lets it give (``regrasp.handover_turns``: about x or z,
  ending on the robot's side or above), the giver's one-slab push-grasps whose
  pinch does not end on the work axis (the grasp module's rule), and from arm
  postures found backwards (``turn_postures``, ``--seeds`` starts a grip) the
  chains whose turn and retreat are smooth; of those, the ones whose every turn
  waypoint keeps the injected errors' ``--sigmas`` box in reach
  (``reachable``, the margin a swing keeps). A turn with no such chain can end a
  trial ``unreachable`` whatever the grip choice;
* **twist grips**: each hand's one- and two-slab push-grasps of its own face
  (four finger placements), reachable with that margin from ``--seeds`` random
  starts.

Runs on PyBullet (IK is the robot's, not the engine's; the engine only holds
the arms to read the tool frames and measure the pre-shapes). Examples (about
a minute a position)::

    PYTHONPATH=src:plugins python bench/scan_herb_twist_position.py --x 0.85,0.90,0.95 --z 1.05,1.10,1.15
    # the belief SAPIEN Rubiks-1-100 seed 0 had at its failed hand-over turn (6.3 deg off faces-level)
    PYTHONPATH=src:plugins python bench/scan_herb_twist_position.py --x 0.90 --z 1.10 \
        --orientation=-0.69983,-0.03688,-0.71226,-0.03947

docs/herb_push_grasp.md, "Where the cube is twisted", has what it found.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation


def _ctx(seed: int):
    from benchharness.backends.interface import PhysicsConfig
    from benchharness.cube import parse_sequence
    from benchharness.plugin import get_manager
    from benchharness.runner.contract import RubiksItem, TimeBudget, TrialContext
    from benchharness.runner.recorder import TrialRecorder

    m = get_manager()
    phys = PhysicsConfig(seed=seed)
    b = m.create("backend", "pybullet", config=phys)
    item = RubiksItem("Rubiks-1-1", 1, 1, tuple(parse_sequence("R")), seed)
    ctx = TrialContext(
        item=item,
        trial_index=1,
        robot=m.create("robot", "herb"),
        backend=b,
        sensors={},
        rng=np.random.default_rng(seed),
        budget=TimeBudget(),
        recorder=TrialRecorder(clock=lambda: float(b.time)),
        physics=phys,
    )
    return ctx, b


def _margin_ok(m, hand, path, grip, q0, n, sigmas) -> bool:
    """Every waypoint of the turn from ``q0`` (forwards, each seeded with the last) keeps the margin."""
    base = hand.arm.base_pose()
    q = np.asarray(q0, dtype=float)
    for i in range(0, n + 1):
        pose = path.at(grip, i, n)
        res = hand.arm.ik((base.inv() * pose).as_matrix()[None], seed_q=q)
        if not res.success[0]:
            return False
        q = np.asarray(res.q[0], dtype=float)
        if not m.reachable(hand, pose, q, sigmas=sigmas):
            return False
    return True


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--x", default="0.85,0.90,0.95", help="candidate x (m), comma-separated")
    ap.add_argument("--y", default="0.0")
    ap.add_argument("--z", default="1.05,1.10,1.15")
    ap.add_argument("--seeds", type=int, default=16, help="backward starts per grip")
    ap.add_argument(
        "--sigmas", type=float, default=3.0, help="reach margin, in injected-error sigmas"
    )
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--orientation",
        default=None,
        help="the believed cube's orientation, quaternion x,y,z,w (default faces-level, F to the robot)",
    )
    args = ap.parse_args()

    from benchharness.geometry import Pose
    from benchharness.strategies.bimanual.machine import SIDE_DIR, level_correction
    from benchharness.strategies.herb_rubiks.frames import pinch_axis, push_grip_candidates
    from benchharness.strategies.herb_rubiks.strategy import GIVE_SHAPE, PushGraspStrategy
    from benchharness.strategies.regrasp.model import handover_turns

    ctx, b = _ctx(args.seed)
    strat = PushGraspStrategy()
    base_cfg = strat.grasp.config
    # run the trial's set-up only (scene, robot, hands, camera), no action
    strat.grasp.config = replace(base_cfg, max_actions=0)
    strat.run_trial(ctx)
    m = strat
    grasp = m.grasp
    depths = {}
    for side, hand in m.hands.items():
        for shape in (1, 2, GIVE_SHAPE):
            grasp._preshape(m, hand, shape)
            depths[(side, shape)] = hand.state.face_depth
    dirs = {"x": np.array([1.0, 0, 0]), "z": np.array([0, 0, 1.0])}
    n_way = max(1, base_cfg.handover_waypoints)
    rng = np.random.default_rng(args.seed)
    believed = (
        Rotation.from_euler("z", -90, degrees=True)
        if args.orientation is None
        else Rotation.from_quat([float(v) for v in args.orientation.split(",")])
    )
    tilt = np.degrees(np.linalg.norm(level_correction(believed)))
    print(
        "per hand (l, r): twist grips of its own face reachable with the margin, one and two slabs"
        " deep (of 4 placements); per hand-over turn the giver may give: chains found backwards"
        f" (of {args.seeds} x 2 grips) / of them with the margin at every waypoint, with the"
        f" {100 * base_cfg.handover_retreat:.0f} cm retreat and then the turn alone"
    )
    print(
        f"belief {tilt:.1f} deg off faces-level; reach margin {args.sigmas} sigma = {1000 * m.reach_margin(args.sigmas)[0]:.1f} mm, "
        f"{math.degrees(m.reach_margin(args.sigmas)[1]):.1f} deg; {args.seeds} starts a grip"
    )
    for x in (float(v) for v in args.x.split(",")):
        for y in (float(v) for v in args.y.split(",")):
            for z in (float(v) for v in args.z.split(",")):
                p = (x, y, z)
                grasp.config = replace(base_cfg, twist_position=p, max_actions=0)
                m.est = Pose.from_rotation(p, believed)
                cells = []
                for side, hand in m.hands.items():
                    base = hand.arm.base_pose()
                    # twist grips of its own face
                    for shape in (1, 2):
                        ok = 0
                        for g in push_grip_candidates(m.est, SIDE_DIR[side], depths[(side, shape)]):
                            lo, hi = hand.arm.lower, hand.arm.upper
                            for _ in range(args.seeds):
                                s = lo + rng.random(lo.size) * (hi - lo)
                                r = hand.arm.ik((base.inv() * g).as_matrix()[None], seed_q=s)
                                if r.success[0] and m.reachable(
                                    hand, g, r.q[0], sigmas=args.sigmas
                                ):
                                    ok += 1
                                    break
                        cells.append(f"{side[0]}{shape}:{ok}/4")
                    for axis, qt in handover_turns(side):
                        angle = qt * math.pi / 2
                        turned = Rotation.from_rotvec(dirs[axis] * angle)
                        grips = [
                            g
                            for g in push_grip_candidates(
                                m.est, SIDE_DIR[side], depths[(side, GIVE_SHAPE)]
                            )
                            if abs(float(turned.apply(pinch_axis(g))[1])) <= 0.7
                        ]
                        path = m.turn_path(axis, angle)
                        counts = []
                        for retreat in (base_cfg.handover_retreat, 0.0):
                            grasp.config = replace(
                                base_cfg, twist_position=p, max_actions=0, handover_retreat=retreat
                            )
                            owner, qs = m.turn_postures(hand, base, grips, axis, angle, args.seeds)
                            margin = sum(
                                _margin_ok(m, hand, path, grips[o], q, n_way, args.sigmas)
                                for o, q in zip(owner, qs, strict=True)
                            )
                            counts.append(f"{len(owner)}/{margin}")
                        grasp.config = replace(base_cfg, twist_position=p, max_actions=0)
                        cells.append(f"{side[0]} {axis}{qt:+d}: {' '.join(counts)}")
                print(f"({x:.2f}, {y:.2f}, {z:.2f})  " + "  ".join(cells), flush=True)
    b.close()


if __name__ == "__main__":
    main()
