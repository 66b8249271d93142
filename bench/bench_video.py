"""What recording a trial video costs: one Rubiks-1-5 trial with and without ``--video``.

Runs ``benchharness run --task Rubiks-1-5 --robot pr2 --strategy
dead-reckoning-exact --seed 0`` as a child process on each engine, once
plain and once with ``--video`` (default view, size and rate unless
``--video-args`` says otherwise), each into a fresh store, and reports the
child's CPU time (user + system, the ffmpeg encoder included: it is a
child of the child), its wall time, the ratio filmed / plain, and checks
that the stored status, score and simulated time are the same filmed.
A backend without a camera is refused by ``run --video`` (exit 2): reported
as such.

    python bench/bench_video.py                       # both engines
    python bench/bench_video.py --backends pybullet --video-args "--video-size 640x480"
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TRIAL = [
    "--task",
    "Rubiks-1-5",
    "--robot",
    "pr2",
    "--strategy",
    "dead-reckoning-exact",
    "--seed",
    "0",
]


def _run(backend: str, extra: list[str], store: Path) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(ROOT / "src"), str(ROOT / "plugins"), env.get("PYTHONPATH", "")]
    )
    cmd = [sys.executable, "-m", "benchharness.cli.main", "run", *TRIAL, "--backend", backend]
    cmd += ["--workers", "0", "--no-progress", "--json", "--store", str(store), *extra]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    w0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - w0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    out: dict = {"rc": proc.returncode, "cpu_s": cpu, "wall_s": wall}
    try:
        data = json.loads(proc.stdout[proc.stdout.index("{") :])
        t = data["trials"][0]
        out.update(status=t["status"], score=t["score"], sim_s=t["sim_s"], video=data.get("video"))
    except (ValueError, KeyError, IndexError):
        out["error"] = (proc.stderr or proc.stdout).strip().splitlines()[-1:]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--backends", default="pybullet,sapien")
    ap.add_argument("--video-args", default="", help="extra run options for the filmed run")
    ap.add_argument("--keep", type=Path, default=None, help="directory to keep the MP4s in")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_video_"))
    keep = args.keep or tmp
    keep.mkdir(parents=True, exist_ok=True)
    print(f"load average at start: {os.getloadavg()[0]:.1f}")
    print(
        "| engine | plain CPU s | filmed CPU s | ratio | plain wall s | filmed wall s "
        "| frames | render CPU s (in-process) | same result |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for backend in [b.strip() for b in args.backends.split(",") if b.strip()]:
        plain = _run(backend, [], tmp / f"{backend}-plain.sqlite")
        mp4 = keep / f"{backend}.mp4"
        filmed = _run(
            backend,
            ["--video", str(mp4), *shlex.split(args.video_args)],
            tmp / f"{backend}-video.sqlite",
        )
        if filmed["rc"] == 2:
            why = " ".join(filmed.get("error", []))
            print(
                f"| {backend} | {plain['cpu_s']:.1f} | refused | — | {plain['wall_s']:.1f} | — | — | — "
                f"| — ({why[:90]}) |"
            )
            continue
        same = all(plain.get(k) == filmed.get(k) for k in ("status", "score", "sim_s"))
        v = filmed.get("video") or {}
        print(
            f"| {backend} | {plain['cpu_s']:.1f} | {filmed['cpu_s']:.1f} "
            f"| {filmed['cpu_s'] / plain['cpu_s']:.2f} | {plain['wall_s']:.1f} | {filmed['wall_s']:.1f} "
            f"| {v.get('frames')} | {v.get('render_cpu_s')} "
            f"| {'yes' if same else 'NO'} ({plain.get('status')}, score {plain.get('score')}, "
            f"sim {plain.get('sim_s')}) |"
        )
    print(f"load average at end: {os.getloadavg()[0]:.1f}; videos in {keep}")


if __name__ == "__main__":
    main()
