"""``benchharness inhand``: in-hand manipulation benchmark scoring.

Heavy imports (trimesh, matplotlib, odfpy) happen inside the commands so that
``benchharness --help`` stays fast.
"""

from __future__ import annotations

import math
from pathlib import Path

import click

from .common import emit_json, fail, json_option


@click.group()
def inhand() -> None:
    """In-hand manipulation benchmark: score recorded results, plot, import the published data."""


def _fmt(x: float, digits: int = 3) -> str:
    """Three significant figures: the precision the paper reports."""
    if x is None or not math.isfinite(x):
        return "-"
    if x == 0:
        return "0"
    if abs(x) >= 1e9:  # a huge error is shown, not spelled out in 200 digits
        return f"{x:.{digits}g}"
    if abs(x) >= 10**digits:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


def _cell(stats, scale: float) -> str:
    if stats.n == 0:
        return "-"
    return f"{_fmt(stats.median * scale)} [{_fmt(stats.q1 * scale)}, {_fmt(stats.q3 * scale)}]"


def _num(x: float) -> float | None:
    """JSON has no NaN: a statistic of an empty sample is null."""
    return float(x) if x is not None and math.isfinite(x) else None


def _json_summary(summaries, metrics):
    from ..metrics.inhand import METRICS

    groups = []
    for s in summaries:
        ms = {}
        for m in metrics:
            b, info = s.stats[m], METRICS[m]
            k = info.scale
            ms[m] = {
                "unit": info.unit,
                "n": b.n,
                "median": _num(b.median * k),
                "q1": _num(b.q1 * k),
                "q3": _num(b.q3 * k),
                "whisker_low": _num(b.whisker_low * k),
                "whisker_high": _num(b.whisker_high * k),
                "min": _num(b.minimum * k),
                "max": _num(b.maximum * k),
                "mean": _num(b.mean * k),
            }
        groups.append(
            {
                "key": dict(zip(s.by, s.key)),
                "n_trials": s.n_trials,
                "n_dropped": s.n_dropped,
                "n_discarded": s.n_discarded,
                "drops_percent": _num(s.drops_percent),
                "metrics": ms,
            }
        )
    return groups


def _discarded_rows(scored):
    r, sc = scored.results, scored.scores
    rows = []
    for i in map(int, sc.discarded.nonzero()[0]):
        d = r.row(i)
        d.update(
            setup_err_pos_cm=float(sc.setup.pos[i] * 100),
            setup_err_pos_percent=float(sc.setup.pos_percent[i]),
            setup_err_or_percent=float(sc.setup.or_percent[i]),
        )
        rows.append(d)
    return rows


