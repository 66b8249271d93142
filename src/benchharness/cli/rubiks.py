"""``benchharness rubiks``: the Rubik's cube protocol software.

Thin: parse options, call :mod:`benchharness.cube` and
:mod:`benchharness.metrics.rubiks`, print. Exit codes: 0 yes/ok, 1 a negative
answer (state differs, tier not completed, string not a legal cube), 2 bad
input.
"""

from __future__ import annotations

from pathlib import Path

import click

from ..cube import (
    ALGORITHM,
    SOLVED_STRING,
    MoveError,
    UnknownTierError,
    differences,
    expected_final,
    facelet_problems,
    format_problems,
    format_sequence,
    get_tier,
    load_tiers,
    parse_sequence,
)
from .common import EXIT_NEGATIVE, emit_json, fail, json_option
from .validate import SEED_MAX

_CTX = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


def _moves(text: str, option: str = "--sequence"):
    try:
        return parse_sequence(text)
    except MoveError as exc:
        fail(f"{option}: {exc}")


def _facelets(text: str) -> str:
    """Drop all whitespace, so a state may be typed grouped by face."""
    return "".join(text.split())


def _initial(text: str) -> str:
    text = _facelets(text)
    problems = facelet_problems(text)
    if problems:
        fail("--initial is not a legal cube: " + "; ".join(problems))
    return text


@click.group(context_settings=_CTX)
def rubiks() -> None:
    """Rubik's cube protocol: sequences, expected states, validation, scores.

    Facelet strings are 54 letters in Kociemba's URFDLB order (U1..U9, R1..R9,
    F1..F9, D1..D9, L1..L9, B1..B9), each letter naming the face whose centre
    has that colour, read with the U centre up and the F centre in front;
    whitespace inside is ignored. Solved: UUUUUUUUURRRRRRRRRFFFFFFFFFDDDDDDDDDLLLLLLLLLBBBBBBBBB.

    \b
    Moves: U D L R F B, slices M E S, rotations x y z; suffix ' or 2.
    See docs/rubiks.md.
    """


@rubiks.command(
    "tiers", context_settings=_CTX, short_help="List tiers with M, N and published baselines."
)
@json_option
def tiers_cmd(as_json: bool) -> None:
    """List the twelve tiers with M, N and the paper's Table I baselines.

    \b
    Example:
      benchharness rubiks tiers
    """
    tiers = load_tiers()
    if as_json:
        emit_json([t.to_dict() for t in tiers.values()])
        return
    labels = [b.label for b in next(iter(tiers.values())).baselines]
    head = f"{'tier':<14}{'M':>3}{'N':>5}  " + "".join(f"{lab:<26}" for lab in labels)
    click.echo(head.rstrip())
    for t in tiers.values():
        cells = "".join(f"{b.describe():<26}" for b in t.baselines)
        click.echo(f"{t.name:<14}{t.trials:>3}{t.moves:>5}  {cells}".rstrip())
    click.echo(
        "Published mean / standard deviation of trial time in seconds (Yang et al., RA-L, Table I);"
    )
    click.echo('"—" std: single trial.')


@rubiks.command(
    "sequence", context_settings=_CTX, short_help="Print a tier's fixed-seed move sequences."
)
@click.option(
    "--tier", "tier_name", required=True, metavar="TIER", help="Tier name, e.g. Rubiks-5-20."
)
@click.option(
    "--seed",
    type=click.IntRange(min=0, max=SEED_MAX),
    default=0,
    show_default=True,
    help="Integer seed in 0..2**63-1 (what a run's store holds); report it with your score.",
)
@json_option
def sequence_cmd(tier_name: str, seed: int, as_json: bool) -> None:
    """Print the tier's M move sequences, one line of N moves per trial.

    Deterministic on every platform and version (algorithm
    benchharness-rubiks-v1, see docs/rubiks.md). Line k is trial k.

    \b
    Example:
      benchharness rubiks sequence --tier Rubiks-5-20 --seed 7
    """
    try:
        tier = get_tier(tier_name)
    except UnknownTierError as exc:
        fail(str(exc))
    seqs = tier.sequences(seed)
    if as_json:
        emit_json(
            {
                "tier": tier.name,
                "seed": seed,
                "algorithm": ALGORITHM,
                "trials": tier.trials,
                "moves": tier.moves,
                "sequences": [format_sequence(s) for s in seqs],
                "expected_final_from_solved": [expected_final(s) for s in seqs],
            }
        )
        return
    for s in seqs:
        click.echo(format_sequence(s))


@rubiks.command(
    "expect", context_settings=_CTX, short_help="Print the state expected after a sequence."
)
@click.option(
    "--sequence", "sequence", required=True, help="Moves, space separated, e.g. \"R U R' U'\"."
)
@click.option(
    "--initial",
    default=SOLVED_STRING,
    show_default="solved",
    metavar="FACELETS",
    help="Initial state (54 letters).",
)
@json_option
def expect_cmd(sequence: str, initial: str, as_json: bool) -> None:
    """Print the 54-letter state expected after SEQUENCE from the initial state.

    The result is read as a person holds the cube (U centre up, F centre in
    front), so whole-cube rotations x y z do not change it.

    \b
    Example:
      benchharness rubiks expect --sequence "R U R' U'"
    """
    moves = _moves(sequence)
    init = _initial(initial)
    final = expected_final(moves, init)
    if as_json:
        emit_json(
            {
                "initial": init,
                "sequence": format_sequence(moves),
                "moves": len(moves),
                "final": final,
            }
        )
        return
    click.echo(final)


