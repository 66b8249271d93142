"""The one metric module: every score in benchharness is computed here.

Pure functions, arrays and meshes in, numbers out; nothing here imports a
simulator, so a real robot's recorded poses and a simulated trial's records go
through the same code. Plotting lives in :mod:`benchharness.metrics.plots`
(imported on demand, so this package does not pull in matplotlib).

* Rubik's cube (paper: Protocol, section III): :func:`score_trial`,
  :func:`score_tier` (mean and sample standard deviation; a tier is completed
  only if all M trials end in the expected state).
* In-hand (paper section III-A): :func:`err_pos`, :func:`err_pos_percent`,
  :func:`err_or_percent` (eq. 1-3), :func:`setup_check` (the 10 % rule),
  :func:`contact_region_error` (Algorithm 1, Euclidean and geodesic, G_min),
  :func:`box_stats` (median, quartiles, 1.5 IQR whiskers),
  :func:`score_trials` / :func:`summarize_scores` (per object and method).
"""

from .contact import ContactError, ObjectSurface, contact_region_error, object_surface
from .inhand import TrialScores, score_trials, summarize_scores  # noqa: F401 - public API
from .pose import SetupCheck, err_or_percent, err_pos, err_pos_percent, setup_check
from .rubiks import RubiksTrial, TierScore, TrialResult, mean_and_std, score_tier, score_trial
from .stats import BoxStats, box_stats, drops_percent, summarize_groups

__all__ = [
    "BoxStats",
    "ContactError",
    "ObjectSurface",
    "RubiksTrial",
    "SetupCheck",
    "TierScore",
    "TrialResult",
    "TrialScores",
    "box_stats",
    "contact_region_error",
    "drops_percent",
    "err_or_percent",
    "err_pos",
    "err_pos_percent",
    "mean_and_std",
    "object_surface",
    "score_tier",
    "score_trial",
    "score_trials",
    "setup_check",
    "summarize_groups",
]
