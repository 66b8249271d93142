"""Score a recorded-results file: the file-reading layer over
:mod:`benchharness.metrics.inhand`.

Contact metrics (Levels II/III) need the object mesh, so they are computed
for a trial only when its ``object_mesh`` column names a mesh file. The
desired region comes from ``desired_region`` (a region mesh file, or
``vertices:i;j;k`` object vertex indices) or else from the
``desired_contactK_*`` points; the robot contact from a ``reached_links``
column (``;``-separated link mesh files, in the object frame) or else from
the ``reached_contactK_*`` points. Paths are relative to the results file.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..metrics.contact import (
    DEFAULT_CONTACT_TOL,
    ContactError,
    contact_region_error,
    object_surface,
)
from ..metrics.inhand import METRICS, TrialScores, score_trials, summarize_scores
from ..metrics.stats import GroupStats
from .fileformat import FileFormatError
from .records import ResultSet

__all__ = ["ScoredResults", "score_results", "grouping", "group_columns"]


@dataclass(frozen=True)
class ScoredResults:
    results: ResultSet
    scores: TrialScores


def _load_mesh(results: ResultSet, rel: str, row: int, column: str):
    import trimesh

    path = results.resolve(rel)
    if path is None or not path.is_file():
        raise FileFormatError(results.source, f"mesh file {rel!r} not found", row, column)
    try:
        mesh = trimesh.load(path, force="mesh")
    except Exception as e:  # noqa: BLE001 - trimesh raises many kinds for bad files
        raise FileFormatError(
            results.source, f"cannot read mesh {rel!r}: {e}", row, column
        ) from None
    return mesh


def _points(results: ResultSet, stage: str, i: int) -> np.ndarray | None:
    c = results.contacts.get(stage)
    if c is None:
        return None
    pts = c[i][np.all(np.isfinite(c[i]), axis=1)]
    return pts if len(pts) else None


def _contact_errors(
    results: ResultSet, method: str, contact_tol: float
) -> list[ContactError | None] | None:
    meshes = results.object_mesh
    if meshes is None or not any(meshes):
        return None
    cache: dict[str, object] = {}
    out: list[ContactError | None] = []
    links_col = results.extra.get("reached_links")
    for i in range(len(results)):
        row = i + 1
        if not meshes[i] or results.dropped[i]:
            out.append(None)
            continue
        if meshes[i] not in cache:
            cache[meshes[i]] = object_surface(_load_mesh(results, meshes[i], row, "object_mesh"))
        surf = cache[meshes[i]]
        region = results.desired_region[i] if results.desired_region is not None else ""
        if region.startswith("vertices:"):
            try:
                desired = np.array(
                    [int(v) for v in region[len("vertices:") :].split(";") if v.strip()],
                    dtype=np.int64,
                )
            except ValueError:
                raise FileFormatError(
                    results.source, "vertices: takes ;-separated integers", row, "desired_region"
                ) from None
        elif region:
            desired = _load_mesh(results, region, row, "desired_region")
        else:
            desired = _points(results, "desired", i)
        if links_col is not None and links_col[i]:
            reached = [
                _load_mesh(results, p.strip(), row, "reached_links")
                for p in links_col[i].split(";")
                if p.strip()
            ]
        else:
            reached = _points(results, "reached", i)
        if desired is None or reached is None:
            out.append(None)
            continue
        try:
            out.append(
                contact_region_error(surf, desired, reached, method=method, contact_tol=contact_tol)
            )
        except (ValueError, IndexError) as e:
            raise FileFormatError(
                results.source, f"contact error: {e}", row, "object_mesh"
            ) from None
    return out


def score_results(
    results: ResultSet,
    *,
    geodesic: str = "heat",
    contact_tol: float = DEFAULT_CONTACT_TOL,
    normalize: bool = False,
) -> ScoredResults:
    contact = _contact_errors(results, geodesic, contact_tol)
    scores = score_trials(
        results.initial,
        results.desired,
        results.reached,
        setup=results.setup,
        dropped=results.dropped,
        plan_time_s=results.plan_time_s,
        exec_time_s=results.exec_time_s,
        contact=contact,
        normalize=normalize,
    )
    return ScoredResults(results, scores)


def group_columns(results: ResultSet) -> dict[str, np.ndarray]:
    cols = {
        "method": results.method,
        "object": results.object,
        "task_id": results.task_id,
        "level": results.level,
        "trial": results.trial,
    }
    cols.update(results.extra)
    return cols


def grouping(by: Sequence[str]) -> tuple[str, ...]:
    """``--by object`` means per method *and* object: methods are never pooled."""
    by = tuple(b for b in by if b)
    return by if "method" in by else ("method",) + by


def summarize(scored: ScoredResults, by: Sequence[str]) -> list[GroupStats]:
    r = scored.results
    return summarize_scores(scored.scores, group_columns(r), grouping(by), r.dropped)


def metrics_present(summaries: Sequence[GroupStats]) -> list[str]:
    """Metrics with data in at least one group, in :data:`METRICS` order."""
    return [m for m in METRICS if any(s.stats[m].n for s in summaries)]
