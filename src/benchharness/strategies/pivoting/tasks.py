"""The Level I pivoting task set, derived from the published Level I tasks (``tasks/inhand/level1_pivoting.csv``).

The published Level I tasks are Allegro palm poses; the paper applies the
relative change ``T = H_d H_i^-1`` to each robot's own hand frame. A
parallel gripper can only re-orient an object in its grasp about the grasp
axis, so a pivoting task keeps the **magnitude** of the published task's
re-orientation and realises it about the grasp axis:

* ``pivot = s * angle(R_d R_i^-1)``, with the sign ``s`` of the rotation
  vector's largest component (so the set turns both ways, as the published
  tasks do);
* the initial grasp is the object's own: closing along ``grasp_axis``
  (object frame), the object resting on the table in its most probable
  stable pose that keeps that axis horizontal and the gripper clear of the
  table (column ``rest_pose``: object pose on the table, x y z qx qy qz qw), the fingers coming from above
  tilted by ``-pivot / 2`` about the grasp axis, the tool centre point on the
  object's mid-plane, ``GRASP_DEPTH`` below the top (pads fully on the
  faces); the desired grasp is the initial one turned by ``pivot`` about the
  grasp axis (hand z). The hand position does not change, so ``err_pos%``
  is undefined for these tasks (NaN) and ``err_pos`` measures the grasp
  point's slip.

Objects: those of the published Level I set that the PR2 gripper can pivot
on a table -- two flat parallel faces at most ``MAX_WIDTH`` apart and a rest
face that resists tipping about the grasp axis (``PIVOT_OBJECTS``, with the
reasons for the others in ``docs/pivoting.md``).

Object models: the tasks are hand poses in the object frame, so they belong
to the model they were derived on. ``model="ycb"`` (the default task set
``inhand-level1-pivoting``, ``level1_pivoting.csv``) derives them on the
vendored YCB scans in the published frames; ``model="generated"``
(``inhand-level1-pivoting-generated``) on the shapes generated from the
published dimensions. Each row names its model (column ``model``) and the
strategy simulates and scores that one. The grasp axis is found on the model
itself (:func:`grasp_axis`): the scans' boxes are not aligned with their
frames (the gelatin box scan is turned 13.4 deg about its thin axis).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose

__all__ = [
    "PIVOT_OBJECTS",
    "PivotObject",
    "GRASP_DEPTH",
    "MAX_WIDTH",
    "PIVOT_TASK_FILES",
    "pivot_angle",
    "grasp_axis",
    "initial_grasp",
    "derive_pivot_tasks",
    "write_pivot_tasks",
]


@dataclass(frozen=True)
class PivotObject:
    """How an object is pivoted: which of its oriented bounding box's axes is the grasp (closing)
    axis, by rank of extent (0 thinnest), and on which object models it can be (``why_not``: the
    measured reason for the others)."""

    axis_rank: int
    models: tuple[str, ...] = ("ycb", "generated")
    why_not: str = ""


#: the pivoting objects: the gelatin box across its 28 mm, the Lego Duplo across its 31.7 mm
#: (its 22.6 mm height has the studs on one side); docs/pivoting.md has the reasons for the others
PIVOT_OBJECTS = {
    "gelatin box": PivotObject(0),
    "Lego Duplo": PivotObject(
        1,
        ("generated",),
        "the YCB scan's ends slope (1.8 mm in at 8-12 mm up, 19 mm at the top): it does not stand"
        " on an end, and lying down (24 mm) it is too low for the pads to grip it above the table",
    ),
}
GRASP_DEPTH = (
    0.020  #: m, tool centre point below the object's top: the 36 mm pads' half length + 2 mm
    # (their centre 0.3-0.7 mm behind the tool frame at these objects' 28-32 mm widths, so the
    # pads' upper ends sit 1.3-1.7 mm below the top)
)
MAX_WIDTH = 0.080  #: m, PR2 gripper opening (90 mm) less 5 mm each side
#: object model -> task file under ``tasks/inhand``
PIVOT_TASK_FILES = {"ycb": "level1_pivoting.csv", "generated": "level1_pivoting_generated.csv"}
#: faces within this angle of the grasp axis count as the flat faces the pads press
FLAT_FACE_DEG = 10.0


def pivot_angle(initial_q, desired_q) -> float:
    """Signed magnitude (rad) of the published relative rotation ``R_d R_i^-1`` (see module docstring)."""
    rv = (
        Rotation.from_quat(np.asarray(desired_q, float))
        * Rotation.from_quat(np.asarray(initial_q, float)).inv()
    ).as_rotvec()
    ang = float(np.linalg.norm(rv))
    return ang if ang == 0.0 else ang * float(np.sign(rv[int(np.argmax(np.abs(rv)))]))


def _model(obj: str, model: str):
    from ...objects import load_object

    return load_object(obj, model=model)


def _find(obj: str) -> str | None:
    """The ``PIVOT_OBJECTS`` key of ``obj`` (any case and spacing), or None."""
    keys = {" ".join(k.lower().split()): k for k in PIVOT_OBJECTS}
    return keys.get(" ".join(str(obj).lower().split()))


def _key(obj: str) -> str:
    k = _find(obj)
    if k is None:
        raise ValueError(f"{obj!r} is not a pivoting object (use one of {sorted(PIVOT_OBJECTS)})")
    return k


@functools.lru_cache(maxsize=16)
def _box(obj: str, model: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(grasp axis, grasp centre) of ``obj``'s ``model`` in its object frame, rounded (see
    :func:`grasp_axis`): the centre is the oriented bounding box's, on the mid-plane between the
    object's extremes along the grasp axis (where symmetric fingers centre it)."""
    import trimesh

    spec = PIVOT_OBJECTS[_key(obj)]
    if model not in spec.models:
        raise ValueError(f"{obj!r} cannot be pivoted on its {model!r} model: {spec.why_not}")
    surface = _model(obj, model).surface
    to_box, extents = trimesh.bounds.oriented_bounds(surface)
    box = np.linalg.inv(to_box)
    axis = box[:3, int(np.argsort(extents)[spec.axis_rank])]
    n, area = np.asarray(surface.face_normals), np.asarray(surface.area_faces)
    sides = n @ axis
    flat = np.abs(sides) > math.cos(math.radians(FLAT_FACE_DEG))
    a = (n[flat] * (np.sign(sides[flat]) * area[flat])[:, None]).sum(axis=0)
    a = a / np.linalg.norm(a)
    a = a * np.sign(a[int(np.argmax(np.abs(a)))])
    a = np.round(a, 4) + 0.0
    a = a / np.linalg.norm(a)
    # the box's centre, moved along the grasp axis onto the mid-plane of the object's extremes
    s = np.asarray(surface.vertices) @ a
    centre = box[:3, 3] + ((s.max() + s.min()) / 2 - box[:3, 3] @ a) * a
    return tuple(a), tuple(np.round(centre, 7) + 0.0)


