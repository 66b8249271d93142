"""Built-in Rubik's cube tasks: the paper's twelve tiers, one task each.

The tiers are data (``tasks/rubiks/tiers.toml``); this module only announces
them through the ``benchharness_tasks`` hook, exactly as a third-party plugin
would announce its own tasks. Each factory returns the typed
:class:`benchharness.cube.tiers.RubiksTier`.
"""

from __future__ import annotations

from functools import partial

from benchharness.cube.tiers import RubiksTier, get_tier, load_tiers
from benchharness.plugin import Registration, hookimpl


def make_tier(name: str) -> RubiksTier:
    return get_tier(name)


@hookimpl
def benchharness_tasks() -> list[Registration]:
    regs = []
    for tier in load_tiers().values():
        meta = {
            "benchmark": "rubiks",
            "trials": tier.trials,
            "moves": tier.moves,
            "baselines": {b.key: b.describe() for b in tier.baselines},
        }
        regs.append(Registration(tier.name, partial(make_tier, tier.name), tier.summary, meta))
    return regs
