"""The results store: one SQLite file, one row per finished trial.

Default path ``./benchharness-results.sqlite`` (the current directory, so
each project folder keeps its own results), overridden by the
``BENCHHARNESS_STORE`` environment variable and by ``--store``.

Durability: WAL journal, and every trial is committed the moment it is
written, so killing a sweep loses only the trials still running. Only the
sweep's parent process writes; workers return records.

Ownership: a store is marked as ours by ``PRAGMA application_id``
(:data:`APPLICATION_ID`) and versioned by ``PRAGMA user_version`` and the
``schema_version`` table. A file is inspected (read-only, through the SQLite
header and a read-only connection) *before* anything is written to it: any
other program's database is refused untouched; a store of an older version
is migrated when opened for writing and read as it is otherwise; a newer or
unknown version is refused with its number. Read-only opening
(``read_only=True``) never creates or changes a file.

Claims: before a sweep runs a trial it claims it (table ``claims``: owner
host, pid and token, lease expiry renewed while the owner runs), so two runs
of the same command share the trials instead of both running each.
"""

from __future__ import annotations

import json
import math
import os
import socket
import sqlite3
import threading
import time
import uuid
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from .causes import FailureCause, TrialStatus
from .records import TrialRecord, comparable_fields
from .spec import RunSpec

__all__ = [
    "APPLICATION_ID",
    "ClaimOwner",
    "DEFAULT_STORE",
    "SCHEMA_VERSION",
    "ResultsStore",
    "StoredTrial",
    "StoreError",
    "default_store_path",
]

DEFAULT_STORE = "benchharness-results.sqlite"
STORE_ENV = "BENCHHARNESS_STORE"
SCHEMA_VERSION = 2
#: ``PRAGMA application_id`` of a benchharness store (the bytes ``bhrs``), from version 2.
APPLICATION_ID = int.from_bytes(b"bhrs", "big")
_SQLITE_MAGIC = b"SQLite format 3\x00"

