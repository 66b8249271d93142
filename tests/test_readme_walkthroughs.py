"""The README's simulation walkthroughs run as shown (slow: whole trials on both engines).

``tests/test_readme.py`` runs the protocol and scoring examples; the
``run`` / ``compare`` / ``table`` examples of the walkthroughs simulate whole
trials, so they run here under ``-m slow``, in the order the README gives,
against one fresh results store. Each must exit 0 or 1 (1: a negative
result, e.g. a tier not completed, which the README explains) and print the
trial-row prefixes the README shows (``│     1 │`` ...): the same trials
ran. Outcomes themselves are deterministic per machine, not across
machines, so the shown figures are not compared.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

pytestmark = [pytest.mark.slow, pytest.mark.sim]


def walkthrough_examples() -> list[tuple[str, list[str]]]:
    text = (ROOT / "README.md").read_text()
    out: list[tuple[str, list[str]]] = []
    for section in re.split(r"\n### ", text):
        if not section.startswith("Walkthrough"):
            continue
        for block in re.findall(r"```console\n(.*?)```", section, flags=re.S):
            current = None
            for line in block.splitlines():
                if line.startswith("$ "):
                    current = (line[2:].split("  #")[0].strip(), [])
                    out.append(current)
                elif current is not None and line.strip() and line.strip() != "...":
                    current[1].append(line.rstrip())
    return out


def test_the_readme_has_walkthroughs():
    cmds = [c for c, _ in walkthrough_examples()]
    assert any("inhand-level1" in c for c in cmds) and any("inhand-level3-dmg" in c for c in cmds)
    assert any("Rubiks-" in c for c in cmds)


def test_walkthroughs_run_as_shown(tmp_path):
    env = {
        **os.environ,
        "BENCHHARNESS_STORE": str(tmp_path / "results.sqlite"),
        "MPLBACKEND": "Agg",
    }
    for command, shown in walkthrough_examples():
        argv = shlex.split(command)
        assert argv[0] == "benchharness", command
        argv = [
            a if not a.endswith((".png", ".mp4", ".gif")) else str(tmp_path / a) for a in argv[1:]
        ]
        proc = subprocess.run(
            [
                sys.executable,
                "-m",
                "benchharness.cli.main",
                *argv,
                *(["--no-progress"] if argv[0] in ("run", "compare") else []),
            ],
            capture_output=True,
            text=True,
            cwd=ROOT,
            timeout=3000,
            env=env,
        )
        output = proc.stdout + proc.stderr
        assert proc.returncode in (0, 1), f"{command}\n{output}"
        for line in shown:
            m = re.match(r"│\s+\d+\s+│", line)
            if m:
                assert m.group(0) in output, (
                    f"{command}: trial row {m.group(0)!r} missing\n{output}"
                )
