"""Wall time of one sweep grid with the process pool and on a local Ray cluster, 1 and 2 workers (issue 12; not a test).

Runs the real ``benchharness sweep`` command in a child process, once per
executor configuration, each into a fresh throw-away store:

* ``pool-1`` / ``pool-2``: the local process pool, ``--workers 1`` / ``2``;
* ``ray-1`` / ``ray-2``: a local Ray cluster started by the command (every port
  on 127.0.0.1, no dashboard), ``--num-cpus 1`` / ``2``.

For each it reports the wall time, the CPU time of the whole process tree
(user + system: the sweep, its pool workers, and Ray's head processes and
workers) and the speed-up from 1 to 2 workers (wall time of the 1-worker run
over the 2-worker run; 2.0 is perfect scaling).

Why a cgroup for the CPU time: ``getrusage(RUSAGE_CHILDREN)`` counts only
processes that some ancestor waited for, and Ray's raylet ignores SIGCHLD so
the kernel reaps its workers itself and drops their CPU time (the trials'
physics). Each sweep therefore runs in a fresh cgroup (v1 ``cpuacct`` or v2
``cpu.stat``) whose counter covers every process in it, however it ends.
Where no cgroup can be made (not root, no writable hierarchy) the script
falls back to ``RUSAGE_CHILDREN`` and marks the Ray rows' CPU as a lower
bound. The script also makes itself a child subreaper (Linux
``PR_SET_CHILD_SUBREAPER``): whatever the sweep leaves behind is re-parented
here and reaped, and any process still alive ``--grace`` seconds after the
sweep exits is reported as left behind and killed. Last, it checks
that the four stores hold the same rows (``TrialRecord.comparable()``: status,
score, simulated times, outcome, diagnostics), since the executor must not
change a result.

The machine's cores are shared: the script prints the load average before
and after, and the default order interleaves the configurations
(``--repeats`` rounds of pool-1, ray-1, pool-2, ray-2). Compare the rows of
one run, not runs on different days.

Usage (from the repository root, after the README's set-up with the
``[cluster]`` extra)::

    python bench/bench_sweep_scaling.py
    python bench/bench_sweep_scaling.py --tasks Rubiks-1-5 --strategies sensor-aided,dead-reckoning \
        --backends pybullet,sapien --seeds 0,1 --configs pool-1,pool-2,ray-1,ray-2 --json
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CONFIGS = {
    "pool-1": ["--executor", "pool", "--workers", "1"],
    "pool-2": ["--executor", "pool", "--workers", "2"],
    "ray-1": ["--executor", "ray", "--num-cpus", "1"],
    "ray-2": ["--executor", "ray", "--num-cpus", "2"],
}
PR_SET_CHILD_SUBREAPER = 36


def _become_subreaper() -> None:
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_CHILD_SUBREAPER) failed")


def _reap_orphans(grace_s: float) -> list[int]:
    """Reap every re-parented descendant (their CPU joins RUSAGE_CHILDREN); the pids still alive after ``grace_s``."""
    deadline = time.monotonic() + grace_s
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return []
        if pid == 0:
            if time.monotonic() > deadline:
                break
            time.sleep(0.1)
    left = []
    for p in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{p}/stat") as f:
                ppid = int(f.read().rsplit(")", 1)[1].split()[1])
        except OSError:
            continue
        if ppid == os.getpid():
            left.append(int(p))
    return left


class _CpuGroup:
    """A fresh cgroup whose CPU counter covers every process started in it (None where none can be made)."""

    def __init__(self, name: str) -> None:
        self.path: Path | None = None
        self.usage_file = ""
        v1 = Path("/sys/fs/cgroup/cpuacct")
        v2 = Path("/sys/fs/cgroup")
        candidates = [(v1, "cpuacct.usage")]
        if (v2 / "cgroup.controllers").exists():
            own = Path("/proc/self/cgroup").read_text().splitlines()[0].split("::", 1)[-1]
            candidates.append((v2 / own.lstrip("/"), "cpu.stat"))
        for root, usage in candidates:
            if not (root / usage).exists():
                continue
            try:
                path = root / name
                path.mkdir()
            except OSError:
                continue
            self.path, self.usage_file = path, usage
            return

    def enter(self) -> None:
        """Move the calling process in (run in the child between fork and exec)."""
        if self.path is not None:
            (self.path / "cgroup.procs").write_text(str(os.getpid()))

    def cpu_s(self) -> float:
        assert self.path is not None
        text = (self.path / self.usage_file).read_text()
        if self.usage_file == "cpuacct.usage":
            return int(text) / 1e9
        return int(dict(line.split() for line in text.splitlines())["usage_usec"]) / 1e6

    def remove(self) -> None:
        if self.path is not None:
            self.path.rmdir()


def _sweep(grid: list[str], config: str, store: Path, grace_s: float) -> dict:
    """One sweep command; its wall time, the whole tree's CPU time, and what it left running."""
    cmd = [sys.executable, "-m", "benchharness", "sweep", *grid, *CONFIGS[config]]
    cmd += ["--store", str(store), "--no-progress", "--json"]
    env = dict(os.environ, RAY_USAGE_STATS_ENABLED="0")
    env.pop("RAY_ADDRESS", None)
    group = _CpuGroup(f"bench-sweep-{os.getpid()}-{config}")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, preexec_fn=group.enter)
    wall = time.perf_counter() - t0
    left = _reap_orphans(grace_s)
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    _reap_orphans(5.0)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if group.path is not None:
        cpu, how = group.cpu_s(), "cgroup"
        group.remove()
    else:
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        how = (
            "rusage"
            if config.startswith("pool")
            else "rusage (lower bound: Ray's workers are not counted)"
        )
    if proc.returncode != 0:
        raise SystemExit(f"{config}: sweep exited {proc.returncode}: {proc.stderr.strip()[-2000:]}")
    return {
        "config": config,
        "wall_s": wall,
        "cpu_s": cpu,
        "cpu_measured_by": how,
        "left_behind": left,
    }


