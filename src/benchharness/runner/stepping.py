"""What the runner does after every physics step: budget, first contact, video frames.

The runner registers one step callback on the trial's backend
(:meth:`~benchharness.backends.Backend.add_step_callback`), so whatever
advances time — a strategy, a robot, the cube mechanism — is watched at
physics-step resolution without asking strategies to cooperate.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

from .contract import TrialContext, TrialTimeout
from .video import TrialFilm

__all__ = ["StepHooks", "wall_alarm"]


class StepHooks:
    """The runner's step callback for one trial: install before the strategy runs, uninstall after.

    After each physics step: the first contact between the watched bodies
    (checked until one is seen, so ``first_contact_s`` is exact to a step),
    the video frames due by the new simulated time, then the budgets (a
    spent budget raises :class:`TrialTimeout` out of ``backend.step``).
    """

    def __init__(self, ctx: TrialContext, film: TrialFilm | None = None) -> None:
        self.ctx = ctx
        self.backend = ctx.backend
        self.film = film
        self._handle: int | None = None

    def install(self) -> None:
        if self._handle is None:
            self._handle = self.backend.add_step_callback(self._after_step)

    def uninstall(self) -> None:
        if self._handle is not None:
            self.backend.remove_step_callback(self._handle)
            self._handle = None

    def _after_step(self) -> None:
        rec = self.ctx.recorder
        if rec.watched and rec.first_contact_s is None:
            for a, b in rec.watched:
                if self.backend.contacts(a, b):
                    rec.contact()
                    break
        if self.film is not None:  # renders only when a frame is due (simulated time)
            self.film.after_step()
        self.ctx.check_budget()


@contextmanager
def wall_alarm(seconds: float | None) -> Iterator[None]:
    """A backstop for code that never steps: SIGALRM raises :class:`TrialTimeout`.

    Only on Unix and in the main thread (sweep workers and the CLI are); a
    little slack over the budget lets the per-step check speak first.
    """
    usable = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
    if seconds is None or not usable:
        yield
        return
    limit = float(seconds) * 1.1 + 1.0

    def _raise(signum: int, frame: FrameType | None) -> None:
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
