"""How many of a PR2 Rubik's run's arm joint targets lie outside the PR2's soft limits (issue 11; not a test).

The real PR2's safety controller resists any arm joint beyond its
``<safety_controller>`` soft limits (pr2_description; ours carry the same,
see ``src/benchharness/robots/descriptions/pr2.py``). This runs one tier
through the runner in this process, as ``benchharness run --workers 0`` does,
and records on the way

* every joint goal a strategy asks an arm for (``RobotArm.move_to_joints``,
  which ``move_to_pose`` calls with its IK solution), *before* the primitive
  clips it to the limits, with the strategy function that asked for it;
* every PD target the robot sends to an arm joint (``Robot.drive``: every
  control tick of every trajectory and hold).

and reports how many lie outside the soft limits (and outside the hard
ones), per joint and per calling function. Exit status 1 if any driven
target lies outside the soft limits. Example (minutes)::

    PYTHONPATH=src:plugins python bench/bench_soft_limits.py --task Rubiks-5-10 --backend pybullet

``--soft-limits off`` runs the robot with ``RobotConfig.soft_limits=False``
(hard limits only), which is how the arm targets were counted before the soft
limits were part of the robot.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

TOL = 1e-9  # rad: a target on the limit is inside


class Recorder:
    """Counts arm joint goals/targets outside the PR2's soft and hard limits."""

    def __init__(self) -> None:
        self.goals = 0
        self.goals_outside_soft = 0
        self.goals_outside_hard = 0
        self.goal_joints: Counter[str] = Counter()
        self.goal_callers: Counter[str] = Counter()
        #: goals with a joint pinned on a soft limit (within 1e-6 rad; IK clamps there): where the limits bite
        self.goals_at_soft = 0
        self.at_soft: Counter[str] = Counter()  # "caller: joint lower|upper"
        self.targets = 0  # (tick, joint) pairs driven
        self.targets_outside_soft = 0
        self.target_joints: Counter[str] = Counter()
        self.worst: dict[
            str, float
        ] = {}  # joint -> largest goal excursion beyond the soft limit (rad)
        self.worst_driven: dict[str, float] = {}  # the same for driven targets

    @staticmethod
    def _limits(robot, joints):
        import numpy as np

        js = [robot.urdf_joints[j] for j in joints]
        soft = (np.array([j.soft_lower for j in js]), np.array([j.soft_upper for j in js]))
        hard = (np.array([j.lower for j in js]), np.array([j.upper for j in js]))
        return soft, hard

    def goal(self, arm, q, caller: str) -> None:
        import numpy as np

        (slo, shi), (hlo, hhi) = self._limits(arm.robot, arm.joints)
        q = np.asarray(q, dtype=float)
        out = (q < slo - TOL) | (q > shi + TOL)
        self.goals += 1
        if out.any():
            self.goals_outside_soft += 1
            self.goal_callers[caller] += 1
            for j, o, v, lo, hi in zip(arm.joints, out, q, slo, shi):
                if o:
                    self.goal_joints[j] += 1
                    self.worst[j] = max(self.worst.get(j, 0.0), float(max(lo - v, v - hi)))
        if ((q < hlo - TOL) | (q > hhi + TOL)).any():
            self.goals_outside_hard += 1
        hard_differs = (slo > hlo) | (shi < hhi)
        at_lo = hard_differs & (np.abs(q - slo) < 1e-6)
        at_hi = hard_differs & (np.abs(q - shi) < 1e-6)
        if (at_lo | at_hi).any():
            self.goals_at_soft += 1
            for j, lo_, hi_ in zip(arm.joints, at_lo, at_hi):
                if lo_ or hi_:
                    self.at_soft[f"{caller}: {j} {'lower' if lo_ else 'upper'}"] += 1

    def drive(self, robot, joints, q) -> None:
        import numpy as np

        arm_joints = {j for a in robot.config.arms for j in a.joints}
        sel = [i for i, j in enumerate(joints) if j in arm_joints]
        if not sel:
            return
        names = [joints[i] for i in sel]
        (slo, shi), _ = self._limits(robot, names)
        v = np.asarray(q, dtype=float)[sel]
        out = (v < slo - TOL) | (v > shi + TOL)
        self.targets += len(sel)
        self.targets_outside_soft += int(out.sum())
        for j, o, x, lo, hi in zip(names, out, v, slo, shi):
            if o:
                self.target_joints[j] += 1
                e = float(max(lo - x, x - hi))
                self.worst_driven[j] = max(self.worst_driven.get(j, 0.0), e)

    def report(self) -> dict:
        return {
            "arm_goals": self.goals,
            "arm_goals_outside_soft": self.goals_outside_soft,
            "arm_goals_outside_hard": self.goals_outside_hard,
            "goals_outside_soft_by_joint": dict(self.goal_joints.most_common()),
            "goals_outside_soft_by_caller": dict(self.goal_callers.most_common()),
            "worst_excursion_rad": {k: round(v, 4) for k, v in sorted(self.worst.items())},
            "arm_goals_at_a_soft_limit": self.goals_at_soft,
            "at_soft_limit_by_caller_and_joint": dict(self.at_soft.most_common()),
            "driven_arm_targets": self.targets,
            "driven_arm_targets_outside_soft": self.targets_outside_soft,
            "driven_outside_soft_by_joint": dict(self.target_joints.most_common()),
            "worst_driven_excursion_rad": {
                k: round(v, 4) for k, v in sorted(self.worst_driven.items())
            },
        }


