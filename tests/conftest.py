"""Suite-wide test configuration.

* Tests under ``tests/backends`` and ``tests/robots`` are marked ``sim`` so the
  simulator-free tox environment can deselect them.
* ``BENCHHARNESS_BACKENDS=pybullet`` (comma-separated) restricts every test
  parametrised over a backend name to those backends (used by tox).
"""

from __future__ import annotations

import os

import matplotlib
import pytest

matplotlib.use("Agg")

BACKEND_NAMES = ("pybullet", "sapien")


def pytest_collection_modifyitems(config, items):
    wanted = {b.strip() for b in os.environ.get("BENCHHARNESS_BACKENDS", "").split(",") if b.strip()}
    for item in items:
        parts = set(item.nodeid.replace("\\", "/").split("/"))
        if "backends" in parts or "robots" in parts:
            item.add_marker(pytest.mark.sim)
        if not wanted:
            continue
        params = getattr(getattr(item, "callspec", None), "params", {})
        used = {v for v in params.values() if isinstance(v, str) and v in BACKEND_NAMES}
        if used and not used <= wanted:
            item.add_marker(pytest.mark.skip(reason=f"backend not in BENCHHARNESS_BACKENDS={sorted(wanted)}"))
