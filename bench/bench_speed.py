"""A trial's speed against its engine's floor, and the CLI's fixed cost (issue 12; not a test).

For each trial this runs the real ``benchharness run`` command in a child
process (``--workers 0``, a throw-away store) with three counters:

* ``engine``: CPU time spent inside the engine's own step call (the
  backend's ``_engine_step``: ``pybullet.stepSimulation`` or the PhysX
  system's ``step``), and the number of those steps;
* ``trial``: CPU time of ``execute_trial`` (backend, robot and strategy set-up,
  the strategy's run, scoring, closing the backend);
* ``total``: the child's whole CPU time (user + system, from ``wait4``),
  interpreter start-up and exit included; ``exit``: the part after the
  command returned (the interpreter's teardown), and whether torch was
  imported by then;
* ``trial_import``: CPU time of the (outermost) imports made during the trial
  (the robot factory imports torch, the backend its engine...): paid once per
  process, so the report also gives the ratio and fixed cost with these counted
  as start-up, as a worker's later trials see them.

It reports, per trial, the simulated seconds stepped per CPU-second of the
engine alone (``engine_rate``) and of the whole trial (``trial_rate``), their
ratio (target >= 0.85), and the fixed cost ``total - trial`` (target <= 1
CPU-s for a Rubik's ``run``). CPU time, not wall time, because the machine is
shared; the ratio is measured inside one run, so it is robust to load. With
``--protocol`` it also times a protocol command (``rubiks expect``), whose
target is <= 0.15 CPU-s.

Usage (from the repository root, the package importable)::

    python bench/bench_speed.py                       # the issue's default set
    python bench/bench_speed.py --only Rubiks-1-5 --backends sapien --repeats 3
    python bench/bench_speed.py --profile /tmp/prof   # one cProfile per trial
    python bench/bench_speed.py --only '' --protocol --protocol-repeats 10   # `rubiks expect` alone
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

#: (label, CLI arguments after ``run``, without --backend)
TRIALS = {
    "Rubiks-1-5": "--task Rubiks-1-5 --robot pr2 --strategy sensor-aided --seed 0 --trials 1",
    "Rubiks-1-20": "--task Rubiks-1-20 --robot pr2 --strategy sensor-aided --seed 0 --trials 1",
    "inhand-level1": "--task inhand-level1 --robot allegro --strategy point-contact --seed 0 --trials 1",
}
PROTOCOL = ["rubiks", "expect", "--sequence", "R U"]


def trial_argv(label: str, backend: str, store: str) -> list[str]:
    """The ``benchharness`` arguments of one of :data:`TRIALS` (also what profile_trial.py samples)."""
    return ["run", *TRIALS[label].split(), "--backend", backend, "--workers", "0", "--store", store]


def _child(out: str, profile: str | None, argv: list[str]) -> None:
    """Run the CLI in this process with the engine and trial counters; write them to ``out``."""
    counters = {
        "engine_cpu": 0.0,
        "engine_steps": 0,
        "trial_cpu": 0.0,
        "trial_import_cpu": 0.0,
        "dt": 0.0,
    }
    clock = time.process_time
    if argv[0] == "run":
        # CPU spent importing modules during the trial (torch, the engines...): paid once per
        # process, so a worker running many trials pays it once (outermost imports only)
        import builtins

        original_import = builtins.__import__
        depth = [0]
        in_trial = [False]

        def timed_import(*a, **kw):  # type: ignore[no-untyped-def]
            if depth[0] or not in_trial[0]:
                depth[0] += 1
                try:
                    return original_import(*a, **kw)
                finally:
                    depth[0] -= 1
            depth[0] += 1
            c0 = clock()
            try:
                return original_import(*a, **kw)
            finally:
                depth[0] -= 1
                counters["trial_import_cpu"] += clock() - c0

        builtins.__import__ = timed_import
    if argv[0] == "run":
        from benchharness.backends import interface
        from benchharness.runner import sweep

        original_step = interface.Backend.step

        def timed(inner):  # type: ignore[no-untyped-def]
            def step(*a, **kw):  # type: ignore[no-untyped-def]
                c0 = clock()
                inner(*a, **kw)
                counters["engine_cpu"] += clock() - c0
                counters["engine_steps"] += 1

            return step

        def timed_engine(be: interface.Backend) -> None:
            # wrap the backend's engine step once; counted per call
            be._bench_wrapped = True  # type: ignore[attr-defined]
            if hasattr(be, "_engine_step"):
                be._engine_step = timed(be._engine_step)  # type: ignore[attr-defined]
            elif be.name == "pybullet":  # code from before _engine_step (for --src comparisons)
                import types

                from benchharness.backends import pybullet_backend as mod

                ns = types.SimpleNamespace(**vars(mod.pb))
                ns.stepSimulation = timed(mod.pb.stepSimulation)
                mod.pb = ns  # type: ignore[assignment]
            else:
                scene = be._scene  # type: ignore[attr-defined]
                scene.step = timed(scene.step)

        def step_wrapper(self: interface.Backend, n: int = 1) -> None:
            if not getattr(self, "_bench_wrapped", False):
                timed_engine(self)
                counters["dt"] = self.config.timestep
            original_step(self, n)

        interface.Backend.step = step_wrapper  # type: ignore[method-assign]
        original_trial = sweep.execute_trial

        def trial(*a, **kw):  # type: ignore[no-untyped-def]
            c0 = clock()
            in_trial[0] = True
            try:
                if profile:
                    import cProfile

                    prof = cProfile.Profile(time.process_time)  # CPU: wall time is load noise
                    rec = prof.runcall(original_trial, *a, **kw)
                    prof.dump_stats(profile)
                    return rec
                return original_trial(*a, **kw)
            finally:
                counters["trial_cpu"] += clock() - c0
                in_trial[0] = False

        sweep.execute_trial = trial
    import inspect

    from benchharness.cli import main as entry

    try:
        if inspect.signature(entry.main).parameters:
            entry.main(argv)  # the console script's own path, its exit included
        else:  # code from before main() took arguments (for --src comparisons)
            entry.cli.main(argv, standalone_mode=False)
    finally:
        # what is left after this is the interpreter's exit (module teardown): ``exit_cpu``
        counters["main_end_cpu"] = clock()
        counters["torch_loaded"] = "torch" in sys.modules
        with open(out, "w") as f:
            json.dump(counters, f)


def _run_child(argv: list[str], profile: str | None = None, src: str | None = None) -> dict:
    fd, out = tempfile.mkstemp(suffix=".json", prefix="bench_speed_")
    os.close(fd)
    cmd = [sys.executable, os.path.abspath(__file__), "--child", out]
    if profile:
        cmd += ["--child-profile", profile]
    env = dict(os.environ)
    if src:  # another checkout's sources (e.g. the code before a change), same interpreter
        env["PYTHONPATH"] = os.pathsep.join([f"{src}/src", f"{src}/plugins"])
    proc = subprocess.Popen([*cmd, "--", *argv], stdout=subprocess.DEVNULL, env=env)
    _, status, ru = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    with open(out) as f:
        res = json.load(f)
    os.unlink(out)
    res["total_cpu"] = ru.ru_utime + ru.ru_stime
    res["rc"] = proc.returncode
    return res


def _run_cli(argv: list[str], src: str | None = None) -> dict:
    """CPU time of a plain ``benchharness`` command (no counters: nothing of ours in the way)."""
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = os.pathsep.join([f"{src}/src", f"{src}/plugins"])
    cmd = [sys.executable, "-m", "benchharness.cli.main", *argv]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, env=env)
    _, status, ru = os.wait4(proc.pid, 0)
    return {"total_cpu": ru.ru_utime + ru.ru_stime, "rc": os.waitstatus_to_exitcode(status)}


def measure_trial(
    label: str, backend: str, profile: str | None = None, src: str | None = None
) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        r = _run_child(trial_argv(label, backend, os.path.join(tmp, "s.sqlite")), profile, src)
    sim = r["engine_steps"] * r["dt"]
    r["sim_s"] = sim
    r["engine_rate"] = sim / r["engine_cpu"] if r["engine_cpu"] else float("nan")
    r["trial_rate"] = sim / r["trial_cpu"] if r["trial_cpu"] else float("nan")
    r["ratio"] = r["engine_cpu"] / r["trial_cpu"] if r["trial_cpu"] else float("nan")
    r["fixed_cpu"] = r["total_cpu"] - r["trial_cpu"]
    r["exit_cpu"] = r["total_cpu"] - r["main_end_cpu"]
    # the same with the trial's one-off imports counted as start-up (as in a worker's later trials)
    warm = r["trial_cpu"] - r.get("trial_import_cpu", 0.0)
    r["warm_trial_cpu"] = warm
    r["warm_ratio"] = r["engine_cpu"] / warm if warm else float("nan")
    r["warm_fixed_cpu"] = r["total_cpu"] - warm
    return r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", default=",".join(TRIALS), help="comma-separated trial labels")
    ap.add_argument("--backends", default="pybullet,sapien")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--protocol", action="store_true", help="also time `rubiks expect`")
    ap.add_argument("--protocol-repeats", type=int, default=5)
    ap.add_argument("--profile", help="directory for one cProfile file per trial")
    ap.add_argument(
        "--src",
        action="append",
        help="a checkout whose src/ and plugins/ to measure (repeatable; alternated per repeat); "
        "default: the importable benchharness",
    )
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--child-profile", help=argparse.SUPPRESS)
    ap.add_argument("rest", nargs="*", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        _child(a.child, a.child_profile, a.rest)
        return
    rows = []
    for label in filter(
        None, a.only.split(",")
    ):  # --only '' --protocol: the protocol command alone
        for be in a.backends.split(","):
            for rep in range(a.repeats):
                for src in a.src or [None]:
                    prof = None
                    if a.profile:
                        os.makedirs(a.profile, exist_ok=True)
                        prof = os.path.join(a.profile, f"{label}-{be}-{rep}.prof")
                    r = measure_trial(label, be, prof, src)
                    r.update(trial=label, backend=be, src=src)
                    rows.append(r)
                    tag = f" [{src}]" if src else ""
                    print(
                        f"{label:14s} {be:8s}{tag} sim {r['sim_s']:7.2f} s  engine {r['engine_cpu']:6.2f} "
                        f"CPU-s ({r['engine_rate']:5.1f} sim-s/CPU-s)  trial {r['trial_cpu']:6.2f} "
                        f"CPU-s ({r['trial_rate']:5.1f})  ratio {r['ratio']:.3f}  "
                        f"fixed {r['fixed_cpu']:.2f} CPU-s  rc {r['rc']} | trial's imports "
                        f"{r['trial_import_cpu']:.2f} CPU-s: without them ratio {r['warm_ratio']:.3f}, "
                        f"fixed {r['warm_fixed_cpu']:.2f} CPU-s | of the fixed cost, the "
                        f"interpreter's exit {r['exit_cpu']:.2f} CPU-s (torch "
                        f"{'imported' if r['torch_loaded'] else 'not imported'})",
                        flush=True,
                    )
    if a.protocol:
        for _ in range(a.protocol_repeats):
            for src in a.src or [None]:
                r = _run_cli(PROTOCOL, src)
                r["command"] = " ".join(PROTOCOL)
                r["src"] = src
                rows.append(r)
                tag = f" [{src}]" if src else ""
                print(f"{r['command']}{tag}: {r['total_cpu']:.3f} CPU-s  rc {r['rc']}", flush=True)
    if a.json:
        print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
