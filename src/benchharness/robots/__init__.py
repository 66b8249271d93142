"""Robots: descriptions, kinematics and motion primitives, all through the Backend interface.

A :class:`Robot` is composed from a :class:`RobotConfig` — arms
(:class:`RobotArm`, a chain ending in a tool frame) and grippers/hands
(:class:`Gripper`, coupled finger joints). The built-in ``pr2``, ``herb``
and ``allegro`` are registered as plugins in ``benchharness_builtins.robots``.

The configs are plain data and import light; the parts and the robot (NumPy
kinematics, the backends' interface) are loaded on first use of their names
here, so that reading a config (``benchharness robots`` lists DOF and groups
from the configs) stays cheap. Neither imports torch: pytorch-kinematics is
loaded only for large IK/FK batches and whole-tree FK (:mod:`.kinematics`).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .config import ArmConfig, GripperConfig, RobotConfig

if TYPE_CHECKING:
    from .parts import GraspResult, Gripper, MotionResult, RobotArm, RobotHand
    from .robot import Robot

_LAZY = {
    "GraspResult": ".parts",
    "Gripper": ".parts",
    "MotionResult": ".parts",
    "RobotArm": ".parts",
    "RobotHand": ".parts",
    "Robot": ".robot",
}

__all__ = [
    "ArmConfig",
    "GraspResult",
    "Gripper",
    "GripperConfig",
    "MotionResult",
    "Robot",
    "RobotArm",
    "RobotConfig",
    "RobotHand",
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
