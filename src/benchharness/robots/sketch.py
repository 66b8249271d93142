"""A checkable drawing of a robot: its URDF geometry, posed by our FK, in a side and a top view.

``benchharness robot inspect NAME --png FILE`` writes this picture. It is made
without a simulator camera, so it works the same on a headless CPU machine and
is deterministic: every link's ``<collision>`` shapes (its ``<visual>`` ones
where it has no collision shape) are tessellated (boxes, cylinders, spheres;
meshes through trimesh), placed at the link poses that
:class:`~benchharness.robots.kinematics.KinematicTree` gives for the chosen joint
values and the robot's base pose, and projected orthographically onto two
panels:

* **side (from -y)**: x to the right, z up (the robot faces +x);
* **top (from +z)**: x to the right, y up.

Faces are drawn far to near (painter's algorithm, back faces culled) with
Lambert shading, one colour per link (hues spaced by the golden ratio, so
links next to each other in the file differ strongly and every link has its
own hue). The floor (z = 0) is a line in the side view and a shaded
rectangle in the top view; each panel is framed on the robot's bounding box
with a small margin, axes in metres. ``frames=True`` adds an RGB triad
(x red, y green, z blue) at every movable joint's origin, optionally labelled.
"""

from __future__ import annotations

import colorsys
import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = [
    "LinkShape",
    "SketchResult",
    "View",
    "VIEWS",
    "draw_robot",
    "link_colours",
    "read_link_shapes",
    "robot_link_poses",
]

#: panel margin around the robot's projected bounding box, as a fraction of its larger side
MARGIN = 0.06
#: the side view shows the floor line when the gap between it and the robot is at most this
#: fraction of the robot's height; otherwise the floor is marked by an arrow and its distance
FLOOR_GAP_SHOWN = 0.35
_CYL_SEGMENTS = 32
_SPHERE_RINGS, _SPHERE_SEGMENTS = 12, 24


@dataclass(frozen=True)
class View:
    """An orthographic view: screen axes ``u`` (right) and ``v`` (up), ``toward`` the viewer."""

    name: str
    title: str
    u: tuple[float, float, float]
    v: tuple[float, float, float]
    toward: tuple[float, float, float]
    u_label: str
    v_label: str


VIEWS = (
    View("side", "side (from \u2212y)", (1, 0, 0), (0, 0, 1), (0, -1, 0), "x (m)", "z (m)"),
    View("top", "top (from +z)", (1, 0, 0), (0, 1, 0), (0, 0, 1), "x (m)", "y (m)"),
)


@dataclass
class LinkShape:
    """One URDF geometry element of a link as outward-facing polygons in the link frame."""

    link: str
    kind: str  #: box, cylinder, sphere or mesh
    polygons: list[np.ndarray]  #: each (k, 3), k >= 3
    normals: np.ndarray  #: (n, 3) outward unit normals, one per polygon
    outlined: np.ndarray  #: (n,) bool: the polygon's edges are the shape's edges (box faces, caps)


@dataclass
class SketchResult:
    """What was drawn: for tests and ``--json``."""

    path: Path
    size: tuple[int, int]  #: pixels (width, height)
    bounds: np.ndarray  #: (2, 3) world min / max of the drawn geometry, m
    links: list[str]  #: links that have geometry, in drawing-colour order
    colours: dict[str, tuple[float, float, float]]
    panels: dict[str, dict[str, Any]] = field(default_factory=dict)
    frames: list[str] = field(default_factory=list)  #: joints whose frames were drawn

    def as_dict(self) -> dict[str, Any]:
        return {
            "path": str(self.path),
            "size": list(self.size),
            "bounds_m": self.bounds.tolist(),
            "links_drawn": len(self.links),
            "frames": list(self.frames),
            "panels": self.panels,
        }


