"""Time-parameterised joint-space trajectories that respect joint velocity limits."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["QuinticTrajectory"]

#: Peak of ds/dt for the quintic time scaling s(t) = 10 t^3 - 15 t^4 + 6 t^5 on t in [0, 1].
QUINTIC_PEAK_VELOCITY = 1.875


@dataclass(frozen=True)
class QuinticTrajectory:
    """A straight line in joint space with a quintic time scaling (zero velocity and acceleration at both ends).

    Why quintic: the PD drives get continuous velocity and acceleration
    targets, so a tracking error reflects the controller, not a kinked
    reference. The duration is the shortest at which no joint exceeds its
    velocity limit (times a scale), unless a longer one is asked for.
    """

    q0: np.ndarray
    q1: np.ndarray
    duration: float

    @classmethod
    def plan(
        cls,
        q0: np.ndarray,
        q1: np.ndarray,
        max_velocity: np.ndarray,
        *,
        velocity_scale: float = 1.0,
        min_duration: float = 0.05,
        duration: float | None = None,
    ) -> QuinticTrajectory:
        q0 = np.asarray(q0, dtype=float)
        q1 = np.asarray(q1, dtype=float)
        vmax = np.asarray(max_velocity, dtype=float) * velocity_scale
        need = float(np.max(QUINTIC_PEAK_VELOCITY * np.abs(q1 - q0) / vmax)) if q0.size else 0.0
        t = max(need, min_duration, duration or 0.0)
        return cls(q0, q1, t)

    def sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Position and velocity at time ``t`` (clamped to the ends)."""
        s = min(max(t / self.duration, 0.0), 1.0)
        pos = 10 * s**3 - 15 * s**4 + 6 * s**5
        vel = (30 * s**2 - 60 * s**3 + 30 * s**4) / self.duration
        d = self.q1 - self.q0
        return self.q0 + pos * d, vel * d

    def peak_velocity(self) -> np.ndarray:
        return QUINTIC_PEAK_VELOCITY * np.abs(self.q1 - self.q0) / self.duration
