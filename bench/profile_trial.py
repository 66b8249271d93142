"""Where a trial's CPU goes besides the engine's step: a sampled profile split by kind of work (issue 12).

``bench_speed.py`` measures a trial's simulated seconds per CPU-second against
its engine's own steps (target ratio >= 0.85). This script says what the rest
of the trial's CPU is, so that the shortfall has a measured cause. It runs the
real ``benchharness run`` command (``--workers 0``, a throw-away store) under
``py-spy record`` (a sampling profiler: unlike cProfile it does not inflate the
cost of Python calls, which is what is being measured) and attributes every
sample taken inside ``execute_trial`` to one kind of work:

* the engine's step: the sample's innermost Python frame is the backend's
  ``self._engine_step()`` line (``pybullet.stepSimulation`` / PhysX's step);
* otherwise the **deepest** frame matching one of :data:`KINDS` decides (an IK
  solve inside a grasp choice is IK, not planning);
* imports made during the trial are counted apart: a sweep's worker pays them
  once, not per trial (``bench_speed.py`` reports the ratio both ways).

It also reports the ratio the trial would reach were everything done once per
motion or per trial (planning, IK, sensing, set-up, the rest of the strategy)
free: the engine against the engine plus the work done on **every physics
step** (the control tick, the step callbacks, PyBullet's drive law). That bound
shows whether the per-step loop alone keeps the trial under the target.

Usage (from the repository root; py-spy is in the ``bench`` extra)::

    python bench/profile_trial.py                                  # Rubiks-1-5, both engines
    python bench/profile_trial.py --only Rubiks-1-20 --backends sapien --rate 100
    python bench/profile_trial.py --raw prof.txt                   # split a saved raw profile
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_speed import TRIALS, trial_argv

#: kinds of work outside the engine's step, each a pattern on a frame's "function (file)";
#: the deepest matching frame of a sample names its kind. Shared helpers (FK, Jacobians,
#: rotations) are named by none: their time goes to the work that called them (IK or a check)
KINDS: tuple[tuple[str, str], ...] = (
    (
        "per step: drive law (PyBullet's mass matrix, inverse dynamics)",
        r"^PyBulletBackend\.(_apply_drives|_mass_inverse|_inverse_dynamics|_motion) ",
    ),
    (
        "per step: callbacks (fingertip re-aim, detents, contact reads)",
        r"^Backend\._run_step_callbacks ",
    ),
    (
        "per step: control tick (targets, joint reads, gravity, engine loop)",
        r"^(Robot\.(track|step|drive|settle|_gravity_all)|Backend\.step|\w+Backend\."
        r"(_step_engine|set_joint_targets|_send_targets|get_joint_motion|gravity_torques|"
        r"_retarget_driven)|Backend\.retarget_joints) ",
    ),
    (
        "per motion: IK (seeded damped least squares)",
        r"^(KinematicChain\.ik|RobotArm\.ik|RobotArm\._ik_continuous) ",
    ),
    (
        "per motion: sensing (pre-touch ray casts, filter)",
        r"(_relocalise_sweep\.<locals>\.read|\w+Backend\.ray_cast|KalmanFilter|filterpy)",
    ),
    (
        "per motion: planning and checks (grasp choice, swept paths, detours)",
        r"^(BimanualRubiksMachine\.(transit|turn_travel|_make_detour)|_clears|PR2Grasp\.choose|"
        r"_path_points) ",
    ),
    # an in-hand trial's plan is the method itself (the paper times it apart, Table II)
    ("per trial: in-grasp planning (the method's optimisation)", r"/ingrasp/planner\.py\)$"),
    (
        "per trial: set-up (scene, robot, object scan and its placement)",
        r"(load_urdf|make_backend|build_robot|\w+Backend\.add_body|load_object|HandKinematics\.__init__|"
        r"/ingrasp/placement\.py\)$)",
    ),
)
OTHER = "per motion: the rest of the strategy"
IMPORTS = "imports during the trial (once per process)"
ENGINE = "engine step"
BACKEND_FILES = (
    "benchharness/backends/pybullet_backend.py",
    "benchharness/backends/sapien_backend.py",
)


def _engine_lines() -> set[str]:
    """``file:line`` of every ``self._engine_step()`` call in the backends (found, not hard-coded)."""
    import benchharness

    root = Path(benchharness.__file__).resolve().parent.parent
    lines = set()
    for rel in BACKEND_FILES:
        for i, text in enumerate((root / rel).read_text().splitlines(), start=1):
            if text.strip() == "self._engine_step()":
                lines.add(f"{rel}:{i}")
    return lines


_FRAME = re.compile(r"^(?P<func>.*) \((?P<file>.*?):(?P<line>\d+)\)$")


def split(raw: str) -> dict[str, int]:
    """Samples per kind of work in a py-spy ``--format raw`` file (collapsed stacks, root first)."""
    engine_lines = _engine_lines()
    kinds = [(name, re.compile(rx)) for name, rx in KINDS]
    counts: collections.Counter[str] = collections.Counter()
    for line in Path(raw).read_text().splitlines():
        stack, n = line.rsplit(" ", 1)
        frames = [_FRAME.match(f) for f in stack.split(";")]
        named = [f"{m['func']} ({m['file']})" if m else "" for m in frames]
        if not any(x.startswith("execute_trial ") for x in named):
            # the store's claim-renewing thread too: its stack starts at its own bootstrap
            counts["outside the trial (start-up, exit, store)"] += int(n)
            continue
        if any("importlib" in x for x in named):
            counts[IMPORTS] += int(n)
            continue
        leaf = frames[-1]
        if leaf and f"{leaf['file']}:{leaf['line']}" in engine_lines:
            counts[ENGINE] += int(n)
            continue
        kind = next((name for x in reversed(named) for name, rx in kinds if rx.search(x)), OTHER)
        counts[kind] += int(n)
    return dict(counts)


def report(counts: dict[str, int]) -> dict[str, float]:
    """Shares of the trial (imports apart), the measured ratio and its per-step bound."""
    trial = {k: v for k, v in counts.items() if k == ENGINE or k.startswith("per ")}
    total = sum(trial.values())
    engine = trial.get(ENGINE, 0)
    per_step = sum(v for k, v in trial.items() if k.startswith("per step"))
    out = {k: round(100 * v / total, 1) for k, v in sorted(trial.items(), key=lambda kv: -kv[1])}
    out["ratio (engine / trial)"] = round(engine / total, 3)
    out["bound: engine / (engine + per step)"] = round(engine / (engine + per_step), 3)
    out["samples in the trial"] = total
    out["samples of imports"] = counts.get(IMPORTS, 0)
    return out


def profile(label: str, backend: str, rate: int, keep: str | None) -> dict[str, int]:
    spy = shutil.which("py-spy") or str(Path(sys.executable).with_name("py-spy"))
    with tempfile.TemporaryDirectory() as tmp:
        raw = keep or os.path.join(tmp, "profile.txt")
        cmd = [
            spy,
            "record",
            "-r",
            str(rate),
            "-f",
            "raw",
            "-o",
            raw,
            "--",
            sys.executable,
            "-m",
            "benchharness.cli.main",
            *trial_argv(label, backend, os.path.join(tmp, "s.sqlite")),
        ]
        env = dict(os.environ, OMP_NUM_THREADS="1")
        proc = subprocess.run(
            cmd, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env
        )
        if not os.path.exists(raw) or not os.path.getsize(raw):
            # e.g. py-spy not installed, or not allowed to read another process (ptrace)
            last = (proc.stderr.strip().splitlines() or ["no output"])[-1]
            sys.exit(f"profile_trial: py-spy wrote no profile for {label} on {backend}: {last}")
        return split(raw)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default="Rubiks-1-5", help=f"comma-separated of {', '.join(TRIALS)}")
    ap.add_argument("--backends", default="sapien,pybullet")
    ap.add_argument("--rate", type=int, default=200, help="samples per second")
    ap.add_argument("--keep", help="directory to keep the raw profiles in")
    ap.add_argument("--raw", help="split this saved raw profile instead of running a trial")
    args = ap.parse_args()
    if args.raw:
        print(json.dumps(report(split(args.raw)), indent=1))
        return
    labels, backends = args.only.split(","), args.backends.split(",")
    for bad in [x for x in labels if x not in TRIALS]:
        ap.error(f"--only: unknown trial {bad!r} (one of {', '.join(TRIALS)})")
    for bad in [x for x in backends if x not in ("pybullet", "sapien")]:
        ap.error(f"--backends: unknown backend {bad!r} (pybullet or sapien)")
    if args.keep:
        os.makedirs(args.keep, exist_ok=True)
    for label in labels:
        for backend in backends:
            keep = os.path.join(args.keep, f"{label}-{backend}.txt") if args.keep else None
            res = report(profile(label, backend, args.rate, keep))
            print(json.dumps({"trial": label, "backend": backend, **res}, indent=1))


if __name__ == "__main__":
    main()
