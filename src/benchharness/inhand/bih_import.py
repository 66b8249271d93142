"""Convert the published in-hand benchmark dataset into benchharness files.

Source: the dataset repository of Cruciani, Sundaralingam et al.,
"Benchmarking In-Hand Manipulation" (three ``.ods`` spreadsheets, see
``tasks/inhand/README.md``). Outputs, all CSV in the formats of
:mod:`benchharness.inhand.fileformat`:

``level1_hand_poses.csv``
    ``dataset/hand_poses.ods``: the 100 Level I palm-pose tasks (10 objects
    x 2 initial x 5 desired grasps), ``set = allegro-level1``.
``level3_dmg_hand_poses.csv``
    The 4 other rows of ``hand_poses.ods`` -- gelatin box, spatula, potted
    meat can, cracker box -- which are the hand poses of the YuMi/DMG Level
    III tasks (gripper pose = fingertip midpoint), with ``set =
    dmg-level3`` and a note naming the DMG task. A Level III set of their
    own, so that ``level1_hand_poses.csv`` holds exactly the Level I tasks.
``level3_dmg_tasks.csv``
    The four DMG tasks of ``results/yumi_lvl_3/DMG.ods`` as Level III tasks:
    hand poses (fingertip midpoint + given quaternion) and contact points.
``published/allegro_lvl1_relaxed_rigidity.csv``
    ``results/allegro_lvl_1/relaxed-rigidity-dataset.ods`` as a results file
    (one trial per task), keeping the AR tag offset, initial grasp joint
    configuration and fingers used as extra columns.
``published/yumi_lvl3_dmg.csv``
    ``results/yumi_lvl_3/DMG.ods`` as a results file with contact columns.

(``published/`` and not ``results/``: the repository ignores ``results/``.)

Conventions: RPY palm poses are extrinsic xyz (``pose_from_xyz_rpy``);
quaternions from DMG.ods are copied **unnormalised** because eq. 3 is
evaluated on them as published (see :mod:`benchharness.metrics.pose`).
Output is deterministic: rows in sheet order, numbers through
:func:`~benchharness.inhand.fileformat.format_number`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..geometry import pose_from_xyz_rpy
from .fileformat import write_results, write_tasks
from .ods import read_ods
from .records import ResultSet, TaskSet

__all__ = ["BihImportError", "ImportReport", "convert_bih", "default_source", "OUTPUT_FILES"]

HAND_POSES = Path("dataset/hand_poses.ods")
ALLEGRO = Path("results/allegro_lvl_1/relaxed-rigidity-dataset.ods")
DMG = Path("results/yumi_lvl_3/DMG.ods")

OUTPUT_FILES = (
    "level1_hand_poses.csv",
    "level3_dmg_hand_poses.csv",
    "level3_dmg_tasks.csv",
    "published/allegro_lvl1_relaxed_rigidity.csv",
    "published/yumi_lvl3_dmg.csv",
)

ALLEGRO_JOINTS = tuple(f"{f}_j{j}" for f in ("index", "middle", "ring", "thumb") for j in range(4))

#: hand_poses.ods rows that are DMG task hand poses: (object, DMG task number).
_DMG_ROWS_NOTE = (
    "hand poses of YuMi DMG task {task} (task_id {dmg_id} in level3_dmg_tasks.csv): "
    "gripper position = fingertip midpoint; not an Allegro Level I task"
)


class BihImportError(ValueError):
    """The source spreadsheets are not what the converter expects."""


@dataclass(frozen=True)
class ImportReport:
    source: Path
    out: Path
    files: tuple[Path, ...]
    counts: dict[str, int]


def default_source() -> Path:
    """``../shared/data/bih_dataset`` relative to the repository root."""
    from ..paths import data_root

    return (data_root() / ".." / "shared" / "data" / "bih_dataset").resolve()


def slug(name: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", name.strip().lower()).strip("_")


def _numbers(text: str, n: int, where: str) -> np.ndarray:
    parts = [p for p in text.replace(" ", "").split(",") if p != ""]
    if len(parts) != n:
        raise BihImportError(f"{where}: expected {n} comma-separated numbers, got {text!r}")
    try:
        return np.array([float(p) for p in parts])
    except ValueError:
        raise BihImportError(f"{where}: not numbers: {text!r}") from None


def _sheet(path: Path, header0: str, width: int) -> list[list[str]]:
    if not path.is_file():
        raise BihImportError(f"missing source file {path}")
    sheets = read_ods(path)
    if len(sheets) != 1:
        raise BihImportError(f"{path}: expected one sheet, found {list(sheets)}")
    rows = next(iter(sheets.values()))
    if not rows or rows[0][0].strip() != header0:
        raise BihImportError(f"{path}: unexpected header {rows[:1]}")
    body = rows[1:]
    for i, r in enumerate(body):
        if len(r) != width:
            raise BihImportError(f"{path}: data row {i + 1} has {len(r)} cells, expected {width}")
    return body


def _xyz_rpy(text: str, where: str) -> np.ndarray:
    return pose_from_xyz_rpy(_numbers(text, 6, where)).as_array()


def _dmg_rows(source: Path):
    """Parse DMG.ods: per task the contacts and raw quaternions."""
    path = source / DMG
    out = []
    for i, r in enumerate(_sheet(path, "Object", 11)):
        w = f"{path} row {i + 2}"
        c = {
            k: _numbers(r[j], 3, f"{w} col {j + 1}")
            for k, j in (("i1", 2), ("i2", 3), ("d1", 5), ("d2", 6), ("r1", 8), ("r2", 9))
        }
        q = {k: _numbers(r[j], 4, f"{w} col {j + 1}") for k, j in (("i", 4), ("d", 7), ("r", 10))}
        task = str(int(float(r[1])))
        out.append(dict(object=r[0].strip(), task=task, source_row=i + 2, contacts=c, quats=q))
    return out


def _midpoint_pose(a: np.ndarray, b: np.ndarray, q: np.ndarray) -> np.ndarray:
    # A parallel gripper's hand position is the midpoint of its two
    # fingertip contacts (paper IV-B1); the quaternion is kept as published.
    return np.concatenate([(a + b) / 2.0, q])


def _hand_pose_tasks(source: Path, dmg) -> TaskSet:
    path = source / HAND_POSES
    body = _sheet(path, "Object", 3)
    dmg_by_object = {d["object"]: d for d in dmg}
    ids, objs, levels, ini, des, sets, rows, notes = [], [], [], [], [], [], [], []
    counter: dict[str, int] = {}
    for i, r in enumerate(body):
        obj = r[0].strip()
        counter[obj] = counter.get(obj, 0) + 1
        tid = f"{slug(obj)}-{counter[obj]:02d}"
        w = f"{path} row {i + 2}"
        ip, dp = _xyz_rpy(r[1], w + " col 2"), _xyz_rpy(r[2], w + " col 3")
        d = dmg_by_object.get(obj)
        is_dmg = False
        if d is not None:
            mid_i = (d["contacts"]["i1"] + d["contacts"]["i2"]) / 2
            mid_d = (d["contacts"]["d1"] + d["contacts"]["d2"]) / 2
            # Match on the position that is right in both files (desired);
            # the spatula row's initial y has the opposite sign of DMG.ods.
            is_dmg = bool(np.allclose(dp[:3], mid_d, atol=1e-6))
        note = ""
        if is_dmg:
            dmg_id = f"{slug(obj)}-dmg{d['task']}"
            note = _DMG_ROWS_NOTE.format(task=d["task"], dmg_id=dmg_id)
            if not np.allclose(ip[:3], mid_i, atol=1e-6):
                note += "; initial position differs from DMG.ods fingertip midpoint " + ",".join(
                    format(float(x), ".6g") for x in mid_i
                )
        ids.append(tid)
        objs.append(obj)
        levels.append(3 if is_dmg else 1)
        ini.append(ip)
        des.append(dp)
        sets.append("dmg-level3" if is_dmg else "allegro-level1")
        rows.append(str(i + 2))
        notes.append(note)
    return TaskSet(
        task_id=np.array(ids, dtype=object),
        object=np.array(objs, dtype=object),
        level=np.array(levels),
        initial=np.array(ini),
        desired=np.array(des),
        extra={
            "set": np.array(sets, dtype=object),
            "source_row": np.array(rows, dtype=object),
            "note": np.array(notes, dtype=object),
        },
    )


def _dmg_tasks(dmg) -> TaskSet:
    n = len(dmg)
    contacts = {s: np.zeros((n, 2, 3)) for s in ("initial", "desired")}
    ini, des = [], []
    for k, d in enumerate(dmg):
        c, q = d["contacts"], d["quats"]
        ini.append(_midpoint_pose(c["i1"], c["i2"], q["i"]))
        des.append(_midpoint_pose(c["d1"], c["d2"], q["d"]))
        contacts["initial"][k] = [c["i1"], c["i2"]]
        contacts["desired"][k] = [c["d1"], c["d2"]]
    return TaskSet(
        task_id=np.array([f"{slug(d['object'])}-dmg{d['task']}" for d in dmg], dtype=object),
        object=np.array([d["object"] for d in dmg], dtype=object),
        level=np.full(n, 3),
        initial=np.array(ini),
        desired=np.array(des),
        contacts=contacts,
        extra={
            "dmg_task": np.array([d["task"] for d in dmg], dtype=object),
            "source_row": np.array([str(d["source_row"]) for d in dmg], dtype=object),
        },
    )


def _dmg_results(dmg) -> ResultSet:
    n = len(dmg)
    tasks = _dmg_tasks(dmg)
    contacts = dict(tasks.contacts)
    contacts["reached"] = np.array([[d["contacts"]["r1"], d["contacts"]["r2"]] for d in dmg])
    reached = np.array(
        [_midpoint_pose(d["contacts"]["r1"], d["contacts"]["r2"], d["quats"]["r"]) for d in dmg]
    )
    blank = ResultSet.empty_like_columns(n)
    return ResultSet(
        method=np.full(n, "DMG", dtype=object),
        object=tasks.object,
        task_id=tasks.task_id,
        trial=np.ones(n, dtype=int),
        level=tasks.level,
        dropped=np.zeros(n, dtype=bool),
        initial=tasks.initial,
        desired=tasks.desired,
        reached=reached,
        setup=blank["setup"],
        plan_time_s=blank["plan_time_s"],
        exec_time_s=blank["exec_time_s"],
        contacts=contacts,
        extra={"robot": np.full(n, "yumi", dtype=object), **tasks.extra},
    )


def _allegro_results(source: Path, hand_tasks: TaskSet) -> ResultSet:
    path = source / ALLEGRO
    body = _sheet(path, "Object", 7)
    hp_rows = _sheet(source / HAND_POSES, "Object", 3)
    lookup = {
        (r[0].strip(), r[1].strip(), r[2].strip()): hand_tasks.task_id[i]
        for i, r in enumerate(hp_rows)
    }
    n = len(body)
    ini, des, rea, ids = [], [], [], []
    extra: dict[str, list[str]] = {
        "robot": [],
        "ar_tag_offset_x": [],
        "ar_tag_offset_y": [],
        "ar_tag_offset_z": [],
    }
    extra.update({f"grasp_{j}": [] for j in ALLEGRO_JOINTS})
    extra.update({"fingers": [], "source_row": []})
    for i, r in enumerate(body):
        w = f"{path} row {i + 2}"
        obj = r[0].strip()
        _numbers(r[1], 3, w + " col 2")  # validate: x,y,z
        _numbers(r[2], 16, w + " col 3")  # validate: 16 joint angles
        fingers = [int(x) for x in _numbers(r[3], len(r[3].split(",")), w + " col 4")]
        ini.append(_xyz_rpy(r[4], w + " col 5"))
        des.append(_xyz_rpy(r[5], w + " col 6"))
        rea.append(_xyz_rpy(r[6], w + " col 7"))
        key = (obj, r[4].strip(), r[5].strip())
        if key not in lookup:
            raise BihImportError(f"{w}: initial/desired palm poses match no row of {HAND_POSES}")
        ids.append(lookup[key])
        extra["robot"].append("allegro")
        # Offsets and joints are copied as published text, not re-formatted.
        for a, v in zip("xyz", r[1].split(",")):
            extra[f"ar_tag_offset_{a}"].append(v.strip())
        for j, v in zip(ALLEGRO_JOINTS, r[2].split(",")):
            extra[f"grasp_{j}"].append(v.strip())
        extra["fingers"].append(";".join(str(f) for f in fingers))
        extra["source_row"].append(str(i + 2))
    blank = ResultSet.empty_like_columns(n)
    return ResultSet(
        method=np.full(n, "relaxed-rigidity", dtype=object),
        object=np.array([r[0].strip() for r in body], dtype=object),
        task_id=np.array(ids, dtype=object),
        trial=np.ones(n, dtype=int),
        level=np.ones(n, dtype=int),
        dropped=np.zeros(n, dtype=bool),
        initial=np.array(ini),
        desired=np.array(des),
        reached=np.array(rea),
        setup=blank["setup"],
        plan_time_s=blank["plan_time_s"],
        exec_time_s=blank["exec_time_s"],
        extra={k: np.array(v, dtype=object) for k, v in extra.items()},
    )


def _rows(ts: TaskSet, keep: np.ndarray) -> TaskSet:
    """The rows ``keep`` (a boolean mask) of a contact-free hand-pose task set."""
    return TaskSet(
        task_id=ts.task_id[keep],
        object=ts.object[keep],
        level=ts.level[keep],
        initial=ts.initial[keep],
        desired=ts.desired[keep],
        extra={k: v[keep] for k, v in ts.extra.items()},
    )


def convert_bih(source: str | Path | None = None, out: str | Path | None = None) -> ImportReport:
    """Convert the dataset at ``source`` into the five files under ``out``."""
    from ..paths import tasks_dir

    source = Path(source) if source is not None else default_source()
    out = Path(out) if out is not None else tasks_dir() / "inhand"
    if not source.is_dir():
        raise BihImportError(f"source folder {source} does not exist")
    dmg = _dmg_rows(source)
    hand = _hand_pose_tasks(source, dmg)
    dmg_tasks = _dmg_tasks(dmg)
    allegro = _allegro_results(source, hand)
    dmg_res = _dmg_results(dmg)
    paths = [out / f for f in OUTPUT_FILES]
    write_tasks(_rows(hand, hand.level == 1), paths[0])
    write_tasks(_rows(hand, hand.level == 3), paths[1])
    write_tasks(dmg_tasks, paths[2])
    write_results(allegro, paths[3])
    write_results(dmg_res, paths[4])
    counts = {
        "level1_tasks": int(np.sum(hand.level == 1)),
        "dmg_hand_pose_rows": int(np.sum(hand.level == 3)),
        "dmg_tasks": len(dmg_tasks),
        "allegro_trials": len(allegro),
        "dmg_trials": len(dmg_res),
    }
    return ImportReport(source, out, tuple(paths), counts)
