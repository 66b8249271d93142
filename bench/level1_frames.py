"""Do the dataset's AR tag offsets fix the Level I object frames on the YCB scans? (issue 14)

The relaxed-rigidity results file gives, per task, the palm pose ``H_i`` in the tracked object frame,
the Allegro joint angles of the initial grasp and an "AR tag offset ... from YCB object mesh". If the
tracked frame were the scan's frame moved by that offset (and turned by one of the 24 axis-aligned
rotations: the file gives no rotation), the published grasp put on our hand model would touch the
scan with every used fingertip at the right hypothesis. For each of the 20 distinct initial grasps
this prints the hypothesis (rotation index into scipy's octahedral group, offset convention) whose
largest fingertip gap is smallest, and the runner-up; then, per object, the one hypothesis that fits
its two grasps best (the larger of their two largest gaps). If the data fixed the frame, an object's
two grasps would agree on a hypothesis; with 120 hypotheses and three gaps each, fits of a few
millimetres for one grasp also arise by chance.

    python bench/level1_frames.py
"""

from __future__ import annotations

import csv

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from benchharness.objects import load_object
from benchharness.robots.descriptions.allegro import TIP_R
from benchharness.strategies.ingrasp.hand import HandKinematics
from benchharness.strategies.ingrasp.tasks import distinct_initial_grasps, published_level1_path

#: where the scan's origin lies in the tracked frame, per convention (R: the scan's rotation there)
CONVENTIONS = {
    "none": lambda r, off: np.zeros(3),
    "-off": lambda r, off: -off,
    "+off": lambda r, off: off,
    "-R off": lambda r, off: -r @ off,
    "+R off": lambda r, off: r @ off,
}


def main() -> None:
    with open(published_level1_path(), newline="") as fh:
        offsets = {
            row["task_id"]: np.array([float(row[f"ar_tag_offset_{a}"]) for a in "xyz"])
            for row in csv.DictReader(fh)
        }
    kin = HandKinematics()
    rotations = [r.as_matrix() for r in Rotation.create_group("O")]
    meshes: dict[str, trimesh.Trimesh] = {}
    per_object: dict[str, list[dict[tuple[int, str], float]]] = {}
    print("grasp                          best: gap mm, rotation, offset   runner-up")
    for task in distinct_initial_grasps():
        if task.object not in meshes:
            s = load_object(task.object).surface
            meshes[task.object] = trimesh.Trimesh(np.asarray(s.vertices), np.asarray(s.faces))
        tips = kin.tip_poses_np(task.q0_used, task.hand_fingers)[0, :, :3, 3]  # palm frame
        tracked = (np.linalg.inv(task.initial_matrix) @ np.c_[tips, np.ones(len(tips))].T).T[:, :3]
        off = offsets[task.task_id]
        fits = []
        for i, r in enumerate(rotations):
            for name, origin in CONVENTIONS.items():
                in_scan = (tracked - origin(r, off)) @ r  # r^T (p - origin), row vectors
                gaps = -trimesh.proximity.signed_distance(meshes[task.object], in_scan) - TIP_R
                fits.append((float(np.max(np.abs(gaps))), i, name))
        per_object.setdefault(task.object, []).append({(i, n): g for g, i, n in fits})
        fits.sort()
        (g1, r1, c1), (g2, r2, c2) = fits[0], fits[1]
        print(
            f"{task.task_id:<30s} {1e3 * g1:5.1f}  {r1:2d}  {c1:<7s}   {1e3 * g2:5.1f}  {r2:2d}  {c2}"
        )
    print(
        "\nobject                         one hypothesis for both grasps: larger gap mm, rotation, offset"
    )
    for name, grasps in per_object.items():
        worst, (rot, conv) = min((max(g[k] for g in grasps), k) for k in grasps[0])
        print(f"{name:<30s} {1e3 * worst:5.1f}  {rot:2d}  {conv}")


if __name__ == "__main__":
    main()
