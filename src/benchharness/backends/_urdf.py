"""Engine-independent helpers shared by the built-in backends.

* mass properties of collision shapes (uniform density; the formulas are
  :mod:`benchharness.inertia`'s),
* a small URDF reader (joints, limits, links) so that both engines report the
  same joint order, limits and collision filtering,
* writing a collision-only copy of a URDF (SAPIEN's loader needs a render
  device for ``<visual>``).

Nothing here imports an engine.
"""

from __future__ import annotations

import math
import os
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..geometry import Pose
from ..inertia import (
    box_inertia,
    box_volume,
    convex_hull_properties,
    cylinder_inertia,
    cylinder_volume,
    parallel_axis,
    sphere_inertia,
    sphere_volume,
)
from .interface import BackendError, Box, Cylinder, JointInfo, MeshShape, Shape, Sphere

MOVABLE = ("revolute", "prismatic", "continuous")


# -- mass properties ----------------------------------------------------------
def shape_volume_com_inertia(shape: Shape) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centre (shape frame) and inertia tensor per unit density about that centre.

    The one mapping from a collision :class:`Shape` to the primitive formulas
    of :mod:`benchharness.inertia`; the object models use it too
    (:func:`benchharness.objects.mass.mass_properties`).
    """
    if isinstance(shape, Box):
        size = (2.0 * np.asarray(shape.half_extents, dtype=float)).tolist()
        v = box_volume(size)
        return v, np.zeros(3), np.diag(box_inertia(v, size))
    if isinstance(shape, Sphere):
        v = sphere_volume(shape.radius)
        return v, np.zeros(3), np.diag(sphere_inertia(v, shape.radius))
    if isinstance(shape, Cylinder):
        length = 2.0 * float(shape.half_length)
        v = cylinder_volume(shape.radius, length)
        return v, np.zeros(3), np.diag(cylinder_inertia(v, shape.radius, length))
    if isinstance(shape, MeshShape):
        return convex_hull_properties(shape.vertices)
    raise BackendError(f"unknown shape type {type(shape).__name__}")


@dataclass(frozen=True)
class BodyInertial:
    """A rigid body's mass, centre of mass and principal inertia, as the engines take them
    (the object catalogue's published figures are :class:`benchharness.objects.MassProperties`)."""

    mass: float
    com: np.ndarray  #: body frame
    inertia_diag: np.ndarray  #: principal moments about the COM
    principal: np.ndarray  #: quaternion (x, y, z, w) of the principal axes in the body frame

    @property
    def inertial_pose(self) -> Pose:
        return Pose(self.com, self.principal)


def mass_properties(
    shapes: Sequence[Shape],
    mass: float,
    com: Sequence[float] | None = None,
    inertia_diag: Sequence[float] | None = None,
) -> BodyInertial:
    """Uniform-density mass properties of a compound, overridden by ``com``/``inertia_diag``."""
    if not shapes:
        raise BackendError("a body needs at least one shape")
    vols, centres, tensors = [], [], []
    for s in shapes:
        v, c, i = shape_volume_com_inertia(s)
        r = s.pose.rotation.as_matrix()
        vols.append(v)
        centres.append(s.pose.apply(c))
        tensors.append(r @ i @ r.T)
    total_v = float(sum(vols))
    if total_v <= 0:
        raise BackendError("shapes have zero volume")
    density = mass / total_v
    c_body = np.asarray(sum(v * c for v, c in zip(vols, centres)), dtype=float) / total_v
    i_body = np.zeros((3, 3))
    for v, c, i in zip(vols, centres, tensors):
        d = c - c_body
        i_body += density * (i + parallel_axis(v, d))
    if com is not None:
        c_body = np.asarray(com, dtype=float)
    if inertia_diag is not None:
        return BodyInertial(
            float(mass), c_body, np.asarray(inertia_diag, dtype=float), np.array([0, 0, 0, 1.0])
        )
    w, vec = np.linalg.eigh(0.5 * (i_body + i_body.T))
    if np.linalg.det(vec) < 0:
        vec[:, 2] *= -1
    if np.allclose(
        i_body, np.diag(np.diag(i_body)), atol=1e-12 * max(1e-30, float(np.max(np.abs(i_body))))
    ):
        return BodyInertial(float(mass), c_body, np.diag(i_body).copy(), np.array([0, 0, 0, 1.0]))
    return BodyInertial(float(mass), c_body, w, Rotation.from_matrix(vec).as_quat())


# -- URDF ---------------------------------------------------------------------
@dataclass
class ParsedUrdf:
    """What the backends read of a URDF file (links, joints, masses); robots write theirs
    with ``robots.urdf_builder.UrdfBuilder``."""

    path: Path
    root_link: str
    links: list[str]
    joints: list[JointInfo]  #: every joint, file order (fixed ones too, type "fixed")
    movable: list[JointInfo] = field(default_factory=list)  #: movable joints, file order
    mimic: list[str] = field(default_factory=list)
    masses: dict[str, float] = field(
        default_factory=dict
    )  #: link -> <inertial> mass (links that have one)

    @property
    def total_mass(self) -> float:
        return float(sum(self.masses.values()))

    def filtered_link_pairs(self) -> list[frozenset[str]]:
        """Link groups whose members must not collide with each other.

        Links joined by fixed joints form one rigid group; a group and each
        group it is joined to by a movable joint are filtered as a whole.
        Engines already skip direct parent/child pairs; this adds pairs that
        are adjacent *through* a fixed link, and links of the same rigid group.
        Returned as cliques (sets of links), one per movable edge or lone
        multi-link group.
        """
        parent = {l: l for l in self.links}

        def find(x: str) -> str:
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        for j in self.joints:
            if j.type == "fixed":
                parent[find(j.child_link)] = find(j.parent_link)
        groups: dict[str, set[str]] = {}
        for l in self.links:
            groups.setdefault(find(l), set()).add(l)
        cliques: list[frozenset[str]] = []
        covered: set[str] = set()
        for j in self.joints:
            if j.type == "fixed":
                continue
            ga, gb = groups[find(j.parent_link)], groups[find(j.child_link)]
            if len(ga) + len(gb) > 2:
                cliques.append(frozenset(ga | gb))
                covered.add(find(j.parent_link))
                covered.add(find(j.child_link))
        for root, g in groups.items():
            if len(g) > 1 and root not in covered:
                cliques.append(frozenset(g))
        return cliques


def _f(el: ET.Element | None, attr: str, default: float) -> float:
    v = None if el is None else el.get(attr)
    return default if v is None else float(v)


def _req(el: ET.Element | None, attr: str, path: Path, what: str) -> str:
    """A required attribute, or a :class:`BackendError` naming the file and the element."""
    v = None if el is None else el.get(attr)
    if v is None:
        raise BackendError(f"{path}: {what} has no {attr!r}")
    return v


def parse_urdf(path: str | Path) -> ParsedUrdf:
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise BackendError(f"cannot read URDF {path}: {exc}") from exc
    links = [_req(l, "name", path, "a <link>") for l in root.findall("link")]
    masses: dict[str, float] = {}
    for l in root.findall("link"):
        m = l.find("inertial/mass")
        if m is not None:
            masses[_req(l, "name", path, "a <link>")] = float(m.get("value", 0.0))
    missing = [l for l in links if l not in masses]
    if missing:
        import warnings

        warnings.warn(
            f"{path}: links without <inertial> {missing}: PyBullet and SAPIEN give them different "
            "default masses; give every link an <inertial>",
            stacklevel=3,
        )
    joints: list[JointInfo] = []
    children: set[str] = set()
    mimic: list[str] = []
    for j in root.findall("joint"):
        name = _req(j, "name", path, "a <joint>")
        jtype = _req(j, "type", path, f"joint {name!r}")
        parent = _req(j.find("parent"), "link", path, f"the <parent> of joint {name!r}")
        child = _req(j.find("child"), "link", path, f"the <child> of joint {name!r}")
        children.add(child)
        lim = j.find("limit")
        if jtype == "continuous":
            lo, hi = -math.inf, math.inf
        elif jtype in ("revolute", "prismatic"):
            lo, hi = _f(lim, "lower", 0.0), _f(lim, "upper", 0.0)
        else:
            lo = hi = 0.0
        if jtype not in MOVABLE and jtype != "fixed":
            raise BackendError(f"{path}: joint {name!r} has unsupported type {jtype!r}")
        if j.find("mimic") is not None:
            mimic.append(name)
        joints.append(
            JointInfo(
                name=name,
                type=jtype,
                lower=lo,
                upper=hi,
                max_velocity=_f(lim, "velocity", math.inf) or math.inf,
                max_effort=_f(lim, "effort", math.inf) or math.inf,
                parent_link=parent,
                child_link=child,
            )
        )
    roots = [l for l in links if l not in children]
    if len(roots) != 1:
        raise BackendError(f"{path}: expected one root link, found {roots}")
    if mimic:
        import warnings

        warnings.warn(
            f"{path}: <mimic> on joints {mimic} is not enforced by the backends (PhysX has no mimic "
            "joints); drive those joints explicitly",
            stacklevel=3,
        )
    model = ParsedUrdf(
        path=path, root_link=roots[0], links=links, joints=joints, mimic=mimic, masses=masses
    )
    model.movable = [j for j in joints if j.type in MOVABLE]
    return model


def collision_only_copy(path: str | Path) -> str:
    """Write a copy of the URDF without ``<visual>`` elements; mesh paths made absolute.

    ``continuous`` joints become ``revolute`` with limits -inf..inf: SAPIEN's
    loader makes a continuous joint a *wrapped* PhysX revolute joint, whose
    position wraps past 2*pi while a drive target does not (a driven joint
    sent past 2*pi spins wildly), and a revolute with infinite limits an
    unwrapped, free one — what a URDF continuous joint means, and what
    PyBullet does. Returns the path of the temporary file (the caller deletes it).
    """
    path = Path(path).resolve()
    tree = ET.parse(path)
    root = tree.getroot()
    for joint in root.findall("joint"):
        if joint.get("type") == "continuous":
            joint.set("type", "revolute")
            lim = joint.find("limit")
            if lim is None:
                lim = ET.SubElement(joint, "limit")
            lim.set("lower", "-inf")
            lim.set("upper", "inf")
    for link in root.findall("link"):
        for vis in link.findall("visual"):
            link.remove(vis)
    for mesh in root.iter("mesh"):
        fn = mesh.get("filename")
        if fn and "://" not in fn and not os.path.isabs(fn):
            mesh.set("filename", str((path.parent / fn).resolve()))
    fd, out = tempfile.mkstemp(suffix=".urdf", prefix="bh_collision_")
    with os.fdopen(fd, "wb") as fh:
        tree.write(fh)
    return out


def ground_ray_fixup(
    grounds: dict[int, float],
    ignore: set[int],
    o: np.ndarray,
    d: np.ndarray,
    maxd: np.ndarray,
    hit: np.ndarray,
    dist: np.ndarray,
    point: np.ndarray,
    normal: np.ndarray,
    body: np.ndarray,
) -> None:
    """Ground planes hit analytically when an ignored body's exit carried the ray past them.

    A ray continued past an ignored body starts just beyond its exit; if that
    body rested on the ground the new start is already under the plane and
    the engine misses it. Rays starting above a ground plane must cross it.
    """
    for g, h in grounds.items():
        if g in ignore:
            continue
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (h - o[:, 2]) / d[:, 2]
        ok = (o[:, 2] >= h - 1e-9) & (d[:, 2] < 0) & (t <= maxd) & (t < dist) & (t >= 0)
        for i in np.nonzero(ok)[0]:
            hit[i] = True
            dist[i] = t[i]
            point[i] = o[i] + t[i] * d[i]
            normal[i] = (0.0, 0.0, 1.0)
            body[i] = g
