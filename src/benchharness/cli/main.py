"""Entry point of the ``benchharness`` console script."""

from __future__ import annotations

import gc
import importlib
import os
import sys

# One BLAS thread unless the user says otherwise, set before NumPy is first
# imported (``.common`` imports it). Our linear algebra is small (poses,
# 7-joint Jacobians, Kalman updates), below the size where OpenBLAS splits
# work over threads, so its thread pool only costs start-up: importing NumPy
# with the default pool took 0.18 CPU-s here against 0.13 CPU-s with one
# thread, which is what keeps ``rubiks expect`` over its 0.15 CPU-s target
# (BENCHMARKS.md, issue 12). Trial worker processes inherit the setting.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import click

from .. import __version__
from .common import error_line

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
    "sweep": ("benchharness.cli.sweep", "sweep"),
}


class LazyGroup(click.Group):
    """Imports a subcommand's module only when that subcommand is used.

    Also prints click's own usage errors (an unknown option, a value out of
    range) as the one line every other bad input gets, a JSON object under
    ``--json``, exit 2 as before.
    """

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        argv = list(sys.argv[1:] if args is None else args)
        try:
            rv = super().main(argv, prog_name, complete_var, standalone_mode=False, **extra)
        except click.exceptions.UsageError as exc:
            message = exc.format_message()
            if exc.ctx is not None and exc.ctx.command_path and "--json" not in argv:
                message += f" (see {exc.ctx.command_path} --help)"
            click.echo(error_line(message, exc.exit_code, "--json" in argv), err=True)
            sys.exit(exc.exit_code)
        except click.ClickException as exc:
            click.echo(error_line(exc.format_message(), exc.exit_code, "--json" in argv), err=True)
            sys.exit(exc.exit_code)
        except click.exceptions.Abort:
            click.echo("Aborted!", err=True)
            sys.exit(1)
        if not standalone_mode:
            return rv
        sys.exit(rv if isinstance(rv, int) else 0)

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


def main(argv: list[str] | None = None, prog_name: str | None = None) -> None:
    """The console script: the command, then a cheaper interpreter exit.

    After the command has returned (its results written, its files closed),
    every object still alive is moved out of the garbage collector's reach
    (``gc.freeze``). The interpreter's exit would otherwise run full cycle
    collections over them: with torch imported (a Rubik's trial's arm check
    imports it through pytorch-kinematics) that traversal cost 0.3-0.5 CPU-s
    of a Rubiks-1-20 ``run`` command's exit, against a 1 CPU-s fixed-cost
    target (issue 12, BENCHMARKS.md "exit freeze"). Reference counting still frees objects and
    ``atexit`` handlers (process pools, Ray) still run; only cyclic garbage
    left at exit goes back to the OS with the process instead of being
    collected first.
    """
    try:
        cli.main(argv, prog_name=prog_name)
    finally:
        gc.freeze()


if __name__ == "__main__":
    main()
