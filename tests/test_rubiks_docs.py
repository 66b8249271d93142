"""The CLI examples in docs/rubiks.md run and print what the page says."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from click.testing import CliRunner

from benchharness.cli.main import cli

DOC = Path(__file__).resolve().parents[1] / "docs" / "rubiks.md"


def examples():
    """(command, expected output or None if elided with …, expected exit code or None)."""
    out = []
    for block in re.findall(r"```\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S):
        lines = block.splitlines()
        i = 0
        while i < len(lines):
            line = lines[i]
            if not line.startswith("$ benchharness "):
                i += 1
                continue
            j = i + 1
            while j < len(lines) and not lines[j].startswith("$ "):
                j += 1
            body = [x for x in lines[i + 1 : j]]
            while body and not body[-1].strip():
                body.pop()
            code = None
            if j < len(lines) and lines[j] == "$ echo $?":
                code = int(lines[j + 1])
                j += 2
            text = "\n".join(body)
            out.append((line[2:], None if "…" in text else text, code))
            i = j
    return out


EXAMPLES = examples()


def test_the_page_has_examples():
    assert len(EXAMPLES) >= 8


@pytest.mark.parametrize("command, expected, code", EXAMPLES, ids=[e[0][:60] for e in EXAMPLES])
def test_example(command, expected, code, monkeypatch):
    monkeypatch.chdir(DOC.parents[1])
    args = shlex.split(command)[1:]
    result = CliRunner().invoke(cli, args)
    if code is not None:
        assert result.exit_code == code
    if expected is not None:
        assert result.output.rstrip("\n") == expected
