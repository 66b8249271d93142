"""How an in-hand trial's outcome becomes its stored status: the 10 % set-up rule before the drop.

The paper: a trial whose set-up is off the initial pose by more than 10 % "must be discarded". The
set-up does not depend on the method, so the same rejected set-up must get the same status under
every method, whether or not the object was lost after it (it used to be ``dropped`` for a method
that lost it and ``discarded`` for one that held it). The oracle for "rejected" is the metric
module's own ``setup_check``.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchharness.metrics.pose import setup_check
from benchharness.runner.causes import FailureCause, TrialStatus
from benchharness.runner.contract import InhandItem, TrialOutcome
from benchharness.runner.scoring import score_inhand

IDENTITY = [0.0, 0.0, 0.0, 1.0]
INITIAL = np.array([0.0, 0.0, 0.05, *IDENTITY])
DESIRED = np.array([0.05, 0.0, 0.05, *IDENTITY])  # a 5 cm move
ITEM = InhandItem("test", "box-01", "box", 1, INITIAL, DESIRED)
GOOD_SETUP = INITIAL + np.array([0.001, 0, 0, 0, 0, 0, 0])  # 1 mm: 2 % of the move
BAD_SETUP = INITIAL + np.array([0.01, 0, 0, 0, 0, 0, 0])  # 1 cm: 20 %


def _rejected(setup: np.ndarray) -> bool:
    check = setup_check(INITIAL[:3], INITIAL[3:], setup[:3], setup[3:], DESIRED[:3])
    return bool(np.atleast_1d(check.discard)[0])


def test_the_oracle_rejects_only_the_bad_set_up():
    assert _rejected(BAD_SETUP) and not _rejected(GOOD_SETUP)


@pytest.mark.parametrize("dropped", [False, True])
def test_a_rejected_set_up_is_discarded_whatever_followed(dropped):
    out = TrialOutcome(
        reached=None if dropped else DESIRED,
        setup=BAD_SETUP,
        dropped=dropped,
        message="dropped during hold: no fingertip contact for 0.10 s" if dropped else "",
    )
    v = score_inhand(ITEM, out)
    assert v.status is TrialStatus.DISCARDED and v.cause is None
    assert v.outcome["discarded"] is True and v.outcome["dropped"] is dropped
    assert v.message.startswith("set-up pose off by more than 10 % (discarded)")
    assert ("then dropped during hold" in v.message) is dropped


def test_a_drop_after_a_good_set_up_is_a_dropped_failure():
    out = TrialOutcome(setup=GOOD_SETUP, dropped=True, message="dropped during execution")
    v = score_inhand(ITEM, out)
    assert (v.status, v.cause, v.message) == (
        TrialStatus.FAILURE,
        FailureCause.DROPPED,
        "dropped during execution",
    )
    assert v.outcome["discarded"] is False