@inhand.command("score")
@click.argument("results_file", metavar="RESULTS", type=click.Path(path_type=Path))
@click.option(
    "--by",
    "by",
    default="method",
    show_default=True,
    help="Comma-separated grouping columns (method, object, task_id, level, or any extra column). "
    "Methods are never pooled: --by object groups by method and object.",
)
@click.option(
    "--plot",
    "plot_path",
    type=click.Path(path_type=Path),
    default=None,
    help="Write a Figure-7-style box plot (per object, one box per method); .png or .svg.",
)
@click.option(
    "--discarded",
    "show_discarded",
    is_flag=True,
    help="List the trials discarded by the 10 % set-up rule (section II-B).",
)
@click.option(
    "--geodesic",
    type=click.Choice(["heat", "exact"]),
    default="heat",
    show_default=True,
    help="Geodesic distances for G_geo: heat method (cached, fast) or exact (pygeodesic).",
)
@click.option(
    "--contact-tol",
    type=float,
    default=2e-3,
    show_default=True,
    help="Distance (m) from the object surface within which a mesh point counts as contact.",
)
@click.option(
    "--normalize-quaternions",
    is_flag=True,
    help="Normalise quaternions before eq. 3 (default: as recorded, which reproduces the paper).",
)
@json_option
def score_cmd(
    results_file: Path,
    by: str,
    plot_path: Path | None,
    show_discarded: bool,
    geodesic: str,
    contact_tol: float,
    normalize_quaternions: bool,
    as_json: bool,
) -> None:
    """Score a recorded-results file (CSV or JSON, format in docs/inhand.md).

    Prints, per group, drops %, median [first quartile, third quartile] of
    err_pos (cm), err_pos%, err_or%, the contact-region errors G_euc, G_geo,
    G_min (cm) where the file has contacts and an object mesh, the set-up
    errors where set-up poses were recorded, and plan/execution times.
    Trials whose set-up missed the dataset initial pose by more than 10 %
    are discarded; dropped trials count in drops % only.

    Example, scoring the published YuMi/DMG Level III results per object:

    \b
      benchharness inhand score tasks/inhand/published/yumi_lvl3_dmg.csv --by object
      benchharness inhand score tasks/inhand/published/allegro_lvl1_relaxed_rigidity.csv \\
          --by object --plot allegro.png --json
    """
    from ..inhand.fileformat import FileFormatError, read_results
    from ..inhand.scoring import metrics_present, score_results, summarize
    from ..metrics.inhand import METRICS

    if plot_path is not None and plot_path.suffix.lower() not in (".png", ".svg"):
        fail(f"--plot: {plot_path} must end in .png or .svg")
    if not (math.isfinite(contact_tol) and contact_tol >= 0):
        fail(f"--contact-tol {contact_tol:g}: must be a non-negative distance in metres")
    try:
        results = read_results(results_file)
        scored = score_results(
            results, geodesic=geodesic, contact_tol=contact_tol, normalize=normalize_quaternions
        )
        summaries = summarize(scored, [b.strip() for b in by.split(",")])
    except FileFormatError as e:
        fail(str(e))
    except KeyError as e:
        fail(f"--by: {e.args[0]}")
    except ValueError as e:  # the metrics' own checks (e.g. an error beyond the float range)
        fail(f"{results_file}: {e}")
    metrics = metrics_present(summaries)
    discarded = _discarded_rows(scored)
    has_setup = bool(results.has_setup.any())

    if plot_path is not None:
        from ..inhand.scoring import group_columns
        from ..metrics.inhand import summarize_scores
        from ..metrics.plots import box_plot

        plot_metrics = [
            m
            for m in ("err_pos", "err_pos_percent", "err_or_percent", "g_euc", "g_geo")
            if m in metrics
        ]
        per_object = summarize_scores(
            scored.scores, group_columns(results), ("object", "method"), results.dropped
        )
        box_plot(
            per_object,
            plot_metrics,
            plot_path,
            labels={m: f"{METRICS[m].label} ({METRICS[m].unit})" for m in plot_metrics},
            scales={m: METRICS[m].scale for m in plot_metrics},
            title=results_file.name,
        )

    if as_json:
        out = {
            "file": str(results_file),
            "n_trials": len(results),
            "by": list(summaries[0].by),
            "setup_rule_applied": has_setup,
            "groups": _json_summary(summaries, metrics),
        }
        if show_discarded:
            out["discarded"] = discarded
        if plot_path is not None:
            out["plot"] = str(plot_path)
        emit_json(out)
        return

    from rich.table import Table

    from .common import console as rich_console
    from .common import print_table

    console = rich_console()
    table = Table(title=f"{results_file.name}: median [Q1, Q3] per {', '.join(summaries[0].by)}")
    for b in summaries[0].by:
        table.add_column(b, no_wrap=True)
    table.add_column("n", justify="right")
    table.add_column("drops %", justify="right")
    for m in metrics:
        table.add_column(f"{METRICS[m].label} ({METRICS[m].unit})", justify="right", no_wrap=True)
    for s in summaries:
        table.add_row(
            *s.key,
            str(s.n_trials),
            _fmt(s.drops_percent),
            *[_cell(s.stats[m], METRICS[m].scale) for m in metrics],
        )
    print_table(table, console)
    n_disc = len(discarded)
    if has_setup:
        console.print(f"{n_disc} of {len(results)} trials discarded by the 10 % set-up rule.")
    else:
        console.print("No set-up poses recorded: the 10 % set-up rule was not applied.")
    if show_discarded and n_disc:
        t = Table(title="Discarded trials (set-up error > 10 %)")
        for c in (
            "method",
            "object",
            "task_id",
            "trial",
            "setup err_pos (cm)",
            "setup err_pos%",
            "setup err_or%",
        ):
            t.add_column(c)
        for d in discarded:
            t.add_row(
                d["method"],
                d["object"],
                d["task_id"],
                str(d["trial"]),
                _fmt(d["setup_err_pos_cm"]),
                _fmt(d["setup_err_pos_percent"]),
                _fmt(d["setup_err_or_percent"]),
            )
        print_table(t, console)
    if plot_path is not None:
        console.print(f"Box plot written to {plot_path}")


