"""Tables from the store, laid out like the papers' (data only; the CLI prints them).

* :func:`rubiks_table` — Table I: tiers × methods, mean / std seconds of the
  trial scores where the tier was *completed* (every one of its M trials ended
  in the expected state), ``—`` where not; the published baselines beside.
* :func:`inhand_table2` — Table II: per method, drops % and median err_pos,
  err_pos%, err_or%; the paper's methods beside.
* :func:`inhand_table3` — Table III: per task, the metrics of one method;
  the paper's DMG figures beside.
* :func:`inhand_box_plot` — the paper's Figure 7 from stored trials: per
  object, one box per method.
* :func:`compare_backends` — one run's trials on several backends, side by side.

Every number comes from :mod:`benchharness.metrics` (``mean_and_std``,
``score_trials``, ``summarize_scores``) over the stored outcomes.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..cube import get_tier, load_tiers
from ..cube.tiers import UnknownTierError
from ..metrics import TrialScores, mean_and_std, score_trials, summarize_scores
from .causes import TrialStatus
from .published import PLAN_TIME_S, TABLE_II, TABLE_III
from .store import StoredTrial, group_by_run

__all__ = [
    "Column",
    "RubiksCell",
    "RubiksTable",
    "rubiks_table",
    "inhand_table2",
    "inhand_table3",
    "inhand_box_plot",
    "compare_backends",
    "format_cell",
]

_DISTINGUISH = ("seed", "physics_hash", "options_hash", "code_version")


@dataclass(frozen=True)
class Column:
    """A method: everything in the run key but the task."""

    label: str
    robot: str
    strategy: str
    sensors: str
    backend: str
    seed: int
    physics_hash: str
    options_hash: str
    code_version: str

    @property
    def key(self) -> tuple:
        return (
            self.robot,
            self.strategy,
            self.sensors,
            self.backend,
            self.seed,
            self.physics_hash,
            self.options_hash,
            self.code_version,
        )


def _columns(trials: Iterable[StoredTrial]) -> tuple[list[Column], dict[str, Column]]:
    """Columns in first-seen order, labelled as briefly as still tells them apart.

    Run options (budgets, repeats) and code versions split a method into
    several columns only where the same task was run with different ones:
    the default simulated-time budget grows with a tier's moves, so every tier
    of one method has its own options hash and must still land in one column,
    and a sweep whose tiers straddle a commit is still one method. A merged
    column's ``code_version`` lists every version in it (comma-separated), so
    nothing is hidden; ``table`` prints them under the table.
    """
    trials = list(trials)

    def method_key(t: StoredTrial) -> tuple:
        return (t.robot, t.strategy, t.sensors, t.backend, t.seed, t.physics_hash)

    def opt_key(t: StoredTrial) -> tuple:
        # strategy options make another method whatever the budgets (the label names them)
        return (method_key(t), t.strategy_options)

    per_task: dict[tuple, set[tuple[str, str]]] = {}
    for t in trials:
        per_task.setdefault((opt_key(t), t.task), set()).add((t.options_hash, t.code_version))
    split_opt = {mk for (mk, _), s in per_task.items() if len({o for o, _ in s}) > 1}
    split_code = {mk for (mk, _), s in per_task.items() if len({c for _, c in s}) > 1}
    raw: dict[tuple, StoredTrial] = {}
    codes: dict[tuple, list[str]] = {}
    by_run: dict[str, tuple] = {}
    for t in trials:
        mk = opt_key(t)
        k = (
            *mk[0],
            t.options_hash if mk in split_opt else "",
            t.code_version if mk in split_code else "",
            t.strategy_options,
        )
        raw.setdefault(k, t)
        if t.code_version not in codes.setdefault(k, []):
            codes[k].append(t.code_version)
        by_run[t.run_key] = k
    base: dict[tuple, str] = {k: t.method for k, t in raw.items()}
    labels: dict[tuple, str] = {}
    for k, t in raw.items():
        same = [o for o, lab in base.items() if lab == base[k] and o != k]
        extra = []
        for f in _DISTINGUISH:
            if (f == "options_hash" and not k[6]) or (f == "code_version" and not k[7]):
                continue
            if any(getattr(raw[o], f) != getattr(t, f) for o in same):
                extra.append(
                    f"seed {t.seed}" if f == "seed" else f"{f.split('_')[0]} {getattr(t, f)}"
                )
        labels[k] = base[k] + (" " + ", ".join(extra) if extra else "")
    cols = {
        k: Column(labels[k], k[0], k[1], k[2], k[3], k[4], k[5], k[6], ", ".join(codes[k]))
        for k in raw
    }
    return list(cols.values()), {run: cols[k] for run, k in by_run.items()}


@dataclass(frozen=True)
class RubiksCell:
    trials_required: int
    trials_run: int
    successes: int
    completed: bool
    mean_s: float | None
    std_s: float | None
    causes: dict[str, int] = field(default_factory=dict)
    sim_s_mean: float | None = None
    wall_s_mean: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def rubiks_cell(trials: Sequence[StoredTrial], required: int) -> RubiksCell:
    indices = {t.trial_index for t in trials}
    ok = [t for t in trials if t.status is TrialStatus.SUCCESS and t.score is not None]
    completed = indices == set(range(1, required + 1)) and len(ok) == required
    mean, std = mean_and_std([float(t.score) for t in ok if t.score is not None])
    causes = Counter(t.failure_cause.value for t in trials if t.failure_cause is not None)
    sims = [t.sim_s for t in trials if t.sim_s is not None]
    walls = [t.wall_s for t in trials if t.wall_s is not None]
    return RubiksCell(
        required,
        len(indices),
        len(ok),
        completed,
        mean,
        std,
        dict(causes),
        float(np.mean(sims)) if sims else None,
        float(np.mean(walls)) if walls else None,
    )


def format_cell(cell: RubiksCell | None) -> str:
    """Table I's notation: ``mean / std`` (``-`` for no std), ``—`` not completed."""
    if cell is None:
        return ""
    if cell.completed:
        std = "-" if cell.std_s is None else f"{cell.std_s:.2f}"
        return f"{cell.mean_s:.2f} / {std}"
    failed = cell.trials_run - cell.successes
    if failed == 0 and cell.trials_run < cell.trials_required:
        return f"… {cell.trials_run}/{cell.trials_required} run"
    return f"— ({cell.successes}/{cell.trials_required})"


