"""Fixtures for the strategy tests: a TrialContext built in-process, as the runner builds one."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture
def make_ctx():
    """``make_ctx(backend_name, sequence_text, seed=0)`` -> (ctx, backend); the backend is closed afterwards."""
    from benchharness.backends.interface import PhysicsConfig
    from benchharness.cube import parse_sequence
    from benchharness.plugin import get_manager
    from benchharness.runner.contract import RubiksItem, TimeBudget, TrialContext
    from benchharness.runner.recorder import TrialRecorder

    made = []

    def make(backend: str, sequence: str = "R", seed: int = 0):
        m = get_manager()
        phys = PhysicsConfig(seed=seed)
        b = m.create("backend", backend, config=phys)
        made.append(b)
        seq = tuple(parse_sequence(sequence))
        item = RubiksItem("Rubiks-1-1", 1, 1, seq, seed)
        rec = TrialRecorder(clock=lambda: float(b.time))
        ctx = TrialContext(
            item=item,
            trial_index=1,
            robot=m.create("robot", "pr2"),
            backend=b,
            sensors={},
            rng=np.random.default_rng(seed),
            budget=TimeBudget(),
            recorder=rec,
            physics=phys,
        )
        return ctx, b

    yield make
    for b in made:
        b.close()