@inhand.command("import-bih")
@click.option(
    "--source",
    type=click.Path(path_type=Path),
    default=None,
    help="The published dataset folder (default: ../shared/data/bih_dataset next to the repository).",
)
@click.option(
    "--out",
    type=click.Path(path_type=Path),
    default=None,
    help="Output folder (default: the repository's tasks/inhand).",
)
@json_option
def import_bih_cmd(source: Path | None, out: Path | None, as_json: bool) -> None:
    """Convert the published in-hand benchmark dataset (.ods) into task and results CSVs.

    Writes level1_hand_poses.csv, level3_dmg_tasks.csv and
    published/{allegro_lvl1_relaxed_rigidity,yumi_lvl3_dmg}.csv; the output
    is deterministic, so re-running it reproduces the committed files.

    \b
    Example:
      benchharness inhand import-bih --source ../shared/data/bih_dataset --out tasks/inhand
    """
    from ..inhand.bih_import import BihImportError, convert_bih

    try:
        report = convert_bih(source, out)
    except BihImportError as e:
        fail(str(e))
    if as_json:
        emit_json(
            {
                "source": str(report.source),
                "out": str(report.out),
                "files": [str(f) for f in report.files],
                "counts": report.counts,
            }
        )
        return
    click.echo(f"Converted {report.source}")
    for f in report.files:
        click.echo(f"  wrote {f}")
    click.echo("  " + ", ".join(f"{k}={v}" for k, v in report.counts.items()))


@inhand.command("regions")
@click.argument("store", metavar="STORE", type=click.Path(path_type=Path))
@json_option
def regions_cmd(store: Path, as_json: bool) -> None:
    """Contact-region errors (G_euc, G_geo, G_min) of the DMG trials in a results store.

    Reads STORE (the SQLite file ``benchharness run`` writes) without
    modifying it: every stored trial of ``inhand-level3-dmg`` and
    ``inhand-level2-dmg-regions``, and for successful trials with reached
    contacts Algorithm 1 on our mesh in the task frame (docs/dmg.md).

    \b
    Example:
      benchharness inhand regions benchharness-results.sqlite
    """
    from ..runner.contact_regions import score_store

    if not store.is_file():
        fail(f"{store}: no such results store")
    try:
        rows = score_store(store)
    except (OSError, ValueError) as exc:
        fail(str(exc))
    if as_json:
        emit_json({"store": str(store), "trials": rows})
        return
    from rich.table import Table

    from .common import print_table
    from .run import _esc

    t = Table(title=f"contact-region errors of the DMG trials in {_esc(store)} (cm)")
    for c in ("task", "backend", "trial", "task id", "status"):
        t.add_column(c, overflow="fold", justify="right" if c == "trial" else "left")
    for c in ("G_euc", "G_geo", "G_min"):
        t.add_column(c, justify="right")
    for r in rows:
        g = [f"{r[k] * 100:.3f}" if k in r else "—" for k in ("g_euc", "g_geo", "g_min")]
        t.add_row(
            _esc(r["task"]),
            _esc(r["backend"]),
            str(r["trial"]),
            _esc(r["task_id"]),
            _esc(r["status"]),
            *g,
        )
    print_table(t)
    if not rows:
        click.echo("No DMG trials in this store (benchharness run --task inhand-level3-dmg ...).")


@inhand.command("region-tasks")
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(dir_okay=False, path_type=Path),
    help="Where to write the Level II task CSV (the tracked one is tasks/inhand/level2_dmg_regions.csv).",
)
@json_option
def region_tasks_cmd(out: Path, as_json: bool) -> None:
    """Derive the Level II contact-region task file from the published DMG tasks and write it to --out.

    Deterministic: writing it over tasks/inhand/level2_dmg_regions.csv
    reproduces the committed file (docs/dmg.md says how it is derived).

    \b
    Example:
      benchharness inhand region-tasks --out /tmp/level2_dmg_regions.csv
    """
    from ..runner.contact_regions import write_region_tasks

    if not out.parent.is_dir():
        fail(f"--out {out}: folder {out.parent} does not exist")
    path = write_region_tasks(out)
    if as_json:
        emit_json({"written": str(path)})
    else:
        click.echo(f"wrote {path}")
