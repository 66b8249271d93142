"""``benchharness plugins``: what is registered, by whom, what failed to load, what is disabled."""

from __future__ import annotations

import click
from rich.markup import escape
from rich.table import Table

from ..plugin import DISABLED_ENV, KIND_HOOKS, get_manager
from .common import console as rich_console
from .common import emit_json, fail, json_option, print_table


@click.command("plugins")
@click.option(
    "--kind",
    type=click.Choice(list(KIND_HOOKS)),
    default=None,
    help="Only list items of this kind.",
)
@click.option(
    "--options",
    "options_of",
    metavar="STRATEGY",
    default=None,
    help="List what --strategy-option can set for this strategy: key, type, default.",
)
@json_option
def plugins_cmd(kind: str | None, options_of: str | None, as_json: bool) -> None:
    """List every registered backend, robot, sensor, strategy and task.

    Items come from the 'benchharness' entry-point group: built-ins and
    third-party distributions alike. Plugins that failed to load are listed
    with the entry point, the distribution and the reason; entry points named
    in BENCHHARNESS_DISABLED_PLUGINS (comma-separated) are not loaded and are
    listed as disabled. With --options STRATEGY, lists the fields of that
    strategy's configuration that `run --strategy-option KEY=VALUE` may set.
    """
    manager = get_manager()
    if options_of is not None:
        _list_options(manager, options_of, as_json)
        return
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


def _list_options(manager, name: str, as_json: bool) -> None:
    """The ``--strategy-option`` keys of one strategy (exit 2 naming an unknown strategy)."""
    from ..plugin import PluginNotFoundError
    from ..runner.options import describe_options

    try:
        item = manager.get("strategy", name)
    except PluginNotFoundError as exc:
        fail(str(exc))
    rows = describe_options(item.options()) if item.options is not None else []
    if as_json:
        emit_json(
            {
                "strategy": item.name,
                "options": [
                    {"key": k, "type": t, "default": d, "doc": doc} for k, t, d, doc in rows
                ],
            }
        )
        return
    console = rich_console()
    if not rows:
        console.print(f"strategy {escape(item.name)} declares no options")
        return
    table = Table(title=f"--strategy-option keys of {item.name}")
    for col in ("key", "type", "default", "what"):
        table.add_column(col)
    for k, t, d, doc in rows:
        table.add_row(escape(k), escape(t), escape(d), escape(_first_sentence(doc)))
    print_table(table, console)


def _first_sentence(text: str, limit: int = 100) -> str:
    """A field comment's first sentence, cut to ``limit`` characters (``--json`` has it whole)."""
    import re

    head = re.split(r"(?<=\.)\s", text, maxsplit=1)[0]
    return head if len(head) <= limit else head[: limit - 1].rstrip() + "\u2026"
