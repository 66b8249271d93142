import sys
import warnings
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))  # backend_scenes.py

from benchharness.backends import Backend, PhysicsConfig
from benchharness.plugin import get_manager

BACKEND_ITEMS = get_manager().items("backend")


@pytest.fixture(params=BACKEND_ITEMS, ids=[it.name for it in BACKEND_ITEMS])
def item(request):
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
