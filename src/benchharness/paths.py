"""Where the data folders (``tasks/``, ``robots/``) are.

In a source checkout (editable install) they are the repository's own
top-level folders; in a wheel they are packaged under ``benchharness/_data``.
``BENCHHARNESS_DATA`` overrides both (a folder holding ``tasks/`` and
``robots/``).
"""

from __future__ import annotations

import os
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def data_root() -> Path:
    env = os.environ.get("BENCHHARNESS_DATA")
    if env:
        return Path(env)
    packaged = _PACKAGE / "_data"
    if packaged.is_dir():
        return packaged
    return _PACKAGE.parents[1]  # src/benchharness -> repository root


def tasks_dir() -> Path:
    return data_root() / "tasks"


def robots_dir() -> Path:
    return data_root() / "robots"
