"""Generators of the shipped collision-only URDFs (``robots/<name>/<name>.urdf``).

The URDF files are generated, not hand-edited: the figures and their sources
live in these modules, and ``python -m benchharness.robots.descriptions``
rewrites the files. A test checks that the shipped files match.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ..urdf_builder import UrdfBuilder

__all__ = ["generators", "write_all"]


def generators() -> dict[str, Callable[[], UrdfBuilder]]:
    """Robot name -> function building its :class:`UrdfBuilder`."""
    from . import allegro, herb, pr2, pr2_gripper

    return {
        "pr2": pr2.build,
        "herb": herb.build,
        "allegro": allegro.build,
        "pr2_gripper": pr2_gripper.build,
    }


def write_all(root: Path) -> list[Path]:
    """Write ``<root>/<name>/<name>.urdf`` for every shipped robot."""
    out = []
    for name, build in generators().items():
        path = root / name / f"{name}.urdf"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(build().to_xml())
        out.append(path)
    return out
