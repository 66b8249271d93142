import sys
import warnings
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))  # backend_scenes.py

from benchharness.backends import Backend, PhysicsConfig
from benchharness.plugin import get_manager

BACKEND_ITEMS = get_manager().items("backend")


# An empty parameter list would make pytest skip every test: with no backend registered the
# suite must fail instead, so it then runs once with None and the fixture fails.
@pytest.fixture(
    params=BACKEND_ITEMS or [None], ids=[it.name for it in BACKEND_ITEMS] or ["no-backend"]
)
def item(request):
    if request.param is None:
        pytest.fail("no backend is registered: the conformance suite has nothing to test")
    return request.param


@pytest.fixture
def make(item):
    """make(**config) -> a fresh Backend of the parametrised kind; closed after the test."""
    made: list[Backend] = []

    def _make(**cfg) -> Backend:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            b = item.create(config=PhysicsConfig(**cfg))
        made.append(b)
        return b

    yield _make
    for b in made:
        b.close()


@pytest.fixture
def backend(make) -> Backend:
    return make()
