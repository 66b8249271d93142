"""The results store: one SQLite file, one row per finished trial.

Default path ``./benchharness-results.sqlite`` (the current directory, so
each project folder keeps its own results), overridden by the
``BENCHHARNESS_STORE`` environment variable and by ``--store``.

Durability: WAL journal, and every trial is committed the moment it is
written, so killing a sweep loses only the trials still running. Only the
sweep's parent process writes; workers return records. Schema changes bump
:data:`SCHEMA_VERSION`; a store written by a newer version is refused rather
than misread.
"""

from __future__ import annotations

import json
import math
import os
import sqlite3
import time
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .causes import FailureCause, TrialStatus
from .records import TrialRecord
from .spec import RunSpec

__all__ = [
    "DEFAULT_STORE",
    "SCHEMA_VERSION",
    "ResultsStore",
    "StoredTrial",
    "StoreError",
    "default_store_path",
]

DEFAULT_STORE = "benchharness-results.sqlite"
STORE_ENV = "BENCHHARNESS_STORE"
SCHEMA_VERSION = 1

_SCHEMA = """
CREATE TABLE IF NOT EXISTS schema_version (version INTEGER NOT NULL);
CREATE TABLE IF NOT EXISTS runs (
    run_key TEXT PRIMARY KEY,
    benchmark TEXT NOT NULL,
    task TEXT NOT NULL,
    robot TEXT NOT NULL,
    strategy TEXT NOT NULL,
    sensors TEXT NOT NULL,
    backend TEXT NOT NULL,
    seed INTEGER NOT NULL,
    physics_hash TEXT NOT NULL,
    options_hash TEXT NOT NULL,
    code_version TEXT NOT NULL,
    trials_total INTEGER NOT NULL,
    spec_json TEXT NOT NULL,
    created_at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS trials (
    run_key TEXT NOT NULL REFERENCES runs(run_key),
    trial_index INTEGER NOT NULL,
    benchmark TEXT NOT NULL,
    task TEXT NOT NULL,
    robot TEXT NOT NULL,
    strategy TEXT NOT NULL,
    sensors TEXT NOT NULL,
    backend TEXT NOT NULL,
    seed INTEGER NOT NULL,
    physics_hash TEXT NOT NULL,
    options_hash TEXT NOT NULL,
    code_version TEXT NOT NULL,
    status TEXT NOT NULL,
    score REAL,
    failure_cause TEXT,
    message TEXT NOT NULL DEFAULT '',
    wall_s REAL,
    sim_s REAL,
    first_contact_s REAL,
    termination_s REAL,
    outcome_json TEXT NOT NULL DEFAULT '{}',
    diagnostics_json TEXT NOT NULL DEFAULT '{}',
    traceback TEXT NOT NULL DEFAULT '',
    finished_at REAL NOT NULL,
    PRIMARY KEY (run_key, trial_index)
);
CREATE INDEX IF NOT EXISTS trials_by_task ON trials (task, strategy, backend);
"""

_KEY_COLUMNS = (
    "task",
    "robot",
    "strategy",
    "sensors",
    "backend",
    "seed",
    "physics_hash",
    "options_hash",
    "code_version",
)


class StoreError(RuntimeError):
    """The store cannot be opened or is of an unknown schema."""


def default_store_path() -> Path:
    return Path(os.environ.get(STORE_ENV) or DEFAULT_STORE)


def _num(x: float | None) -> float | None:
    return None if x is None or (isinstance(x, float) and not math.isfinite(x)) else float(x)


def _json(data: Any) -> str:
    return json.dumps(data, allow_nan=False, default=_default, separators=(",", ":"))


def _default(o: Any) -> Any:
    import numpy as np

    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


