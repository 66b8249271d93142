"""A serial chain read from URDF text the way pytorch-kinematics reads it, without torch.

Why: a Rubik's trial needs only the NumPy model of each arm
(:class:`~.kinematics._SerialModel`); building it from a
pytorch-kinematics chain cost every run command torch's and
pytorch-kinematics' import (~2.5 CPU-s with interpreter teardown, issue 12).
This module reads the same facts from the URDF directly.

Bit for bit the same model: pytorch-kinematics parses each joint origin
into a ``float32`` transform — the position rounded to float32, the
rotation built from the ``rpy`` angles by its
``quaternion_from_euler(rpy, "sxyz")`` and ``quaternion_to_matrix`` in
float32 — and normalises each axis in float32, then converts the chain to
float64. :func:`read_serial_chain` repeats those float32 operations in
NumPy (sine and cosine correctly rounded to float32), so the static
offsets, axes and limits equal pytorch-kinematics' exactly on every
shipped robot (``tests/robots/test_urdf_chain.py`` checks each arm and
finger chain, and the re-centred continuous-joint chains, against it).
For another URDF a float32 sine or cosine may differ from torch's in its
last bit (torch's float32 trigonometry is not correctly rounded): 6e-8 rad,
the size of pytorch-kinematics' own float32 rounding.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

__all__ = ["ChainJoint", "SerialChainSpec", "read_serial_chain"]

_F32 = np.float32
_TYPES = {"fixed": 0, "revolute": 1, "continuous": 1, "prismatic": 2}


@dataclass(frozen=True)
class ChainJoint:
    """One joint on the path root -> tip, as pytorch-kinematics models it."""

    name: str
    kind: int  #: 0 fixed, 1 revolute (or continuous), 2 prismatic (pytorch-kinematics' indices)
    offset: (
        np.ndarray
    )  #: (4, 4) float64: the origin, rounded through float32 as pytorch-kinematics does
    axis: np.ndarray  #: (3,) float64: the unit axis, normalised in float32
    lower: float  #: URDF <limit lower> (0 if absent; -inf without <limit>)
    upper: float  #: URDF <limit upper> (0 if absent; inf without <limit>)


@dataclass(frozen=True)
class SerialChainSpec:
    """The joints from ``root`` to ``tip`` in order; ``movable`` names the non-fixed ones."""

    root: str
    tip: str
    joints: tuple[ChainJoint, ...]

    @property
    def movable(self) -> tuple[ChainJoint, ...]:
        return tuple(j for j in self.joints if j.kind != 0)


def _floats(text: str | None, default: str) -> list[float]:
    return [float(v) for v in (text or default).split()]


def _cos(x: np.float32) -> np.float32:
    return _F32(math.cos(float(x)))


def _sin(x: np.float32) -> np.float32:
    return _F32(math.sin(float(x)))


def _rotation_f32(rpy: list[float]) -> np.ndarray:
    """pytorch-kinematics' float32 rotation of URDF ``rpy`` (static-frame x, y, z)."""
    two = _F32(2.0)
    ai, aj, ak = (_F32(v) / two for v in rpy)
    ci, si, cj, sj, ck, sk = _cos(ai), _sin(ai), _cos(aj), _sin(aj), _cos(ak), _sin(ak)
    cc, cs, sc, ss = ci * ck, ci * sk, si * ck, si * sk
    w = cj * cc + sj * ss
    x = cj * sc - sj * cs
    y = cj * ss + sj * cc
    z = cj * cs - sj * sc
    s = two / (((w * w + x * x) + y * y) + z * z)
    one = _F32(1.0)
    return np.array(
        [
            [one - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
            [s * (x * y + z * w), one - s * (x * x + z * z), s * (y * z - x * w)],
            [s * (x * z - y * w), s * (y * z + x * w), one - s * (x * x + y * y)],
        ],
        dtype=_F32,
    )


def _offset(origin: ET.Element | None) -> np.ndarray:
    t = np.eye(4, dtype=_F32)
    if origin is not None:
        t[:3, 3] = np.array(_floats(origin.get("xyz"), "0 0 0"), dtype=_F32)
        t[:3, :3] = _rotation_f32(_floats(origin.get("rpy"), "0 0 0"))
    return t.astype(np.float64)


def _axis(el: ET.Element | None) -> np.ndarray:
    a = np.array(_floats(el.get("xyz") if el is not None else None, "0 0 1"), dtype=_F32)
    norm = _F32(math.sqrt(float(np.sum(a * a, dtype=_F32))))
    return (a / norm).astype(np.float64)


def read_serial_chain(text: str, root: str, tip: str) -> SerialChainSpec:
    """The chain ``root`` -> ``tip`` of URDF ``text`` (ValueError naming a link not on one path)."""
    tree = ET.fromstring(text)
    by_child: dict[str | None, ET.Element] = {}
    for el in tree.findall("joint"):
        child = el.find("child")
        if child is not None:
            by_child[child.get("link")] = el
    path: list[ET.Element] = []
    link: str | None = tip
    while link != root:
        joint = by_child.get(link)
        if joint is None:
            raise ValueError(f"link {tip!r} is not below {root!r} in this URDF")
        path.append(joint)
        parent = joint.find("parent")
        link = parent.get("link") if parent is not None else None
    joints = []
    for j in reversed(path):
        kind = j.get("type", "fixed")
        if kind not in _TYPES:
            raise ValueError(f"joint {j.get('name')!r}: type {kind!r} is not a serial-chain joint")
        # as urdf_parser_py: <limit> lower/upper default 0 (a continuous joint's 0..0 is then
        # "unbounded" to the chain, as is a joint without <limit>)
        lim = j.find("limit")
        if lim is None:
            lo, hi = -math.inf, math.inf
        else:
            lo, hi = float(lim.get("lower", 0.0)), float(lim.get("upper", 0.0))
        joints.append(
            ChainJoint(
                name=str(j.get("name")),
                kind=_TYPES[kind],
                offset=_offset(j.find("origin")),
                axis=_axis(j.find("axis")),
                lower=lo,
                upper=hi,
            )
        )
    return SerialChainSpec(root, tip, tuple(joints))
