"""``benchharness plugins``: what is registered, by whom, what failed to load, what is disabled."""

from __future__ import annotations

import click
from rich.markup import escape
from rich.table import Table

from ..plugin import DISABLED_ENV, KIND_HOOKS, get_manager
from .common import console as rich_console
from .common import emit_json, json_option, print_table


@click.command("plugins")
@click.option(
    "--kind",
    type=click.Choice(list(KIND_HOOKS)),
    default=None,
    help="Only list items of this kind.",
)
@json_option
def plugins_cmd(kind: str | None, as_json: bool) -> None:
    """List every registered backend, robot, sensor, strategy and task.

    Items come from the 'benchharness' entry-point group: built-ins and
    third-party distributions alike. Plugins that failed to load are listed
    with the entry point, the distribution and the reason; entry points named
    in BENCHHARNESS_DISABLED_PLUGINS (comma-separated) are not loaded and are
    listed as disabled.
    """
    manager = get_manager()
    items = manager.items(kind)
    if as_json:
        emit_json(
            {
                "items": [it.describe() for it in items],
                "errors": [
                    {
                        "entry_point": e.entry_point,
                        "distribution": e.distribution,
                        "reason": e.reason,
                    }
                    for e in manager.errors
                ],
                "disabled": [
                    {"entry_point": d.entry_point, "distribution": d.distribution}
                    for d in manager.disabled
                ],
                "disabled_unmatched": list(manager.disabled_unmatched),
            }
        )
        return
    console = rich_console()
    table = Table(title="benchharness plugins")
    for col in ("kind", "name", "distribution", "entry point", "summary"):
        table.add_column(col)
    # stable sort: by kind, then in registration order (tiers stay 1-5, 1-10, ...); the
    # entry point column shows the name BENCHHARNESS_DISABLED_PLUGINS takes
    for it in sorted(items, key=lambda i: list(KIND_HOOKS).index(i.kind)):
        table.add_row(
            it.kind, it.name, it.distribution, escape(it.entry_point.split(" = ")[0]), it.summary
        )
    print_table(table, console)
    for e in manager.errors:
        console.print(f"[red]failed:[/red] {escape(str(e))}")
    for d in manager.disabled:
        console.print(f"[yellow]disabled:[/yellow] {escape(str(d))}")
    for name in manager.disabled_unmatched:
        console.print(
            f"[yellow]{DISABLED_ENV}[/yellow] names {escape(repr(name))}, which is no entry point"
        )