def _clean(data: Any) -> Any:
    """NaN/inf → None so the JSON is standard (SQLite's json functions can read it)."""
    if isinstance(data, float):
        return data if math.isfinite(data) else None
    if isinstance(data, dict):
        return {k: _clean(v) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [_clean(v) for v in data]
    return data


@dataclass(frozen=True)
class StoredTrial:
    """A trial row as read back (run fields included)."""

    run_key: str
    trial_index: int
    benchmark: str
    task: str
    robot: str
    strategy: str
    sensors: str
    backend: str
    seed: int
    physics_hash: str
    options_hash: str
    code_version: str
    status: TrialStatus
    score: float | None
    failure_cause: FailureCause | None
    message: str
    wall_s: float | None
    sim_s: float | None
    first_contact_s: float | None
    termination_s: float | None
    outcome: dict
    diagnostics: dict
    traceback: str
    finished_at: float

    @property
    def method(self) -> str:
        """How a run is named in tables: strategy, robot, sensors, backend."""
        sensors = f"+{self.sensors}" if self.sensors else ""
        return f"{self.strategy}{sensors} ({self.robot}, {self.backend})"

    def comparable(self) -> dict[str, Any]:
        return {
            "trial_index": self.trial_index,
            "status": self.status.value,
            "score": self.score,
            "failure_cause": self.failure_cause.value if self.failure_cause else None,
            "sim_s": self.sim_s,
            "first_contact_s": self.first_contact_s,
            "termination_s": self.termination_s,
            "outcome": self.outcome,
            "diagnostics": self.diagnostics,
        }


class ResultsStore:
    """Open (creating if needed) a results store. Use as a context manager."""

    def __init__(self, path: str | Path | None = None) -> None:
        self.path = Path(path) if path is not None else default_store_path()
        if self.path.parent and not self.path.parent.exists():
            self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self.conn = sqlite3.connect(str(self.path), timeout=30.0, isolation_level=None)
            self.conn.row_factory = sqlite3.Row
            self.conn.execute("PRAGMA journal_mode=WAL")
            self.conn.execute("PRAGMA synchronous=NORMAL")
            self.conn.execute("PRAGMA foreign_keys=ON")
            self._migrate()
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"{self.path}: not a benchharness results store ({exc})") from None

    def _migrate(self) -> None:
        with self.conn:
            self.conn.execute("BEGIN IMMEDIATE")
            for stmt in filter(str.strip, _SCHEMA.split(";")):
                self.conn.execute(stmt)
            row = self.conn.execute("SELECT max(version) FROM schema_version").fetchone()
            version = row[0]
            if version is None:
                self.conn.execute(
                    "INSERT INTO schema_version (version) VALUES (?)", (SCHEMA_VERSION,)
                )
            elif version > SCHEMA_VERSION:
                raise StoreError(
                    f"{self.path} has schema version {version}, newer than this benchharness "
                    f"understands ({SCHEMA_VERSION}); upgrade benchharness or use another --store"
                )

    def close(self) -> None:
        self.conn.close()

    def __enter__(self) -> ResultsStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- writing -------------------------------------------------------------------------
    def ensure_run(self, spec: RunSpec, benchmark: str, total: int) -> None:
        k = spec.key_fields()
        with self.conn:
            self.conn.execute(
                "INSERT OR IGNORE INTO runs (run_key, benchmark, task, robot, strategy, sensors, backend, seed,"
                " physics_hash, options_hash, code_version, trials_total, spec_json, created_at)"
                " VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
                (
                    spec.run_key,
                    benchmark,
                    *[k[c] for c in _KEY_COLUMNS],
                    total,
                    _json(spec.to_json()),
                    time.time(),
                ),
            )

    def write(self, record: TrialRecord) -> None:
        """Insert (or replace) one trial and commit at once."""
        run = self.conn.execute(
            "SELECT * FROM runs WHERE run_key = ?", (record.run_key,)
        ).fetchone()
        if run is None:
            raise StoreError(f"run {record.run_key} is not in the store (call ensure_run first)")
        values = {
            "run_key": record.run_key,
            "trial_index": int(record.trial_index),
            "benchmark": run["benchmark"],
            **{c: run[c] for c in _KEY_COLUMNS},
            "status": record.status.value,
            "score": _num(record.score),
            "failure_cause": record.failure_cause.value if record.failure_cause else None,
            "message": record.message or "",
            "wall_s": _num(record.wall_s),
            "sim_s": _num(record.sim_s),
            "first_contact_s": _num(record.first_contact_s),
            "termination_s": _num(record.termination_s),
            "outcome_json": _json(_clean(record.outcome)),
            "diagnostics_json": _json(_clean(record.diagnostics)),
            "traceback": record.traceback or "",
            "finished_at": time.time(),
        }
        cols = ", ".join(values)
        marks = ", ".join("?" for _ in values)
        with self.conn:
            self.conn.execute(
                f"INSERT OR REPLACE INTO trials ({cols}) VALUES ({marks})", tuple(values.values())
            )

    # -- reading ---------------------------------------------------------------------------
    def finished(self, run_key: str, *, retry_failed: bool = False) -> set[int]:
        """Trial indices of ``run_key`` already stored (the ones a resume skips)."""
        sql = "SELECT trial_index FROM trials WHERE run_key = ?"
        if retry_failed:
            sql += " AND status != 'failure'"
        return {r[0] for r in self.conn.execute(sql, (run_key,))}

    def trials(
        self,
        *,
        run_key: str | None = None,
        benchmark: str | None = None,
        failures_only: bool = False,
        **filters: str | int | Sequence | None,
    ) -> list[StoredTrial]:
        """Trials in run-creation then trial order; ``filters`` on key columns (value or list of values)."""
        where, args = [], []
        if run_key is not None:
            where.append("t.run_key = ?")
            args.append(run_key)
        if benchmark is not None:
            where.append("t.benchmark = ?")
            args.append(benchmark)
        if failures_only:
            where.append("t.status = 'failure'")
        for col, val in filters.items():
            if val is None:
                continue
            if col not in _KEY_COLUMNS:
                raise ValueError(f"cannot filter on {col!r}; columns are {', '.join(_KEY_COLUMNS)}")
            vals = list(val) if isinstance(val, (list, tuple, set)) else [val]
            if col == "task":
                where.append(f"lower(t.task) IN ({','.join('?' * len(vals))})")
                vals = [str(v).lower() for v in vals]
            else:
                where.append(f"t.{col} IN ({','.join('?' * len(vals))})")
            args.extend(vals)
        sql = "SELECT t.* FROM trials t JOIN runs r ON r.run_key = t.run_key"
        if where:
            sql += " WHERE " + " AND ".join(where)
        sql += " ORDER BY r.created_at, r.run_key, t.trial_index"
        return [self._row(r) for r in self.conn.execute(sql, args)]

    def runs(self) -> list[dict[str, Any]]:
        return [
            dict(r) for r in self.conn.execute("SELECT * FROM runs ORDER BY created_at, run_key")
        ]

    def count(self, run_key: str) -> int:
        return self.conn.execute(
            "SELECT count(*) FROM trials WHERE run_key = ?", (run_key,)
        ).fetchone()[0]

    @staticmethod
    def _row(r: sqlite3.Row) -> StoredTrial:
        return StoredTrial(
            run_key=r["run_key"],
            trial_index=r["trial_index"],
            benchmark=r["benchmark"],
            task=r["task"],
            robot=r["robot"],
            strategy=r["strategy"],
            sensors=r["sensors"],
            backend=r["backend"],
            seed=r["seed"],
            physics_hash=r["physics_hash"],
            options_hash=r["options_hash"],
            code_version=r["code_version"],
            status=TrialStatus(r["status"]),
            score=r["score"],
            failure_cause=FailureCause(r["failure_cause"]) if r["failure_cause"] else None,
            message=r["message"],
            wall_s=r["wall_s"],
            sim_s=r["sim_s"],
            first_contact_s=r["first_contact_s"],
            termination_s=r["termination_s"],
            outcome=json.loads(r["outcome_json"]),
            diagnostics=json.loads(r["diagnostics_json"]),
            traceback=r["traceback"],
            finished_at=r["finished_at"],
        )


def group_by_run(trials: Iterable[StoredTrial]) -> Iterator[tuple[str, list[StoredTrial]]]:
    """``(run_key, trials)`` in first-seen order."""
    groups: dict[str, list[StoredTrial]] = {}
    for t in trials:
        groups.setdefault(t.run_key, []).append(t)
    yield from groups.items()
