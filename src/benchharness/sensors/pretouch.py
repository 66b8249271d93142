"""Optical time-of-flight pre-touch sensors: rays from a link, ranges with noise.

The sensor-aided PR2 baseline re-localises the cube just before each regrasp
with ToF proximity sensors in its fingertips (Yang et al.). A sensor here is
one or more emitters rigidly mounted on a link; a reading casts every
emitter's ray in one batched :meth:`Backend.ray_cast` call and reports the
noisy range, NaN where the target is inside the minimum range and inf where
nothing is within the maximum range.

A reading also records which body each ray hit. That is for diagnostics and
tests only: a real sensor cannot tell the cube from the table, so the
estimator never looks at it (it gates by innovation instead).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from ..backends.interface import Backend, BodyId
from ..geometry import Pose
from .config import ToFConfig

__all__ = ["Emitter", "PreTouchSensor", "Scan", "ToFReading", "free_body_mover", "scan"]


@dataclass(frozen=True)
class Emitter:
    """One ToF emitter/receiver pair, fixed in its link's frame."""

    origin: tuple[float, float, float]  #: ray origin in the link frame (m), on the sensor's window
    direction: tuple[float, float, float]  #: ray direction in the link frame (normalised on use)
    name: str = ""

    def __post_init__(self) -> None:
        o = np.asarray(self.origin, dtype=float)
        d = np.asarray(self.direction, dtype=float)
        if (
            o.shape != (3,)
            or d.shape != (3,)
            or not np.all(np.isfinite(o))
            or not np.all(np.isfinite(d))
        ):
            raise ValueError("an Emitter needs a finite 3-vector origin and direction")
        if np.linalg.norm(d) < 1e-9:
            raise ValueError("an Emitter's direction must be non-zero")


@dataclass(frozen=True)
class ToFReading:
    """One reading of every emitter of a sensor (row i is emitter i).

    ``origins``/``directions`` are the rays as the robot believes them (world
    frame): what the estimator must use. ``true_distance`` and ``body`` are
    ground truth for diagnostics.
    """

    origins: np.ndarray  #: (n, 3) world ray origins (m)
    directions: np.ndarray  #: (n, 3) world unit ray directions
    distance: np.ndarray  #: (n,) measured range (m); NaN below min range, inf beyond max range
    true_distance: np.ndarray  #: (n,) noiseless engine range (m); inf where nothing was hit
    body: np.ndarray  #: (n,) body hit (-1 for none); diagnostics only
    time: float = 0.0

    @property
    def valid(self) -> np.ndarray:
        """(n,) bool: rays that returned a range."""
        return np.isfinite(self.distance)

    def __len__(self) -> int:
        return int(self.distance.shape[0])


