"""The Rubik's cube metric (paper, Section III-B), from real-robot or simulated logs.

Per trial: the trial succeeds when the observed final state equals the state
the protocol validator expects (:func:`benchharness.cube.expected_final`); its
score is ``termination_s - first_contact_s`` — "the time elapsed between the
robot first making contact with the Rubik's cube and the termination of
manipulation" — and is only meaningful for a successful trial.

Per tier: mean and **sample** standard deviation (``ddof = 1``, i.e. divided by
M − 1, as one reports the spread of a few repeated runs) of the trial scores.
With fewer than two scores there is no standard deviation (``None``, printed
"—", as Table I does for M = 1). A tier is *completed* only when the log holds
exactly trials 1..M of it, once each, and every one succeeded; only then is the
mean/std the tier's score. Otherwise the figures over the successful trials
are still given, as a diagnosis, never as a score.

Pure: no simulator imports; arrays and strings in, numbers out.

Bad logs raise :class:`TrialLogError` (the CLI exits 2): an unknown tier, an
invalid initial state or move, a malformed observed state (wrong length,
letters, colour counts or centres — a transcription error), missing or
non-numeric times on a trial that succeeded, termination before first
contact. A well-formed observed state that is not a legal cube (a twisted
corner, say — loose cubes do that under a gripper) is a *failed trial*, with
the reason.
"""

from __future__ import annotations

import csv
import io
import json
import math
import statistics
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..cube import (
    SOLVED_STRING,
    FaceletError,
    MoveError,
    UnknownTierError,
    differences,
    expected_final,
    facelet_problems,
    format_problems,
    generate_sequence,
    get_tier,
    parse_sequence,
)

#: Columns of the CSV log (and keys of the JSON log's trial objects).
LOG_FIELDS = (
    "tier",
    "trial",
    "initial",
    "sequence",
    "final",
    "first_contact_s",
    "termination_s",
    "note",
)
REQUIRED_FIELDS = ("tier", "trial", "sequence", "final")


class TrialLogError(ValueError):
    """A log that cannot be scored as written; the message says where and why."""


@dataclass(frozen=True)
class RubiksTrial:
    """One trial as recorded: what was prescribed, what was observed, when.

    ``trial`` is 1-based (trial k of M). ``initial`` defaults to solved.
    Times are seconds on any one clock (e.g. the video's timestamps).
    """

    tier: str
    trial: int
    sequence: str
    final: str
    initial: str = SOLVED_STRING
    first_contact_s: float | None = None
    termination_s: float | None = None
    note: str = ""


@dataclass(frozen=True)
class TrialResult:
    trial: RubiksTrial
    expected_final: str
    success: bool
    score_s: float | None
    reason: str = ""


@dataclass(frozen=True)
class TierScore:
    tier: str
    trials_required: int
    results: tuple[TrialResult, ...]
    completed: bool
    mean_s: float | None
    std_s: float | None
    problems: tuple[str, ...] = field(default_factory=tuple)

    @property
    def successes(self) -> int:
        return sum(r.success for r in self.results)

    def to_dict(self) -> dict[str, Any]:
        return {
            "tier": self.tier,
            "trials_required": self.trials_required,
            "trials_logged": len(self.results),
            "successes": self.successes,
            "completed": self.completed,
            "mean_s": self.mean_s,
            "std_s": self.std_s,
            "std_kind": "sample (ddof=1)",
            "problems": list(self.problems),
            "trials": [
                {
                    "trial": r.trial.trial,
                    "success": r.success,
                    "score_s": r.score_s,
                    "expected_final": r.expected_final,
                    "observed_final": r.trial.final,
                    "reason": r.reason,
                    "note": r.trial.note,
                }
                for r in self.results
            ],
        }


def mean_and_std(scores: Sequence[float]) -> tuple[float | None, float | None]:
    """Mean and sample standard deviation (ddof=1); ``None`` where undefined."""
    if not scores:
        return None, None
    mean = statistics.fmean(scores)
    std = statistics.stdev(scores) if len(scores) > 1 else None
    return mean, std


