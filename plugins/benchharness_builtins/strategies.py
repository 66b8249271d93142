"""Built-in manipulation strategies.

Each strategy family keeps its registrations in its own module under
``benchharness.strategies``; this entry point collects them so adding a
strategy never means editing a shared list here.
"""

from __future__ import annotations

import importlib
import pkgutil

from benchharness.plugin import Registration, hookimpl


@hookimpl
def benchharness_strategies() -> list[Registration]:
    import benchharness.strategies as pkg

    regs: list[Registration] = []
    for info in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda i: i.name):
        module = importlib.import_module(f"{pkg.__name__}.{info.name}")
        regs.extend(getattr(module, "REGISTRATIONS", []))
    return regs
