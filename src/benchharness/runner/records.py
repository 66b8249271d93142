"""The record of one finished trial, as the parent process stores it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

from .causes import FailureCause, TrialStatus

__all__ = ["TrialRecord", "comparable_fields"]


@dataclass(frozen=True)
class TrialRecord:
    """One trial's result. Picklable: workers return it; only the parent writes it.

    ``score`` is the benchmark's per-trial score: Rubik's, seconds from first
    contact to termination (successful trials only); in-hand, err_pos in
    metres (NaN → ``None`` for dropped trials). ``sim_s`` is the simulated
    time the whole trial took, ``wall_s`` the wall-clock time. ``outcome``
    holds what is needed to re-score (states, poses, per-trial metrics);
    ``diagnostics`` the recorder's log.
    """

    run_key: str
    trial_index: int
    status: TrialStatus
    score: float | None
    failure_cause: FailureCause | None
    message: str
    wall_s: float
    sim_s: float | None
    first_contact_s: float | None
    termination_s: float | None
    outcome: dict[str, Any] = field(default_factory=dict)
    diagnostics: dict[str, Any] = field(default_factory=dict)
    traceback: str = ""

    @property
    def failed(self) -> bool:
        return self.status is TrialStatus.FAILURE

    def comparable(self) -> dict[str, Any]:
        """Everything but the wall-clock measurements (for determinism checks)."""
        return comparable_fields(self)


class _TrialFields(Protocol):
    """What a trial's record and its stored row share (:class:`TrialRecord`, ``StoredTrial``)."""

    @property
    def trial_index(self) -> int: ...
    @property
    def status(self) -> TrialStatus: ...
    @property
    def score(self) -> float | None: ...
    @property
    def failure_cause(self) -> FailureCause | None: ...
    @property
    def sim_s(self) -> float | None: ...
    @property
    def first_contact_s(self) -> float | None: ...
    @property
    def termination_s(self) -> float | None: ...
    @property
    def outcome(self) -> dict[str, Any]: ...
    @property
    def diagnostics(self) -> dict[str, Any]: ...


def comparable_fields(rec: _TrialFields) -> dict[str, Any]:
    """A trial's result without its wall-clock measurements, code version or run metadata.

    The one definition of "the same result" for determinism checks: a record
    fresh from a worker and a row read back from a store compare equal through
    it when the trial repeated bit for bit.
    """
    return {
        "trial_index": rec.trial_index,
        "status": rec.status.value,
        "score": rec.score,
        "failure_cause": rec.failure_cause.value if rec.failure_cause else None,
        "sim_s": rec.sim_s,
        "first_contact_s": rec.first_contact_s,
        "termination_s": rec.termination_s,
        "outcome": rec.outcome,
        "diagnostics": rec.diagnostics,
    }
