"""Entry point of the ``benchharness`` console script."""

from __future__ import annotations

import importlib

import click

from .. import __version__

#: Subcommand modules and the click object each exports. Each subcommand lives
#: in its own module so that importing the CLI does not import simulators.
SUBCOMMANDS = {
    "plugins": ("benchharness.cli.plugins", "plugins_cmd"),
    "rubiks": ("benchharness.cli.rubiks", "rubiks"),
    "inhand": ("benchharness.cli.inhand", "inhand"),
    "robots": ("benchharness.cli.robots", "robots_cmd"),
    "robot": ("benchharness.cli.robots", "robot"),
    "run": ("benchharness.cli.run", "run"),
    "table": ("benchharness.cli.run", "table"),
    "compare": ("benchharness.cli.run", "compare"),
    "results": ("benchharness.cli.run", "results"),
}


class LazyGroup(click.Group):
    """Imports a subcommand's module only when that subcommand is used."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(SUBCOMMANDS)

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        target = SUBCOMMANDS.get(name)
        if target is None:
            return None
        module, attr = target
        return getattr(importlib.import_module(module), attr)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="benchharness")
def cli() -> None:
    """Run and score the Rubik's cube and in-hand manipulation benchmarks.

    Protocol software (sequences, validation, metrics) works on real-robot
    logs; simulation runs use PyBullet or SAPIEN through plugins.
    """


def main() -> None:
    cli()


if __name__ == "__main__":
    main()