# -- geometry -------------------------------------------------------------------------
def _origin(el: ET.Element | None) -> np.ndarray:
    t = np.eye(4)
    o = None if el is None else el.find("origin")
    if o is not None:
        t[:3, 3] = [float(x) for x in o.get("xyz", "0 0 0").split()]
        rpy = [float(x) for x in o.get("rpy", "0 0 0").split()]
        t[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
    return t


def _box(half: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    polys, normals = [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            a, b = (axis + 1) % 3, (axis + 2) % 3
            quad = np.zeros((4, 3))
            quad[:, axis] = sign * half[axis]
            for i, (sa, sb) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
                quad[i, a], quad[i, b] = sa * half[a], sb * half[b]
            n = np.zeros(3)
            n[axis] = sign
            polys.append(quad)
            normals.append(n)
    return polys, np.array(normals)


def _cylinder(r: float, half_len: float) -> tuple[list[np.ndarray], np.ndarray]:
    ang = np.linspace(0.0, 2 * math.pi, _CYL_SEGMENTS, endpoint=False)
    ring = np.stack([r * np.cos(ang), r * np.sin(ang)], axis=1)
    polys: list[np.ndarray] = []
    normals: list[np.ndarray] = []
    for i in range(_CYL_SEGMENTS):
        j = (i + 1) % _CYL_SEGMENTS
        polys.append(
            np.array(
                [
                    [*ring[i], -half_len],
                    [*ring[j], -half_len],
                    [*ring[j], half_len],
                    [*ring[i], half_len],
                ]
            )
        )
        mid = ang[i] + math.pi / _CYL_SEGMENTS
        normals.append(np.array([math.cos(mid), math.sin(mid), 0.0]))
    for sign in (-1.0, 1.0):
        polys.append(np.column_stack([ring, np.full(_CYL_SEGMENTS, sign * half_len)]))
        normals.append(np.array([0.0, 0.0, sign]))
    return polys, np.array(normals)


def _sphere(r: float) -> tuple[list[np.ndarray], np.ndarray]:
    theta = np.linspace(0.0, math.pi, _SPHERE_RINGS + 1)  # from the +z pole
    phi = np.linspace(0.0, 2 * math.pi, _SPHERE_SEGMENTS + 1)

    def pt(t: float, p: float) -> np.ndarray:
        return r * np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])

    polys, normals = [], []
    for i in range(_SPHERE_RINGS):
        for j in range(_SPHERE_SEGMENTS):
            quad = np.array(
                [
                    pt(theta[i], phi[j]),
                    pt(theta[i + 1], phi[j]),
                    pt(theta[i + 1], phi[j + 1]),
                    pt(theta[i], phi[j + 1]),
                ]
            )
            n = pt((theta[i] + theta[i + 1]) / 2, (phi[j] + phi[j + 1]) / 2) / r
            polys.append(quad)
            normals.append(n)
    return polys, np.array(normals)


def _mesh(filename: str, scale: np.ndarray, urdf_dir: Path) -> tuple[list[np.ndarray], np.ndarray]:
    import trimesh

    name = filename
    for prefix in ("file://", "package://"):
        if name.startswith(prefix):
            name = name[len(prefix) :]
    path = Path(name) if Path(name).is_absolute() else urdf_dir / name
    mesh: Any = trimesh.load(str(path), force="mesh", process=True)
    mesh.apply_scale(scale)
    if not mesh.is_winding_consistent:
        mesh.fix_normals()
    faces = np.asarray(mesh.vertices)[np.asarray(mesh.faces)]
    return list(faces), np.asarray(mesh.face_normals, dtype=float)


def read_link_shapes(urdf: str | Path) -> dict[str, list[tuple[np.ndarray, LinkShape]]]:
    """Every link's geometry: ``link -> [(origin 4x4 in the link frame, shape), ...]``.

    A link's ``<collision>`` elements are used (what the engines simulate); a
    link with none falls back to its ``<visual>`` elements.
    """
    urdf = Path(urdf)
    root = ET.parse(urdf).getroot()
    out: dict[str, list[tuple[np.ndarray, LinkShape]]] = {}
    for link in root.findall("link"):
        name = link.get("name", "")
        elements = link.findall("collision") or link.findall("visual")
        shapes: list[tuple[np.ndarray, LinkShape]] = []
        for el in elements:
            g = el.find("geometry")
            if g is None or len(g) == 0:
                continue
            geom = g[0]
            if geom.tag == "box":
                size = np.array([float(x) for x in geom.get("size", "0 0 0").split()])
                polys, normals = _box(size / 2)
            elif geom.tag == "cylinder":
                polys, normals = _cylinder(
                    float(geom.get("radius", 0)), float(geom.get("length", 0)) / 2
                )
            elif geom.tag == "sphere":
                polys, normals = _sphere(float(geom.get("radius", 0)))
            elif geom.tag == "mesh":
                scale = np.array([float(x) for x in geom.get("scale", "1 1 1").split()])
                polys, normals = _mesh(geom.get("filename", ""), scale, urdf.parent)
            else:  # capsules and other non-standard tags: not drawn
                continue
            outlined = np.zeros(len(polys), dtype=bool)
            if geom.tag == "box":
                outlined[:] = True
            elif geom.tag == "cylinder":
                outlined[-2:] = True
            shapes.append((_origin(el), LinkShape(name, geom.tag, polys, normals, outlined)))
        if shapes:
            out[name] = shapes
    return out


def robot_link_poses(robot: Any, q: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
    """World 4x4 pose of every link of ``robot`` (a :class:`Robot`) at ``q`` (default: home).

    Our FK (:class:`~benchharness.robots.kinematics.KinematicTree`, URDF root frame)
    composed with the robot's configured base pose; no simulator.
    """
    from .kinematics import KinematicTree

    joints = dict(zip(robot.joint_names, (float(v) for v in robot.home())))
    joints.update(q or {})
    base = robot.config.base_pose.as_matrix()
    return {k: base @ t for k, t in KinematicTree(robot.urdf_text).fk(joints).items()}


def link_colours(links: Sequence[str]) -> dict[str, tuple[float, float, float]]:
    """One RGB colour per link: hues stepped by the golden ratio (every link its own hue,
    neighbours far apart), saturation and value alternating for more contrast."""
    golden = (math.sqrt(5) - 1) / 2
    out = {}
    for i, name in enumerate(links):
        h = (0.02 + i * golden) % 1.0
        s = (0.85, 0.65)[i % 2]
        v = (0.95, 0.80, 0.88)[i % 3]
        out[name] = colorsys.hsv_to_rgb(h, s, v)
    return out


# -- drawing ----------------------------------------------------------------------
@dataclass
class _Faces:
    polys: list[np.ndarray]  #: world vertices
    normals: np.ndarray  #: world
    colours: np.ndarray  #: (n, 3) base colours
    outlined: np.ndarray  #: (n,) bool


def _world_faces(
    shapes: Mapping[str, list[tuple[np.ndarray, LinkShape]]],
    poses: Mapping[str, np.ndarray],
    colours: Mapping[str, tuple[float, float, float]],
) -> _Faces:
    polys: list[np.ndarray] = []
    normals: list[np.ndarray] = []
    cols: list[tuple[float, float, float]] = []
    outlined: list[np.ndarray] = []
    for link, items in shapes.items():
        if link not in poses:
            continue
        for origin, shape in items:
            t = poses[link] @ origin
            r, p = t[:3, :3], t[:3, 3]
            polys.extend(v @ r.T + p for v in shape.polygons)
            normals.append(shape.normals @ r.T)
            cols.extend([colours[link]] * len(shape.polygons))
            outlined.append(shape.outlined)
    return _Faces(
        polys,
        np.concatenate(normals) if normals else np.zeros((0, 3)),
        np.array(cols).reshape(-1, 3),
        np.concatenate(outlined) if outlined else np.zeros(0, dtype=bool),
    )


def _draw_view(ax: Any, view: View, faces: _Faces) -> None:
    from matplotlib.collections import PolyCollection

    u, v, d = (np.asarray(a, dtype=float) for a in (view.u, view.v, view.toward))
    facing = faces.normals @ d
    keep = np.flatnonzero(facing > 1e-6)
    depth = np.array([faces.polys[i].mean(axis=0) @ d for i in keep])
    order = keep[np.argsort(depth, kind="stable")]
    # light from the viewer's upper left, so shapes read as solids
    light = d + 0.6 * v - 0.35 * u
    light /= np.linalg.norm(light)
    lambert = np.clip(faces.normals[order] @ light, 0.0, 1.0)
    shade = (0.38 + 0.62 * lambert)[:, None]
    fc = np.clip(faces.colours[order] * shade, 0, 1)
    # box faces and cylinder caps get a darker outline (the shape's edges); facets of round
    # shapes and meshes are edged in their own colour, which only closes antialiasing seams
    ec = np.where(faces.outlined[order][:, None], fc * 0.55, fc)
    verts = [np.column_stack([faces.polys[i] @ u, faces.polys[i] @ v]) for i in order]
    ax.add_collection(PolyCollection(verts, facecolors=fc, edgecolors=ec, linewidths=0.6, zorder=2))


def _frame_limits(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    span = hi - lo
    pad = MARGIN * max(float(span.max()), 0.02)
    return lo - pad, hi + pad


def draw_robot(
    robot: Any,
    path: str | Path,
    *,
    q: Mapping[str, float] | None = None,
    size: tuple[int, int] = (1400, 700),
    frames: bool = False,
    frame_labels: bool = False,
    title: str | None = None,
) -> SketchResult:
    """Draw ``robot`` (a :class:`~benchharness.robots.robot.Robot`) at ``q`` (joint name ->
    value; joints not named stay at home) into the PNG ``path`` of ``size`` pixels.

    ``path``'s folder must exist (the caller checks: nothing is created here).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    path = Path(path)
    shapes = read_link_shapes(robot.urdf_path)
    poses = robot_link_poses(robot, q)
    order = [lk for lk in robot.link_names if lk in shapes]
    colours = link_colours(order)
    faces = _world_faces(shapes, poses, colours)
    if not faces.polys:
        raise ValueError(f"robot {robot.name!r}: its URDF has no geometry to draw")
    allv = np.concatenate(faces.polys)
    bounds = np.stack([allv.min(axis=0), allv.max(axis=0)])
    height = float(bounds[1, 2] - bounds[0, 2])

    width_px, height_px = size
    dpi = 100.0
    fig = Figure(figsize=(width_px / dpi, height_px / dpi), dpi=dpi, facecolor="white")
    FigureCanvasAgg(fig)
    fs = max(7.0, min(width_px, 2 * height_px) / 140)
    fig.suptitle(
        title
        or (
            f"{robot.name}: collision geometry, one colour per link, "
            + (f"home pose except {', '.join(sorted(q))}" if q else "home pose")
            + ("; joint frames x red, y green, z blue" if frames else "")
        ),
        fontsize=fs * 1.25,
        y=0.985,
    )
    # two panels side by side; room for titles, tick labels and axis labels
    left, right, bottom, top, gap = 0.07, 0.985, 0.1, 0.88, 0.08
    pw = (right - left - gap) / 2
    result = SketchResult(path, (width_px, height_px), bounds, order, colours)
    movable = list(robot.joint_names)
    child_of = {j.name: j.child for j in robot.urdf_joints.values()}
    frame_len = float(np.clip(0.05 * (bounds[1] - bounds[0]).max(), 0.01, 0.08))
    for k, view in enumerate(VIEWS):
        ax = fig.add_axes((left + k * (pw + gap), bottom, pw, top - bottom))
        u, v = np.asarray(view.u, float), np.asarray(view.v, float)
        corners = np.array(
            [
                [bounds[i, 0], bounds[j, 1], bounds[m, 2]]
                for i in (0, 1)
                for j in (0, 1)
                for m in (0, 1)
            ]
        )
        pu, pv = corners @ u, corners @ v
        lo, hi = _frame_limits(np.array([pu.min(), pv.min()]), np.array([pu.max(), pv.max()]))
        floor_note = None
        if view.name == "side":
            gap_below = float(bounds[0, 2])
            if 0.0 <= gap_below <= FLOOR_GAP_SHOWN * max(height, 1e-3):
                lo[1] = min(lo[1], -MARGIN * max(float((hi - lo).max()), 0.02))
            elif gap_below > 0:
                floor_note = gap_below
        # equal scale on both axes: widen the limits along the axis with room to spare
        box_w, box_h = pw * width_px, (top - bottom) * height_px
        scale = max((hi[0] - lo[0]) / box_w, (hi[1] - lo[1]) / box_h)  # m per pixel
        mid = (lo + hi) / 2
        half = np.array([box_w, box_h]) * scale / 2
        lo, hi = mid - half, mid + half
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_facecolor("white")
        note = "" if floor_note is None else f"; floor (z = 0) {floor_note:.2f} m below"
        ax.set_title(view.title + note, fontsize=fs * 1.1)
        ax.set_xlabel(view.u_label, fontsize=fs)
        ax.set_ylabel(view.v_label, fontsize=fs)
        ax.tick_params(labelsize=fs * 0.9)
        ax.grid(True, color="0.88", linewidth=0.6, zorder=0)
        ax.set_axisbelow(True)
        big = 100.0
        if view.name == "side":
            ax.axhspan(-big, 0.0, facecolor="0.90", edgecolor="none", zorder=0.5)
            ax.axhline(0.0, color="0.35", linewidth=1.6, zorder=1)
        else:
            ax.add_patch(
                Rectangle(
                    (-big, -big),
                    2 * big,
                    2 * big,
                    facecolor="0.93",
                    edgecolor="none",
                    zorder=0.5,
                    label="floor (z = 0)",
                )
            )
        _draw_view(ax, view, faces)
        if frames:
            result.frames = movable
            for jn in movable:
                t = poses[child_of[jn]]
                o = t[:3, 3]
                ou, ov = o @ u, o @ v
                for axis, colour in enumerate(("#e00000", "#00b000", "#0040ff")):
                    e = o + frame_len * t[:3, axis]
                    ax.plot(
                        [ou, e @ u],
                        [ov, e @ v],
                        color=colour,
                        linewidth=1.3,
                        solid_capstyle="round",
                        zorder=4,
                    )
                ax.plot([ou], [ov], "o", color="black", markersize=2.0, zorder=4.5)
            if frame_labels:
                # joints whose origins fall within a few pixels share one stacked label
                groups: dict[tuple[int, int], list[str]] = {}
                cell = 10 * scale
                for jn in movable:
                    o = poses[child_of[jn]][:3, 3]
                    groups.setdefault((round(o @ u / cell), round(o @ v / cell)), []).append(jn)
                for names in groups.values():
                    o = poses[child_of[names[0]]][:3, 3]
                    ax.annotate(
                        "\n".join(names),
                        (o @ u, o @ v),
                        xytext=(4, -4),
                        textcoords="offset points",
                        ha="left",
                        va="top",
                        fontsize=fs * 0.6,
                        color="0.05",
                        bbox={
                            "boxstyle": "square,pad=0.1",
                            "fc": "white",
                            "ec": "none",
                            "alpha": 0.6,
                        },
                        zorder=6,
                    )
        fig.canvas.draw()
        xl, yl = ax.get_xlim(), ax.get_ylim()
        bbox = ax.get_window_extent()
        result.panels[view.name] = {
            "title": view.title,
            "u_axis": view.u_label,
            "v_axis": view.v_label,
            "limits_m": [list(map(float, xl)), list(map(float, yl))],
            # the panel's data area in image pixels, (left, top, right, bottom) from the top-left corner
            "pixels": [
                float(bbox.x0),
                float(height_px - bbox.y1),
                float(bbox.x1),
                float(height_px - bbox.y0),
            ],
        }
    fig.savefig(str(path), dpi=dpi, format="png", metadata={"Software": None})
    return result
