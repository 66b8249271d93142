"""The runnable example in docs/sensors.md runs and does what the page says."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

pytest.importorskip("filterpy")

DOC = Path(__file__).resolve().parents[2] / "docs" / "sensors.md"

pytestmark = pytest.mark.sim


def _example() -> str:
    text = DOC.read_text(encoding="utf-8")
    section = text.split("## Runnable example", 1)[1]
    return re.search(r"```python\n(.*?)```", section, flags=re.S).group(1)


@pytest.mark.parametrize("backend_name", ["pybullet", "sapien"])
def test_doc_example_runs(capsys, backend_name):
    """The page shows PyBullet's output; SAPIEN's ray casts agree, so it prints the same."""
    code = _example().replace('"pybullet"', repr(backend_name), 1)
    ns: dict = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        exec(compile(code, str(DOC), "exec"), ns)
    out = capsys.readouterr().out
    text = DOC.read_text(encoding="utf-8")
    promised = re.search(r"it prints\n\n((?:    .*\n)+)", text).group(1)
    assert out.strip().splitlines() == [ln[4:] for ln in promised.strip("\n").splitlines()]
    filt = float(re.search(r"filter: ([0-9.]+) mm", out).group(1))
    assert filt < 3.0
    assert ns["report"].n_used > 60
    kf = ns["kf"]
    assert kf.estimate.position_std.max() > ns["est"].position_std.max()  # the carry grew it
