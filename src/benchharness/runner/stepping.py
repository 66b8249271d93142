"""What the runner does at every ``backend.step``: budget, first contact, video frames.

``backend.step`` is the one call every strategy, robot and cube mechanism
makes to advance time, so the runner wraps it on the trial's backend
instance (an instance attribute shadowing the method; ``isinstance`` checks
and the engine are untouched) instead of asking strategies to cooperate.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from ..backends.interface import CameraSpec
from .contract import TrialContext, TrialTimeout
from .video import VideoWriter

__all__ = ["StepHooks", "wall_alarm"]


class StepHooks:
    def __init__(
        self,
        ctx: TrialContext,
        video: VideoWriter | None = None,
        camera: CameraSpec | None = None,
        fps: float = 30.0,
    ) -> None:
        self.ctx = ctx
        self.backend = ctx.backend
        self.video, self.camera, self.fps = video, camera, fps
        self._next_frame = ctx.sim_start
        self._orig = None

    def install(self) -> None:
        self._orig = self.backend.step
        self.backend.step = self._step  # type: ignore[method-assign]

    def uninstall(self) -> None:
        if self._orig is not None:
            try:
                del self.backend.step
            except AttributeError:
                pass
            self._orig = None

    def _fine(self) -> bool:
        rec = self.ctx.recorder
        return self.video is not None or (bool(rec.watched) and rec.first_contact_s is None)

    def _step(self, n: int = 1) -> None:
        if not self._fine():
            self._orig(n)
            self._after()
            return
        for _ in range(int(n)):  # one at a time: contact times and frames at step resolution
            self._orig(1)
            self._after()

    def _after(self) -> None:
        rec = self.ctx.recorder
        if rec.watched and rec.first_contact_s is None:
            for a, b in rec.watched:
                if self.backend.contacts(a, b):
                    rec.contact()
                    break
        if self.video is not None:
            t = float(self.backend.time)
            while t + 1e-9 >= self._next_frame:
                self.video.write(self.backend.render(self.camera))
                self._next_frame += 1.0 / self.fps
        self.ctx.check_budget()


@contextmanager
def wall_alarm(seconds: float | None) -> Iterator[None]:
    """A backstop for code that never steps: SIGALRM raises :class:`TrialTimeout`.

    Only on Unix and in the main thread (sweep workers and the CLI are); a
    little slack over the budget lets the per-step check speak first.
    """
    usable = (
        seconds is not None
        and hasattr(signal, "setitimer")
        and threading.current_thread() is threading.main_thread()
    )
    if not usable:
        yield
        return
    limit = float(seconds) * 1.1 + 1.0

    def _raise(signum, frame):
        raise TrialTimeout(
            f"wall-time budget of {seconds:g} s spent (no step returned for a while)"
        )

    old = signal.signal(signal.SIGALRM, _raise)
    signal.setitimer(signal.ITIMER_REAL, limit)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