def score_trial(trial: RubiksTrial, seed: int | None = None) -> TrialResult:
    """Success and score of one trial.

    With ``seed``, the recorded sequence must also be the generator's sequence
    for that seed, tier and trial; otherwise the trial fails (it attempted a
    different task).
    """
    where = f"{trial.tier} trial {trial.trial}"
    try:
        moves = parse_sequence(trial.sequence)
        expected = expected_final(moves, trial.initial)
    except (MoveError, FaceletError) as exc:
        raise TrialLogError(f"{where}: {exc}") from exc
    malformed = format_problems(trial.final)
    if malformed:
        raise TrialLogError(f"{where}: invalid observed final state: " + "; ".join(malformed))
    problems = facelet_problems(trial.final)
    reason = ""
    if seed is not None:
        try:
            n_moves = get_tier(trial.tier).moves
        except UnknownTierError as exc:
            raise TrialLogError(f"{where}: {exc}") from exc
        prescribed = (
            generate_sequence(seed, trial.tier, trial.trial, n_moves) if trial.trial >= 1 else ()
        )
        if tuple(moves) != prescribed:
            reason = f"the sequence is not the generator's for seed {seed}, {trial.tier}, trial {trial.trial}"
    if not reason and problems:
        reason = "observed final state is not a legal cube: " + "; ".join(problems)
    if not reason and trial.final != expected:
        diff = differences(expected, trial.final)
        reason = f"observed final state differs from the expected one at {len(diff)} facelets"
    success = not reason
    score = None
    if success:
        if trial.first_contact_s is None or trial.termination_s is None:
            raise TrialLogError(
                f"{where}: a successful trial needs first_contact_s and termination_s"
            )
        score = trial.termination_s - trial.first_contact_s
        if not math.isfinite(score) or score < 0:
            raise TrialLogError(
                f"{where}: termination_s ({trial.termination_s}) is before first_contact_s ({trial.first_contact_s})"
            )
    return TrialResult(trial, expected, success, score, reason)


def score_tier(
    trials: Iterable[RubiksTrial],
    tier: str,
    trials_required: int | None = None,
    seed: int | None = None,
) -> TierScore:
    """Score the trials of one tier. ``trials_required`` defaults to the tier's M."""
    try:
        known = get_tier(tier)
        tier = known.name
        if trials_required is None:
            trials_required = known.trials
    except UnknownTierError as exc:
        if trials_required is None:
            raise TrialLogError(str(exc)) from exc
    rows = [replace(t, tier=tier) for t in trials if t.tier.lower() == tier.lower()]
    results = tuple(score_trial(t, seed) for t in sorted(rows, key=lambda t: t.trial))
    problems: list[str] = []
    numbers = [r.trial.trial for r in results]
    missing = [k for k in range(1, trials_required + 1) if k not in numbers]
    repeated = sorted({k for k in numbers if numbers.count(k) > 1})
    extra = sorted({k for k in numbers if not 1 <= k <= trials_required})
    if missing:
        problems.append(
            f"trial{'s' if len(missing) > 1 else ''} {', '.join(map(str, missing))} not logged"
        )
    if repeated:
        problems.append(
            f"trial{'s' if len(repeated) > 1 else ''} {', '.join(map(str, repeated))} logged more than once"
        )
    if extra:
        problems.append(
            f"trial{'s' if len(extra) > 1 else ''} {', '.join(map(str, extra))} outside 1..{trials_required}"
        )
    for r in results:
        if not r.success:
            problems.append(f"trial {r.trial.trial} failed: {r.reason}")
    mean, std = mean_and_std([r.score_s for r in results if r.success and r.score_s is not None])
    return TierScore(tier, trials_required, results, not problems, mean, std, tuple(problems))


def canonical_tier_names(trials: Iterable[RubiksTrial]) -> list[RubiksTrial]:
    """Spell every tier as the tier table does (``rubiks-5-20`` → ``Rubiks-5-20``)."""
    out = []
    for t in trials:
        try:
            name = get_tier(t.tier).name
        except UnknownTierError as exc:
            raise TrialLogError(f"{t.tier} trial {t.trial}: {exc}") from exc
        out.append(t if name == t.tier else replace(t, tier=name))
    return out