def _rows(store: Path) -> list:
    """The store's trials by what they are (not by run key: a run key holds the code version, which
    changes with any commit or edit between two configurations of one bench run)."""
    from benchharness.runner import ResultsStore

    with ResultsStore(store, read_only=True) as s:
        return sorted(
            (
                (
                    t.task,
                    t.robot,
                    t.strategy,
                    t.backend,
                    t.seed,
                    t.physics_hash,
                    t.options_hash,
                    t.trial_index,
                ),
                t.comparable(),
            )
            for t in s.trials()
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tasks", default="Rubiks-1-5")
    ap.add_argument("--robots", default="pr2")
    ap.add_argument("--strategies", default="sensor-aided,dead-reckoning")
    ap.add_argument("--backends", default="pybullet,sapien")
    ap.add_argument("--seeds", default="0,1")
    ap.add_argument("--configs", default="pool-1,ray-1,pool-2,ray-2")
    ap.add_argument("--repeats", type=int, default=1, help="rounds of the configurations")
    ap.add_argument(
        "--grace", type=float, default=60.0, help="seconds to wait for a sweep's leftovers"
    )
    ap.add_argument("--keep", help="keep the stores in this folder")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    configs = [c for c in args.configs.split(",") if c]
    unknown = [c for c in configs if c not in CONFIGS]
    if unknown:
        ap.error(f"unknown configuration {unknown[0]!r} (choose from {', '.join(CONFIGS)})")
    grid = ["--tasks", args.tasks, "--robots", args.robots, "--strategies", args.strategies]
    grid += ["--backends", args.backends, "--seeds", args.seeds]

    _become_subreaper()
    tmp = Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    load0 = os.getloadavg()
    runs = []
    try:
        for r in range(args.repeats):
            for config in configs:
                store = tmp / f"{config}-{r}.sqlite"
                run = _sweep(grid, config, store, args.grace)
                run["round"] = r
                run["rows"] = _rows(store)
                runs.append(run)
                if not args.json:
                    print(
                        f"{config} (round {r}): wall {run['wall_s']:.1f} s, CPU {run['cpu_s']:.1f} s,"
                        f" {len(run['rows'])} trials, left behind {run['left_behind'] or 'none'}",
                        flush=True,
                    )
        load1 = os.getloadavg()
        if args.keep:
            shutil.copytree(tmp, args.keep, dirs_exist_ok=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    reference = runs[0]["rows"]
    identical = all(run["rows"] == reference for run in runs)
    best = {c: min(run["wall_s"] for run in runs if run["config"] == c) for c in configs}
    speedup = {
        ex: best[f"{ex}-1"] / best[f"{ex}-2"]
        for ex in ("pool", "ray")
        if f"{ex}-1" in best and f"{ex}-2" in best
    }
    statuses: dict[str, int] = {}
    for _, row in reference:
        statuses[row["status"]] = statuses.get(row["status"], 0) + 1
    report = {
        "grid": grid,
        "trials": len(reference),
        "statuses": statuses,
        "load_before": load0,
        "load_after": load1,
        "cores": os.cpu_count(),
        "runs": [{k: v for k, v in run.items() if k != "rows"} for run in runs],
        "best_wall_s": best,
        "speedup_1_to_2": speedup,
        "rows_identical": identical,
    }
    if args.json:
        print(json.dumps(report, indent=2))
        return
    print(f"grid: {' '.join(grid)} -> {len(reference)} trials {statuses}")
    print(f"load average before {load0[0]:.2f}, after {load1[0]:.2f}; {os.cpu_count()} cores")
    print("| configuration | wall s (best) | CPU s (whole tree) |")
    print("|---|---|---|")
    for c in configs:
        cpu = min(run["cpu_s"] for run in runs if run["config"] == c)
        how = next(run["cpu_measured_by"] for run in runs if run["config"] == c)
        print(f"| {c} | {best[c]:.1f} | {cpu:.1f} ({how}) |")
    for ex, s in speedup.items():
        print(f"{ex}: speed-up 1 -> 2 workers {s:.2f}x (wall)")
    print(f"stores hold the same rows: {'yes' if identical else 'NO'}")
    if not identical:
        sys.exit(1)


if __name__ == "__main__":
    main()
