"""Joint facts read from a URDF before any backend is involved (limits, velocities, efforts)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

__all__ = ["UrdfJoint", "read_joints", "read_links"]

MOVABLE = ("revolute", "prismatic", "continuous")


@dataclass(frozen=True)
class UrdfJoint:
    name: str
    type: str
    parent: str
    child: str
    lower: float
    upper: float
    velocity: float
    effort: float


def read_joints(urdf: str | Path) -> list[UrdfJoint]:
    """Movable joints in file order (the order the backends report)."""
    root = ET.parse(str(urdf)).getroot()
    out = []
    for j in root.findall("joint"):
        t = j.get("type")
        if t not in MOVABLE:
            continue
        lim = j.find("limit")
        if t == "continuous":
            lo, hi = -math.inf, math.inf
        elif lim is not None:
            lo, hi = float(lim.get("lower", 0.0)), float(lim.get("upper", 0.0))
        else:
            lo, hi = 0.0, 0.0
        out.append(
            UrdfJoint(
                j.get("name"),
                t,
                j.find("parent").get("link"),
                j.find("child").get("link"),
                lo,
                hi,
                float(lim.get("velocity", math.inf)) if lim is not None else math.inf,
                float(lim.get("effort", math.inf)) if lim is not None else math.inf,
            )
        )
    return out


def read_links(urdf: str | Path) -> list[str]:
    return [lk.get("name") for lk in ET.parse(str(urdf)).getroot().findall("link")]