def _caller() -> str:
    """The nearest strategy function on the stack (what asked for the motion)."""
    f = sys._getframe(2)
    while f is not None:
        mod = f.f_globals.get("__name__", "")
        if mod.startswith("benchharness.strategies"):
            return f"{mod.rsplit('.', 1)[-1]}.{f.f_code.co_name}"
        f = f.f_back
    return "?"


def install(rec: Recorder, soft_limits: bool) -> None:
    """Wrap the two choke points every PR2 arm motion passes through (in this process)."""
    from dataclasses import replace

    from benchharness.robots import pr2 as pr2_mod
    from benchharness.robots.parts import RobotArm
    from benchharness.robots.robot import Robot

    move = RobotArm.move_to_joints
    drive = Robot.drive

    def move_to_joints(self, q_goal, **kw):
        if self.robot.name == "pr2":
            rec.goal(self, q_goal, _caller())
        return move(self, q_goal, **kw)

    def drive_(self, joints, q, qd=None):
        if self.name == "pr2":
            rec.drive(self, list(joints), q)
        return drive(self, joints, q, qd)

    RobotArm.move_to_joints = move_to_joints  # type: ignore[method-assign]
    Robot.drive = drive_  # type: ignore[method-assign]
    if not soft_limits:
        config = pr2_mod.pr2_config

        def hard_only(*a, **kw):
            return replace(config(*a, **kw), soft_limits=False)

        pr2_mod.pr2_config = hard_only  # make_pr2 looks it up at call time


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", default="Rubiks-5-10")
    ap.add_argument("--strategy", default="sensor-aided")
    ap.add_argument("--backend", default="pybullet", choices=("pybullet", "sapien"))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--soft-limits", choices=("on", "off"), default="on")
    ap.add_argument("--json", type=Path, help="also write the report here")
    ap.add_argument(
        "--store",
        type=Path,
        help="keep the trials in this results store (default: a temporary one)",
    )
    args = ap.parse_args(argv)

    from benchharness.runner import ResultsStore, RunSpec, run_sweep

    rec = Recorder()
    install(rec, args.soft_limits == "on")
    spec = RunSpec(
        task=args.task, robot="pr2", strategy=args.strategy, backend=args.backend, seed=args.seed
    )
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        store = ResultsStore(args.store or Path(tmp) / "bench.sqlite")
        run = run_sweep(spec, store, workers=0)
        store.close()
    recs = run.records
    out = {
        "command": " ".join(["python", "bench/bench_soft_limits.py", *(argv or sys.argv[1:])]),
        "task": args.task,
        "strategy": args.strategy,
        "backend": args.backend,
        "seed": args.seed,
        "soft_limits": args.soft_limits,
        "trials": len(recs),
        "successes": sum(r.status.value == "success" for r in recs),
        "causes": [r.failure_cause.value if r.failure_cause else None for r in recs],
        "wall_s": round(time.perf_counter() - t0, 1),
        **rec.report(),
    }
    text = json.dumps(out, indent=2)
    print(text)
    if args.json:
        args.json.write_text(text + "\n")
    return 1 if rec.targets_outside_soft else 0


if __name__ == "__main__":
    sys.exit(main())
