"""``benchharness inhand``: in-hand manipulation benchmark scoring."""

import click


@click.group()
def inhand() -> None:
    """In-hand manipulation benchmark: score recorded results, plot."""
