"""The contract between the runner and a strategy: what a trial gets, what it returns.

The runner builds a :class:`TrialContext` and calls
``strategy.run_trial(ctx) -> TrialOutcome``. The strategy *acts* and
*reports what it observed*; it never scores itself: success, score and
failure cause are decided by the runner through :mod:`benchharness.metrics`,
so a simulated trial and a real robot's log go through the same code.

Everything in the context is fresh for the trial (a new backend world, a new
robot, new sensors, a new strategy instance) and every random draw must come
from ``ctx.rng`` (or the generators handed to sensors), which is derived from
(run seed, task, trial index) alone: the same arguments give the same trial
whatever the number of workers and whichever trials ran before.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from ..cube import SOLVED_STRING, Move, format_sequence
from .causes import FailureCause

if TYPE_CHECKING:  # imported for annotations only: the runner must not pull in engines
    from ..backends.interface import Backend, PhysicsConfig
    from .recorder import TrialRecorder

__all__ = [
    "InhandItem",
    "RubiksItem",
    "SensorSlot",
    "Strategy",
    "TimeBudget",
    "TrialContext",
    "TrialItem",
    "TrialOutcome",
    "TrialTimeout",
    "check_drives",
    "declared_robots",
]


class TrialTimeout(BaseException):
    """The trial's time budget ran out.

    A ``BaseException`` (like ``KeyboardInterrupt``) on purpose: a strategy's
    ``except Exception`` around a motion must not swallow the end of its own
    trial. The runner catches it and records cause ``timeout``.
    """


@dataclass(frozen=True)
class RubiksItem:
    """One Rubik's trial: trial ``trial`` (1-based) of tier ``tier``.

    ``sequence`` is the protocol generator's sequence for (seed, tier, trial);
    the cube starts in ``initial`` (solved). The expected final state is not
    given: the validator computes it after the trial.
    """

    tier: str
    trial: int
    trials_in_tier: int
    sequence: tuple[Move, ...]
    seed: int
    initial: str = SOLVED_STRING

    benchmark = "rubiks"

    @property
    def sequence_text(self) -> str:
        return format_sequence(self.sequence)

    @property
    def label(self) -> str:
        return f"{self.tier} trial {self.trial}"


@dataclass(frozen=True)
class InhandItem:
    """One in-hand trial: a row of an in-hand task set, possibly repeated.

    Poses are ``[x, y, z, qx, qy, qz, qw]`` of the hand in the object frame
    (see ``docs/inhand.md``); ``contacts`` maps ``"initial"``/``"desired"`` to
    ``(k, 3)`` fingertip contact points (object frame) where the task defines
    them (Levels II/III).
    """

    task_set: str
    task_id: str
    object: str
    level: int
    initial: np.ndarray
    desired: np.ndarray
    repeat: int = 1
    contacts: Mapping[str, np.ndarray] = field(default_factory=dict)
    extra: Mapping[str, Any] = field(default_factory=dict)

    benchmark = "inhand"

    @property
    def label(self) -> str:
        return f"{self.task_set} {self.task_id} repeat {self.repeat}"


TrialItem = RubiksItem | InhandItem


@dataclass
class SensorSlot:
    """A sensor named on the command line (``--sensors``), for the strategy to create.

    The runner cannot build sensors itself: a pre-touch sensor needs the body
    and link it is mounted on and its emitter layout, which only exist once
    the strategy has spawned the robot. So the runner hands over the plugin's
    factory and the sensor's own random stream; the strategy calls
    :meth:`create` with whatever the factory needs and passes :attr:`rng` to
    every measurement (``camera.observe(backend, cube, slot.rng)``).
    """

    name: str
    rng: np.random.Generator
    factory: Callable[..., Any]
    meta: Mapping[str, Any] = field(default_factory=dict)
    instance: Any = None

    def create(self, **kwargs: Any) -> Any:
        """Build the sensor (``factory(**kwargs)``); kept as :attr:`instance`."""
        self.instance = self.factory(**kwargs)
        return self.instance


@dataclass(frozen=True)
class TimeBudget:
    """Limits of one trial. ``None`` means unlimited.

    ``sim_s`` counts simulated seconds from the start of the trial (enforced
    at every ``backend.step``); ``wall_s`` counts wall-clock seconds (enforced
    at every step and, as a backstop for code that never steps, by an alarm
    signal in the worker a little after the limit).
    """

    sim_s: float | None = None
    wall_s: float | None = None


@dataclass
class TrialOutcome:
    """What the strategy observed. The runner scores it; the strategy does not.

    Rubik's: ``final_state`` is the observed logical 54-facelet state
    (e.g. :attr:`benchharness.cube_physics.PhysicalCube.state_string`), or
    ``None`` if there is none to observe (cube dropped, twist jammed).
    ``termination_s`` is the simulated time at which manipulation terminated
    (default: the backend clock when ``run_trial`` returned). First contact
    comes from the recorder (:meth:`TrialRecorder.contact` or
    :meth:`TrialRecorder.watch_contact`) unless given here.

    In-hand: ``reached`` (and optionally ``setup``) hand pose in the object
    frame, ``dropped``, planning/execution time and reached contact points.

    ``failure`` declares a failure the strategy itself detected (``dropped``,
    ``jammed``, ``unreachable``); ``message`` says more. ``extra`` is any
    JSON-serialisable data to keep with the trial.
    """

    final_state: str | None = None
    termination_s: float | None = None
    first_contact_s: float | None = None
    failure: FailureCause | str | None = None
    message: str = ""
    reached: Sequence[float] | np.ndarray | None = None
    setup: Sequence[float] | np.ndarray | None = None
    dropped: bool = False
    plan_time_s: float | None = None
    exec_time_s: float | None = None
    reached_contacts: Sequence[Sequence[float]] | np.ndarray | None = None
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass
class TrialContext:
    """Everything one trial may use; built by the runner, fresh per trial.

    ``robot`` is created but not spawned: the strategy builds its scene
    (ground, table, cube, ``robot.spawn(backend, ...)``) in ``backend``, which
    is an empty world with ``physics`` applied. ``sensors`` maps each name
    given with ``--sensors`` (in that order) to a :class:`SensorSlot`. ``run``
    holds the run's identifying fields (task, robot, strategy, sensors,
    backend, seed).
    """

    item: TrialItem
    trial_index: int
    robot: Any
    backend: Backend
    sensors: Mapping[str, SensorSlot]
    rng: np.random.Generator
    budget: TimeBudget
    recorder: TrialRecorder
    physics: PhysicsConfig
    run: Mapping[str, Any] = field(default_factory=dict)
    wall_start: float = field(default_factory=time.perf_counter)
    sim_start: float = 0.0

    @property
    def benchmark(self) -> str:
        return self.item.benchmark

    @property
    def sim_elapsed(self) -> float:
        return float(self.backend.time) - self.sim_start

    @property
    def wall_elapsed(self) -> float:
        return time.perf_counter() - self.wall_start

    def check_budget(self) -> None:
        """Raise :class:`TrialTimeout` if a budget is spent.

        Called by the runner after every ``backend.step``; a strategy that
        spends long stretches without stepping (planning) may call it too.
        """
        b = self.budget
        if b.sim_s is not None and self.sim_elapsed > b.sim_s:
            raise TrialTimeout(
                f"simulated-time budget of {b.sim_s:g} s spent ({self.sim_elapsed:.3f} s)"
            )
        if b.wall_s is not None and self.wall_elapsed > b.wall_s:
            raise TrialTimeout(
                f"wall-time budget of {b.wall_s:g} s spent ({self.wall_elapsed:.1f} s)"
            )


@runtime_checkable
class Strategy(Protocol):
    """A manipulation strategy as the runner sees it.

    Registered as a ``strategy`` plugin whose factory takes no arguments and
    returns a fresh instance (one per trial). Optional attribute
    ``benchmarks``: the benchmarks it can run (``("rubiks",)``,
    ``("inhand",)``); the runner refuses other tasks before starting.

    The robots a strategy drives are declared in its registration, as
    ``meta={"robots": ["pr2"]}`` (read by :func:`declared_robots`): the run
    command refuses any other robot before a trial runs or a store is
    opened, without building the strategy. No ``robots`` key: any robot.
    """

    def run_trial(self, ctx: TrialContext) -> TrialOutcome: ...


def declared_robots(meta: Mapping[str, Any]) -> tuple[str, ...] | None:
    """The robots a strategy's registration says it drives; ``None`` if it does not say."""
    robots = meta.get("robots")
    if robots is None:
        return None
    if isinstance(robots, str) or not all(isinstance(r, str) for r in robots):
        raise TypeError(f"strategy meta 'robots' must be a list of robot names, not {robots!r}")
    return tuple(robots)


def check_drives(strategy: str, meta: Mapping[str, Any], robot: str) -> None:
    """Raise a one-line :class:`ValueError` if strategy ``strategy`` does not drive ``robot``."""
    robots = declared_robots(meta)
    if robots is not None and robot not in robots:
        raise ValueError(
            f"--robot {robot!r}: strategy {strategy!r} drives only these robots: {', '.join(robots)}"
        )
