"""Issue 13 item 14: text output is never cut at 80 columns.

Through click's CliRunner (not a terminal, like a pipe) with ``COLUMNS=80``,
the widths rich would otherwise use: plugin names one must type, joint names
and failure messages appear whole, and no cell ends in an ellipsis. In a
terminal of 80 columns, long cells fold onto the next line instead
(``print_table``). Every table has a ``--json`` twin; the text is checked
against it.
"""

from __future__ import annotations

import io
import json
import textwrap

import pytest
from click.testing import CliRunner

from benchharness.cli.main import cli

NARROW = {"COLUMNS": "80", "LINES": "24"}
LONG_MESSAGE = (
    "the grasp planner found no collision-free regrasp for the left gripper after "
    "trying every candidate: l_shoulder_pan_joint_limit_exceeded_by_0.3_rad_at_waypoint_17 "
    "(this message is deliberately longer than any terminal is wide) END"
)


def _invoke(*args):
    return CliRunner(env=NARROW).invoke(cli, [*map(str, args)], catch_exceptions=False)


def test_plugin_names_are_whole_at_80_columns():
    r = _invoke("plugins", "--kind", "strategy")
    assert r.exit_code == 0, r.output
    assert "…" not in r.output
    names = [
        i["name"]
        for i in json.loads(_invoke("plugins", "--kind", "strategy", "--json").stdout)["items"]
    ]
    assert "relaxed-position-orientation" in names
    for n in names:
        assert f" {n} " in r.output, n


def test_joint_names_are_whole_at_80_columns():
    pytest.importorskip("pybullet")
    r = _invoke("robot", "inspect", "pr2", "--backend", "pybullet")
    assert r.exit_code == 0, r.output
    joints = [
        j["name"] for j in json.loads(_invoke("robot", "inspect", "pr2", "--json").stdout)["joints"]
    ]
    assert any(j.startswith("l_shoulder_") for j in joints)
    assert "…" not in r.output
    for j in joints:
        assert f" {j} " in r.output, j


@pytest.mark.sim
def test_failure_messages_are_whole_at_80_columns(tmp_path, monkeypatch):
    pytest.importorskip("pybullet")
    (tmp_path / "longmsg_plugin.py").write_text(
        textwrap.dedent(
            f"""
            from benchharness.plugin import Registration, hookimpl

            class LongMessage:
                def run_trial(self, ctx):
                    raise ValueError({LONG_MESSAGE!r})

            @hookimpl
            def benchharness_strategies():
                return [Registration("test-longmsg", LongMessage, "fails with a long message")]
            """
        )
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    store = tmp_path / "s.sqlite"
    common = ["--store", store]
    r = _invoke(
        "run",
        "--task",
        "Rubiks-1-5",
        "--robot",
        "test-stub",
        "--strategy",
        "test-longmsg",
        "--plugin",
        "runner_testplugins",
        "--plugin",
        "longmsg_plugin",
        "--workers",
        "0",
        "--no-progress",
        *common,
    )
    assert r.exit_code == 1, r.output
    for out in (r.output, _invoke("results", "--failures", *common).output):
        assert LONG_MESSAGE in out and "…" not in out
    data = json.loads(_invoke("results", "--failures", "--json", *common).stdout)
    assert LONG_MESSAGE in data["trials"][0]["message"]


def test_a_narrow_terminal_folds_cells_instead_of_cutting_them():
    from rich.console import Console
    from rich.table import Table

    from benchharness.cli.common import print_table

    name = "l_shoulder_pan_joint_with_a_name_longer_than_any_terminal_column_is_wide_xyz"
    buf = io.StringIO()
    con = Console(file=buf, force_terminal=True, width=80, color_system=None)
    t = Table()
    for c in ("kind", "name", "message"):
        t.add_column(c, no_wrap=True)  # print_table overrides a caller's no_wrap
    t.add_row("strategy", name, LONG_MESSAGE)
    print_table(t, con)
    out = buf.getvalue()
    assert "…" not in out and max(len(ln) for ln in out.splitlines()) <= 80
    # read the folded cells back column by column: nothing is lost
    cols: dict[int, str] = {1: "", 2: ""}
    for ln in out.splitlines():
        cells = ln.split("│")
        if len(cells) == 5:
            cols[1] += cells[2].strip()
            cols[2] += cells[3].strip() + " "
    assert cols[1] == name
    assert " ".join(cols[2].split()).replace(" ", "") == LONG_MESSAGE.replace(" ", "")