# Version 1 (0ffcf61) had the schema_version, runs and trials tables below and no
# application_id; version 2 added the claims table and the two header pragmas.
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
CREATE TABLE IF NOT EXISTS claims (
    run_key TEXT NOT NULL,
    trial_index INTEGER NOT NULL,
    host TEXT NOT NULL,
    pid INTEGER NOT NULL,
    token TEXT NOT NULL,
    expires_at REAL NOT NULL,
    PRIMARY KEY (run_key, trial_index)
);
"""

_RUN_COLUMNS = (
    "run_key benchmark task robot strategy sensors backend seed physics_hash options_hash"
    " code_version trials_total spec_json created_at"
).split()
_TRIAL_COLUMNS = (
    "run_key trial_index benchmark task robot strategy sensors backend seed physics_hash"
    " options_hash code_version status score failure_cause message wall_s sim_s"
    " first_contact_s termination_s outcome_json diagnostics_json traceback finished_at"
).split()
#: The columns each schema version's tables must have (what reading relies on).
_REQUIRED: dict[int, dict[str, list[str]]] = {
    1: {"schema_version": ["version"], "runs": _RUN_COLUMNS, "trials": _TRIAL_COLUMNS},
    2: {
        "schema_version": ["version"],
        "runs": _RUN_COLUMNS,
        "trials": _TRIAL_COLUMNS,
        "claims": "run_key trial_index host pid token expires_at".split(),
    },
}

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


@dataclass(frozen=True)
class ClaimOwner:
    """Who claimed a trial: a sweep in a process on a host (token: unique per sweep)."""

    host: str
    pid: int
    token: str

    @classmethod
    def new(cls) -> ClaimOwner:
        return cls(socket.gethostname(), os.getpid(), uuid.uuid4().hex)

    def alive(self) -> bool:
        """False only when the owner is known dead (its pid is gone on this host)."""
        if self.host != socket.gethostname():
            return True  # another machine: only its lease tells
        try:
            os.kill(self.pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True


ClaimResult = Literal["claimed", "done", "busy"]


@dataclass(frozen=True)
class _Inspection:
    """What is at a store path, found without writing: ``None`` version = nothing yet."""

    version: int | None


def _ro_uri(path: Path) -> str:
    """A read-only URI that makes SQLite create no file.

    With no ``-wal`` beside it no connection has the store open (SQLite deletes
    the WAL when the last one closes), and ``immutable=1`` then keeps a reader
    from creating ``-wal``/``-shm`` files; while a run is writing, the reader
    uses that run's WAL (``mode=ro``).
    """
    uri = path.resolve().as_uri() + "?mode=ro"
    if not Path(str(path) + "-wal").exists():
        uri += "&immutable=1"
    return uri


def _inspect(path: Path, *, read_only: bool) -> _Inspection:
    """Decide whether ``path`` is (or may become) a benchharness store; raise StoreError if not."""
    if not path.exists():
        if read_only:
            raise StoreError(f"{path}: no results store there (run `benchharness run` first)")
        return _Inspection(None)
    if path.is_dir():
        raise StoreError(f"{path} is a directory, not a benchharness results store")
    with open(path, "rb") as f:
        header = f.read(100)
    if not header:
        if read_only:
            raise StoreError(f"{path} is an empty file, not a benchharness results store")
        return _Inspection(None)
    if not header.startswith(_SQLITE_MAGIC) or len(header) < 100:
        raise StoreError(f"{path}: not a benchharness results store (not an SQLite database)")
    app_id = int.from_bytes(header[68:72], "big")
    if app_id not in (0, APPLICATION_ID):
        raise StoreError(
            f"{path}: not a benchharness results store (SQLite application_id {app_id}: "
            "another program's database); left untouched"
        )
    try:
        con = sqlite3.connect(_ro_uri(path), uri=True, timeout=30.0)
    except sqlite3.Error as exc:
        raise StoreError(f"{path}: cannot open it read-only ({exc})") from None
    try:
        found = [r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")]
        tables = {
            n: [c[1] for c in con.execute('PRAGMA table_info("{}")'.format(n.replace('"', '""')))]
            for n in found
        }
        if not tables and app_id == 0:
            if read_only:
                raise StoreError(f"{path}: an empty database, not a benchharness results store")
            return _Inspection(None)
        if "schema_version" not in tables or "version" not in tables["schema_version"]:
            names = ", ".join(sorted(tables)) or "none"
            raise StoreError(
                f"{path}: not a benchharness results store (its tables: {names}; no "
                "schema_version); left untouched"
            )
        version = con.execute("SELECT max(version) FROM schema_version").fetchone()[0]
    except sqlite3.DatabaseError as exc:
        raise StoreError(f"{path}: not a benchharness results store ({exc})") from None
    finally:
        con.close()
    if version is None:
        raise StoreError(f"{path}: a benchharness store with no schema version recorded")
    if version > SCHEMA_VERSION:
        raise StoreError(
            f"{path} has schema version {version}, newer than this benchharness "
            f"understands ({SCHEMA_VERSION}); upgrade benchharness or use another --store"
        )
    if version not in _REQUIRED:
        raise StoreError(
            f"{path} has schema version {version}, older than any this benchharness reads or "
            f"migrates (1..{SCHEMA_VERSION}); use another --store"
        )
    for table, cols in _REQUIRED[version].items():
        missing = [c for c in cols if c not in tables.get(table, [])]
        if missing:
            what = (
                f"table {table!r} lacks {', '.join(missing)}"
                if table in tables
                else (f"no table {table!r}")
            )
            raise StoreError(
                f"{path}: not a readable benchharness store of schema version {version} ({what})"
            )
    return _Inspection(int(version))


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
    #: the run's ``--strategy-option`` settings, ``key=value`` comma-joined ("" for none)
    strategy_options: str = ""

    @property
    def method(self) -> str:
        """How a run is named in tables: strategy (and its options), robot, sensors, backend."""
        sensors = f"+{self.sensors}" if self.sensors else ""
        opts = f" [{self.strategy_options}]" if self.strategy_options else ""
        return f"{self.strategy}{sensors}{opts} ({self.robot}, {self.backend})"

    def comparable(self) -> dict[str, Any]:
        """Everything but the wall-clock measurements, as :meth:`TrialRecord.comparable`."""
        return comparable_fields(self)


class ResultsStore:
    """Open a results store (creating or migrating it unless ``read_only``). A context manager.

    ``read_only=True`` is for commands that only read: a missing path, an
    empty file or any file that is not a store is a :class:`StoreError`, and
    nothing is created or changed (SQLite opened with ``mode=ro``).
    """

    def __init__(self, path: str | Path | None = None, *, read_only: bool = False) -> None:
        self.path = Path(path) if path is not None else default_store_path()
        self.read_only = read_only
        found = _inspect(self.path, read_only=read_only)
        self.version = found.version or SCHEMA_VERSION
        try:
            if read_only:
                self.conn = sqlite3.connect(_ro_uri(self.path), uri=True, timeout=30.0)
                self.conn.row_factory = sqlite3.Row
                return
            if not self.path.parent.exists():
                self.path.parent.mkdir(parents=True, exist_ok=True)
            self.conn = sqlite3.connect(str(self.path), timeout=30.0, isolation_level=None)
            self.conn.row_factory = sqlite3.Row
            self.conn.execute("PRAGMA journal_mode=WAL")
            self.conn.execute("PRAGMA synchronous=NORMAL")
            self.conn.execute("PRAGMA foreign_keys=ON")
            self._migrate()
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"{self.path}: not a benchharness results store ({exc})") from None

    def _migrate(self) -> None:
        """Create the tables (new store) or bring a version-1 store to this version."""
        with self.conn:
            self.conn.execute("BEGIN IMMEDIATE")
            for stmt in filter(str.strip, _SCHEMA.split(";")):
                self.conn.execute(stmt)
            version = self.conn.execute("SELECT max(version) FROM schema_version").fetchone()[0]
            if version is None:
                self.conn.execute(
                    "INSERT INTO schema_version (version) VALUES (?)", (SCHEMA_VERSION,)
                )
            elif version > SCHEMA_VERSION:  # written by a newer harness since we looked
                raise StoreError(
                    f"{self.path} has schema version {version}, newer than this benchharness "
                    f"understands ({SCHEMA_VERSION}); upgrade benchharness or use another --store"
                )
            elif version < SCHEMA_VERSION:  # 1 -> 2: the claims table (created above)
                self.conn.execute("UPDATE schema_version SET version = ?", (SCHEMA_VERSION,))
            self.conn.execute(f"PRAGMA application_id = {APPLICATION_ID}")
            self.conn.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")
        self.version = SCHEMA_VERSION

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

    def write(self, record: TrialRecord, owner: ClaimOwner | None = None) -> bool:
        """Insert (or replace) one trial and commit at once.

        With ``owner``: only while ``owner`` holds the trial's claim (which is
        then released); False (nothing written) if another sweep took it over
        after the lease lapsed — that sweep writes it.
        """
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
        key = (record.run_key, int(record.trial_index))
        with self.conn:
            self.conn.execute("BEGIN IMMEDIATE")
            if owner is not None:
                held = self.conn.execute(
                    "SELECT token FROM claims WHERE run_key = ? AND trial_index = ?", key
                ).fetchone()
                if held is None or held[0] != owner.token:
                    return False
                self.conn.execute("DELETE FROM claims WHERE run_key = ? AND trial_index = ?", key)
            self.conn.execute(
                f"INSERT OR REPLACE INTO trials ({cols}) VALUES ({marks})", tuple(values.values())
            )
        return True

    # -- claims ----------------------------------------------------------------------------
    def claim(
        self,
        run_key: str,
        index: int,
        owner: ClaimOwner,
        *,
        lease_s: float,
        redo: Literal["failed", "any"] | None = None,
        since: float = 0.0,
    ) -> ClaimResult:
        """Claim trial ``index`` for ``owner`` unless it is stored or another live sweep has it.

        ``"done"``: stored (and not to be redone: ``redo`` re-runs a row stored
        before ``since`` — failed ones, or any); ``"busy"``: claimed by another
        sweep whose lease runs and which is not known dead; ``"claimed"``: ours
        until ``lease_s`` from now (renew with :meth:`keep_claims`).
        """
        key = (run_key, int(index))
        with self.conn:
            self.conn.execute("BEGIN IMMEDIATE")
            row = self.conn.execute(
                "SELECT status, finished_at FROM trials WHERE run_key = ? AND trial_index = ?", key
            ).fetchone()
            if row is not None:
                stale = redo is not None and row["finished_at"] < since
                if not (stale and (redo == "any" or row["status"] == TrialStatus.FAILURE.value)):
                    return "done"
            held = self.conn.execute(
                "SELECT host, pid, token, expires_at FROM claims"
                " WHERE run_key = ? AND trial_index = ?",
                key,
            ).fetchone()
            now = time.time()
            if held is not None and held["token"] != owner.token:
                other = ClaimOwner(held["host"], held["pid"], held["token"])
                if held["expires_at"] > now and other.alive():
                    return "busy"
            self.conn.execute(
                "INSERT OR REPLACE INTO claims (run_key, trial_index, host, pid, token, expires_at)"
                " VALUES (?, ?, ?, ?, ?, ?)",
                (*key, owner.host, owner.pid, owner.token, now + lease_s),
            )
        return "claimed"

    def release(self, owner: ClaimOwner) -> None:
        """Drop every claim ``owner`` still holds (its sweep ended or was interrupted)."""
        with self.conn:
            self.conn.execute("DELETE FROM claims WHERE token = ?", (owner.token,))

    @contextmanager
    def keep_claims(self, owner: ClaimOwner, lease_s: float) -> Iterator[None]:
        """Renew ``owner``'s leases from a thread (own connection) every lease/4 s; release at the end.

        A thread, so the lease is renewed while a trial runs in this process
        (``workers=0``) as well as while the parent waits on its workers.
        """
        stop = threading.Event()

        def renew() -> None:
            con = sqlite3.connect(str(self.path), timeout=30.0, isolation_level=None)
            try:
                while not stop.wait(lease_s / 4):
                    try:
                        con.execute(
                            "UPDATE claims SET expires_at = ? WHERE token = ?",
                            (time.time() + lease_s, owner.token),
                        )
                    except sqlite3.Error:
                        pass  # busy: the next round renews; the lease has slack for it
            finally:
                con.close()

        thread = threading.Thread(target=renew, name="benchharness-claims", daemon=True)
        thread.start()
        try:
            yield
        finally:
            stop.set()
            thread.join()
            self.release(owner)

    def claims(self) -> list[dict[str, Any]]:
        """Current claims (trials some sweep is running or was running when it died)."""
        if self.version < 2:
            return []
        return [
            dict(r) for r in self.conn.execute("SELECT * FROM claims ORDER BY run_key, trial_index")
        ]

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
        where: list[str] = []
        args: list[Any] = []
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
            vals: list[Any] = list(val) if isinstance(val, (list, tuple, set)) else [val]
            if col == "task":
                where.append(f"lower(t.task) IN ({','.join('?' * len(vals))})")
                vals = [str(v).lower() for v in vals]
            else:
                where.append(f"t.{col} IN ({','.join('?' * len(vals))})")
            args.extend(vals)
        sql = (
            "SELECT t.*, r.spec_json AS run_spec_json FROM trials t"
            " JOIN runs r ON r.run_key = t.run_key"
        )
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
            strategy_options=_options_text(r),
        )


def _options_text(r: sqlite3.Row) -> str:
    """A row's run's strategy options from its spec JSON, ``key=value`` comma-joined."""
    if "run_spec_json" not in r.keys():
        return ""
    try:
        opts = json.loads(r["run_spec_json"]).get("strategy_options") or {}
    except (TypeError, ValueError, AttributeError):
        return ""
    return ",".join(f"{k}={v}" for k, v in sorted(opts.items()))


def group_by_run(trials: Iterable[StoredTrial]) -> Iterator[tuple[str, list[StoredTrial]]]:
    """``(run_key, trials)`` in first-seen order."""
    groups: dict[str, list[StoredTrial]] = {}
    for t in trials:
        groups.setdefault(t.run_key, []).append(t)
    yield from groups.items()
