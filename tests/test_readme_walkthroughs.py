"""The README's simulation walkthroughs run as shown, with the outcomes shown.

``tests/test_readme.py`` runs the protocol and scoring examples; the
``run`` / ``compare`` / ``table`` examples of the walkthroughs simulate whole
trials, so they run here under ``-m slow`` (``test_walkthroughs_run_as_shown``),
in the order the README gives, against one fresh results store. Each must
exit 0 or 1 (1: a negative result, e.g. a tier not completed, which the
README explains), and every table line the README shows under a command
must be in that command's output: each shown cell equal -- statuses and
names exactly, numbers to the digits printed (a README row ending in ``...``
is compared on its shown cells only) -- and each other shown line present.
Outcomes are deterministic for a machine and library versions; where
another machine's differ, the README's figures are stale for it, and the
failure says which cell.

The parser and the comparison run in the default suite, on the README's
own text: every table line it shows is parsed, the README's rows match
themselves, and each row fails once one of its outcomes is changed.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from benchharness.runner.causes import FailureCause, TrialStatus

ROOT = Path(__file__).resolve().parents[1]
NUMBER = re.compile(r"-?\d+(\.\d+)?")
#: Arguments naming files a walkthrough writes: they go to the test's folder.
FILE_SUFFIXES = (".png", ".mp4", ".gif")
#: A cell holding ours and the paper's figure, as Table III prints them.
PAIR = " | "


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


@dataclass(frozen=True)
class TableLine:
    """A line of a rich table: a header (``┃``) or a row (``│``), its cells stripped.

    ``truncated``: the README cut the row short with ``...`` after its last
    shown cell, so only the shown cells are compared.
    """

    kind: str  #: "header" or "row"
    cells: tuple[str, ...]
    truncated: bool = False

    @property
    def key(self) -> str:
        return self.cells[0]


def parse_table_line(line: str) -> TableLine | None:
    """The table line ``line`` is, or None for any other line (text, ``...``, borders)."""
    s = line.strip()
    for mark, kind in (("│", "row"), ("┃", "header")):
        if s.startswith(mark):
            parts = s.split(mark)[1:]
            truncated = parts[-1].strip() == "..."
            if truncated or parts[-1].strip() == "":
                parts = parts[:-1]
            return TableLine(kind, tuple(p.strip() for p in parts), truncated)
    return None


def cell_matches(shown: str, actual: str) -> bool:
    """A shown cell against the printed one: numbers to the digits shown, anything else exactly."""
    if PAIR in shown:
        s_parts, a_parts = shown.split(PAIR), actual.split(PAIR)
        return len(s_parts) == len(a_parts) and all(map(cell_matches, s_parts, a_parts))
    shown, actual = shown.strip(), actual.strip()
    if NUMBER.fullmatch(shown):
        if not NUMBER.fullmatch(actual):
            return False
        digits = len(shown.split(".")[1]) if "." in shown else 0
        return _rounded(actual, digits) == _rounded(shown, digits)
    return shown == actual


def _rounded(number: str, digits: int) -> str:
    """``number`` printed to ``digits`` decimals, with no sign on a zero (-0.000 is 0.000)."""
    text = f"{float(number):.{digits}f}"
    return text.lstrip("-") if float(text) == 0 else text


def line_matches(shown: TableLine, actual: TableLine) -> bool:
    if shown.kind != actual.kind:
        return False
    if len(actual.cells) < len(shown.cells):
        return False
    if not shown.truncated and len(actual.cells) != len(shown.cells):
        return False
    return all(map(cell_matches, shown.cells, actual.cells))


def output_mismatches(shown: list[str], output: str) -> list[str]:
    """What of ``shown`` (the README's lines under one command) ``output`` does not have.

    Table lines are matched in order: each must match a later line of the
    output than the one before it, with the same first cell (trial index,
    backend, metric). Other lines (``...`` aside) must be in the output as
    they are.
    """
    actual = [a for a in map(parse_table_line, output.splitlines()) if a is not None]
    problems, at = [], 0
    for line in shown:
        if line.strip() == "...":
            continue
        want = parse_table_line(line)
        if want is None:
            if line.strip() not in output:
                problems.append(f"line not in the output: {line.strip()!r}")
            continue
        same_key = [i for i in range(at, len(actual)) if actual[i].key == want.key]
        hit = next((i for i in same_key if line_matches(want, actual[i])), None)
        if hit is None:
            printed = [" │ ".join(actual[i].cells) for i in same_key] or ["no such line"]
            problems.append(f"shown {want.kind} {' │ '.join(want.cells)!r}; printed: {printed}")
        else:
            at = hit + 1
    return problems


def test_the_readme_has_walkthroughs():
    cmds = [c for c, _ in walkthrough_examples()]
    assert any("inhand-level1" in c for c in cmds) and any("inhand-level3-dmg" in c for c in cmds)
    assert any("Rubiks-" in c for c in cmds)


#: Every word a status column prints.
STATUSES = {s.value for s in TrialStatus} | {c.value for c in FailureCause}


def test_the_parser_finds_every_table_line_the_readme_shows():
    """Each ``│``/``┃`` line of a walkthrough block is parsed, with its cells.

    Counted independently of the parser (by the line's first character),
    so a row the parser skipped -- and then never compared -- fails here.
    """
    examples = walkthrough_examples()
    shown = [line for _, lines in examples for line in lines]
    table_lines = [line for line in shown if line.lstrip()[:1] in ("│", "┃")]
    parsed = [p for p in map(parse_table_line, shown) if p is not None]
    assert len(parsed) == len(table_lines) >= 10
    for line, p in zip(table_lines, parsed):
        assert len(p.cells) == line.count("│" if p.kind == "row" else "┃") - 1
    trial_rows = [p for p in parsed if p.kind == "row" and p.key.isdigit()]
    assert len(trial_rows) >= 9  # Rubik's run and compare, Level I and Level III trials
    for p in trial_rows:  # every trial row shows at least one status, each a real one
        assert any(c in STATUSES for c in p.cells), p


def test_cell_matching():
    assert cell_matches("0.005", "0.0049") and cell_matches("99.558", "99.558")
    assert not cell_matches("0.005", "0.0061") and not cell_matches("7.47", "7.470001e9")
    assert cell_matches("—", "—") and not cell_matches("—", "0.003")
    assert not cell_matches("0.003", "—") and not cell_matches("success", "dropped")
    assert cell_matches("— | 0.505", "— | 0.505") and not cell_matches("— | 0.505", "0.2 | 0.505")
    assert cell_matches("", "") and not cell_matches("", "timeout")
    assert cell_matches("0.000", "-0.0001") and not cell_matches("-1.5", "1.5")
    row = parse_table_line("│     1 │ success │ 99.558 │       │ 104.60 │ ...")
    assert row == TableLine("row", ("1", "success", "99.558", "", "104.60"), truncated=True)
    longer = parse_table_line("│ 1 │ success │ 99.558 │  │ 104.60 │ 3 │")
    assert longer is not None and line_matches(row, longer)
    full = parse_table_line("│ 1 │ success │ 99.558 │  │ 104.60 │")
    assert full is not None and not full.truncated and not line_matches(full, longer)


def _mutations(line: str) -> list[str]:
    """``line`` with one outcome changed at a time: each status swapped, each number's last digit moved."""
    p = parse_table_line(line)
    assert p is not None
    out = []
    for i, cell in enumerate(p.cells):
        if i == 0:
            continue  # the key: a changed key finds no line, which is tested by any mutation below
        if cell in STATUSES:
            new = "success" if cell != "success" else "dropped"
        elif NUMBER.fullmatch(cell):
            new = cell[:-1] + str((int(cell[-1]) + 3) % 10)
        else:
            continue
        cells = list(p.cells)
        cells[i] = new
        out.append("│ " + " │ ".join(cells) + (" │ ..." if p.truncated else " │"))
    return out


def test_every_shown_row_is_compared_on_its_outcomes():
    """On the README itself: its rows match themselves, and a changed status or score does not."""
    changed = 0
    for command, shown in walkthrough_examples():
        output = "\n".join(shown)
        assert output_mismatches(shown, output) == [], command
        for line in shown:
            p = parse_table_line(line)
            if p is None or p.kind != "row":
                continue
            for bad in _mutations(line):
                assert output_mismatches(shown, output.replace(line, bad, 1)), (command, bad)
                changed += 1
    assert changed >= 20


@pytest.mark.slow
@pytest.mark.sim
def test_walkthroughs_run_as_shown(tmp_path):
    env = {
        **os.environ,
        "BENCHHARNESS_STORE": str(tmp_path / "results.sqlite"),
        "MPLBACKEND": "Agg",
    }
    stale: list[str] = []
    for command, shown in walkthrough_examples():
        argv = shlex.split(command)
        assert argv[0] == "benchharness", command
        argv = [a if not a.endswith(FILE_SUFFIXES) else str(tmp_path / a) for a in argv[1:]]
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
        files = {a: str(tmp_path / a) for a in shlex.split(command) if a.endswith(FILE_SUFFIXES)}
        shown = [_replace_all(line, files) for line in shown]
        problems = output_mismatches(shown, output)
        if problems:  # go on: later commands' rows say whether the rest of the README holds
            stale.append(f"$ {command}\n" + "\n".join(problems) + f"\n--- output:\n{output}")
    assert stale == [], "\n\n".join(stale)


def _replace_all(line: str, names: dict[str, str]) -> str:
    for old, new in names.items():
        line = line.replace(old, new)
    return line
