"""An in-grasp problem in our hand's terms: initial joints, object frame, goal.

Separate from :mod:`.tasks` so that tests and users can pose problems the
dataset does not contain (e.g. a goal produced by a known joint trajectory).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .hand import FINGERS, HandKinematics, joint_indices
from .rotations import pose_matrix
from .tasks import InGraspTask

__all__ = ["InGraspProblem", "problem_from_task", "clamp_grasp"]


@dataclass(frozen=True)
class InGraspProblem:
    """Everything the optimiser needs; all poses in the palm frame (4x4)."""

    fingers: tuple[str, ...]  #: fingers that move, reference finger first
    q0: np.ndarray  #: (4 k,) initial joints of those fingers, within limits
    object_initial: np.ndarray  #: object frame at the initial grasp
    goal: np.ndarray  #: desired object frame
    q_rest: np.ndarray  #: (16,) the whole hand at the initial grasp (unused fingers stay there)
    task_id: str = ""
    clamped: tuple[str, ...] = ()  #: joints of the published grasp moved onto our limits

    @property
    def dof(self) -> int:
        return 4 * len(self.fingers)


def clamp_grasp(
    q16: np.ndarray, hand: HandKinematics, margin: float = 0.0
) -> tuple[np.ndarray, tuple[str, ...]]:
    """A published 16-joint grasp moved inside our joint limits, and the joints that moved."""
    lo, hi = hand.limits(FINGERS)
    q = np.clip(np.asarray(q16, float), lo + margin, hi - margin)
    names = [n for f in FINGERS for n in hand.joint_names[f]]
    moved = tuple(names[i] for i in np.flatnonzero(np.abs(q - q16) > 1e-12))
    return q, moved


def problem_from_task(
    task: InGraspTask, hand: HandKinematics, margin: float = 0.0
) -> InGraspProblem:
    """Our problem for a published task (see :mod:`.tasks` for the frame conventions)."""
    q16, moved = clamp_grasp(task.q0_published, hand, margin)
    idx = joint_indices(task.fingers)
    h_i = pose_matrix(task.initial)
    return InGraspProblem(
        task.fingers, q16[idx], h_i, task.goal_matrix(h_i), q16, task.task_id, moved
    )
