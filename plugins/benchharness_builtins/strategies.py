"""Built-in manipulation strategies.

Each strategy family keeps its registrations beside its code, in its
package's ``REGISTRATIONS`` (summaries, factories, and the ``benchmarks`` and
``robots`` it declares, see :mod:`benchharness.runner.contract`); this module
names the packages. The list is explicit, like every other built-in module's:
a package that is misspelled or lacks ``REGISTRATIONS`` fails at import
instead of registering nothing.
"""

from __future__ import annotations

from benchharness.plugin import Registration, hookimpl
from benchharness.strategies import dmg, herb_rubiks, ingrasp, pivoting, pr2_rubiks

#: The strategy packages (``regrasp`` is the Rubik's planner library, not a strategy).
PACKAGES = (dmg, herb_rubiks, ingrasp, pivoting, pr2_rubiks)


@hookimpl
def benchharness_strategies() -> list[Registration]:
    return [reg for package in PACKAGES for reg in package.REGISTRATIONS]
