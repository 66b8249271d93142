"""Level I tasks as optimisation problems for our Allegro model.

The published grasp sets give, per task, the initial grasp joint
configuration (16 joints, the Utah lab's Allegro), the fingers used, and an
initial and desired "palm pose" ``H_i``, ``H_d``. Those poses behave as the
*object's* pose in the palm frame (their positions lie at the fingertips of
the initial grasp in our ``palm_link`` frame, see ``docs/ingrasp.md``), so:

* the initial grasp is the published joint vector, clamped to our joint
  limits (the thumb's ``joint_12`` is published up to 1.62 rad; our URDF
  stops at 1.396);
* the object frame sits at ``H_i`` in our palm frame at that grasp and is
  rigidly attached there to the frame carrying it (fingertip triangle or
  reference fingertip, ``IngraspConfig.object_frame``);
* the goal is the paper's relative change applied to our frame,
  ``H_d^rob = (H_d H_i^-1) H_i^rob``; with ``H_i^rob = H_i`` that is ``H_d``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .hand import FINGERS, joint_indices
from .rotations import pose_matrix

__all__ = ["InGraspTask", "distinct_initial_grasps", "published_tasks", "published_level1_path"]


def published_level1_path() -> Path:
    """The published relaxed-rigidity results file: the only file holding the Level I grasps."""
    from benchharness.paths import tasks_dir

    return tasks_dir() / "inhand" / "published" / "allegro_lvl1_relaxed_rigidity.csv"


@dataclass(frozen=True)
class InGraspTask:
    """One Level I task for our hand."""

    task_id: str
    object: str
    fingers: tuple[str, ...]  #: fingers used, reference finger first
    q0_published: np.ndarray  #: (16,) published initial grasp, rad
    initial: np.ndarray  #: (7,) published H_i (object frame <-> palm), as in the dataset
    desired: np.ndarray  #: (7,) published H_d

    @property
    def initial_matrix(self) -> np.ndarray:
        return pose_matrix(self.initial)

    @property
    def hand_fingers(self) -> tuple[str, ...]:
        """The fingers used, in the hand's order (index, middle, ring, thumb)."""
        return tuple(f for f in FINGERS if f in self.fingers)

    @property
    def q0_used(self) -> np.ndarray:
        """The used fingers' published joints (unclamped), in :attr:`hand_fingers` order: what
        ``HandKinematics.tip_poses_np(q0_used, hand_fingers)`` reads."""
        return self.q0_published[joint_indices(self.hand_fingers)]

    def goal_matrix(self, initial_rob: np.ndarray | None = None) -> np.ndarray:
        """``(H_d H_i^-1) H_i^rob``; ``initial_rob`` defaults to ``H_i`` (then the goal is ``H_d``)."""
        hi, hd = pose_matrix(self.initial), pose_matrix(self.desired)
        rob = hi if initial_rob is None else initial_rob
        return hd @ np.linalg.inv(hi) @ rob


def _order(fingers: list[int], reference: str) -> tuple[str, ...]:
    names = [FINGERS[i] for i in fingers]
    if reference in names:
        names.remove(reference)
        names.insert(0, reference)
    return tuple(names)


def distinct_initial_grasps(tasks: Sequence[InGraspTask] | None = None) -> list[InGraspTask]:
    """The first task of each distinct initial grasp (object and published joint vector).

    The published file sets two grasps per object, each shared by five tasks: 20 of the 100.
    """
    seen: set[tuple] = set()
    out = []
    for t in published_tasks() if tasks is None else tasks:
        key = (t.object, tuple(np.round(t.q0_published, 6)))
        if key not in seen:
            seen.add(key)
            out.append(t)
    return out


def published_tasks(path: str | Path | None = None, reference: str = "index") -> list[InGraspTask]:
    """The 100 Level I tasks from the published relaxed-rigidity file (it carries the grasps)."""
    from benchharness.inhand.fileformat import read_results

    rs = read_results(path if path is not None else published_level1_path())
    cols = [f"grasp_{f}_j{k}" for f in FINGERS for k in range(4)]
    out = []
    for i in range(len(rs)):
        q0 = np.array([float(rs.extra[c][i]) for c in cols])
        fingers = [int(x) for x in str(rs.extra["fingers"][i]).split(";") if x != ""]
        out.append(
            InGraspTask(
                str(rs.task_id[i]),
                str(rs.object[i]),
                _order(fingers, reference),
                q0,
                np.asarray(rs.initial[i], float),
                np.asarray(rs.desired[i], float),
            )
        )
    return out
