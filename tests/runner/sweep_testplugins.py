"""A test-only strategy for the Ray executor's crash test (``--plugin sweep_testplugins``).

``test-pidsleep``: the first time a trial runs it writes its worker's pid to
``$SWEEP_TEST_PIDDIR/<trial>.pid`` and sleeps (the test kills that pid); a
run that finds the file (the retry) finishes at once like ``test-timed``.
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


@hookimpl
def benchharness_strategies():
    return [Registration("test-pidsleep", PidSleepStrategy, "test-only: sleeps until killed once")]
