"""Built-in in-hand manipulation task sets (converted from the authors' published data).

Each task set is one registration whose factory reads the committed CSV
under ``tasks/inhand/`` into a :class:`benchharness.inhand.records.TaskSet`.
Reading is deferred to the factory so listing plugins stays cheap.
"""

from __future__ import annotations

from functools import partial

from benchharness.paths import tasks_dir
from benchharness.plugin import Registration, hookimpl

#: name -> (file under tasks/inhand, summary)
TASK_SETS = {
    "inhand-level1": (
        "level1_hand_poses.csv",
        "In-hand Level I: desired palm pose changes on 10 YCB objects (published hand_poses.ods)",
    ),
    "inhand-level3-dmg-hand-poses": (
        "level3_dmg_hand_poses.csv",
        "In-hand Level III: the 4 DMG tasks' hand poses as listed in hand_poses.ods (no contacts)",
    ),
    "inhand-level3-dmg": (
        "level3_dmg_tasks.csv",
        "In-hand Level III: contact + pose tasks for a parallel gripper (published DMG.ods)",
    ),
    "inhand-level1-pivoting": (
        "level1_pivoting.csv",
        "In-hand Level I for a parallel gripper: published re-orientations as pivots about the grasp axis (YCB scans)",
    ),
    "inhand-level1-pivoting-generated": (
        "level1_pivoting_generated.csv",
        "In-hand Level I pivots on the shapes generated from the published dimensions",
    ),
    "inhand-level2-dmg-regions": (
        "level2_dmg_regions.csv",
        "In-hand Level II: desired contact regions only (5 mm discs at the published DMG desired contacts)",
    ),
}


def _load(filename: str, **_: object):
    from benchharness.inhand.fileformat import read_tasks

    return read_tasks(tasks_dir() / "inhand" / filename)


@hookimpl
def benchharness_tasks() -> list[Registration]:
    return [
        Registration(
            name,
            partial(_load, filename),
            summary,
            meta={"benchmark": "inhand", "file": f"tasks/inhand/{filename}"},
        )
        for name, (filename, summary) in TASK_SETS.items()
    ]
