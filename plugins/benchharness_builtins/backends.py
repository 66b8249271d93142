"""Built-in physics backends, registered exactly as a third-party backend would be.

The engines are imported only when a backend is created, so listing plugins
does not need PyBullet or SAPIEN installed.
"""

from __future__ import annotations

from dataclasses import asdict

from benchharness.backends import (
    PYBULLET_CAPABILITIES,
    SAPIEN_CAPABILITIES,
    PhysicsConfig,
    create_pybullet,
    create_sapien,
)
from benchharness.plugin import Registration, hookimpl


def _pybullet(config: PhysicsConfig | None = None):
    return create_pybullet(config)


def _sapien(config: PhysicsConfig | None = None):
    return create_sapien(config)


@hookimpl
def benchharness_backends() -> list[Registration]:
    return [
        Registration(
            "pybullet",
            _pybullet,
            "PyBullet 3 (Bullet multibody, DIRECT mode, TinyRenderer camera)",
            meta={"capabilities": asdict(PYBULLET_CAPABILITIES), "engine": "pybullet"},
        ),
        Registration(
            "sapien",
            _sapien,
            "SAPIEN 3 (PhysX 5 CPU, TGS solver; no renderer on headless machines)",
            meta={"capabilities": asdict(SAPIEN_CAPABILITIES), "engine": "sapien"},
        ),
    ]
