"""The strategy object the plugin registrations build: one variant, one hand model."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from .config import VARIANTS, IngraspConfig
from .hand import HandKinematics
from .planner import PlanResult, plan
from .problem import InGraspProblem, problem_from_task
from .tasks import InGraspTask

__all__ = ["InGraspPlanner"]


class InGraspPlanner:
    """Plans Level I in-grasp trajectories on the Allegro with one variant.

    The hand model is built once per planner (URDF parsing is slower than a
    plan); pass ``hand`` to share one between planners.
    """

    def __init__(self, variant: str = "relaxed-rigidity", config: IngraspConfig | None = None,
                 urdf: str | Path | None = None, hand: HandKinematics | None = None, **overrides) -> None:
        if variant not in VARIANTS:
            raise ValueError(f"unknown variant {variant!r}; one of {', '.join(VARIANTS)}")
        self.variant = variant
        self.config = replace(config or IngraspConfig(), **overrides)
        self.hand = hand or HandKinematics(urdf)

    def problem(self, task: InGraspTask) -> InGraspProblem:
        return problem_from_task(task, self.hand, self.config.limit_margin)

    def plan(self, problem: InGraspProblem) -> PlanResult:
        return plan(self.hand, problem, self.variant, self.config)

    def plan_task(self, task: InGraspTask) -> PlanResult:
        return self.plan(self.problem(task))