@dataclass(frozen=True)
class RubiksTable:
    tiers: list[str]
    published: list[tuple[str, str]]  # (baseline key, label)
    columns: list[Column]
    cells: dict[tuple[str, str], RubiksCell]  # (tier, column label) -> cell

    def published_cell(self, tier: str, key: str) -> str:
        for b in get_tier(tier).baselines:
            if b.key == key:
                if not b.completed:
                    return "—"
                return f"{b.mean_s:.2f} / {'-' if b.std_s is None else f'{b.std_s:.2f}'}"
        return ""

    def to_dict(self) -> dict[str, Any]:
        tiers = load_tiers()
        out = []
        for tier in self.tiers:
            row: dict[str, Any] = {"tier": tier, "published": {}, "ours": {}}
            for b in tiers[tier].baselines:
                row["published"][b.label] = {
                    "completed": b.completed,
                    "mean_s": b.mean_s,
                    "std_s": b.std_s,
                }
            for c in self.columns:
                cell = self.cells.get((tier, c.label))
                if cell is not None:
                    row["ours"][c.label] = cell.to_dict()
            out.append(row)
        return {"columns": [c.__dict__ for c in self.columns], "rows": out}


def rubiks_table(trials: Sequence[StoredTrial], *, all_tiers: bool = True) -> RubiksTable:
    trials = [t for t in trials if t.benchmark == "rubiks"]
    columns, col_of = _columns(trials)
    cells: dict[tuple[str, str], RubiksCell] = {}
    seen_tiers: list[str] = []
    for run, rows in group_by_run(trials):
        try:
            tier = get_tier(rows[0].task)
        except UnknownTierError:
            continue
        seen_tiers.append(tier.name)
        cells[(tier.name, col_of[run].label)] = rubiks_cell(rows, tier.trials)
    known = load_tiers()
    tiers = [t for t in known if all_tiers or t in seen_tiers]
    first = next(iter(known.values()))
    published = [(b.key, b.label) for b in first.baselines]
    return RubiksTable(tiers, published, columns, cells)


