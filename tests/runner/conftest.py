"""Fixtures for the runner tests.

The test-only strategies live in ``runner_testplugins`` (this folder, which
pytest puts on ``sys.path``; spawned sweep workers inherit ``sys.path``) and
are registered per run with ``plugins=("runner_testplugins",)`` /
``--plugin runner_testplugins``, never in the built-in registry.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

HERE = Path(__file__).resolve().parent
PLUGIN = "runner_testplugins"


@pytest.fixture
def store_path(tmp_path: Path) -> Path:
    return tmp_path / "results.sqlite"


@pytest.fixture
def make_spec():
    from benchharness.runner import RunSpec, TimeBudget

    def make(
        strategy: str = "test-drop",
        task: str = "Rubiks-5-5",
        backend: str = "pybullet",
        seed: int = 0,
        budget: TimeBudget | None = None,
        **kw,
    ):
        return RunSpec(
            task=task,
            robot="test-stub",
            strategy=strategy,
            backend=backend,
            seed=seed,
            plugins=(PLUGIN,),
            budget=budget or TimeBudget(sim_s=30.0),
            **kw,
        )

    return make


@pytest.fixture
def invoke(store_path: Path):
    """Invoke one of the runner's click commands against the test store."""

    def call(command, *args: str, store: Path | None = None):
        argv = [*args, "--store", str(store or store_path)]
        return CliRunner().invoke(command, argv, catch_exceptions=False)

    return call
