"""Suite-wide test configuration.

* Tests under ``tests/backends`` and ``tests/robots`` are marked ``sim`` so the
  simulator-free tox environment can deselect them.
* ``BENCHHARNESS_BACKENDS=pybullet`` (comma-separated) restricts every test
  parametrised over a backend name to those backends (used by tox).
"""

from __future__ import annotations

import importlib.util
import os

import matplotlib
import pytest

matplotlib.use("Agg")

BACKEND_NAMES = ("pybullet", "sapien")

#: Test folders/files that need the simulator extras (``pip install -e '.[sim]'``).
#: Without them (tox's ``core`` environment) they are not collected at all,
#: rather than failing on import.
SIM_MODULES = ("pybullet", "sapien", "torch", "pytorch_kinematics")
SIM_TESTS = [
    *(
        f"{d}{suffix}"
        for d in ("backends", "robots", "cube_physics", "strategies")
        for suffix in ("", "/*")
    ),
    "test_ingrasp*.py",
    "test_example_plugin.py",
]
collect_ignore_glob = (
    SIM_TESTS if any(importlib.util.find_spec(m) is None for m in SIM_MODULES) else []
)


def pytest_collection_modifyitems(config, items):
    wanted = {
        b.strip() for b in os.environ.get("BENCHHARNESS_BACKENDS", "").split(",") if b.strip()
    }
    for item in items:
        parts = set(item.nodeid.replace("\\", "/").split("/"))
        if "backends" in parts or "robots" in parts:
            item.add_marker(pytest.mark.sim)
        if not wanted:
            continue
        params = getattr(getattr(item, "callspec", None), "params", {})
        used = {v for v in params.values() if isinstance(v, str) and v in BACKEND_NAMES}
        if used and not used <= wanted:
            item.add_marker(
                pytest.mark.skip(reason=f"backend not in BENCHHARNESS_BACKENDS={sorted(wanted)}")
            )


@pytest.fixture
def make_backend():
    """make_backend(name) -> a fresh backend from the plugin manager; closed after the test."""
    from benchharness.plugin import get_manager

    made = []

    def _make(name: str):
        be = get_manager().create("backend", name)
        made.append(be)
        return be

    yield _make
    for be in made:
        be.close()


@pytest.fixture
def make_robot():
    """make_robot(name, **kwargs) -> a fresh robot object from the plugin manager."""
    from benchharness.plugin import get_manager

    def _make(name: str, **kwargs):
        return get_manager().create("robot", name, **kwargs)

    return _make
