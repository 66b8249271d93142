"""``benchharness robots`` and ``benchharness robot``: robot plugins."""

import click


@click.command("robots")
def robots_cmd() -> None:
    """List registered robots."""


@click.group()
def robot() -> None:
    """Inspect one robot."""
