"""Writes collision-only URDFs from primitive shapes, with inertias computed from them.

Why a builder instead of hand-written XML: every link's inertia must follow
from its collision shapes and its mass, and a hand-typed tensor is the usual
place where simulated robots go quietly wrong. Each link's mass is spread
over its shapes by volume; the composite inertia about the link COM is
diagonalised and written as principal moments plus an ``<inertial>`` rpy,
because PyBullet ignores off-diagonal terms while SAPIEN honours them — a
diagonal tensor in a rotated frame means the same thing to both.

Where a robot's description publishes a link's inertial (centre of mass
and full tensor), :class:`Link` takes it as is (``com``, ``inertia``) instead
of computing one from the stand-in shapes, whose centres can lie centimetres
from the real COM; it is still written diagonalised, for the same reason.

Joints may carry soft limits (``soft_lower``/``soft_upper``), written as a
``<safety_controller>`` element as in ``pr2_description``: the position
limits that IK and the motion primitives respect, inside the hard
``<limit>`` that the engines enforce.

Every figure carries a ``source`` string that is written as an XML comment,
so the generated file says where each number came from.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal
from xml.sax.saxutils import escape

import numpy as np
from scipy.spatial.transform import Rotation

from ..inertia import (
    box_inertia,
    box_volume,
    cylinder_inertia,
    cylinder_volume,
    parallel_axis,
    sphere_inertia,
    sphere_volume,
)

__all__ = ["Geom", "Link", "Joint", "UrdfBuilder", "shape_inertia", "composite_inertia"]


@dataclass(frozen=True)
class Geom:
    """A primitive collision shape in its link frame.

    ``size``: box full extents (x, y, z); cylinder (radius, length) along
    local z; sphere (radius,).
    """

    kind: Literal["box", "cylinder", "sphere"]
    size: tuple[float, ...]
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def volume(self) -> float:
        if self.kind == "box":
            return box_volume(self.size)
        if self.kind == "cylinder":
            r, length = self.size
            return cylinder_volume(r, length)
        (r,) = self.size
        return sphere_volume(r)


def shape_inertia(g: Geom, mass: float) -> np.ndarray:
    """Inertia tensor (3x3) of a uniform solid about its own centre, in the link frame
    (the primitive's moments from :mod:`benchharness.inertia`, turned by ``rpy``)."""
    if g.kind == "box":
        d = box_inertia(mass, g.size)
    elif g.kind == "cylinder":
        r, h = g.size
        d = cylinder_inertia(mass, r, h)
    else:
        (r,) = g.size
        d = sphere_inertia(mass, r)
    R = Rotation.from_euler("xyz", g.rpy).as_matrix()
    return R @ np.diag(d) @ R.T


def composite_inertia(geoms: Sequence[Geom], mass: float) -> tuple[np.ndarray, np.ndarray]:
    """COM and inertia tensor about the COM of ``mass`` spread over ``geoms`` by volume."""
    vols = np.array([g.volume() for g in geoms])
    masses = mass * vols / vols.sum()
    centres = np.array([g.xyz for g in geoms], dtype=float)
    com = (masses[:, None] * centres).sum(axis=0) / mass
    inertia = np.zeros((3, 3))
    for g, m, c in zip(geoms, masses, centres):
        r = c - com
        inertia += shape_inertia(g, m) + parallel_axis(m, r)
    return com, inertia


def _principal(inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments and the rpy of the principal frame (a proper rotation).

    Eigenvectors are matched to the link axes they are closest to, so an
    already-diagonal tensor keeps rpy = 0 instead of a permuted frame.
    """
    off = inertia - np.diag(np.diag(inertia))
    if np.abs(off).max() <= 1e-12 * max(np.abs(inertia).max(), 1e-30):
        return np.diag(inertia).copy(), np.zeros(3)
    w, v = np.linalg.eigh(inertia)
    order = np.full(3, -1)
    used: set[int] = set()
    for axis in np.argsort(-np.abs(v).max(axis=1)):
        cands = [c for c in np.argsort(-np.abs(v[axis])) if c not in used]
        order[axis] = cands[0]
        used.add(int(cands[0]))
    v = v[:, order]
    w = w[order]
    for k in range(3):
        if v[k, k] < 0:
            v[:, k] = -v[:, k]
    if np.linalg.det(v) < 0:
        v[:, 2] = -v[:, 2]
    rpy = Rotation.from_matrix(v).as_euler("xyz")
    rpy[np.abs(rpy) < 1e-12] = 0.0
    return w, rpy


FRAME_MASS = 0.001  #: kg, token mass of a shapeless frame link
FRAME_RADIUS = 0.005  #: m, its inertia is that of a solid sphere of this radius


def _f(x: float) -> str:
    s = f"{x:.9g}"
    return "0" if s in ("-0", "0") else s


def _vec(v: Sequence[float]) -> str:
    return " ".join(_f(float(x)) for x in v)


@dataclass
class Link:
    """A link: collision shapes, mass, and where the figures come from.

    A link with no shapes and no mass (a frame such as a tool-centre point)
    gets a token 1 g point mass: PyBullet gives a link without
    ``<inertial>`` a mass of 1 kg, which would hang a phantom kilogram on
    every tool frame. ``point_mass_radius`` gives a shapeless link (e.g. a roll
    actuator frame) a mass as a small solid sphere, so its inertia is still
    computed rather than made up.
    """

    name: str
    geoms: list[Geom] = field(default_factory=list)
    mass: float = 0.0
    source: str = ""
    point_mass_radius: float | None = None
    #: published centre of mass (link frame); with ``inertia``, replaces the one computed from ``geoms``
    com: tuple[float, float, float] | None = None
    #: published inertia about ``com`` in link axes: (ixx, ixy, ixz, iyy, iyz, izz)
    inertia: tuple[float, float, float, float, float, float] | None = None

    def xml(self) -> str:
        out = []
        if self.source:
            out.append(f"  <!-- {escape(self.source)} -->")
        out.append(f'  <link name="{self.name}">')
        geoms = self.geoms
        if self.mass <= 0 and not geoms:
            self.mass, self.point_mass_radius = FRAME_MASS, FRAME_RADIUS
        if (self.com is None) != (self.inertia is None):
            raise ValueError(f"link {self.name}: give both com and inertia, or neither")
        if self.mass > 0:
            if self.com is not None and self.inertia is not None:
                xx, xy, xz, yy, yz, zz = self.inertia
                com = np.asarray(self.com, dtype=float)
                inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)
            elif geoms:
                com, inertia = composite_inertia(geoms, self.mass)
            elif self.point_mass_radius:
                g = Geom("sphere", (self.point_mass_radius,))
                com, inertia = np.zeros(3), shape_inertia(g, self.mass)
            else:
                raise ValueError(f"link {self.name}: a mass needs shapes or point_mass_radius")
            moments, rpy = _principal(inertia)
            out += [
                "    <inertial>",
                f'      <origin xyz="{_vec(com)}" rpy="{_vec(rpy)}"/>',
                f'      <mass value="{_f(self.mass)}"/>',
                f'      <inertia ixx="{_f(moments[0])}" ixy="0" ixz="0" iyy="{_f(moments[1])}" iyz="0" izz="{_f(moments[2])}"/>',
                "    </inertial>",
            ]
        for g in geoms:
            if g.kind == "box":
                shape = f'<box size="{_vec(g.size)}"/>'
            elif g.kind == "cylinder":
                shape = f'<cylinder radius="{_f(g.size[0])}" length="{_f(g.size[1])}"/>'
            else:
                shape = f'<sphere radius="{_f(g.size[0])}"/>'
            out += [
                "    <collision>",
                f'      <origin xyz="{_vec(g.xyz)}" rpy="{_vec(g.rpy)}"/>',
                f"      <geometry>{shape}</geometry>",
                "    </collision>",
            ]
        out.append("  </link>")
        return "\n".join(out)


@dataclass
class Joint:
    name: str
    type: Literal["revolute", "prismatic", "fixed", "continuous"]
    parent: str
    child: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    lower: float = 0.0
    upper: float = 0.0
    effort: float = 0.0
    velocity: float = 0.0
    damping: float = 0.0
    source: str = ""
    #: soft position limits (``<safety_controller>``), inside ``lower``/``upper``; None: none
    soft_lower: float | None = None
    soft_upper: float | None = None
    k_position: float = (
        0.0  #: safety-controller gains, written as published (not used by the harness)
    )
    k_velocity: float = 0.0

    def xml(self) -> str:
        out = []
        if self.source:
            out.append(f"  <!-- {escape(self.source)} -->")
        out.append(f'  <joint name="{self.name}" type="{self.type}">')
        out.append(f'    <parent link="{self.parent}"/>')
        out.append(f'    <child link="{self.child}"/>')
        out.append(f'    <origin xyz="{_vec(self.xyz)}" rpy="{_vec(self.rpy)}"/>')
        if self.type != "fixed":
            out.append(f'    <axis xyz="{_vec(self.axis)}"/>')
            lim = f'effort="{_f(self.effort)}" velocity="{_f(self.velocity)}"'
            if self.type != "continuous":
                lim = f'lower="{_f(self.lower)}" upper="{_f(self.upper)}" ' + lim
            out.append(f"    <limit {lim}/>")
            if (self.soft_lower is None) != (self.soft_upper is None):
                raise ValueError(f"joint {self.name}: give both soft limits, or neither")
            if self.soft_lower is not None and self.soft_upper is not None:
                if not self.lower <= self.soft_lower < self.soft_upper <= self.upper:
                    raise ValueError(f"joint {self.name}: soft limits outside the hard limits")
                out.append(
                    f'    <safety_controller k_position="{_f(self.k_position)}" '
                    f'k_velocity="{_f(self.k_velocity)}" soft_lower_limit="{_f(self.soft_lower)}" '
                    f'soft_upper_limit="{_f(self.soft_upper)}"/>'
                )
            if self.damping:
                out.append(f'    <dynamics damping="{_f(self.damping)}" friction="0"/>')
        out.append("  </joint>")
        return "\n".join(out)


@dataclass
class UrdfBuilder:
    """A robot description being written: links and joints in, URDF text out
    (the backends' reader of URDF files is ``backends._urdf.ParsedUrdf``)."""

    name: str
    header: str = ""
    links: list[Link] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)

    def link(self, *args, **kwargs) -> Link:
        lk = Link(*args, **kwargs)
        self.links.append(lk)
        return lk

    def joint(self, *args, **kwargs) -> Joint:
        j = Joint(*args, **kwargs)
        self.joints.append(j)
        return j

    def to_xml(self) -> str:
        names = [lk.name for lk in self.links]
        if len(set(names)) != len(names):
            raise ValueError("duplicate link names")
        known = set(names)
        for j in self.joints:
            if j.parent not in known or j.child not in known:
                raise ValueError(f"joint {j.name} refers to an unknown link")
        parts = ['<?xml version="1.0"?>']
        if self.header:
            parts.append("<!--\n" + escape(self.header.strip()).replace("--", "-") + "\n-->")
        parts.append(f'<robot name="{self.name}">')
        parts += [lk.xml() for lk in self.links]
        parts += [j.xml() for j in self.joints]
        parts.append("</robot>")
        return "\n".join(parts) + "\n"
