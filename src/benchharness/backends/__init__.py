"""Physics backends behind one interface.

Importing this package never imports an engine: ``pybullet`` and ``sapien``
are imported by :func:`create_pybullet` / :func:`create_sapien` (and the
modules they load) only when a backend is created.
"""

from __future__ import annotations

from .interface import (
    Backend,
    BackendError,
    BodyId,
    Box,
    CameraSpec,
    Capabilities,
    CapabilityError,
    Contact,
    Cylinder,
    JointInfo,
    JointState,
    MeshShape,
    PhysicsConfig,
    RayHits,
    Shape,
    SimulationError,
    Sphere,
    StepCallback,
)

__all__ = [
    "Backend",
    "BackendError",
    "BodyId",
    "Box",
    "CameraSpec",
    "Capabilities",
    "CapabilityError",
    "Contact",
    "Cylinder",
    "JointInfo",
    "JointState",
    "MeshShape",
    "PhysicsConfig",
    "RayHits",
    "Shape",
    "SimulationError",
    "Sphere",
    "StepCallback",
    "PYBULLET_CAPABILITIES",
    "SAPIEN_CAPABILITIES",
    "create_pybullet",
    "create_sapien",
]

#: capability flags, known without importing the engines (the classes carry the same values)
PYBULLET_CAPABILITIES = Capabilities(camera=True, gravity_torques=True, joint_coupling=True)
SAPIEN_CAPABILITIES = Capabilities(camera=False, gravity_torques=True, joint_coupling=True)


def create_pybullet(config: PhysicsConfig | None = None) -> Backend:
    """A PyBullet world (DIRECT mode)."""
    from .pybullet_backend import PyBulletBackend

    return PyBulletBackend(config)


def create_sapien(config: PhysicsConfig | None = None) -> Backend:
    """A SAPIEN 3 world (PhysX CPU, no renderer)."""
    from .sapien_backend import SapienBackend

    return SapienBackend(config)