# -- in-hand ---------------------------------------------------------------------------------

_INHAND_FIELDS = ("initial", "desired", "reached", "setup")


def _inhand_arrays(trials: Sequence[StoredTrial]) -> dict[str, np.ndarray]:
    def pose(t: StoredTrial, k: str) -> list[float]:
        v = t.outcome.get(k) or [None] * 7
        return [np.nan if x is None else float(x) for x in v]

    def num(t: StoredTrial, k: str) -> float:
        v = t.outcome.get(k)
        return np.nan if v is None else float(v)

    return {
        **{k: np.array([pose(t, k) for t in trials], float).reshape(-1, 7) for k in _INHAND_FIELDS},
        "dropped": np.array([bool(t.outcome.get("dropped")) for t in trials], bool),
        "plan_time_s": np.array([num(t, "plan_time_s") for t in trials], float),
        "exec_time_s": np.array([num(t, "exec_time_s") for t in trials], float),
    }


def _score_stored(trials: Sequence[StoredTrial]) -> tuple[dict[str, np.ndarray], TrialScores]:
    """The stored trials' pose arrays and their scores: one scoring path for Tables II, III and the summaries."""
    a = _inhand_arrays(trials)
    s = score_trials(
        a["initial"],
        a["desired"],
        a["reached"],
        setup=a["setup"],
        dropped=a["dropped"],
        plan_time_s=a["plan_time_s"],
        exec_time_s=a["exec_time_s"],
    )
    return a, s


def _scorable(trials: Iterable[StoredTrial]) -> tuple[list[StoredTrial], list[StoredTrial]]:
    """Trials with a pose outcome (scored, dropped or discarded) and the others (errors, timeouts...)."""
    scored, other = [], []
    for t in trials:
        if t.benchmark != "inhand":
            continue
        if t.status is not TrialStatus.FAILURE or t.outcome.get("dropped"):
            scored.append(t)
        else:
            other.append(t)
    return scored, other


def _median(stats, name: str, scale: float = 1.0) -> float | None:
    s = stats[name]
    return None if s.n == 0 else float(s.median * scale)


def _plan_time_medians(trials: Sequence[StoredTrial], col_of) -> dict[str, float]:
    """Per method label: median ``plan_time_s`` over every trial that recorded one.

    Planning comes before the set-up, so discarded, dropped and failed trials
    planned too (the paper's "median planning time across all objects").
    """
    by: dict[str, list[float]] = {}
    for t in trials:
        v = t.outcome.get("plan_time_s")
        if v is not None and np.isfinite(float(v)):
            by.setdefault(col_of[t.run_key].label, []).append(float(v))
    return {k: float(np.median(v)) for k, v in by.items()}


