"""``benchharness rubiks``: the Rubik's cube protocol software."""

import click


@click.group()
def rubiks() -> None:
    """Rubik's cube protocol: sequences, expected states, validation."""
