"""PR2 Rubik's cube baselines (Yang et al. 2020, Sec. IV-A) on the regrasp/twist planner.

* ``dead-reckoning`` — the head camera's one-shot estimate, then every gripper
  target from the pose believed through commanded motion only;
* ``sensor-aided`` — dead reckoning plus a pre-touch ToF reading at every
  pre-grasp, fused by ``benchharness.sensors.CubePoseFilter`` (simplified: no sweep);
* ``dead-reckoning-exact`` — the same with every injected error (arm
  calibration, tracking noise, camera noise) set to zero: a diagnostic that
  separates the strategy's own mistakes from the benchmark's error sources.

Both run on the bimanual state machine (:mod:`..bimanual.machine`) with the
PR2's grasp module. Modules: :mod:`.config` (parameters), :mod:`.strategy`
(the grasp modules and the strategies), :mod:`.workspace` (the IK scan that
placed the twisting pose). See docs/strategies.md.
Heavy imports (torch, engines) happen only inside the factories' products.
"""

from __future__ import annotations

from benchharness.plugin import Registration

__all__ = ["REGISTRATIONS", "make_dead_reckoning", "make_dead_reckoning_exact", "make_sensor_aided"]


def make_dead_reckoning(config=None):
    """Strategy factory: :class:`.strategy.DeadReckoningStrategy` with ``config`` (default parameters)."""
    from .strategy import DeadReckoningStrategy

    return DeadReckoningStrategy(config)


def make_dead_reckoning_exact(config=None):
    """Strategy factory: dead reckoning with every injected error zero."""
    from .strategy import DeadReckoningStrategy

    return DeadReckoningStrategy(config or _exact_options()["config"])


def make_sensor_aided(config=None):
    """Strategy factory: :class:`.strategy.SensorAidedStrategy` (pre-touch before every grasp)."""
    from .strategy import SensorAidedStrategy

    return SensorAidedStrategy(config)


def _options():
    """``--strategy-option`` defaults: the PR2 baselines' one config (:class:`.config.PR2RubiksConfig`)."""
    from .config import PR2RubiksConfig

    return {"config": PR2RubiksConfig()}


def _exact_options():
    from .config import PR2RubiksConfig

    return {"config": PR2RubiksConfig().zero_error()}


REGISTRATIONS = [
    Registration(
        "dead-reckoning",
        make_dead_reckoning,
        "PR2 Rubik's baseline: head-camera estimate, then dead reckoning through regrasps",
        {"benchmarks": ["rubiks"], "robots": ["pr2"]},
        options=_options,
    ),
    Registration(
        "dead-reckoning-exact",
        make_dead_reckoning_exact,
        "PR2 Rubik's dead reckoning with zero injected error (diagnostic)",
        {"benchmarks": ["rubiks"], "robots": ["pr2"]},
        options=_exact_options,
    ),
    Registration(
        "sensor-aided",
        make_sensor_aided,
        "PR2 Rubik's baseline with pre-touch ToF re-localisation (EKF) before every grasp",
        {"benchmarks": ["rubiks"], "robots": ["pr2"], "sensors": ["pretouch-tof"]},
        options=_options,
    ),
]
