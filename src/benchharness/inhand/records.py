"""Columnar, typed form of task sets and recorded results.

Columns rather than one object per trial because every metric is vectorised
over trials; a row view (:meth:`ResultSet.row`) exists for reporting.
Poses are kept as raw arrays (``[x, y, z, qx, qy, qz, qw]``, NaN where
absent) and *not* as :class:`benchharness.geometry.Pose`, because ``Pose``
normalises its quaternion and eq. 3 is evaluated on the quaternions as
recorded (see :mod:`benchharness.metrics.pose`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["POSE_STAGES", "POSE_FIELDS", "ResultSet", "TaskSet"]

#: Pose column prefixes, in file order.
POSE_STAGES = ("initial", "desired", "setup", "reached")
#: Pose column suffixes: position (m) then scalar-last quaternion.
POSE_FIELDS = ("x", "y", "z", "qx", "qy", "qz", "qw")


def _nan_poses(n: int) -> np.ndarray:
    return np.full((n, 7), np.nan)


@dataclass
class TaskSet:
    """Tasks: desired changes of grasp, one row per task.

    ``contacts[stage]`` is ``(n, k, 3)`` (NaN-padded) for stages
    ``initial``/``desired``; ``extra`` holds any further columns verbatim.
    """

    task_id: np.ndarray
    object: np.ndarray
    level: np.ndarray
    initial: np.ndarray
    desired: np.ndarray
    contacts: dict[str, np.ndarray] = field(default_factory=dict)
    desired_region: np.ndarray | None = None
    object_mesh: np.ndarray | None = None
    extra: dict[str, np.ndarray] = field(default_factory=dict)
    source: Path | None = None

    def __len__(self) -> int:
        return len(self.task_id)


@dataclass
class ResultSet:
    """Recorded trials, one row per trial (see ``docs/inhand.md``).

    ``setup``/``reached`` rows are NaN where not recorded (no set-up pose;
    dropped trial). Times are NaN where not recorded. ``desired_region`` and
    ``object_mesh`` are paths as written in the file (resolve them with
    :meth:`resolve`) or ``""``.
    """

    method: np.ndarray
    object: np.ndarray
    task_id: np.ndarray
    trial: np.ndarray
    level: np.ndarray
    dropped: np.ndarray
    plan_time_s: np.ndarray
    exec_time_s: np.ndarray
    initial: np.ndarray
    desired: np.ndarray
    setup: np.ndarray
    reached: np.ndarray
    contacts: dict[str, np.ndarray] = field(default_factory=dict)
    desired_region: np.ndarray | None = None
    object_mesh: np.ndarray | None = None
    extra: dict[str, np.ndarray] = field(default_factory=dict)
    source: Path | None = None

    def __len__(self) -> int:
        return len(self.method)

    @property
    def has_setup(self) -> np.ndarray:
        return np.all(np.isfinite(self.setup), axis=1)

    def resolve(self, relpath: str) -> Path | None:
        """A path from the file, relative to the file's folder."""
        if not relpath:
            return None
        p = Path(relpath)
        if not p.is_absolute() and self.source is not None:
            p = self.source.parent / p
        return p

    def row(self, i: int) -> dict:
        """One trial as a plain dict (for messages and JSON)."""
        return {
            "method": str(self.method[i]),
            "object": str(self.object[i]),
            "task_id": str(self.task_id[i]),
            "trial": int(self.trial[i]),
            "level": int(self.level[i]),
            "dropped": bool(self.dropped[i]),
        }

    @classmethod
    def empty_like_columns(cls, n: int) -> dict:
        """Default columns for ``n`` trials (used by the readers and tests)."""
        return {
            "setup": _nan_poses(n),
            "reached": _nan_poses(n),
            "plan_time_s": np.full(n, np.nan),
            "exec_time_s": np.full(n, np.nan),
        }
