"""Layering rules that keep the project livable (DESIGN.md "Layers").

* the metric module is pure: importing it pulls in no simulator, no torch and
  no plotting library, so real-robot users can score logs anywhere;
* importing the CLI imports no simulator (subcommands load lazily);
* only ``benchharness/backends`` imports pybullet or sapien.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "benchharness"
HEAVY = ("pybullet", "sapien", "torch", "matplotlib")


@pytest.mark.parametrize(
    "module", ["benchharness.metrics", "benchharness.cli.main", "benchharness.cube"]
)
def test_import_is_light(module):
    code = (
        f"import sys, {module}\n"
        f"heavy = sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r}))\n"
        "print(','.join(heavy))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert out == "", f"importing {module} pulled in {out}"


def test_only_backends_import_engines():
    pattern = re.compile(r"^\s*(import|from)\s+(pybullet|sapien)\b", re.M)
    offenders = [
        str(p.relative_to(SRC))
        for p in SRC.rglob("*.py")
        if "backends" not in p.relative_to(SRC).parts and pattern.search(p.read_text())
    ]
    assert offenders == []
