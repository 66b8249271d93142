"""``benchharness inhand`` through click's CliRunner."""

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from benchharness.cli.main import cli

REPO = Path(__file__).resolve().parents[1]
DMG = REPO / "tasks" / "inhand" / "published" / "yumi_lvl3_dmg.csv"
ALLEGRO = REPO / "tasks" / "inhand" / "published" / "allegro_lvl1_relaxed_rigidity.csv"


def run(*args):
    return CliRunner().invoke(cli, ["inhand", *map(str, args)])


def test_score_text_by_object():
    r = run("score", DMG, "--by", "object")
    assert r.exit_code == 0, r.output
    for text in ("gelatin box", "0.505", "9.9", "0.0159", "err_or%", "not applied"):
        assert text in r.output


def test_score_json():
    r = run("score", DMG, "--by", "object", "--json")
    assert r.exit_code == 0, r.output
    data = json.loads(r.output)
    assert data["by"] == ["method", "object"] and data["n_trials"] == 4
    gel = next(g for g in data["groups"] if g["key"]["object"] == "gelatin box")
    assert gel["metrics"]["err_pos"]["unit"] == "cm"
    assert gel["metrics"]["err_pos"]["median"] == pytest.approx(0.50486, abs=1e-4)
    assert gel["drops_percent"] == 0.0


def test_score_plot_png(tmp_path):
    out = tmp_path / "fig.png"
    r = run("score", ALLEGRO, "--plot", out)
    assert r.exit_code == 0, r.output
    assert out.stat().st_size > 10_000 and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bad_file_exit_2_names_row_and_column(tmp_path):
    lines = DMG.read_text().splitlines()
    header = lines[0].split(",")
    cells = lines[2].split(",")
    cells[header.index("reached_qw")] = "oops"
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join([lines[0], lines[1], ",".join(cells)]) + "\n")
    r = run("score", bad)
    assert r.exit_code == 2
    assert "row 2" in r.output and "'reached_qw'" in r.output and "bad.csv" in r.output


def test_missing_file_exit_2(tmp_path):
    assert run("score", tmp_path / "nope.csv").exit_code == 2


def _box_mesh(path):
    import trimesh

    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(path)


def test_setup_rule_discarded_and_contacts(tmp_path):
    _box_mesh(tmp_path / "box.stl")
    head = [
        "method",
        "object",
        "task_id",
        "trial",
        "level",
        "dropped",
        "plan_time_s",
        "exec_time_s",
    ]
    for s in ("initial", "desired", "setup", "reached"):
        head += [f"{s}_{f}" for f in ("x", "y", "z", "qx", "qy", "qz", "qw")]
    head += [
        "desired_contact1_x",
        "desired_contact1_y",
        "desired_contact1_z",
        "reached_contact1_x",
        "reached_contact1_y",
        "reached_contact1_z",
        "object_mesh",
    ]
    q = ["0", "0", "0", "1"]

    def row(trial, setup_x, dropped=0):
        return [
            "M",
            "box",
            "t1",
            str(trial),
            "3",
            str(dropped),
            "0.1",
            "2.0",
            "0",
            "0",
            "0",
            *q,
            "0.1",
            "0",
            "0",
            *q,
            str(setup_x),
            "0",
            "0",
            *q,
            *(["0.09", "0", "0", *q] if not dropped else [""] * 7),
            # desired contact at a top corner, reached at the adjacent corner: 10 cm along an edge
            "0.05",
            "0.05",
            "0.05",
            "-0.05",
            "0.05",
            "0.05",
            "box.stl",
        ]

    rows = [row(1, 0.0), row(2, 0.02), row(3, 0.0, dropped=1), row(4, 0.005)]
    p = tmp_path / "res.csv"
    p.write_text("\n".join(",".join(r) for r in [head, *rows]) + "\n")
    r = run(
        "score", p, "--discarded", "--json", "--geodesic", "exact"
    )  # heat is coarse on 8 vertices
    assert r.exit_code == 0, r.output
    data = json.loads(r.output)
    (g,) = data["groups"]
    assert (
        g["n_discarded"] == 1
        and g["n_trials"] == 3
        and g["drops_percent"] == pytest.approx(100 / 3)
    )
    assert [d["trial"] for d in data["discarded"]] == [2]
    assert data["discarded"][0]["setup_err_pos_percent"] == pytest.approx(20.0)
    assert g["metrics"]["g_euc"]["median"] == pytest.approx(10.0)
    assert g["metrics"]["g_geo"]["median"] == pytest.approx(10.0)
    assert g["metrics"]["g_min"]["median"] == pytest.approx(10.0)  # the 8-vertex box
    text = run("score", p, "--discarded")
    assert text.exit_code == 0 and "Discarded trials" in text.output and "1 of 4" in text.output


def test_import_bih_help_and_bad_source(tmp_path):
    r = run("import-bih", "--help")
    assert r.exit_code == 0 and "import-bih --source" in r.output
    r = run("import-bih", "--source", tmp_path / "missing", "--out", tmp_path / "o")
    assert r.exit_code == 2 and "does not exist" in r.output


def test_score_help_has_example():
    r = run("score", "--help")
    assert r.exit_code == 0 and "tasks/inhand/published/yumi_lvl3_dmg.csv" in r.output


def test_unknown_grouping_column_exit_2():
    r = run("score", DMG, "--by", "colour")
    assert r.exit_code == 2 and "colour" in r.output


def test_group_by_extra_column():
    r = run("score", DMG, "--by", "robot", "--json")
    assert r.exit_code == 0 and json.loads(r.output)["by"] == ["method", "robot"]