def grasp_axis(obj: str, model: str = "ycb") -> np.ndarray:
    """The grasp (closing) axis of ``obj`` on ``model``, object frame: the area-weighted mean normal of
    the flat faces (within ``FLAT_FACE_DEG``) across the oriented-bounding-box axis that
    ``PIVOT_OBJECTS`` names, signed so that its largest component is positive and rounded to 1e-4
    so that the derived tasks do not depend on the last bits of the CPU's arithmetic."""
    return np.array(_box(obj, model)[0])


def rest_pose(obj: str, grasp_axis, pivot: float = 0.0, model: str = "ycb") -> Pose:
    """The most probable stable rest pose on the table that keeps ``grasp_axis`` horizontal
    and leaves the gripper clear of the table at both ends of a pivot of ``pivot`` rad."""
    from .config import MotionConfig
    from .rig import clearance, stable_rest_poses

    m = _model(obj, model)
    rests = stable_rest_poses(m.surface, m.mass.com, grasp_axis)
    width = float(
        np.ptp(
            np.asarray(m.surface.vertices)
            @ (np.asarray(grasp_axis, float) / np.linalg.norm(grasp_axis))
        )
    )
    for rest in rests:
        hi = initial_grasp(obj, grasp_axis, pivot, rest, model)
        hd = hi * Pose.from_rotation(np.zeros(3), Rotation.from_rotvec([0.0, 0.0, pivot]))
        if (
            min(clearance(rest * h, width + 0.03, 0.0, width) for h in (hi, hd))
            >= MotionConfig().min_clearance
        ):
            return rest
    raise ValueError(
        f"{obj}: no stable rest pose keeps the grasp axis {grasp_axis} horizontal with the gripper clear of the table"
    )


