"""Test-only robot and strategies, registered with ``--plugin runner_testplugins``.

Never registered as built-ins: these exist to drive the runner through every
outcome (success on a real backend, wrong state, simulator error, strategy
error, timeouts, declared failures) with known, deterministic numbers.
"""

from __future__ import annotations

import dataclasses
import os
import time
from dataclasses import dataclass, field

import numpy as np

from benchharness.backends import Box, SimulationError
from benchharness.cube import expected_final, parse_sequence
from benchharness.geometry import Pose
from benchharness.plugin import Registration, hookimpl
from benchharness.runner import TrialOutcome

CUBE_HALF = 0.0285


class StubRobot:
    """No description, no kinematics: the strategies below need none."""

    name = "test-stub"


def _scene(ctx):
    """A fixed pad (the 'robot') and a 5.7 cm cube dropped onto it; first contact is watched."""
    b = ctx.backend
    b.add_ground()
    pad = b.add_body([Box((0.05, 0.05, 0.01))], Pose([0.0, 0.0, 0.30]), 0.0, fixed=True, name="pad")
    cube = b.add_body([Box((CUBE_HALF,) * 3)], Pose([0.0, 0.0, 0.40]), 0.094, name="cube")
    ctx.recorder.watch_contact(cube, pad)
    return pad, cube


class DropStrategy:
    """Drops a box on a pad, then 'executes' each move by holding still a random number of steps."""

    benchmarks = ("rubiks",)
    wrong = False

    def run_trial(self, ctx):
        b = ctx.backend
        pad, cube = _scene(ctx)
        while ctx.recorder.first_contact_s is None:
            b.step(1)
        belief = b.get_pose(cube).as_array()
        slot = ctx.sensors.get("test-noise")
        sensor = slot.create(scale=0.5) if slot is not None else None
        for i, move in enumerate(ctx.item.sequence):
            b.step(int(ctx.rng.integers(4, 16)))
            true = b.get_pose(cube)
            if sensor is not None:  # re-localise: the belief is the measurement
                belief = sensor.observe(true, slot.rng)
            else:  # dead reckoning: the belief drifts
                belief = belief + np.r_[ctx.rng.normal(0, 0.001, 3), np.zeros(4)]
            ctx.recorder.pose_estimate(i, true, belief)
            ctx.recorder.move(i, str(move))
        moves = tuple(ctx.item.sequence)
        if self.wrong:
            ctx.recorder.unintended_rotation(len(moves) - 1, "-", "U")
            moves += parse_sequence("U")
        final = expected_final(moves, ctx.item.initial)
        if os.environ.get("RUNNER_TEST_SLEEP"):
            time.sleep(float(os.environ["RUNNER_TEST_SLEEP"]))
        if os.environ.get("RUNNER_TEST_HANG_FROM") and ctx.trial_index >= int(
            os.environ["RUNNER_TEST_HANG_FROM"]
        ):
            time.sleep(120)  # a long trial still in flight when the test stops the run
        if os.environ.get("RUNNER_TEST_LOG"):  # who ran which trial: one line per execution
            with open(os.environ["RUNNER_TEST_LOG"], "a") as f:
                f.write(f"{os.getpid()} {ctx.trial_index}\n")
        return TrialOutcome(final_state=final)


class NoiseSensor:
    """A position sensor with Gaussian noise: randomness only from the rng passed in."""

    def __init__(self, scale: float = 1.0, std_m: float = 0.001) -> None:
        self.std = scale * std_m

    def observe(self, true_pose, rng):
        a = true_pose.as_array().copy()
        a[:3] += rng.normal(0, self.std, 3)
        return a


class WrongStateStrategy(DropStrategy):
    wrong = True


class TimedStrategy:
    """Touches at t=0 and terminates after exactly ``trial`` simulated seconds: scores 1, 2, ..., M."""

    def run_trial(self, ctx):
        ctx.backend.add_ground()
        ctx.recorder.contact()
        steps = round(ctx.item.trial / ctx.physics.timestep)
        ctx.backend.step(steps)
        return TrialOutcome(
            final_state=expected_final(ctx.item.sequence, ctx.item.initial),
            termination_s=ctx.sim_start + steps * ctx.physics.timestep,
            first_contact_s=ctx.sim_start,
        )


class SimErrorStrategy:
    def run_trial(self, ctx):
        ctx.backend.add_ground()
        ctx.backend.step(10)
        raise SimulationError("cube state became NaN (test)")


class CrashStrategy:
    def run_trial(self, ctx):
        raise ValueError("bug in the strategy (test)")


class SlowSimStrategy:
    """Steps forever: the simulated-time budget must stop it."""

    def run_trial(self, ctx):
        ctx.backend.add_ground()
        while True:
            try:
                ctx.backend.step(24)
            except Exception:  # noqa: BLE001 - a careless strategy: must not swallow the timeout
                pass


