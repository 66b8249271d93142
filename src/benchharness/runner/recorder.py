"""Per-trial diagnostics a strategy logs while it acts, stored as JSON with the trial.

The score needs only first contact and termination; everything else here is
for *understanding* a score: how far the believed cube pose drifted from the
true one at each regrasp, which twists went wrong and when. Entries carry
the simulated time at which they were logged, so plots and a video line up.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ..backends.interface import BodyId

__all__ = ["LoggedEstimate", "TrialRecorder", "pose_errors"]


def _jsonable(v: Any) -> Any:
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    if hasattr(v, "as_array"):  # geometry.Pose
        return v.as_array().tolist()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def _pose_array(pose: Any) -> np.ndarray:
    a = pose.as_array() if hasattr(pose, "as_array") else np.asarray(pose, dtype=float).reshape(-1)
    if a.shape != (7,):
        raise ValueError(f"a pose is [x, y, z, qx, qy, qz, qw] or a Pose, got shape {a.shape}")
    return a


def pose_errors(true_pose: Any, estimated_pose: Any) -> tuple[float, float]:
    """Position error (m) and rotation error (deg) between two poses; q and -q agree."""
    t, e = _pose_array(true_pose), _pose_array(estimated_pose)
    pos = float(np.linalg.norm(t[:3] - e[:3]))
    qt, qe = t[3:] / np.linalg.norm(t[3:]), e[3:] / np.linalg.norm(e[3:])
    dot = min(1.0, abs(float(np.dot(qt, qe))))
    return pos, math.degrees(2.0 * math.acos(dot))


@dataclass(frozen=True)
class LoggedEstimate:
    """One logged belief of the cube pose beside the truth (a diagnostics row, not a filter state:
    that is :class:`benchharness.sensors.PoseEstimate`)."""

    move_index: int
    t: float
    label: str
    true: tuple[float, ...]
    estimated: tuple[float, ...]
    pos_err_m: float
    rot_err_deg: float


@dataclass
class TrialRecorder:
    """Collects one trial's diagnostics. ``clock`` reads the simulated time.

    Conventions: ``move_index`` is 0-based into the trial's sequence (the
    move about to be executed, or being executed); "first contact" is the
    first robot–cube (robot–object) contact of the trial, the start of the
    Rubik's score.
    """

    clock: Callable[[], float] = lambda: 0.0
    first_contact_s: float | None = None
    events: list[dict[str, Any]] = field(default_factory=list)
    estimates: list[LoggedEstimate] = field(default_factory=list)
    watched: list[tuple[BodyId, BodyId | None]] = field(default_factory=list)

    # -- the score's anchor --------------------------------------------------------------
    def contact(self, t: float | None = None) -> None:
        """Mark robot–cube contact at ``t`` (default now); only the first one counts."""
        if self.first_contact_s is None:
            self.first_contact_s = float(self.clock() if t is None else t)
            self.events.append({"kind": "first_contact", "t": self.first_contact_s})

    def watch_contact(self, body_a: BodyId, body_b: BodyId | None = None) -> None:
        """Let the runner detect first contact: after every step it asks the backend
        for contacts between ``body_a`` (the cube) and ``body_b`` (the robot; ``None``
        = any body) and calls :meth:`contact` at the first one."""
        self.watched.append((body_a, body_b))

    # -- diagnostics ------------------------------------------------------------------------
    def pose_estimate(
        self, move_index: int, true_pose: Any, estimated_pose: Any, label: str = "regrasp"
    ) -> LoggedEstimate:
        """The cube pose the strategy believes vs the true (simulator) pose, e.g. at a regrasp."""
        pos, rot = pose_errors(true_pose, estimated_pose)
        est = LoggedEstimate(
            int(move_index),
            float(self.clock()),
            str(label),
            tuple(map(float, _pose_array(true_pose))),
            tuple(map(float, _pose_array(estimated_pose))),
            pos,
            rot,
        )
        self.estimates.append(est)
        return est

    def move(self, move_index: int, move: str, **data: Any) -> None:
        """A move of the sequence was executed (``data``: e.g. measured layer angles)."""
        self.event("move", move_index=move_index, move=str(move), **data)

    def unintended_rotation(
        self, move_index: int, expected: str, observed: str, **data: Any
    ) -> None:
        """The cube turned differently from the command (dragged middle slab, extra turn)."""
        self.event(
            "unintended_rotation",
            move_index=move_index,
            expected=str(expected),
            observed=str(observed),
            **data,
        )

    def blocked_rotation(self, move_index: int, move: str, reason: str, **data: Any) -> None:
        """A twist could not start or finish (misaligned layer, over-constrained grasp)."""
        self.event(
            "blocked_rotation", move_index=move_index, move=str(move), reason=str(reason), **data
        )

    def event(self, kind: str, **data: Any) -> None:
        """Any other diagnostic; ``data`` must be JSON-serialisable (arrays and Poses are converted)."""
        entry = {"kind": str(kind), "t": float(self.clock())}
        entry.update({k: _jsonable(v) for k, v in data.items()})
        self.events.append(entry)

    def count(self, kind: str) -> int:
        return sum(e["kind"] == kind for e in self.events)

    def to_json(self) -> dict[str, Any]:
        return {
            "first_contact_s": self.first_contact_s,
            "events": self.events,
            "pose_estimates": [
                {
                    "move_index": e.move_index,
                    "t": e.t,
                    "label": e.label,
                    "true": list(e.true),
                    "estimated": list(e.estimated),
                    "pos_err_m": e.pos_err_m,
                    "rot_err_deg": e.rot_err_deg,
                }
                for e in self.estimates
            ],
            "counts": {
                k: self.count(k) for k in ("move", "unintended_rotation", "blocked_rotation")
            },
        }
