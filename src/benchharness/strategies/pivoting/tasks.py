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
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ...geometry import Pose

__all__ = [
    "PIVOT_OBJECTS",
    "GRASP_DEPTH",
    "MAX_WIDTH",
    "pivot_angle",
    "initial_grasp",
    "derive_pivot_tasks",
    "write_pivot_tasks",
    "PIVOT_TASK_FILE",
]

#: object -> grasp (closing) axis in our object frame, chosen across two flat parallel faces
PIVOT_OBJECTS = {"gelatin box": (1.0, 0.0, 0.0), "Lego Duplo": (0.0, 1.0, 0.0)}
GRASP_DEPTH = (
    0.020  #: m, tool centre point below the object's top: the 36 mm pads' half length + 2 mm
    # (their centre 0.3-0.7 mm behind the tool frame at these objects' 28-32 mm widths, so the
    # pads' upper ends sit 1.3-1.7 mm below the top)
)
MAX_WIDTH = 0.080  #: m, PR2 gripper opening (90 mm) less 5 mm each side
PIVOT_TASK_FILE = "level1_pivoting.csv"


def pivot_angle(initial_q, desired_q) -> float:
    """Signed magnitude (rad) of the published relative rotation ``R_d R_i^-1`` (see module docstring)."""
    rv = (
        Rotation.from_quat(np.asarray(desired_q, float))
        * Rotation.from_quat(np.asarray(initial_q, float)).inv()
    ).as_rotvec()
    ang = float(np.linalg.norm(rv))
    return ang if ang == 0.0 else ang * float(np.sign(rv[int(np.argmax(np.abs(rv)))]))


def rest_pose(obj: str, grasp_axis, pivot: float = 0.0) -> Pose:
    """The most probable stable rest pose on the table that keeps ``grasp_axis`` horizontal
    and leaves the gripper clear of the table at both ends of a pivot of ``pivot`` rad."""
    from ...objects import load_object
    from .config import MotionConfig
    from .rig import clearance, stable_rest_poses

    model = load_object(
        obj, model="generated"
    )  # the pivoting tasks are defined on the generated frames
    rests = stable_rest_poses(model.surface, model.mass.com, grasp_axis)
    width = float(
        np.ptp(
            np.asarray(model.surface.vertices)
            @ (np.asarray(grasp_axis, float) / np.linalg.norm(grasp_axis))
        )
    )
    for rest in rests:
        hi = initial_grasp(obj, grasp_axis, pivot, rest)
        hd = hi * Pose.from_rotation(np.zeros(3), Rotation.from_rotvec([0.0, 0.0, pivot]))
        if (
            min(clearance(rest * h, width + 0.03, 0.0, width) for h in (hi, hd))
            >= MotionConfig().min_clearance
        ):
            return rest
    raise ValueError(
        f"{obj}: no stable rest pose keeps the grasp axis {grasp_axis} horizontal with the gripper clear of the table"
    )


def initial_grasp(obj: str, grasp_axis, pivot: float, rest: Pose | None = None) -> Pose:
    """Hand pose (object frame) of the initial grasp for a pivot of ``pivot`` rad (see module docstring)."""
    from ...objects import load_object

    model = load_object(
        obj, model="generated"
    )  # the pivoting tasks are defined on the generated frames
    a = np.asarray(grasp_axis, float) / np.linalg.norm(grasp_axis)
    rest = rest_pose(obj, a, pivot) if rest is None else rest
    verts = rest.apply(np.asarray(model.surface.vertices))
    top = float(verts[:, 2].max())
    width = float(np.ptp(np.asarray(model.surface.vertices) @ a))
    if width > MAX_WIDTH:
        raise ValueError(
            f"{obj}: {width * 1e3:.0f} mm across the grasp axis, more than the {MAX_WIDTH * 1e3:.0f} mm allowed"
        )
    centre = rest.p  # the object frame's origin (bounding-box centre) in the world
    z = rest.rotation.apply(a)  # closing direction, horizontal
    x = np.array([0.0, 0.0, -1.0])  # fingers pointing down ...
    x = Rotation.from_rotvec(z * (-pivot / 2)).apply(
        x
    )  # ... tilted by -pivot/2 about the grasp axis
    y = np.cross(z, x)
    tcp = np.array([centre[0], centre[1], top - GRASP_DEPTH])
    hand_world = Pose.from_rotation(tcp, Rotation.from_matrix(np.column_stack([x, y, z])))
    return rest.inv() * hand_world


def derive_pivot_tasks(level1_path: str | Path | None = None):
    """The pivoting :class:`~benchharness.inhand.records.TaskSet` from the published Level I file."""
    from ...inhand.fileformat import read_tasks
    from ...inhand.records import TaskSet
    from ...paths import tasks_dir

    src = read_tasks(
        Path(level1_path) if level1_path else tasks_dir() / "inhand" / "level1_hand_poses.csv"
    )
    keys = {" ".join(k.lower().split()): k for k in PIVOT_OBJECTS}
    rows = []
    for i in range(len(src)):
        obj = str(src.object[i])
        k = keys.get(" ".join(obj.lower().split()))
        if k is None or int(src.level[i]) != 1:
            continue
        pivot = pivot_angle(src.initial[i, 3:], src.desired[i, 3:])
        axis = PIVOT_OBJECTS[k]
        rest = rest_pose(obj, axis, pivot)
        hi = initial_grasp(obj, axis, pivot, rest)
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
            "set": np.array(["pivoting-level1"] * n, dtype=object),
        },
    )


def write_pivot_tasks(path: str | Path | None = None) -> Path:
    """Write the derived task set (default ``tasks/inhand/level1_pivoting.csv``)."""
    from ...inhand.fileformat import write_tasks
    from ...paths import tasks_dir

    path = Path(path) if path else tasks_dir() / "inhand" / PIVOT_TASK_FILE
    write_tasks(derive_pivot_tasks(), path)
    return path


if __name__ == "__main__":  # python -m benchharness.strategies.pivoting.tasks
    print(write_pivot_tasks())