def inhand_table2(trials: Sequence[StoredTrial]) -> list[dict[str, Any]]:
    """Table II rows: ours (one per method) then the paper's, with ``source``.

    ``plan_time_s`` is the median planning time (every trial that planned;
    the paper's figure from its text, where it gives one).
    """
    scored, other = _scorable(trials)
    inhand = [t for t in trials if t.benchmark == "inhand"]
    columns, col_of = _columns(inhand)
    plan_times = _plan_time_medians(inhand, col_of)
    rows: list[dict[str, Any]] = []
    if scored:
        a, s = _score_stored(scored)
        labels = np.array([col_of[t.run_key].label for t in scored], dtype=object)
        for g in summarize_scores(s, {"method": labels}, ("method",), a["dropped"]):
            label = g.key[0]
            rows.append(
                {
                    "source": "ours",
                    "method": label,
                    "trials": g.n_trials,
                    "discarded": g.n_discarded,
                    "drops_percent": g.drops_percent,
                    "err_pos_cm": _median(g.stats, "err_pos", 100.0),
                    "err_pos_percent": _median(g.stats, "err_pos_percent"),
                    "err_or_percent": _median(g.stats, "err_or_percent"),
                    "failed_other": sum(col_of[t.run_key].label == label for t in other),
                    "plan_time_s": plan_times.get(label),
                }
            )
    for label in {col_of[t.run_key].label for t in other} - {r["method"] for r in rows}:
        rows.append(
            {
                "source": "ours",
                "method": label,
                "trials": 0,
                "discarded": 0,
                "drops_percent": None,
                "err_pos_cm": None,
                "err_pos_percent": None,
                "err_or_percent": None,
                "failed_other": sum(col_of[t.run_key].label == label for t in other),
                "plan_time_s": plan_times.get(label),
            }
        )
    for method, v in TABLE_II.items():
        rows.append(
            {"source": "paper", "method": method, **dict(v), "plan_time_s": PLAN_TIME_S.get(method)}
        )
    for method in sorted(PLAN_TIME_S.keys() - TABLE_II.keys()):  # planned, not run on the robot
        rows.append(
            {
                "source": "paper",
                "method": method,
                **{k: None for k in next(iter(TABLE_II.values()))},
                "plan_time_s": PLAN_TIME_S[method],
            }
        )
    return rows


def inhand_table3(
    trials: Sequence[StoredTrial],
    contact_scorer: Callable[[StoredTrial], Mapping[str, float] | None] | None = None,
) -> list[dict[str, Any]]:
    """Per method: per task, median metrics over its trials, with the paper's DMG figures by object.

    Only Level II/III trials: the paper's per-task table is for contact tasks;
    Level I methods are summarised by Table II. Trials stored without a level
    (older stores) are kept.

    ``contact_scorer(trial)`` gives a successful trial's ``g_euc``, ``g_geo``,
    ``g_min`` (m) from its reached contacts, or None: the contact-region error
    needs the object mesh in the task's frame, which the task's planner
    package knows and the runner does not (the CLI passes one). The DMG
    graph time is the strategy's ``extra["dmg_time_s"]`` where it reports one.
    """
    scored, _ = _scorable(trials)
    scored = [t for t in scored if t.outcome.get("level") in (None, 2, 3)]
    if not scored:
        return []
    columns, col_of = _columns(scored)
    a, s = _score_stored(scored)
    cols = {
        "method": np.array([col_of[t.run_key].label for t in scored], dtype=object),
        "task_id": np.array([t.outcome.get("task_id", "") for t in scored], dtype=object),
    }
    objects = {t.outcome.get("task_id", ""): t.outcome.get("object", "") for t in scored}
    out: list[dict[str, Any]] = []
    contact: dict[int, Mapping[str, float]] = {}
    if contact_scorer is not None:
        for i, t in enumerate(scored):
            if t.status is TrialStatus.SUCCESS and not a["dropped"][i] and not s.discarded[i]:
                g_ = contact_scorer(t)
                if g_:
                    contact[i] = g_
    graph = np.array(
        [float((t.outcome.get("extra") or {}).get("dmg_time_s", np.nan)) for t in scored]
    )
    for g in summarize_scores(s, cols, ("method", "task_id"), a["dropped"]):
        method, task_id = g.key
        obj = objects.get(task_id, "")
        rows_ = [
            i
            for i in range(len(scored))
            if cols["method"][i] == method and cols["task_id"][i] == task_id
        ]

        def med(values: list[float], scale: float = 1.0) -> float | None:
            v = [x for x in values if x is not None and np.isfinite(x)]
            return float(np.median(v) * scale) if v else None

        ours = {
            "err_pos_cm": _median(g.stats, "err_pos", 100.0),
            "err_pos_percent": _median(g.stats, "err_pos_percent"),
            "err_or_percent": _median(g.stats, "err_or_percent"),
            **{
                f"{k}_cm": med([contact[i][k] for i in rows_ if i in contact], 100.0)
                for k in ("g_euc", "g_geo", "g_min")
            },
            "graph_time_s": med([graph[i] for i in rows_]),
            "plan_time_s": _median(g.stats, "plan_time_s"),
        }
        out.append(
            {
                "method": method,
                "task_id": task_id,
                "object": obj,
                "trials": g.n_trials,
                "drops_percent": g.drops_percent,
                "ours": ours,
                "paper": dict(TABLE_III.get(obj, {})),
            }
        )
    return out