@rubiks.command(
    "validate", context_settings=_CTX, short_help="Check an observed final state (exit 0/1/2)."
)
@click.option(
    "--initial",
    default=SOLVED_STRING,
    show_default="solved",
    metavar="FACELETS",
    help="State the cube was in before the sequence.",
)
@click.option("--sequence", "sequence", required=True, help="The moves the robot had to perform.")
@click.option(
    "--final", "final", required=True, metavar="FACELETS", help="The state you observed at the end."
)
@json_option
def validate_cmd(initial: str, sequence: str, final: str, as_json: bool) -> None:
    """Check an observed final state against the expected one (protocol step 6).

    Exit 0: FINAL is the expected state. Exit 1: it is not; the differing
    facelets are listed (e.g. "F5: expected F, got R"); a well-formed FINAL
    that no legal cube can show (a twisted corner, say) is also exit 1, with
    the reason. Exit 2: bad input (unknown move, illegal --initial, or a FINAL
    with the wrong length, letters, colour counts or centres).

    \b
    Example:
      benchharness rubiks validate --sequence "R U R' U'" \\
        --final UULUUFUUFRRUBRRURRFFDFFUFFFDDRDDDDDDBLLLLLLLLBRRBBBBBB
    """
    moves = _moves(sequence)
    init = _initial(initial)
    final = _facelets(final)
    malformed = format_problems(final)
    if malformed:
        fail("--final: " + "; ".join(malformed))
    expected = expected_final(moves, init)
    diffs = differences(expected, final)
    illegal = facelet_problems(final)
    if as_json:
        emit_json(
            {
                "match": not diffs,
                "expected_final": expected,
                "observed_final": final,
                "differences": [
                    {"facelet": d.name, "expected": d.expected, "got": d.observed} for d in diffs
                ],
                "observed_problems": illegal,
            }
        )
    elif not diffs:
        click.echo(f"ok: the final state is the expected one ({len(moves)} moves)")
    else:
        click.echo(f"mismatch: {len(diffs)} of 54 facelets differ from the expected state")
        click.echo(f"expected: {expected}")
        click.echo(f"got:      {final}")
        for problem in illegal:
            click.echo(f"note: the observed state is not a legal cube: {problem}")
        for d in diffs:
            click.echo(str(d))
    if diffs:
        raise SystemExit(EXIT_NEGATIVE)


@rubiks.command(
    "check", context_settings=_CTX, short_help="Say whether a facelet string is a legal cube."
)
@click.argument("facelets")
@json_option
def check_cmd(facelets: str, as_json: bool) -> None:
    """Say whether FACELETS is a legal cube, and if not, why (exit 0 / 1).

    \b
    Example:
      benchharness rubiks check UBULURUFURURFRBRDRFUFLFRFDFDFDLDRDBDLULBLFLDLBUBRBLBDB
    """
    problems = facelet_problems(_facelets(facelets))
    if as_json:
        emit_json({"valid": not problems, "problems": problems})
    elif problems:
        for p in problems:
            click.echo(f"invalid: {p}")
    else:
        click.echo("valid: a legal cube state")
    if problems:
        raise SystemExit(EXIT_NEGATIVE)


@rubiks.command(
    "score", context_settings=_CTX, short_help="Score a trial log: tier score and completion."
)
@click.argument("log", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--seed",
    type=click.IntRange(min=0, max=SEED_MAX),
    default=None,
    help="Also require each sequence to be the generator's for this seed.",
)
@json_option
def score_cmd(log: Path, seed: int | None, as_json: bool) -> None:
    """Score a trial log (CSV or JSON): success per trial, tier score, completion.

    Tier score = mean and sample standard deviation (ddof=1) of
    termination_s - first_contact_s over the M trials; completed only if trials
    1..M are all logged and all end in the expected state. Exit 0 when every
    tier in the log is completed, 1 when one is not, 2 for a bad log. Log format:
    docs/rubiks.md.

    \b
    Example:
      benchharness rubiks score examples/rubiks/trials.csv --seed 7
    """
    from ..metrics.rubiks import TrialLogError, read_log, score_log

    try:
        scores = score_log(read_log(log), seed=seed)
    except TrialLogError as exc:
        fail(str(exc))
    if as_json:
        emit_json({"seed": seed, "tiers": [s.to_dict() for s in scores]})
    else:
        for i, s in enumerate(scores):
            if i:
                click.echo("")
            _print_tier_score(s)
    if not all(s.completed for s in scores):
        raise SystemExit(EXIT_NEGATIVE)


def _fmt(mean: float | None, std: float | None) -> str:
    if mean is None:
        return "—"
    return f"{mean:.2f} s ± {'—' if std is None else f'{std:.2f} s'}"


def _print_tier_score(s) -> None:
    if s.completed:
        click.echo(
            f"{s.tier}: completed, score {_fmt(s.mean_s, s.std_s)} (mean ± sample std, "
            f"{s.trials_required} trial{'s' if s.trials_required != 1 else ''})"
        )
    else:
        click.echo(
            f"{s.tier}: NOT completed ({s.successes} of {s.trials_required} trials succeeded)"
        )
        if s.successes:
            click.echo(f"  successful trials only (not a tier score): {_fmt(s.mean_s, s.std_s)}")
        for p in s.problems:
            click.echo(f"  - {p}")
    for r in s.results:
        status = f"ok {r.score_s:.2f} s" if r.success else "FAILED"
        note = f"  ({r.trial.note})" if r.trial.note else ""
        click.echo(f"  trial {r.trial.trial}: {status}{note}")
    published = "; ".join(f"{b.label} {b.describe()}" for b in get_tier(s.tier).baselines)
    if published:
        click.echo(f"  published (Table I): {published}")
