"""The record of one finished trial, as the parent process stores it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .causes import FailureCause, TrialStatus

__all__ = ["TrialRecord"]


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
        return {
            "trial_index": self.trial_index,
            "status": self.status.value,
            "score": self.score,
            "failure_cause": self.failure_cause.value if self.failure_cause else None,
            "sim_s": self.sim_s,
            "first_contact_s": self.first_contact_s,
            "termination_s": self.termination_s,
            "outcome": self.outcome,
            "diagnostics": self.diagnostics,
        }
