"""Task files and recorded-results files: CSV (canonical) and JSON.

The layout is specified, with an example, in ``docs/inhand.md``. In short,
one row per task / per trial; poses as seven columns ``PREFIX_x, _y, _z,
_qx, _qy, _qz, _qw`` (metres, scalar-last quaternion in the object frame)
with prefixes ``initial_``, ``desired_``, ``setup_``, ``reached_``; contact
points as ``STAGE_contactK_x/_y/_z`` (K = 1, 2, ...); optional
``desired_region`` and ``object_mesh`` paths relative to the file; any other
column is kept verbatim in ``extra``.

Validation happens on read and every error names the file, the row (1-based
data row; the header is line 1) and the column, because these files are
hand-edited spreadsheets far more often than program output.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..geometry import QUAT_NORM_TOL
from .records import POSE_FIELDS, POSE_STAGES, ResultSet, TaskSet

__all__ = [
    "FileFormatError",
    "read_results",
    "write_results",
    "read_tasks",
    "write_tasks",
    "results_to_rows",
    "tasks_to_rows",
    "format_number",
]

RESULTS_FORMAT = "benchharness-inhand-results"
TASKS_FORMAT = "benchharness-inhand-tasks"

_CONTACT_RE = re.compile(r"^(initial|desired|setup|reached)_contact(\d+)_([xyz])$")
_LEVELS = {"1": 1, "2": 2, "3": 3, "i": 1, "ii": 2, "iii": 3}
_TRUE = {"1", "true", "yes", "y", "t"}
_FALSE = {"0", "false", "no", "n", "f", ""}

RESULT_KEYS = (
    "method",
    "object",
    "task_id",
    "trial",
    "level",
    "dropped",
    "plan_time_s",
    "exec_time_s",
)
TASK_KEYS = ("task_id", "object", "level")
PATH_KEYS = ("desired_region", "object_mesh")
_NCELLS = "\0ncells"


class FileFormatError(ValueError):
    """A task/results file that does not follow the format."""

    def __init__(
        self,
        path: Path | str | None,
        message: str,
        row: int | None = None,
        column: str | None = None,
    ):
        self.path, self.row, self.column = path, row, column
        where = str(path) if path is not None else "<data>"
        if row is not None:
            where += f", row {row}"
        if column is not None:
            where += f", column {column!r}"
        super().__init__(f"{where}: {message}")


def pose_columns(stage: str) -> list[str]:
    return [f"{stage}_{f}" for f in POSE_FIELDS]


def format_number(x: float) -> str:
    """Deterministic text for a float: 12 significant digits, no ``-0``.

    12 digits keep every published value (<= 11 digits) exactly while hiding
    last-ulp differences between library versions, so converted files stay
    byte-identical across machines.
    """
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return ""
    v = float(x) + 0.0
    s = format(v, ".12g")
    return "0" if s in ("-0", "0") else s


# --------------------------------------------------------------------------- parsing


class _RowParser:
    def __init__(self, path: Path | None, row: int, values: Mapping[str, Any]):
        self.path, self.row, self.values = path, row, values

    def err(self, column: str | None, message: str) -> FileFormatError:
        return FileFormatError(self.path, message, self.row, column)

    def text(self, column: str, required: bool = True) -> str:
        v = self.values.get(column)
        v = "" if v is None else str(v).strip()
        if required and not v:
            raise self.err(column, "is empty")
        return v

    def number(self, column: str, required: bool) -> float:
        v = self.values.get(column)
        if v is None or (isinstance(v, str) and not v.strip()):
            if required:
                raise self.err(column, "is empty, a number is required")
            return math.nan
        try:
            x = float(v)
        except (TypeError, ValueError):
            raise self.err(column, f"{v!r} is not a number") from None
        if math.isinf(x) or (required and math.isnan(x)):
            raise self.err(column, f"{v!r} is not a finite number")
        return x

    def integer(self, column: str) -> int:
        v = self.text(column)
        try:
            return int(v)
        except ValueError:
            raise self.err(column, f"{v!r} is not an integer") from None

    def level(self) -> int:
        v = self.text("level").lower()
        if v not in _LEVELS:
            raise self.err("level", f"{v!r} is not a task level (1, 2, 3 or I, II, III)")
        return _LEVELS[v]

    def boolean(self, column: str) -> bool:
        v = self.text(column, required=False).lower()
        if v in _TRUE:
            return True
        if v in _FALSE:
            return False
        raise self.err(column, f"{v!r} is not a boolean (0/1, true/false)")

    def pose(self, stage: str, required: bool) -> np.ndarray:
        cols = pose_columns(stage)
        vals = np.array([self.number(c, required) for c in cols])
        present = np.isfinite(vals)
        if present.any() and not present.all():
            missing = [c for c, ok in zip(cols, present) if not ok]
            raise self.err(
                missing[0], f"pose {stage!r} is incomplete (empty: {', '.join(missing)})"
            )
        if present.all():
            norm = float(np.linalg.norm(vals[3:]))
            if norm < 1e-9:
                raise self.err(cols[3], f"pose {stage!r} has a zero quaternion")
            if abs(norm - 1.0) > QUAT_NORM_TOL:
                raise self.err(
                    cols[3],
                    f"pose {stage!r} has a quaternion of norm {norm:.6g}, not a unit one "
                    f"(tolerance {QUAT_NORM_TOL:g})",
                )
        return vals


def _contact_layout(columns: Iterable[str]) -> dict[str, int]:
    """Stage -> number of contact points, from the header."""
    found: dict[str, set[tuple[int, str]]] = {}
    for c in columns:
        m = _CONTACT_RE.match(c)
        if m:
            found.setdefault(m.group(1), set()).add((int(m.group(2)), m.group(3)))
    return {stage: max(k for k, _ in s) for stage, s in found.items()}


def _check_header(path: Path | None, columns: Sequence[str], required: Sequence[str]) -> None:
    seen: set[str] = set()
    for c in columns:
        if c in seen:
            raise FileFormatError(path, "duplicate column in header", 0, c)
        seen.add(c)
    missing = [c for c in required if c not in seen]
    if missing:
        raise FileFormatError(path, f"missing column(s): {', '.join(missing)}", None, missing[0])
    layout = _contact_layout(columns)
    for stage, k in layout.items():
        for i in range(1, k + 1):
            for a in "xyz":
                c = f"{stage}_contact{i}_{a}"
                if c not in seen:
                    raise FileFormatError(path, f"contact columns of {stage!r} skip {c}", None, c)
    setup = pose_columns("setup")
    if any(c in seen for c in setup) and not all(c in seen for c in setup):
        missing = [c for c in setup if c not in seen]
        raise FileFormatError(path, "setup pose needs all seven columns", None, missing[0])


def _known(columns: Iterable[str], is_results: bool) -> set[str]:
    known = set(RESULT_KEYS if is_results else TASK_KEYS) | set(PATH_KEYS)
    for s in POSE_STAGES if is_results else ("initial", "desired"):
        known.update(pose_columns(s))
    return known | {c for c in columns if _CONTACT_RE.match(c)}


def _parse(path: Path | None, columns: Sequence[str], rows: Sequence[Mapping[str, Any]], kind: str):
    is_results = kind == "results"
    required = (
        list(RESULT_KEYS if is_results else TASK_KEYS)
        + pose_columns("initial")
        + pose_columns("desired")
    )
    if is_results:
        required += pose_columns("reached")
    _check_header(path, columns, required)
    if not rows:
        raise FileFormatError(path, "has no data rows")
    layout = _contact_layout(columns)
    extra_cols = [c for c in columns if c not in _known(columns, is_results)]
    n = len(rows)
    out: dict[str, Any] = {
        k: []
        for k in (
            "method",
            "object",
            "task_id",
            "trial",
            "level",
            "dropped",
            "plan_time_s",
            "exec_time_s",
        )
    }
    poses = {s: np.full((n, 7), np.nan) for s in POSE_STAGES}
    contacts = {s: np.full((n, k, 3), np.nan) for s, k in layout.items()}
    paths = {k: [] for k in PATH_KEYS}
    extra = {c: [] for c in extra_cols}
    for r, values in enumerate(rows):
        p = _RowParser(path, r + 1, values)
        if _NCELLS in values:
            raise p.err(None, f"has {values[_NCELLS]} cells but the header has {len(columns)}")
        out["object"].append(p.text("object"))
        out["task_id"].append(p.text("task_id"))
        out["level"].append(p.level())
        poses["initial"][r] = p.pose("initial", True)
        poses["desired"][r] = p.pose("desired", out["level"][-1] != 2)  # Level II: C_d only, no H_d
        if is_results:
            out["method"].append(p.text("method"))
            out["trial"].append(p.integer("trial"))
            dropped = p.boolean("dropped")
            out["dropped"].append(dropped)
            out["plan_time_s"].append(p.number("plan_time_s", False))
            out["exec_time_s"].append(p.number("exec_time_s", False))
            poses["setup"][r] = p.pose("setup", False)
            poses["reached"][r] = p.pose("reached", not dropped)
        for stage, k in layout.items():
            for i in range(k):
                pt = [p.number(f"{stage}_contact{i + 1}_{a}", False) for a in "xyz"]
                ok = np.isfinite(pt)
                if ok.any() and not ok.all():
                    bad = f"{stage}_contact{i + 1}_{'xyz'[int(np.argmin(ok))]}"
                    raise p.err(bad, "contact point is incomplete")
                contacts[stage][r, i] = pt
        for k in PATH_KEYS:
            paths[k].append(p.text(k, required=False))
        for c in extra_cols:
            extra[c].append(p.text(c, required=False))
    common = dict(
        task_id=np.array(out["task_id"], dtype=object),
        object=np.array(out["object"], dtype=object),
        level=np.array(out["level"], dtype=int),
        initial=poses["initial"],
        desired=poses["desired"],
        contacts=contacts,
        desired_region=np.array(paths["desired_region"], dtype=object),
        object_mesh=np.array(paths["object_mesh"], dtype=object),
        extra={c: np.array(v, dtype=object) for c, v in extra.items()},
        source=path,
    )
    if not is_results:
        return TaskSet(**common)
    return ResultSet(
        method=np.array(out["method"], dtype=object),
        trial=np.array(out["trial"], dtype=int),
        dropped=np.array(out["dropped"], dtype=bool),
        plan_time_s=np.array(out["plan_time_s"], dtype=float),
        exec_time_s=np.array(out["exec_time_s"], dtype=float),
        setup=poses["setup"],
        reached=poses["reached"],
        **common,
    )


def _text(path: Path, encoding: str) -> str:
    try:
        return path.read_text(encoding=encoding)
    except UnicodeDecodeError as exc:
        raise FileFormatError(
            path, f"is not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at offset {exc.start})"
        ) from None
    except OSError as exc:
        raise FileFormatError(path, f"cannot be read ({exc.strerror or exc})") from None


def _read_csv(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    text = _text(path, "utf-8-sig")
    reader = csv.reader(io.StringIO(text))
    try:
        header = [h.strip() for h in next(reader)]
    except StopIteration:
        raise FileFormatError(path, "is empty") from None
    rows = []
    for _i, cells in enumerate(reader):
        if not any(c.strip() for c in cells):
            continue
        row = dict(zip(header, cells))
        if len(cells) > len(header):
            row[_NCELLS] = len(cells)  # reported after the header is checked
        rows.append(row)
    return header, rows


def _flatten_json_record(rec: Mapping[str, Any], path: Path, row: int) -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for k, v in rec.items():
        if k in POSE_STAGES:
            if v is None:
                continue
            if not isinstance(v, (list, tuple)) or len(v) != 7:
                raise FileFormatError(path, "a pose is a list [x, y, z, qx, qy, qz, qw]", row, k)
            flat.update(dict(zip(pose_columns(k), v)))
        elif k == "contacts":
            if not isinstance(v, Mapping):
                raise FileFormatError(
                    path, "contacts is an object {stage: [[x, y, z], ...]}", row, k
                )
            for stage, pts in v.items():
                for i, pt in enumerate(pts or []):
                    if not isinstance(pt, (list, tuple)) or len(pt) != 3:
                        raise FileFormatError(
                            path, "a contact point is [x, y, z]", row, f"contacts.{stage}[{i}]"
                        )
                    flat.update({f"{stage}_contact{i + 1}_{a}": c for a, c in zip("xyz", pt)})
        elif k == "extra" and isinstance(v, Mapping):
            flat.update({str(a): b for a, b in v.items()})
        else:
            flat[k] = "" if v is None else v
    return flat


def _read_json(path: Path, key: str) -> tuple[list[str], list[dict[str, Any]]]:
    try:
        data = json.loads(_text(path, "utf-8"))
    except json.JSONDecodeError as e:
        raise FileFormatError(path, f"is not valid JSON ({e.msg} at line {e.lineno})") from None
    records = data.get(key) if isinstance(data, Mapping) else data
    if not isinstance(records, list):
        raise FileFormatError(path, f"expected a list of records under {key!r}")
    rows = []
    columns: dict[str, None] = {}
    for i, rec in enumerate(records):
        if not isinstance(rec, Mapping):
            raise FileFormatError(path, "record is not an object", i + 1)
        flat = _flatten_json_record(rec, path, i + 1)
        columns.update(dict.fromkeys(flat))
        rows.append(flat)
    # Columns every record lacks are absent; ones some records lack are empty.
    return list(columns), rows


def _read(path: str | Path, kind: str):
    path = Path(path)
    if not path.is_file():
        raise FileFormatError(path, "no such file")
    if path.suffix.lower() == ".json":
        columns, rows = _read_json(path, "trials" if kind == "results" else "tasks")
    else:
        columns, rows = _read_csv(path)
    return _parse(path, columns, rows, kind)


def read_results(path: str | Path) -> ResultSet:
    """Read and validate a recorded-results file (``.csv`` or ``.json``)."""
    return _read(path, "results")


def read_tasks(path: str | Path) -> TaskSet:
    """Read and validate a task file (``.csv`` or ``.json``)."""
    return _read(path, "tasks")


# --------------------------------------------------------------------------- writing


def _contact_columns(contacts: Mapping[str, np.ndarray]) -> list[str]:
    cols = []
    for stage in POSE_STAGES:
        if stage in contacts:
            for i in range(contacts[stage].shape[1]):
                cols += [f"{stage}_contact{i + 1}_{a}" for a in "xyz"]
    return cols


def _rows(data: TaskSet | ResultSet, is_results: bool) -> tuple[list[str], list[list[str]]]:
    stages = ["initial", "desired"]
    if is_results:
        stages += ["setup", "reached"]
        if not np.isfinite(data.setup).any():
            stages.remove("setup")
    keys = list(RESULT_KEYS if is_results else TASK_KEYS)
    header = keys + [c for s in stages for c in pose_columns(s)] + _contact_columns(data.contacts)
    paths = [k for k in PATH_KEYS if getattr(data, k) is not None and any(getattr(data, k))]
    header += paths + list(data.extra)
    rows = []
    for i in range(len(data)):
        row: list[str] = []
        for k in keys:
            v = getattr(data, k)[i]
            if k == "dropped":
                row.append("1" if v else "0")
            elif k in ("plan_time_s", "exec_time_s"):
                row.append(format_number(v))
            else:
                row.append(str(v))
        for s in stages:
            row += [format_number(x) for x in getattr(data, s)[i]]
        for stage in POSE_STAGES:
            if stage in data.contacts:
                row += [format_number(x) for x in data.contacts[stage][i].reshape(-1)]
        row += [str(getattr(data, k)[i]) for k in paths]
        row += [str(v[i]) for v in data.extra.values()]
        rows.append(row)
    return header, rows


def results_to_rows(results: ResultSet) -> tuple[list[str], list[list[str]]]:
    return _rows(results, True)


def tasks_to_rows(tasks: TaskSet) -> tuple[list[str], list[list[str]]]:
    return _rows(tasks, False)


def _write_csv(path: Path, header: list[str], rows: list[list[str]]) -> None:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(buf.getvalue(), encoding="utf-8")


def write_results(results: ResultSet, path: str | Path) -> None:
    """Write a results file as CSV (``\\n`` line ends, deterministic numbers)."""
    _write_csv(Path(path), *results_to_rows(results))


def write_tasks(tasks: TaskSet, path: str | Path) -> None:
    _write_csv(Path(path), *tasks_to_rows(tasks))