def inhand_box_plot(trials: Sequence[StoredTrial], path, *, title: str | None = None):
    """Figure 7 from the store: one panel per pose metric, per object one box per method.

    Method labels are the table's column labels (strategy, robot, backend), so
    the same method on two simulators gets two boxes side by side. The boxes
    are :func:`benchharness.metrics.stats.box_stats` numbers, as in the tables.
    """
    from ..metrics.inhand import METRICS
    from ..metrics.plots import box_plot

    scored, _ = _scorable(trials)
    if not scored:
        raise ValueError(
            "no in-hand trials with a reached pose in the selection (benchharness run --task inhand-...)"
        )
    _, col_of = _columns(scored)
    a, s = _score_stored(scored)
    cols = {
        "object": np.array([t.outcome.get("object", "") or "?" for t in scored], dtype=object),
        "method": np.array([col_of[t.run_key].label for t in scored], dtype=object),
    }
    groups = summarize_scores(s, cols, ("object", "method"), a["dropped"])
    metrics = ["err_pos", "err_pos_percent", "err_or_percent"]
    return box_plot(
        groups,
        metrics,
        path,
        labels={m: f"{METRICS[m].label} ({METRICS[m].unit})" for m in metrics},
        scales={m: METRICS[m].scale for m in metrics},
        title=title or "In-hand results per object (Figure 7 layout)",
    )


def _inhand_summary(rows: Sequence[StoredTrial]) -> dict[str, Any] | None:
    """Table II figures (drops %, medians) of one backend's in-hand trials, or None."""
    ours = [r for r in inhand_table2(rows) if r["source"] == "ours"]
    if not ours:
        return None
    r = ours[0]
    return {
        k: r[k]
        for k in (
            "trials",
            "discarded",
            "drops_percent",
            "err_pos_cm",
            "err_pos_percent",
            "err_or_percent",
        )
    }


# -- backend comparison ------------------------------------------------------------------------


def compare_backends(
    runs: Sequence[tuple[str, Sequence[StoredTrial]]], required: int | None
) -> dict[str, Any]:
    """``runs``: (backend, its trials). Per trial and per backend: status, score, cause, sim/wall time."""
    indices = sorted({t.trial_index for _, rows in runs for t in rows})
    per_trial = []
    for i in indices:
        row: dict[str, Any] = {"trial": i}
        for backend, rows in runs:
            t = next((r for r in rows if r.trial_index == i), None)
            row[backend] = (
                None
                if t is None
                else {
                    "status": t.status.value,
                    "score": t.score,
                    "cause": t.failure_cause.value if t.failure_cause else None,
                    "sim_s": t.sim_s,
                    "wall_s": t.wall_s,
                    "message": t.message,
                }
            )
        per_trial.append(row)
    summary = {}
    for backend, rows in runs:
        need = required if required is not None else len(indices)
        cell = rubiks_cell(rows, need) if rows and rows[0].benchmark == "rubiks" else None
        sims = [t.sim_s for t in rows if t.sim_s is not None]
        walls = [t.wall_s for t in rows if t.wall_s is not None]
        summary[backend] = {
            "trials": len(rows),
            "successes": sum(t.status is TrialStatus.SUCCESS for t in rows),
            "completed": None if cell is None else cell.completed,
            "mean_s": None if cell is None else cell.mean_s,
            "std_s": None if cell is None else cell.std_s,
            "causes": dict(Counter(t.failure_cause.value for t in rows if t.failure_cause)),
            "real_time_factor": (sum(sims) / sum(walls))
            if sims and walls and sum(walls) > 0
            else None,
            "inhand": _inhand_summary(rows) if rows and rows[0].benchmark == "inhand" else None,
        }
    return {"trials": per_trial, "summary": summary}
