"""Contact regions on our meshes: the Level II task set and the contact-region errors of stored trials.

This is scoring, not planning, so it lives in the runner beside the pose
scoring (:mod:`.scoring`) and the CLI reaches it without importing a
strategy. What it borrows from the DMG package is object data only: the
placement of our mesh in the published task frame
(:mod:`benchharness.strategies.dmg.placement`), the contacts put on the
surface along the closing line (:func:`~benchharness.strategies.dmg.planner.surface_contacts`)
and the two radii below, which the DMG's results files use as well.

**Level II tasks** (``tasks/inhand/level2_dmg_regions.csv``, task set
``inhand-level2-dmg-regions``): the paper's Level II gives the desired
contact region ``C_d`` only. We derive it from the four published DMG tasks:
same initial grasp (pose and contacts), no desired hand pose (empty
columns, level 2), and ``C_d`` = the union of two geodesic discs of radius
``region_radius`` (:data:`~benchharness.strategies.dmg.strategy.DESIRED_REGION_RADIUS`, 5 mm: about half a
finger pad) on our mesh, centred where the published desired contacts fall
on our surface along the line through them (the fingers' closing line). The
disc centres are kept as ``desired_contact1/2`` so the file stays readable
without meshes; the region is rebuilt on the mesh by :func:`desired_region`.

**Contact-region errors** (:func:`contact_errors`): Algorithm 1
(:func:`benchharness.metrics.contact.contact_region_error`) between ``C_d``
and the two finger pads as they touched the object at the end of the trial
(5 mm geodesic discs around the measured contact points,
:data:`~benchharness.strategies.dmg.strategy.FINGER_PAD_RADIUS`), on our mesh placed in the task frame --
the same construction :func:`~benchharness.strategies.dmg.strategy.results_for_grasps` uses for planned
grasps, so planned and executed figures compare. The runner scores poses
only; :func:`score_store` (``benchharness inhand regions``) and
:func:`stored_contact_scorer` (the Table III columns of ``benchharness table``)
add G_euc / G_geo / G_min to stored trials.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ..metrics.contact import GeodesicMethod

__all__ = [
    "REGION_TASK_FILE",
    "derive_region_tasks",
    "write_region_tasks",
    "desired_region",
    "contact_errors",
    "score_store",
    "stored_contact_scorer",
]

REGION_TASK_FILE = "level2_dmg_regions.csv"


def derive_region_tasks(level3_path: str | Path | None = None):
    """The Level II :class:`~benchharness.inhand.records.TaskSet` from the published DMG tasks."""
    from ..inhand.fileformat import read_tasks
    from ..inhand.records import TaskSet
    from ..paths import tasks_dir
    from ..strategies.dmg.strategy import DESIRED_REGION_RADIUS

    src = read_tasks(
        Path(level3_path) if level3_path else tasks_dir() / "inhand" / "level3_dmg_tasks.csv"
    )
    n = len(src)
    return TaskSet(
        task_id=np.array([f"{t}-region" for t in src.task_id], dtype=object),
        object=src.object.copy(),
        level=np.full(n, 2),
        initial=src.initial.copy(),
        desired=np.full((n, 7), np.nan),
        contacts={k: v[:, :2].copy() for k, v in src.contacts.items()},
        extra={
            "source_task": np.array([str(t) for t in src.task_id], dtype=object),
            "region_radius": np.array([f"{DESIRED_REGION_RADIUS:g}"] * n, dtype=object),
            "set": np.array(["dmg-level2-regions"] * n, dtype=object),
        },
    )


def write_region_tasks(path: str | Path) -> Path:
    """Write the Level II task file to ``path`` (no default: the tracked file is rewritten only when named)."""
    from ..inhand.fileformat import write_tasks

    path = Path(path)
    write_tasks(derive_region_tasks(), path)
    return path


def planner_for_outcome(outcome: dict[str, Any]):
    """A DMG planner on the object model a stored trial ran on (``extra.dmg_surface``; before that
    field existed every DMG trial ran on the generated model)."""
    from ..strategies.dmg.config import DMGSurface
    from ..strategies.dmg.strategy import DMGPlanner

    model = (outcome.get("extra") or {}).get("dmg_surface", "generated")
    return DMGPlanner(surface=DMGSurface(model=model))


def _mesh_in_task_frame(obj: str, planner=None):
    from ..strategies.dmg.strategy import DMGPlanner

    planner = planner or DMGPlanner()
    return planner.placement(obj).mesh_in_published(planner.mesh_for(obj))


def desired_region(mesh, desired_contacts: np.ndarray, radius: float) -> np.ndarray:
    """Vertex indices of ``C_d``: geodesic discs of ``radius`` around the desired contacts put on ``mesh``
    along the line through them."""
    from ..objects import contact_region
    from ..strategies.dmg.planner import surface_contacts

    c = np.asarray(desired_contacts, float)[:2]
    z = c[1] - c[0]
    on, _ = surface_contacts(mesh, c, z / np.linalg.norm(z))
    verts: set[int] = set()
    for p in on:
        verts.update(contact_region(mesh, p, radius, metric="geodesic").vertices.tolist())
    return np.array(sorted(verts), dtype=np.int64)


def contact_errors(
    obj: str,
    desired_contacts,
    reached_contacts,
    *,
    radius: float | None = None,
    pad_radius: float | None = None,
    planner=None,
    method: GeodesicMethod = "heat",
) -> dict[str, float]:
    """G_euc, G_geo, G_min (m) of one trial, all in the task frame (see the module docstring)."""
    from ..metrics.contact import contact_region_error
    from ..objects import contact_region
    from ..strategies.dmg.strategy import DESIRED_REGION_RADIUS, FINGER_PAD_RADIUS

    mesh = _mesh_in_task_frame(obj, planner)
    region = desired_region(
        mesh, desired_contacts, DESIRED_REGION_RADIUS if radius is None else radius
    )
    pads = [
        contact_region(
            mesh,
            np.asarray(c, float),
            FINGER_PAD_RADIUS if pad_radius is None else pad_radius,
            metric="geodesic",
        ).mesh
        for c in np.asarray(reached_contacts, float)
    ]
    err = contact_region_error(mesh, region, pads, method=method)
    return {"g_euc": float(err.euc), "g_geo": float(err.geo), "g_min": float(err.g_min)}


def score_store(
    store: str | Path,
    task_names: tuple[str, ...] = ("inhand-level3-dmg", "inhand-level2-dmg-regions"),
) -> list[dict[str, Any]]:
    """Contact-region errors of every stored DMG trial of ``task_names`` with reached contacts.

    Returns one dict per trial: task, backend, trial index, task id,
    object, status and G_euc / G_geo / G_min (m). The desired contacts come
    from the task set registered under the stored task name.
    """
    import json
    import sqlite3

    from ..plugin import get_manager

    path = Path(store)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such results store")
    tasks = {}
    out = []
    # Read-only: scoring a store never creates or modifies it. A WAL store
    # with no -wal file has nothing outside the main file, and opening it
    # even read-only would create -wal/-shm: read it as immutable then.
    wal = path.with_name(path.name + "-wal").exists()
    mode = "mode=ro" if wal else "mode=ro&immutable=1"
    con = sqlite3.connect(f"{path.resolve().as_uri()}?{mode}", uri=True)
    try:
        rows = con.execute(
            "select task, backend, strategy, trial_index, status, outcome_json from trials "
            "order by task, backend, trial_index"
        ).fetchall()
    except sqlite3.DatabaseError as exc:
        raise ValueError(f"{path}: not a benchharness results store ({exc})") from None
    finally:
        con.close()
    for task, backend, strategy, idx, status, oj in rows:
        if task not in task_names:
            continue
        o = json.loads(oj or "{}")
        rc = o.get("reached_contacts")
        row: dict[str, Any] = {
            "task": task,
            "backend": backend,
            "strategy": strategy,
            "trial": idx,
            "task_id": o.get("task_id"),
            "object": o.get("object"),
            "status": status,
        }
        if rc and status == "success":
            if task not in tasks:
                ts = get_manager().create("task", task)
                tasks[task] = {str(t): ts.contacts["desired"][i] for i, t in enumerate(ts.task_id)}
            row.update(
                contact_errors(
                    o["object"], tasks[task][o["task_id"]], rc, planner=planner_for_outcome(o)
                )
            )
        out.append(row)
    return out


def stored_contact_scorer() -> Callable[[Any], dict[str, float] | None]:
    """G_euc / G_geo / G_min of a stored trial with reached contacts, on our mesh in the task frame.

    The ``contact_scorer`` of :func:`~benchharness.runner.reports.inhand_table3`
    (``benchharness table``): desired contacts come from the task-set plugin
    named by the trial's run, read once per task. A trial without reached
    contacts, or whose task set gives no finite desired contacts for it,
    scores None (the table prints no G for it).
    """
    from ..plugin import get_manager

    desired: dict[str, dict[str, Any]] = {}

    def score(trial) -> dict[str, float] | None:
        o = trial.outcome
        rc = o.get("reached_contacts")
        if not rc:
            return None
        if trial.task not in desired:
            try:
                ts = get_manager().create("task", trial.task)
                desired[trial.task] = {
                    str(t): ts.contacts["desired"][i] for i, t in enumerate(ts.task_id)
                }
            except Exception:  # noqa: BLE001 - not an in-hand task set with contacts
                desired[trial.task] = {}
        want = desired[trial.task].get(o.get("task_id"))
        if want is None or not np.all(np.isfinite(np.asarray(want, float))):
            return None
        return contact_errors(o["object"], want, rc, planner=planner_for_outcome(o))

    return score