class HangStrategy:
    """Never steps: only the wall-clock alarm can stop it."""

    def run_trial(self, ctx):
        time.sleep(60)


class StuckStrategy:
    """Stuck where no Python signal handler runs (as in native code): the wall alarm is blocked."""

    def run_trial(self, ctx):
        import signal

        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})
        time.sleep(60)


class SegfaultStrategy:
    """Kills its own process as an engine crash would (trial 2 only; the others succeed)."""

    def run_trial(self, ctx):
        import signal

        if ctx.trial_index == 2:
            os.kill(os.getpid(), signal.SIGSEGV)
        return TimedStrategy().run_trial(ctx)


class ExitStrategy:
    """Calls sys.exit mid-trial (a library's error path, a stray ``exit()``)."""

    def run_trial(self, ctx):
        ctx.backend.add_ground()
        ctx.backend.step(3)
        raise SystemExit(3)


class InterruptStrategy:
    """Raises KeyboardInterrupt itself (no Ctrl-C was pressed)."""

    def run_trial(self, ctx):
        raise KeyboardInterrupt("raised by the strategy (test)")


class JammedStrategy:
    def run_trial(self, ctx):
        ctx.backend.add_ground()
        ctx.backend.step(5)
        ctx.recorder.blocked_rotation(0, str(ctx.item.sequence[0]), "over-constrained grasp")
        return TrialOutcome(failure="jammed", message="twist 1 jammed")


class NotAnOutcomeStrategy:
    def run_trial(self, ctx):
        return {"final_state": "no"}


class InhandNoisyStrategy:
    """Reaches the desired pose with rng noise; drops the object 20 % of the time.

    Trial k reports a planning time of 0.1 k s, dropped or not.
    """

    benchmarks = ("inhand",)

    def run_trial(self, ctx):
        ctx.backend.step(2)
        plan_time_s = 0.1 * ctx.trial_index
        if ctx.rng.random() < 0.2:
            return TrialOutcome(dropped=True, message="slipped (test)", plan_time_s=plan_time_s)
        reached = np.array(ctx.item.desired, float)
        reached[:3] += ctx.rng.normal(0, 0.005, 3)
        return TrialOutcome(reached=reached, plan_time_s=plan_time_s, exec_time_s=1.67)


@dataclass(frozen=True)
class _Reach:
    """A nested group, as the real strategies' ``errors`` and ``sweep``."""

    #: m, a nested float
    margin: float = 0.01
    enabled: bool = True


@dataclass(frozen=True)
class ConfiguredConfig:
    """Every field type ``--strategy-option`` reads."""

    #: simulated steps held per move
    hold_steps: int = 4
    label: str = "plain"
    scale: float = 1.0
    depth: int | None = None
    offsets: tuple[float, ...] = (0.25, 0.35)
    pair: tuple[float, float] = (0.0, 1.0)
    reach: _Reach = field(default_factory=_Reach)

    def __post_init__(self) -> None:
        if self.label not in ("plain", "fancy"):
            raise ValueError(f"label must be 'plain' or 'fancy', not {self.label!r}")


class ConfiguredStrategy(DropStrategy):
    """Drops the cube as test-drop; records its configuration and whether the backend draws visuals."""

    def __init__(self, config: ConfiguredConfig | None = None) -> None:
        self.config = config or ConfiguredConfig()

    def run_trial(self, ctx):
        out = super().run_trial(ctx)
        ctx.recorder.event("config", **dataclasses.asdict(self.config))
        ctx.recorder.event("backend", draws_visuals=ctx.backend.draws_visuals)
        return out


STRATEGIES = {
    "test-drop": DropStrategy,
    "test-wrong": WrongStateStrategy,
    "test-timed": TimedStrategy,
    "test-simerror": SimErrorStrategy,
    "test-crash": CrashStrategy,
    "test-slowsim": SlowSimStrategy,
    "test-hang": HangStrategy,
    "test-stuck": StuckStrategy,
    "test-exit": ExitStrategy,
    "test-segfault": SegfaultStrategy,
    "test-interrupt": InterruptStrategy,
    "test-jammed": JammedStrategy,
    "test-notoutcome": NotAnOutcomeStrategy,
    "test-inhand": InhandNoisyStrategy,
}


@hookimpl
def benchharness_robots():
    return [Registration("test-stub", StubRobot, "test-only robot with nothing in it")]


@hookimpl
def benchharness_sensors():
    return [Registration("test-noise", NoiseSensor, "test-only noisy position sensor")]


@hookimpl
def benchharness_strategies():
    return [
        Registration(name, cls, f"test-only: {cls.__doc__ or name}".splitlines()[0])
        for name, cls in STRATEGIES.items()
    ] + [
        Registration(
            "test-configured",
            ConfiguredStrategy,
            "test-only: keeps its --strategy-option configuration",
            options=lambda: {"config": ConfiguredConfig()},
        )
    ]
