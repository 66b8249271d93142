"""Robots: descriptions, kinematics and motion primitives, all through the Backend interface.

A :class:`Robot` is composed from a :class:`RobotConfig` — arms
(:class:`RobotArm`, a chain ending in a tool frame) and grippers/hands
(:class:`Gripper`, coupled finger joints). The built-in ``pr2``, ``herb``
and ``allegro`` are registered as plugins in ``benchharness_builtins.robots``.
"""

from .config import ArmConfig, GripperConfig, RobotConfig
from .parts import GraspResult, Gripper, MotionResult, RobotArm, RobotHand
from .robot import Robot

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
