"""Sweep worker processes: one trial at a time, and dead as soon as their parent is.

A worker is a *spawned* interpreter (no inherited engine state or locks)
talking to the parent over a pipe: it receives ``(spec, index, video)``,
answers ``("started", index)`` then ``("done", record)``. It ignores SIGINT
(the parent owns interruption: a terminal's Ctrl-C reaches the whole process
group) and dies with the parent — ``PR_SET_PDEATHSIG`` on Linux, and on every
platform a lifeline pipe whose write end only the parent holds: a worker
thread blocks reading it and ends the process at end-of-file, even while
the trial is stuck in native code.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from multiprocessing.connection import Connection
from typing import Any

from .spec import RunSpec
from .trial import execute_trial
from .video import VideoSpec

__all__ = ["Worker", "die_with_parent", "worker_main"]


def die_with_parent(lifeline: Connection) -> None:
    """End this worker when the parent dies (SIGKILL included), however the trial is stuck."""
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            PR_SET_PDEATHSIG = 1
            libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):
            pass

    def watch() -> None:
        try:
            lifeline.recv()  # the parent never sends: this returns only at end-of-file
        except (EOFError, OSError):
            pass
        os._exit(70)

    threading.Thread(target=watch, name="benchharness-lifeline", daemon=True).start()


def worker_main(conn: Connection, lifeline: Connection, parent: int) -> None:
    """A sweep worker: receive (spec, index, video), send ("started", i) then ("done", record)."""
    die_with_parent(lifeline)
    if os.getppid() != parent:  # the parent died before the death signal was armed
        os._exit(70)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        sys.stdout.flush()
        os.dup2(2, 1)  # engine banners from C: stdout is the parent's report (--json)
    except OSError:
        pass
    while True:
        try:
            job = conn.recv()
        except EOFError:
            return
        if job is None:
            return
        spec, index, video = job
        conn.send(("started", index))
        rec = execute_trial(spec, index, video, contain_interrupts=True)
        conn.send(("done", rec))


class Worker:
    def __init__(self, ctx: Any) -> None:
        self.conn, child = ctx.Pipe()
        lifeline_r, self.lifeline = ctx.Pipe(duplex=False)
        self.proc = ctx.Process(
            target=worker_main, args=(child, lifeline_r, os.getpid()), daemon=True
        )
        self.proc.start()
        child.close()
        lifeline_r.close()
        self.index: int | None = None
        self.sent = 0.0
        self.started: float | None = None

    def give(self, job: tuple[RunSpec, int, VideoSpec | None]) -> None:
        self.index = job[1]
        self.sent, self.started = time.monotonic(), None
        self.conn.send(job)

    def stop(self, kill: bool = False) -> None:
        if self.proc.is_alive():
            if kill:
                self.proc.kill()
            else:
                try:
                    self.conn.send(None)
                except OSError:
                    self.proc.kill()
        self.proc.join(5)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join(5)
        for c in (self.conn, self.lifeline):
            c.close()
