"""Test-only strategies for the sweep executors (``--plugin sweep_testplugins``).

``test-pidsleep`` (the Ray executor's crash test): the first time a trial runs
it writes its worker's pid to ``$SWEEP_TEST_PIDDIR/<trial>.pid`` and sleeps
(the test kills that pid); a run that finds the file (the retry) finishes at
once like ``test-timed``.

``test-rendezvous`` (the pool's grid test): a trial writes
``$SWEEP_TEST_PIDDIR/<pid>.here`` and waits until ``$SWEEP_TEST_MEET`` such
files exist, i.e. until that many trials run at the same time; if they never
do within 20 s it raises (a ``strategy_error`` row), else it finishes like
``test-timed``.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from runner_testplugins import TimedStrategy

from benchharness.plugin import Registration, hookimpl


class PidSleepStrategy:
    def run_trial(self, ctx):
        mark = Path(os.environ["SWEEP_TEST_PIDDIR"]) / f"{ctx.trial_index}.pid"
        if not mark.exists():
            mark.write_text(str(os.getpid()))
            time.sleep(60)
        return TimedStrategy().run_trial(ctx)


class RendezvousStrategy:
    def run_trial(self, ctx):
        here = Path(os.environ["SWEEP_TEST_PIDDIR"])
        (here / f"{os.getpid()}.here").write_text("")
        meet = int(os.environ["SWEEP_TEST_MEET"])
        deadline = time.monotonic() + 20.0
        while len(list(here.glob("*.here"))) < meet:
            if time.monotonic() > deadline:
                raise RuntimeError(f"no {meet} trials ran at the same time")
            time.sleep(0.05)
        return TimedStrategy().run_trial(ctx)


@hookimpl
def benchharness_strategies():
    return [
        Registration("test-pidsleep", PidSleepStrategy, "test-only: sleeps until killed once"),
        Registration(
            "test-rendezvous", RendezvousStrategy, "test-only: waits for trials beside it"
        ),
    ]
