"""The strategy object the plugin registrations build: one variant, one hand model.

``plan_task`` plans offline (the paper's Fig. 6); ``run_trial`` is the
runner's entry point: plan the task, then execute the plan on the simulated
Allegro hand holding our model of the task's object (:mod:`.execution`).
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache
from pathlib import Path

from .collision import CollisionScene, collision_scene
from .config import VARIANTS, IngraspConfig
from .execution import ExecConfig, InGraspExecutor, SetupInfeasible
from .hand import HandKinematics, default_urdf
from .placement import object_surface_arrays
from .planner import PlanResult, plan, tip_rotation_deg
from .problem import InGraspProblem, problem_from_task
from .tasks import InGraspTask, published_tasks

__all__ = ["InGraspPlanner", "task_for_item"]


def _shared_hand(urdf: str | Path | None = None) -> HandKinematics:
    """One hand model per description file and process (URDF parsing costs more than a plan);
    trials share it read-only. ``None``: the stock Allegro (``robots/allegro``)."""
    return _hand_at(str(Path(urdf or default_urdf()).resolve()))


@lru_cache(maxsize=4)
def _hand_at(path: str) -> HandKinematics:
    return HandKinematics(path)


@lru_cache(maxsize=1)
def _published_by_id() -> dict[str, InGraspTask]:
    return {t.task_id: t for t in published_tasks()}


def task_for_item(item) -> InGraspTask:
    """The published Level I task (with its grasp) behind a runner :class:`InhandItem`.

    The task set rows carry only poses; the initial grasp (joints, fingers)
    lives in the published relaxed-rigidity file, matched on ``task_id``.
    The item's own ``initial``/``desired`` poses are used (they equal the
    published ones for ``inhand-level1``).
    """
    import numpy as np

    if getattr(item, "level", 1) != 1:
        raise ValueError(f"in-grasp planners run Level I tasks only, not level {item.level}")
    tasks = _published_by_id()
    if item.task_id not in tasks:
        raise ValueError(
            f"task {item.task_id!r} has no published Allegro grasp "
            f"(tasks/inhand/published/allegro_lvl1_relaxed_rigidity.csv)"
        )
    t = tasks[item.task_id]
    return replace(
        t, initial=np.asarray(item.initial, float), desired=np.asarray(item.desired, float)
    )


class InGraspPlanner:
    """Plans (and, as a runner strategy, executes) Level I in-grasp trajectories on the Allegro.

    The hand model is the trial robot's own description (its URDF, e.g. ``robots/allegro``), built
    once per process, unless ``urdf``/``hand`` fixes one; offline planning (:meth:`plan_task`) uses
    that or the stock Allegro. ``exec_config`` sets up the simulated trials (:class:`ExecConfig`).
    """

    benchmarks = ("inhand",)

    def __init__(
        self,
        variant: str = "relaxed-rigidity",
        config: IngraspConfig | None = None,
        urdf: str | Path | None = None,
        hand: HandKinematics | None = None,
        exec_config: ExecConfig | None = None,
        **overrides,
    ) -> None:
        if variant not in VARIANTS:
            raise ValueError(f"unknown variant {variant!r}; one of {', '.join(VARIANTS)}")
        self.variant = variant
        self.name = variant
        self.config = replace(config or IngraspConfig(), **overrides)
        self.exec_config = exec_config or ExecConfig()
        self._fixed_hand = hand or (HandKinematics(urdf) if urdf is not None else None)

    @property
    def hand(self) -> HandKinematics:
        """The hand model offline planning uses: the one given, else the stock Allegro."""
        return self._fixed_hand or _shared_hand()

    def hand_for(self, robot) -> HandKinematics:
        """The hand model of a trial's ``robot``: its own URDF unless one was fixed at construction."""
        return self._fixed_hand or _shared_hand(robot.urdf_path)

    def problem(self, task: InGraspTask, hand: HandKinematics | None = None) -> InGraspProblem:
        return problem_from_task(task, hand or self.hand, self.config.limit_margin)

    def plan(
        self,
        problem: InGraspProblem,
        hand: HandKinematics | None = None,
        scene: CollisionScene | None = None,
    ) -> PlanResult:
        return plan(hand or self.hand, problem, self.variant, self.config, scene)

    def trial_scene(
        self, backend, robot, problem: InGraspProblem, object_name: str, hand=None
    ) -> CollisionScene | None:
        """The collision scene of a simulated trial: our object model where its set-up puts it in
        ``backend`` (:meth:`InGraspExecutor.nominal_setup`); None when ``w_collision`` is 0.
        Raises :class:`SetupInfeasible` when no placement fits the grasp."""
        if self.config.w_collision <= 0:
            return None
        from benchharness.objects import load_object

        hand = hand or self.hand_for(robot)
        q_touch, place, _ = InGraspExecutor(hand, self.exec_config).nominal_setup(
            backend, robot, problem, object_name
        )
        return collision_scene(
            hand,
            problem,
            object_surface_arrays(load_object(object_name))[0],
            place.pose,
            q_touch=q_touch,
            margin=self.config.collision_margin,
            max_points=self.config.collision_points,
        )

    def plan_task(self, task: InGraspTask) -> PlanResult:
        return self.plan(self.problem(task))

    # ------------------------------------------------------------------ runner
    def run_trial(self, ctx):
        """Plan the trial's task, then set up, execute and hold it in ``ctx.backend`` (see :mod:`.execution`)."""
        import numpy as np

        from benchharness.backends.interface import SimulationError
        from benchharness.runner.contract import TrialOutcome

        task = task_for_item(ctx.item)
        hand = self.hand_for(ctx.robot)
        problem = self.problem(task, hand)
        try:  # the plan keeps the hand off the object where the set-up will put it
            scene = self.trial_scene(ctx.backend, ctx.robot, problem, task.object, hand)
        except SetupInfeasible:  # planned without the object; run() below refuses the set-up
            scene = None
        res = self.plan(problem, hand, scene)
        ctx.check_budget()
        ctx.recorder.event(
            "plan",
            variant=self.variant,
            plan_time_s=round(res.plan_time_s, 4),
            planned_reached=np.round(res.reached, 7).tolist(),
            converged=res.converged,
        )
        extra = {
            "variant": self.variant,
            "planned_reached": np.round(res.reached, 7).tolist(),
            "plan_pos_error_cm": round(res.pos_error * 100, 5),
            "plan_converged": res.converged,
            # per used finger: how far the plan turns the fingertip against the object (rolls it)
            "plan_tip_rotation_deg": np.round(
                tip_rotation_deg(hand, problem.fingers, res.q), 2
            ).tolist(),
        }
        if res.collision_shortfall is not None:
            extra["plan_collision_shortfall_mm"] = round(res.collision_shortfall * 1e3, 4)
        executor = InGraspExecutor(hand, self.exec_config)
        try:
            out = executor.run(
                ctx.backend,
                ctx.robot,
                problem,
                res,
                task.object,
                ctx.rng,
                ctx.recorder,
                duration_s=self.config.duration_s,
            )
        except SimulationError as exc:  # a blow-up ends this trial with its cause, never the sweep
            return TrialOutcome(
                failure="simulator_error",
                message=f"physics blow-up: {exc}",
                plan_time_s=res.plan_time_s,
                extra=extra,
            )
        except SetupInfeasible as exc:  # the grasp cannot be set up on our object model
            return TrialOutcome(
                failure="unreachable",
                message=f"set-up infeasible: {exc}",
                plan_time_s=res.plan_time_s,
                extra=extra,
            )
        extra.update(out.extra)
        return TrialOutcome(
            reached=out.reached,
            setup=out.setup,
            dropped=out.dropped,
            plan_time_s=res.plan_time_s,
            exec_time_s=out.exec_sim_s,
            message=out.message,
            failure="dropped" if out.dropped else None,
            extra=extra,
        )
