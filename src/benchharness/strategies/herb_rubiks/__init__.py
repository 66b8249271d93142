"""HERB push-grasp Rubik's strategy (Yang et al. 2020, Sec. IV-D, Fig. 3) on the regrasp/twist planner.

* ``push-grasp`` — the PR2 baseline's state machine with every grasp a
  push-grasp: the BarrettHand approaches perpendicular to the face with its
  thumb (the "middle finger") flexed in front of the palm, stops when the
  thumb touches, and closes its two outer fingers. Each contact re-anchors
  the believed cube pose along the approach; the head camera is used once.
* ``push-grasp-exact`` — the same with every injected error zero (diagnostic).

Robot ``herb`` only: any other robot is refused with a clear error.
Modules: :mod:`.config` (parameters), :mod:`.frames` (tool frames from an
estimated pose), :mod:`.push` (the push-grasp primitive), :mod:`.strategy`
(the trial). See docs/herb_push_grasp.md. Heavy imports happen only inside
the factories' products.
"""

from __future__ import annotations

from benchharness.plugin import Registration

__all__ = ["REGISTRATIONS", "make_push_grasp", "make_push_grasp_exact"]


def make_push_grasp(config=None):
    """Strategy factory: :class:`.strategy.PushGraspStrategy` with ``config`` (default parameters)."""
    from .strategy import PushGraspStrategy

    return PushGraspStrategy(config)


def make_push_grasp_exact(config=None):
    """Strategy factory: push-grasp with every injected error zero."""
    from .strategy import PushGraspStrategy

    return PushGraspStrategy(config or _exact_options()["config"])


def _options():
    """``--strategy-option`` defaults: :class:`.config.HerbPushGraspConfig`."""
    from .config import HerbPushGraspConfig

    return {"config": HerbPushGraspConfig()}


def _exact_options():
    from .config import HerbPushGraspConfig

    return {"config": HerbPushGraspConfig().zero_error()}


REGISTRATIONS = [
    Registration(
        "push-grasp",
        make_push_grasp,
        "HERB Rubik's strategy: every grasp a BarrettHand push-grasp (thumb stop, outer fingers close)",
        {"benchmarks": ["rubiks"], "robots": ["herb"]},
        options=_options,
    ),
    Registration(
        "push-grasp-exact",
        make_push_grasp_exact,
        "HERB push-grasp with zero injected error (diagnostic)",
        {"benchmarks": ["rubiks"], "robots": ["herb"]},
        options=_exact_options,
    ),
]
