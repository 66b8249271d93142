"""``benchharness rubiks``: outputs, formats and exit codes (0 ok / 1 negative / 2 bad input)."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from benchharness.cli.main import cli

SOLVED = "UUUUUUUUURRRRRRRRRFFFFFFFFFDDDDDDDDDLLLLLLLLLBBBBBBBBB"
SEXY_FINAL = "UULUUFUUFRRUBRRURRFFDFFUFFFDDRDDDDDDBLLLLLLLLBRRBBBBBB"  # magiccube, R U R' U'


def run(*args: str):
    try:
        runner = CliRunner(mix_stderr=False)
    except TypeError:  # click >= 8.2 always keeps stderr apart
        runner = CliRunner()
    return runner.invoke(cli, ["rubiks", *args])


def test_sequence_prints_m_lines_of_n_moves():
    r = run("sequence", "--tier", "Rubiks-5-20", "--seed", "7")
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    assert len(lines) == 5 and all(len(line.split()) == 20 for line in lines)
    assert lines[0] == "R B' F L' D2 B F' U D2 F2 L D2 R2 F B2 D2 F R2 F2 B2"
    assert run("sequence", "--tier", "Rubiks-5-20", "--seed", "7").output == r.output


def test_sequence_json():
    r = run("sequence", "--tier", "Rubiks-1-10", "--seed", "3", "--json")
    data = json.loads(r.stdout)
    assert (
        data["tier"] == "Rubiks-1-10"
        and data["seed"] == 3
        and data["algorithm"] == "benchharness-rubiks-v1"
    )
    assert len(data["sequences"]) == 1 and len(data["sequences"][0].split()) == 10
    expect = run("expect", "--sequence", data["sequences"][0])
    assert data["expected_final_from_solved"] == [expect.stdout.strip()]


def test_sequence_default_seed_is_zero():
    assert (
        run("sequence", "--tier", "Rubiks-1-5").stdout
        == run("sequence", "--tier", "Rubiks-1-5", "--seed", "0").stdout
    )


@pytest.mark.parametrize(
    "args", [["--tier", "Rubiks-2-2"], ["--tier", "Rubiks-1-5", "--seed", "-1"]]
)
def test_sequence_bad_input(args):
    r = run("sequence", *args)
    assert r.exit_code == 2


def test_sequence_unknown_tier_lists_tiers():
    r = run("sequence", "--tier", "Rubiks-2-2")
    assert "unknown tier 'Rubiks-2-2'; tiers are Rubiks-1-5" in r.stderr


def test_expect():
    r = run("expect", "--sequence", "R U R' U'")
    assert r.exit_code == 0 and r.stdout == SEXY_FINAL + "\n"
    r = run("expect", "--sequence", "U R U' R'", "--initial", SEXY_FINAL)
    assert r.stdout.strip() == SOLVED
    data = json.loads(run("expect", "--sequence", "R U R’ U'", "--json").stdout)
    assert data == {"initial": SOLVED, "sequence": "R U R' U'", "moves": 4, "final": SEXY_FINAL}


def test_expect_bad_move():
    r = run("expect", "--sequence", "R U Q U'")
    assert r.exit_code == 2
    assert r.stderr == (
        'error: --sequence: unknown move "Q" at position 3 '
        "(expected U D L R F B M E S x y z with optional ' or 2)\n"
    )


def test_expect_bad_initial():
    r = run("expect", "--sequence", "R", "--initial", SOLVED[:-1])
    assert r.exit_code == 2 and "expected 54 facelets, got 53" in r.stderr


def test_validate_ok():
    r = run("validate", "--sequence", "R U R' U'", "--final", SEXY_FINAL)
    assert r.exit_code == 0 and r.stdout == "ok: the final state is the expected one (4 moves)\n"


def test_facelets_may_be_grouped_by_face():
    grouped = " ".join(SEXY_FINAL[i : i + 9] for i in range(0, 54, 9))
    assert run("validate", "--sequence", "R U R' U'", "--final", grouped).exit_code == 0


def test_validate_mismatch_lists_facelets():
    r = run("validate", "--sequence", "R U R' U'", "--final", SOLVED)
    assert r.exit_code == 1
    lines = r.stdout.splitlines()
    assert lines[0] == "mismatch: 12 of 54 facelets differ from the expected state"
    assert "U3: expected L, got U" in lines and len(lines) == 3 + 12
    assert "R3: expected U, got R" in lines


def test_validate_with_initial_and_json():
    r = run(
        "validate",
        "--initial",
        SEXY_FINAL,
        "--sequence",
        "U R U' R'",
        "--final",
        SEXY_FINAL,
        "--json",
    )
    assert r.exit_code == 1
    data = json.loads(r.stdout)
    assert data["match"] is False and data["expected_final"] == SOLVED
    assert {"facelet": "U3", "expected": "U", "got": "L"} in data["differences"]
    r = run(
        "validate", "--initial", SEXY_FINAL, "--sequence", "U R U' R'", "--final", SOLVED, "--json"
    )
    assert r.exit_code == 0 and json.loads(r.stdout)["match"] is True


def test_validate_twisted_corner_final_is_a_negative_answer_with_reason():
    s = list(SOLVED)
    s[8], s[9], s[20] = s[20], s[8], s[9]  # twist URF in place
    r = run("validate", "--sequence", "U U'", "--final", "".join(s))
    assert r.exit_code == 1
    assert "note: the observed state is not a legal cube: corner twist" in r.stdout
    assert "U9: expected U, got F" in r.stdout


@pytest.mark.parametrize(
    "args, message",
    [
        (["--sequence", "R", "--final", SOLVED[:-1]], "--final: expected 54 facelets, got 53"),
        (["--sequence", "R", "--final", "W" + SOLVED[1:]], "--final: invalid character 'W' at U1"),
        (
            ["--sequence", "R", "--final", "R" + SOLVED[1:]],
            "--final: each colour must appear exactly 9 times",
        ),
        (["--sequence", "R Q", "--final", SOLVED], 'unknown move "Q" at position 2'),
        (
            ["--sequence", "R", "--initial", "R" + SOLVED[1:], "--final", SOLVED],
            "--initial is not a legal cube",
        ),
        (["--sequence", "R"], "Missing option '--final'"),
    ],
)
def test_validate_bad_input_exits_2(args, message):
    r = run("validate", *args)
    assert r.exit_code == 2
    assert message in r.stderr


def test_check():
    assert run("check", SOLVED).exit_code == 0
    flipped = (
        SOLVED[:5] + "R" + SOLVED[6:10] + "U" + SOLVED[11:]
    )  # UR edge flipped in place (U6 <-> R2)
    r = run("check", flipped)
    assert r.exit_code == 1
    assert (
        r.stdout
        == "invalid: edge flip: the edge orientations sum to 1 mod 2, must be 0 (an edge is flipped in place)\n"
    )


def test_tiers_text_and_json():
    r = run("tiers")
    assert r.exit_code == 0
    lines = r.stdout.splitlines()
    assert lines[0].split()[:3] == ["tier", "M", "N"]
    row = next(line for line in lines if line.startswith("Rubiks-5-20"))
    assert (
        row.split()[:3] == ["Rubiks-5-20", "5", "20"]
        and "not completed" in row
        and "416.61 / 23.10 s" in row
    )
    data = json.loads(run("tiers", "--json").stdout)
    assert len(data) == 12 and data[6]["name"] == "Rubiks-5-5"
    assert data[6]["baselines"]["dead_reckoning_pr2"] == {
        "label": "Dead reckoning PR2",
        "completed": True,
        "mean_s": 113.35,
        "std_s": 17.16,
    }


def write_log(tmp_path, rows, name="log.csv"):
    head = "tier,trial,sequence,final,first_contact_s,termination_s\n"
    p = tmp_path / name
    p.write_text(head + "".join(",".join(map(str, r)) + "\n" for r in rows))
    return str(p)


def test_score_completed(tmp_path):
    log = write_log(tmp_path, [("Rubiks-1-5", 1, "R U R' U'", SEXY_FINAL, 1.5, 101.75)])
    r = run("score", log)
    assert r.exit_code == 0, r.output
    assert (
        r.stdout.splitlines()[0]
        == "Rubiks-1-5: completed, score 100.25 s ± — (mean ± sample std, 1 trial)"
    )
    data = json.loads(run("score", log, "--json").stdout)
    tier = data["tiers"][0]
    assert tier["completed"] is True and tier["mean_s"] == 100.25 and tier["std_s"] is None
    assert tier["std_kind"] == "sample (ddof=1)"


def test_score_not_completed(tmp_path):
    log = write_log(tmp_path, [("Rubiks-1-5", 1, "R U R' U'", SOLVED, 1.5, 101.75)])
    r = run("score", log)
    assert r.exit_code == 1
    assert r.stdout.startswith("Rubiks-1-5: NOT completed (0 of 1 trials succeeded)")


def test_score_seed_check(tmp_path):
    log = write_log(tmp_path, [("Rubiks-1-5", 1, "R U R' U'", SEXY_FINAL, 1.5, 101.75)])
    r = run("score", log, "--seed", "0")
    assert r.exit_code == 1 and "not the generator's for seed 0" in r.stdout


def test_score_bad_log(tmp_path):
    log = write_log(tmp_path, [("Rubiks-1-5", 1, "R U R' U'", SEXY_FINAL, 200, 101.75)])
    r = run("score", log)
    assert (
        r.exit_code == 2 and "termination_s (101.75) is before first_contact_s (200.0)" in r.stderr
    )
    r = run("score", str(tmp_path / "nope.csv"))
    assert r.exit_code == 2


@pytest.mark.parametrize("command", ["tiers", "sequence", "expect", "validate", "check", "score"])
def test_every_command_has_help_with_an_example(command):
    r = run(command, "--help")
    assert (
        r.exit_code == 0 and "Example:" in r.stdout and f"benchharness rubiks {command}" in r.stdout
    )


def test_python_dash_m_runs_the_same_command_line():
    """``python -m benchharness`` (an interpreter whose ``bin/`` is not on PATH; the sweep bench uses
    it) is the ``benchharness`` command: same program name, same subcommands, same exit codes."""
    import subprocess
    import sys

    from benchharness import __version__

    out = subprocess.run(
        [sys.executable, "-m", "benchharness", "--version"], capture_output=True, text=True
    )
    assert (out.returncode, out.stdout.strip()) == (0, f"benchharness, version {__version__}")
    usage = subprocess.run(
        [sys.executable, "-m", "benchharness", "rubiks", "sequence", "--help"],
        capture_output=True,
        text=True,
    )
    assert usage.stdout.startswith("Usage: benchharness rubiks sequence [OPTIONS]"), usage.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "benchharness", "rubiks", "sequence", "--tier", "Rubiks-9-9"],
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2 and "unknown tier 'Rubiks-9-9'" in bad.stderr, bad.stderr


def test_console_script_exits_without_collecting_what_it_leaves():
    """The console script moves what is still alive out of the collector's reach once the command
    has returned (``gc.freeze``; its exit's cycle collections cost 0.3-0.5 CPU-s with torch imported,
    BENCHMARKS.md "exit freeze"), on success and on bad input alike, and its exit code is kept.
    Observed from an ``atexit`` hook, which runs after the command and before the teardown."""
    import subprocess
    import sys

    probe = (
        "import atexit, gc, sys\n"
        "atexit.register(lambda: print('frozen', gc.get_freeze_count() > 0))\n"
        "from benchharness.cli.main import main\n"
        "print('before', gc.get_freeze_count() > 0)\n"
        "main(sys.argv[1:])\n"
    )
    for argv, rc in ((["rubiks", "expect", "--sequence", "R U"], 0), (["rubiks", "expect"], 2)):
        out = subprocess.run([sys.executable, "-c", probe, *argv], capture_output=True, text=True)
        lines = out.stdout.splitlines()
        assert out.returncode == rc, out.stderr
        assert lines[0] == "before False" and lines[-1] == "frozen True", out.stdout