class PreTouchSensor:
    """ToF emitters on ``link`` of ``body`` (``link=None``: the body's base)."""

    name = "pretouch-tof"

    def __init__(
        self,
        backend: Backend,
        body: BodyId,
        link: str | None,
        emitters: Sequence[Emitter],
        config: ToFConfig | None = None,
        *,
        ignore_bodies: Iterable[BodyId] | None = None,
        ignore_links: Iterable[tuple[BodyId, str | None]] = (),
    ) -> None:
        if not emitters:
            raise ValueError("a PreTouchSensor needs at least one Emitter")
        self.backend = backend
        self.body = body
        self.link = link
        self.emitters = tuple(emitters)
        self.config = config or ToFConfig()
        #: Bodies the rays pass through. The mounting body by default: the
        #: window sits in the finger, and a ray must not hit its own finger.
        #: On a robot that makes the whole robot transparent to its own
        #: sensors; for a robot that sees its other finger (or its other arm),
        #: pass ``ignore_bodies=()`` and ``ignore_links=((body, link),)``: the
        #: rays then pass only through the mounting link.
        self.ignore_bodies = tuple(ignore_bodies) if ignore_bodies is not None else (body,)
        self.ignore_links = tuple(ignore_links)
        self._o = np.array([e.origin for e in self.emitters], dtype=float)
        d = np.array([e.direction for e in self.emitters], dtype=float)
        self._d = d / np.linalg.norm(d, axis=1, keepdims=True)

    def link_pose(self) -> Pose:
        """The mounting link's true world pose, from the backend."""
        return self.backend.get_link_pose(self.body, self.link)

    def rays(self, link_pose: Pose) -> tuple[np.ndarray, np.ndarray]:
        """World origins and unit directions, (n, 3) each, for a given link pose."""
        return link_pose.apply(self._o), link_pose.rotation.apply(self._d)

    def read(
        self, rng: np.random.Generator, *, believed_link_pose: Pose | None = None
    ) -> ToFReading:
        """Cast every emitter's ray once (one batched call) and add range noise.

        Rays are cast from the link's true pose. The reading reports them from
        ``believed_link_pose`` when given (the robot's forward kinematics,
        calibration offsets and all), otherwise from the true pose.
        """
        if not isinstance(rng, np.random.Generator):
            raise TypeError("rng must be a numpy.random.Generator (seed it explicitly)")
        cfg = self.config
        true_pose = self.link_pose()
        o, d = self.rays(true_pose)
        # The range window applies to the true range (whether light comes back);
        # noise is added after, so a reading near a limit may stray past it.
        hits = self.backend.ray_cast(
            o, d, cfg.max_range, ignore_bodies=self.ignore_bodies, ignore_links=self.ignore_links
        )
        true_d = np.where(hits.hit & (hits.distance <= cfg.max_range), hits.distance, np.inf)
        noise = rng.standard_normal(len(true_d))  # drawn for every ray: same stream whatever is hit
        finite = np.isfinite(true_d)
        measured = np.full(len(true_d), np.inf)
        std = cfg.noise_std + cfg.noise_std_per_m * np.where(finite, true_d, 0.0)
        measured[finite] = np.maximum(true_d[finite] + std[finite] * noise[finite], 0.0)
        measured[finite & (true_d < cfg.min_range)] = np.nan
        if believed_link_pose is not None:
            o, d = self.rays(believed_link_pose)
        return ToFReading(
            o,
            d,
            measured,
            true_d,
            np.where(hits.hit, hits.body, -1).astype(int),
            time=float(self.backend.time),
        )


@dataclass(frozen=True)
class Scan:
    """Readings collected along a path; rows of all steps stacked (step-major)."""

    readings: tuple[ToFReading, ...]
    link_poses: tuple[Pose, ...]  #: the true link pose at each step

    def _cat(self, name: str) -> np.ndarray:
        if not self.readings:
            return np.zeros(
                (0, 3) if name in ("origins", "directions") else 0,
                dtype=int if name == "body" else float,
            )
        return np.concatenate([getattr(r, name) for r in self.readings], axis=0)

    @property
    def origins(self) -> np.ndarray:
        return self._cat("origins")

    @property
    def directions(self) -> np.ndarray:
        return self._cat("directions")

    @property
    def distance(self) -> np.ndarray:
        return self._cat("distance")

    @property
    def true_distance(self) -> np.ndarray:
        return self._cat("true_distance")

    @property
    def body(self) -> np.ndarray:
        return self._cat("body")

    @property
    def time(self) -> float:
        return self.readings[-1].time if self.readings else 0.0

    def __len__(self) -> int:
        return sum(len(r) for r in self.readings)


def free_body_mover(backend: Backend, body: BodyId) -> Callable[[Pose], None]:
    """A ``move_to`` for :func:`scan` that teleports a free-floating sensor body (tests, demos)."""

    def move_to(pose: Pose) -> None:
        backend.set_pose(body, pose)

    return move_to


def scan(
    sensor: PreTouchSensor,
    path: Iterable[Pose],
    move_to: Callable[[Pose], None],
    rng: np.random.Generator,
    *,
    belief: Callable[[Pose, Pose], Pose] | None = None,
) -> Scan:
    """Sweep the sensor along ``path`` (link poses), reading once per step.

    ``move_to(pose)`` brings the link to (near) ``pose``: the caller's arm
    controller, or :func:`free_body_mover`. ``belief(commanded, actual)``
    returns the link pose the robot believes it has, used to report the rays;
    by default the actual pose (perfect joint encoders and calibration).
    """
    readings: list[ToFReading] = []
    poses: list[Pose] = []
    for commanded in path:
        move_to(commanded)
        actual = sensor.link_pose()
        believed = belief(commanded, actual) if belief is not None else None
        readings.append(sensor.read(rng, believed_link_pose=believed))
        poses.append(actual)
    return Scan(tuple(readings), tuple(poses))