def score_log(trials: Sequence[RubiksTrial], seed: int | None = None) -> list[TierScore]:
    """Score every tier present in a log, in order of first appearance."""
    trials = canonical_tier_names(trials)
    order: list[str] = []
    for t in trials:
        if t.tier not in order:
            order.append(t.tier)
    return [score_tier(trials, name, seed=seed) for name in order]


# -- log files ---------------------------------------------------------------


def _float(value: Any, where: str, name: str) -> float | None:
    if value is None or (isinstance(value, str) and not value.strip()):
        return None
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise TrialLogError(f"{where}: {name} must be a number of seconds, got {value!r}") from None
    if not math.isfinite(out):
        raise TrialLogError(f"{where}: {name} must be finite, got {value!r}")
    return out


def trial_from_record(
    rec: dict[str, Any], where: str, default_tier: str | None = None
) -> RubiksTrial:
    """Build a :class:`RubiksTrial` from one CSV row or JSON object."""
    rec = {k.strip() if isinstance(k, str) else k: v for k, v in rec.items()}
    if default_tier and not rec.get("tier"):
        rec["tier"] = default_tier
    unknown = sorted(k for k in rec if k not in LOG_FIELDS)
    if unknown:
        raise TrialLogError(
            f"{where}: unknown field{'s' if len(unknown) > 1 else ''} {', '.join(map(str, unknown))}; "
            f"fields are {', '.join(LOG_FIELDS)}"
        )
    missing = [k for k in REQUIRED_FIELDS if rec.get(k) in (None, "")]
    if missing:
        raise TrialLogError(f"{where}: missing {', '.join(missing)}")
    raw_trial = rec["trial"]
    try:
        trial_no = int(str(raw_trial).strip())
    except ValueError:
        raise TrialLogError(
            f"{where}: trial must be an integer (1-based), got {raw_trial!r}"
        ) from None
    sequence = rec["sequence"]
    if isinstance(sequence, list):
        sequence = " ".join(map(str, sequence))
    initial = "".join(str(rec.get("initial") or "").split()) or SOLVED_STRING
    return RubiksTrial(
        tier=str(rec["tier"]).strip(),
        trial=trial_no,
        sequence=str(sequence).strip(),
        final="".join(str(rec["final"]).split()),  # whitespace may group it by face
        initial=initial,
        first_contact_s=_float(rec.get("first_contact_s"), where, "first_contact_s"),
        termination_s=_float(rec.get("termination_s"), where, "termination_s"),
        note=str(rec.get("note") or ""),
    )


def parse_csv_log(text: str) -> list[RubiksTrial]:
    reader = csv.DictReader(io.StringIO(text))
    if not reader.fieldnames:
        raise TrialLogError("CSV log is empty; its first line must name the columns")
    out = []
    for row in reader:
        if not any((v or "").strip() for v in row.values() if isinstance(v, str)):
            continue  # blank line
        if None in row:
            raise TrialLogError(f"line {reader.line_num}: more values than columns")
        out.append(trial_from_record(row, f"line {reader.line_num}"))
    return out


def parse_json_log(text: str) -> list[RubiksTrial]:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise TrialLogError(f"not valid JSON: {exc}") from None
    default_tier = None
    if isinstance(data, dict):
        default_tier = data.get("tier")
        data = data.get("trials")
    if not isinstance(data, list):
        raise TrialLogError(
            'a JSON log is a list of trial objects, or an object with a "trials" list'
        )
    out = []
    for i, rec in enumerate(data, start=1):
        if not isinstance(rec, dict):
            raise TrialLogError(f"trials[{i - 1}]: expected an object, got {type(rec).__name__}")
        out.append(trial_from_record(rec, f"trials[{i - 1}]", default_tier))
    return out


def read_log(path: str | Path) -> list[RubiksTrial]:
    """Read a CSV (``.csv``) or JSON (``.json``) trial log; other suffixes are sniffed."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise TrialLogError(f"cannot read {path}: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise TrialLogError(
            f"{path} is not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at offset {exc.start})"
        ) from None
    suffix = path.suffix.lower()
    if suffix == ".json" or (suffix != ".csv" and text.lstrip()[:1] in "[{"):
        trials = parse_json_log(text)
    else:
        trials = parse_csv_log(text)
    if not trials:
        raise TrialLogError(f"{path} holds no trials")
    return trials
