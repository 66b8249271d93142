"""The runner: trial = task × robot × strategy × sensors × backend × seed.

* :mod:`.contract` — what a strategy gets (:class:`TrialContext`) and returns
  (:class:`TrialOutcome`); the :class:`Strategy` protocol;
* :mod:`.recorder` — :class:`TrialRecorder`, per-action diagnostics;
* :mod:`.causes` — :class:`TrialStatus`, :class:`FailureCause`;
* :mod:`.spec` — :class:`RunSpec` and the run key;
* :mod:`.seeding` — per-trial generators from (seed, task, trial index);
* :mod:`.tasks` — tiers and in-hand task sets as lists of trials;
* :mod:`.trial` — one trial, start to finish; :mod:`.scoring` — via the metric module;
* :mod:`.store` — the SQLite results store; :mod:`.sweep` — process-pool sweeps with resume;
* :mod:`.reports`, :mod:`.plots`, :mod:`.video` — tables, pose-error plots, trial videos.

See docs/runner.md. Importing this package imports no physics engine.
"""

from .causes import FailureCause, TrialStatus
from .contract import (
    InhandItem,
    RubiksItem,
    SensorSlot,
    Strategy,
    TimeBudget,
    TrialContext,
    TrialItem,
    TrialOutcome,
    TrialTimeout,
)
from .recorder import TrialRecorder
from .records import TrialRecord
from .spec import RunSpec, code_version, parse_physics
from .store import DEFAULT_STORE, ResultsStore, StoredTrial, default_store_path
from .sweep import SweepReport, default_workers, run_sweep
from .trial import execute_trial
from .video import VideoSpec

__all__ = [
    "DEFAULT_STORE",
    "FailureCause",
    "InhandItem",
    "ResultsStore",
    "RubiksItem",
    "RunSpec",
    "SensorSlot",
    "StoredTrial",
    "Strategy",
    "SweepReport",
    "TimeBudget",
    "TrialContext",
    "TrialItem",
    "TrialOutcome",
    "TrialRecord",
    "TrialRecorder",
    "TrialStatus",
    "TrialTimeout",
    "VideoSpec",
    "code_version",
    "default_store_path",
    "default_workers",
    "execute_trial",
    "parse_physics",
    "run_sweep",
]
