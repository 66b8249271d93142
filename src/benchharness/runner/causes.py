"""Trial statuses and failure causes, as stored and as reported.

The causes are a closed set so that tables and ``results --failures`` can
count them across strategies and simulators; a strategy that knows *why* it
failed (the cube slipped out, a twist jammed, no IK solution) says so through
:attr:`~benchharness.runner.contract.TrialOutcome.failure`; the runner assigns
the others (wrong state, timeout, simulator and strategy errors) itself.
"""

from __future__ import annotations

from enum import Enum

__all__ = ["FailureCause", "TrialStatus"]


class TrialStatus(str, Enum):
    """How a finished trial ended. Stored as its value."""

    #: Rubik's: final state as the validator expects; in-hand: object not dropped, not discarded.
    SUCCESS = "success"
    #: The trial failed; :class:`FailureCause` says why.
    FAILURE = "failure"
    #: In-hand only: removed by the 10 % set-up rule (counted nowhere, as the protocol says).
    DISCARDED = "discarded"


class FailureCause(str, Enum):
    """Why a trial failed. Stored as its value."""

    DROPPED = "dropped"  #: the object left the robot's hands / fell (strategy-declared)
    JAMMED = "jammed"  #: a twist or motion could not proceed (strategy-declared)
    WRONG_STATE = (
        "wrong_state"  #: the validator's expected final state differs from the observed one
    )
    UNREACHABLE = "unreachable"  #: no kinematic solution / target out of reach (strategy-declared)
    TIMEOUT = "timeout"  #: the simulated- or wall-time budget ran out
    SIMULATOR_ERROR = "simulator_error"  #: SimulationError/BackendError, or the worker process died
    STRATEGY_ERROR = "strategy_error"  #: any other exception, or an outcome the runner cannot score

    @classmethod
    def parse(cls, value: str | FailureCause) -> FailureCause:
        if isinstance(value, cls):
            return value
        try:
            return cls(str(value).strip().lower().replace("-", "_"))
        except ValueError:
            raise ValueError(
                f"unknown failure cause {value!r}; causes are {', '.join(c.value for c in cls)}"
            ) from None
