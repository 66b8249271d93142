"""Joint facts read from a URDF before any backend is involved (limits, velocities, efforts).

Soft limits come from a joint's ``<safety_controller soft_lower_limit
soft_upper_limit>`` (as ``pr2_description`` writes them); a joint without one
has its hard limits as soft limits.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

__all__ = ["UrdfJoint", "downstream_links", "read_joints", "read_links"]

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
    soft_lower: float = -math.inf  #: ``<safety_controller soft_lower_limit>``, else ``lower``
    soft_upper: float = math.inf  #: ``<safety_controller soft_upper_limit>``, else ``upper``
    has_soft_limits: bool = False  #: the URDF gives this joint a soft position range


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
        sc = j.find("safety_controller")
        soft = (
            sc is not None
            and sc.get("soft_lower_limit") is not None
            and sc.get("soft_upper_limit") is not None
        )
        # a soft limit never widens the hard range
        slo = max(lo, float(sc.get("soft_lower_limit"))) if soft else lo
        shi = min(hi, float(sc.get("soft_upper_limit"))) if soft else hi
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
                slo,
                shi,
                bool(soft),
            )
        )
    return out


def read_links(urdf: str | Path) -> list[str]:
    return [lk.get("name") for lk in ET.parse(str(urdf)).getroot().findall("link")]


def downstream_links(root: ET.Element) -> dict[str, list[str]]:
    """Per joint of a parsed URDF (fixed ones too): the links it moves, its child and every link below
    it in the link tree, depth first from the child."""
    children: dict[str, list[str]] = {}
    for j in root.findall("joint"):
        children.setdefault(j.find("parent").get("link"), []).append(j.find("child").get("link"))
    out: dict[str, list[str]] = {}
    for j in root.findall("joint"):
        links, stack = [], [j.find("child").get("link")]
        while stack:
            lk = stack.pop()
            links.append(lk)
            stack.extend(children.get(lk, []))
        out[j.get("name")] = links
    return out