def initial_grasp(
    obj: str, grasp_axis, pivot: float, rest: Pose | None = None, model: str = "ycb"
) -> Pose:
    """Hand pose (object frame) of the initial grasp for a pivot of ``pivot`` rad (see module docstring)."""
    m = _model(obj, model)
    a = np.asarray(grasp_axis, float) / np.linalg.norm(grasp_axis)
    rest = rest_pose(obj, a, pivot, model) if rest is None else rest
    verts = rest.apply(np.asarray(m.surface.vertices))
    top = float(verts[:, 2].max())
    width = float(np.ptp(np.asarray(m.surface.vertices) @ a))
    if width > MAX_WIDTH:
        raise ValueError(
            f"{obj}: {width * 1e3:.0f} mm across the grasp axis, more than the {MAX_WIDTH * 1e3:.0f} mm allowed"
        )
    centre = rest.apply(np.array(_box(obj, model)[1]))  # on the mid-plane, see _box
    z = rest.rotation.apply(a)  # closing direction: horizontal, or within 5 deg on a scan
    down = np.array([0.0, 0.0, -1.0]) + z[2] * z  # straight down, square to the grasp axis
    down /= np.linalg.norm(down)
    x = Rotation.from_rotvec(z * (-pivot / 2)).apply(down)  # fingers tilted by -pivot/2
    y = np.cross(z, x)
    # from the centre up (square to the axis, so staying on the mid-plane) to GRASP_DEPTH below the top
    tcp = centre + (top - GRASP_DEPTH - centre[2]) / down[2] * down
    hand_world = Pose.from_rotation(tcp, Rotation.from_matrix(np.column_stack([x, y, z])))
    return rest.inv() * hand_world


def derive_pivot_tasks(level1_path: str | Path | None = None, model: str = "ycb"):
    """The pivoting :class:`~benchharness.inhand.records.TaskSet` on ``model`` from the published Level I file."""
    from ...inhand.fileformat import read_tasks
    from ...inhand.records import TaskSet
    from ...paths import tasks_dir

    if model not in PIVOT_TASK_FILES:
        raise ValueError(f"model must be one of {sorted(PIVOT_TASK_FILES)}, not {model!r}")
    src = read_tasks(
        Path(level1_path) if level1_path else tasks_dir() / "inhand" / "level1_hand_poses.csv"
    )
    rows = []
    for i in range(len(src)):
        obj = str(src.object[i])
        k = _find(obj)
        if k is None or model not in PIVOT_OBJECTS[k].models or int(src.level[i]) != 1:
            continue
        pivot = pivot_angle(src.initial[i, 3:], src.desired[i, 3:])
        axis = grasp_axis(obj, model)
        rest = rest_pose(obj, axis, pivot, model)
        hi = initial_grasp(obj, axis, pivot, rest, model)
        hd = hi * Pose.from_rotation(np.zeros(3), Rotation.from_rotvec([0.0, 0.0, pivot]))
        rows.append(
            (
                f"{src.task_id[i]}-pivot",
                obj,
                hi.as_array(),
                hd.as_array(),
                str(src.task_id[i]),
                pivot,
                axis,
                rest,
            )
        )
    n = len(rows)
    return TaskSet(
        task_id=np.array([r[0] for r in rows], dtype=object),
        object=np.array([r[1] for r in rows], dtype=object),
        level=np.ones(n, dtype=int),
        initial=np.array([r[2] for r in rows], float),
        desired=np.array([r[3] for r in rows], float),
        extra={
            "source_task": np.array([r[4] for r in rows], dtype=object),
            "pivot_deg": np.array([f"{math.degrees(r[5]):.4f}" for r in rows], dtype=object),
            "grasp_axis": np.array([" ".join(f"{v:g}" for v in r[6]) for r in rows], dtype=object),
            "rest_pose": np.array(
                [" ".join(f"{v:.6g}" for v in np.round(r[7].as_array(), 9) + 0.0) for r in rows],
                dtype=object,
            ),
            "model": np.array([model] * n, dtype=object),
            "set": np.array(["pivoting-level1"] * n, dtype=object),
        },
    )


def write_pivot_tasks(path: str | Path | None = None, model: str = "ycb") -> Path:
    """Write the task set derived on ``model`` (default ``tasks/inhand/`` + ``PIVOT_TASK_FILES[model]``)."""
    from ...inhand.fileformat import write_tasks
    from ...paths import tasks_dir

    path = Path(path) if path else tasks_dir() / "inhand" / PIVOT_TASK_FILES[model]
    write_tasks(derive_pivot_tasks(model=model), path)
    return path


if __name__ == "__main__":  # python -m benchharness.strategies.pivoting.tasks
    for _kind in PIVOT_TASK_FILES:
        print(write_pivot_tasks(model=_kind))
