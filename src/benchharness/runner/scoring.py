"""From a strategy's :class:`TrialOutcome` to status, score and cause — through the metric module.

The runner, never the strategy, decides success: Rubik's trials go through
:func:`benchharness.metrics.score_trial` (the protocol validator on the
observed final state, score = termination − first contact), in-hand trials
through :func:`benchharness.metrics.score_trials` (err_pos, err_pos%,
err_or%, the 10 % set-up rule). The same functions score real-robot logs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..metrics import RubiksTrial, score_trial, score_trials
from ..metrics.rubiks import TrialLogError
from .causes import FailureCause, TrialStatus
from .contract import InhandItem, RubiksItem, TrialOutcome

__all__ = ["Verdict", "score_rubiks", "score_inhand"]


@dataclass(frozen=True)
class Verdict:
    status: TrialStatus
    score: float | None
    cause: FailureCause | None
    message: str
    outcome: dict[str, Any]


def _f(x: Any) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _declared(outcome: TrialOutcome) -> FailureCause | None:
    return None if outcome.failure is None else FailureCause.parse(outcome.failure)


def score_rubiks(
    item: RubiksItem,
    outcome: TrialOutcome,
    first_contact_s: float | None,
    termination_s: float | None,
) -> Verdict:
    data: dict[str, Any] = {
        "tier": item.tier,
        "trial": item.trial,
        "sequence": item.sequence_text,
        "initial": item.initial,
        "final_state": outcome.final_state,
        "expected_final": None,
        "extra": outcome.extra,
    }
    declared = _declared(outcome)
    if declared is not None:
        return Verdict(TrialStatus.FAILURE, None, declared, outcome.message or declared.value, data)
    if outcome.final_state is None:
        return Verdict(
            TrialStatus.FAILURE,
            None,
            FailureCause.STRATEGY_ERROR,
            "the strategy reported no final cube state and no failure cause",
            data,
        )
    final = "".join(str(outcome.final_state).split())
    trial = RubiksTrial(
        item.tier,
        item.trial,
        item.sequence_text,
        final,
        item.initial,
        first_contact_s,
        termination_s,
        outcome.message,
    )
    try:
        result = score_trial(trial, seed=item.seed)
    except TrialLogError as exc:
        return Verdict(
            TrialStatus.FAILURE,
            None,
            FailureCause.STRATEGY_ERROR,
            f"cannot score the outcome: {exc}",
            data,
        )
    data["expected_final"] = result.expected_final
    if not result.success:
        return Verdict(TrialStatus.FAILURE, None, FailureCause.WRONG_STATE, result.reason, data)
    return Verdict(TrialStatus.SUCCESS, result.score_s, None, outcome.message, data)


def _pose(x: Any) -> np.ndarray:
    if x is None:
        return np.full(7, np.nan)
    a = x.as_array() if hasattr(x, "as_array") else np.asarray(x, dtype=float).reshape(-1)
    if a.shape != (7,):
        raise ValueError(f"an in-hand pose is [x, y, z, qx, qy, qz, qw], got {a.shape[0]} numbers")
    return a


def _list(a: np.ndarray) -> list[float | None]:
    return [_f(v) for v in np.asarray(a, float).reshape(-1)]


def score_inhand(item: InhandItem, outcome: TrialOutcome) -> Verdict:
    declared = _declared(outcome)
    dropped = bool(outcome.dropped) or declared is FailureCause.DROPPED
    data: dict[str, Any] = {
        "task_id": item.task_id,
        "object": item.object,
        "level": item.level,
        "repeat": item.repeat,
        "initial": _list(item.initial),
        "desired": _list(item.desired),
        "dropped": dropped,
        "extra": outcome.extra,
    }
    try:
        reached, setup = _pose(outcome.reached), _pose(outcome.setup)
    except ValueError as exc:
        return Verdict(TrialStatus.FAILURE, None, FailureCause.STRATEGY_ERROR, str(exc), data)
    data.update(
        reached=_list(reached),
        setup=_list(setup),
        plan_time_s=_f(outcome.plan_time_s),
        exec_time_s=_f(outcome.exec_time_s),
        reached_contacts=None
        if outcome.reached_contacts is None
        else np.asarray(outcome.reached_contacts, float).tolist(),
    )
    if declared is not None and declared is not FailureCause.DROPPED:
        return Verdict(TrialStatus.FAILURE, None, declared, outcome.message or declared.value, data)
    if not dropped and not np.all(np.isfinite(reached)):
        return Verdict(
            TrialStatus.FAILURE,
            None,
            FailureCause.STRATEGY_ERROR,
            "the strategy reported no reached pose and did not drop the object",
            data,
        )
    nan = np.nan
    try:
        s = score_trials(
            item.initial[None],
            item.desired[None],
            reached[None],
            setup=setup[None],
            dropped=np.array([dropped]),
            plan_time_s=np.array(
                [nan if outcome.plan_time_s is None else outcome.plan_time_s], float
            ),
            exec_time_s=np.array(
                [nan if outcome.exec_time_s is None else outcome.exec_time_s], float
            ),
        )
    except ValueError as exc:  # e.g. a non-unit reached quaternion: the strategy's report is bad
        return Verdict(
            TrialStatus.FAILURE, None, FailureCause.STRATEGY_ERROR, f"scoring: {exc}", data
        )
    data["metrics"] = {k: _f(v[0]) for k, v in s.values().items()}
    data["discarded"] = bool(s.discarded[0])
    # The 10 % rule first: a set-up it rejects "must be discarded" whatever the execution did after
    # it. Checked after the drop, the same rejected set-up (the set-up does not depend on the
    # method) was stored `dropped` for a method that lost the object and `discarded` for one that
    # held it (500-execution Table II, PyBullet, trial 29), though Table II excluded it either way.
    if s.discarded[0]:
        message = "set-up pose off by more than 10 % (discarded)"
        if dropped:
            message += f"; then {outcome.message or 'object dropped'}"
        return Verdict(TrialStatus.DISCARDED, None, None, message, data)
    if dropped:
        return Verdict(
            TrialStatus.FAILURE,
            None,
            FailureCause.DROPPED,
            outcome.message or "object dropped",
            data,
        )
    return Verdict(TrialStatus.SUCCESS, _f(s.err_pos[0]), None, outcome.message, data)
