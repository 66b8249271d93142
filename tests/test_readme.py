"""The README's and docs/' console examples run and print what the page shows.

Every ``$ benchharness ...`` line in a ```console block of the protocol,
scoring and plugin sections is run from the repository root; each output line
the README shows under it (other than ``...``) must appear in the real
output, and an example whose shown output starts with ``error:`` must exit 2
(bad input). The walkthrough sections, simulation examples (``run``, ``compare``, ``--backend``) and
those writing files or naming the user's own files are left to their own
tests.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SKIP = ("--backend", " run ", " compare ", "--plot", "--png", "my_results", " results")


def examples() -> list[tuple[str, list[str]]]:
    text = (ROOT / "README.md").read_text()
    # The walkthroughs' commands read the store their own earlier commands
    # wrote; tests/test_readme_walkthroughs.py runs them in order.
    text = "\n### ".join(s for s in text.split("\n### ") if not s.startswith("Walkthrough"))
    return _console_examples(text)


#: pages whose examples have a test of their own (docs/rubiks.md: tests/test_rubiks_docs.py)
DOCS_TESTED_ELSEWHERE = ("rubiks.md",)


def doc_examples() -> list[tuple[str, str, list[str]]]:
    """(page, command, shown output) of every console example in docs/ this test runs."""
    out = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        if page.name in DOCS_TESTED_ELSEWHERE:
            continue
        out += [(page.name, c, e) for c, e in _console_examples(page.read_text())]
    return out


def _console_examples(text: str) -> list[tuple[str, list[str]]]:
    out: list[tuple[str, list[str]]] = []
    for block in re.findall(r"```console\n(.*?)```", text, flags=re.S):
        current: tuple[str, list[str]] | None = None
        for line in block.splitlines():
            if line.startswith("$ "):
                cmd = line[2:].split("  #")[0].strip()
                current = (cmd, [])
                out.append(current)
            elif current is not None and line.strip() and line.strip() != "...":
                current[1].append(line.rstrip())
    return [(c, e) for c, e in out if not any(s in f" {c} " for s in SKIP)]


@pytest.mark.parametrize("command,expected", examples(), ids=[c for c, _ in examples()])
def test_readme_example(command, expected):
    _check(command, expected)


@pytest.mark.parametrize(
    "page,command,expected", doc_examples(), ids=[f"{p}: {c}" for p, c, _ in doc_examples()]
)
def test_doc_example(page, command, expected):
    _check(command, expected)


def test_docs_have_checked_examples():
    """The docs' console examples with output are found (docs/inhand.md's score table at least)."""
    shown = [(p, c) for p, c, e in doc_examples() if e]
    assert (
        "inhand.md",
        "benchharness inhand score tasks/inhand/published/yumi_lvl3_dmg.csv --by object",
    ) in shown


def _check(command: str, expected: list[str]) -> None:
    argv = shlex.split(command)
    assert argv[0] == "benchharness"
    proc = subprocess.run(
        [sys.executable, "-m", "benchharness.cli.main", *argv[1:]],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )
    output = proc.stdout + proc.stderr
    if expected and expected[0].startswith("error:"):
        assert proc.returncode == 2, output
    else:
        assert proc.returncode == 0, output
    for line in expected:
        assert line in output, f"README shows {line!r}; got:\n{output}"


def test_there_are_examples():
    assert len(examples()) >= 8
