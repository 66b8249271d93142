"""Results/task file formats: round trip, JSON, and errors naming file, row, column."""

import json

import numpy as np
import pytest

from benchharness.inhand.fileformat import FileFormatError, read_results, read_tasks, write_results

HEADER = (
    "method,object,task_id,trial,level,dropped,plan_time_s,exec_time_s,"
    "initial_x,initial_y,initial_z,initial_qx,initial_qy,initial_qz,initial_qw,"
    "desired_x,desired_y,desired_z,desired_qx,desired_qy,desired_qz,desired_qw,"
    "setup_x,setup_y,setup_z,setup_qx,setup_qy,setup_qz,setup_qw,"
    "reached_x,reached_y,reached_z,reached_qx,reached_qy,reached_qz,reached_qw,"
    "reached_contact1_x,reached_contact1_y,reached_contact1_z,note"
)
ROW_OK = "A,apple,apple-01,1,I,0,0.5,1.67,0,0,0,0,0,0,1,0.1,0,0,0,0,0,1,0.001,0,0,0,0,0,1,0.09,0,0,0,0,0,1,0.01,0.02,0.03,hello"
ROW_DROP = "A,apple,apple-01,2,1,1,0.5,,0,0,0,0,0,0,1,0.1,0,0,0,0,0,1,,,,,,,,,,,,,,,,,,"


def write(tmp_path, *rows, name="r.csv"):
    p = tmp_path / name
    p.write_text("\n".join([HEADER, *rows]) + "\n")
    return p


def test_read_valid_file(tmp_path):
    r = read_results(write(tmp_path, ROW_OK, ROW_DROP))
    assert len(r) == 2 and r.level.tolist() == [1, 1] and r.dropped.tolist() == [False, True]
    assert np.isnan(r.reached[1]).all() and np.isnan(r.exec_time_s[1])
    assert r.contacts["reached"].shape == (2, 1, 3)
    assert r.extra["note"].tolist() == ["hello", ""]


def test_round_trip(tmp_path):
    r = read_results(write(tmp_path, ROW_OK, ROW_DROP))
    out = tmp_path / "out.csv"
    write_results(r, out)
    r2 = read_results(out)
    np.testing.assert_array_equal(r.reached, r2.reached)
    np.testing.assert_array_equal(r.setup, r2.setup)
    assert r2.extra["note"].tolist() == ["hello", ""]


@pytest.mark.parametrize(
    "row, column, message",
    [
        (ROW_OK.replace(",0.09,", ",abc,"), "reached_x", "not a number"),
        (ROW_OK.replace(",I,", ",IV,"), "level", "task level"),
        (ROW_OK.replace("A,apple", ",apple"), "method", "empty"),
        (ROW_OK.replace(",0,0.5,", ",maybe,0.5,"), "dropped", "boolean"),
        (ROW_OK.replace("0.001,0,0,0,0,0,1", "0.001,0,0,,0,0,1"), "setup_qx", "incomplete"),
    ],
)
def test_errors_name_file_row_column(tmp_path, row, column, message):
    p = write(tmp_path, ROW_OK, row)
    with pytest.raises(FileFormatError, match=message) as e:
        read_results(p)
    assert e.value.row == 2 and e.value.column == column
    assert str(p) in str(e.value) and "row 2" in str(e.value) and repr(column) in str(e.value)


def test_reached_required_unless_dropped(tmp_path):
    row = ROW_DROP.replace(",2,1,1,", ",2,1,0,")
    with pytest.raises(FileFormatError, match="empty") as e:
        read_results(write(tmp_path, row))
    assert e.value.column == "reached_x"


def test_missing_column(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text(HEADER.replace("desired_qw,", "") + "\n" + ROW_OK + "\n")
    with pytest.raises(FileFormatError, match="missing column") as e:
        read_results(p)
    assert e.value.column == "desired_qw"


def test_json_results(tmp_path):
    trial = {
        "method": "A",
        "object": "apple",
        "task_id": "t1",
        "trial": 1,
        "level": 3,
        "dropped": False,
        "plan_time_s": 0.2,
        "exec_time_s": None,
        "initial": [0, 0, 0, 0, 0, 0, 1],
        "desired": [0.1, 0, 0, 0, 0, 0, 1],
        "reached": [0.09, 0, 0, 0, 0, 0, 1],
        "contacts": {"reached": [[0, 0, 0], [1, 1, 1]], "desired": [[0, 0, 0]]},
        "extra": {"robot": "yumi"},
    }
    p = tmp_path / "r.json"
    p.write_text(json.dumps({"format": "benchharness-inhand-results", "trials": [trial]}))
    r = read_results(p)
    assert r.contacts["reached"].shape == (1, 2, 3) and r.extra["robot"][0] == "yumi"
    bad = dict(trial, reached=[1, 2, 3])
    p.write_text(json.dumps({"trials": [trial, bad]}))
    with pytest.raises(FileFormatError, match="row 2.*'reached'"):
        read_results(p)


def test_task_file(tmp_path):
    p = tmp_path / "t.csv"
    cols = "task_id,object,level," + ",".join(
        f"{s}_{f}" for s in ("initial", "desired") for f in ("x", "y", "z", "qx", "qy", "qz", "qw")
    )
    p.write_text(cols + "\nt1,apple,1,0,0,0,0,0,0,1,0.1,0,0,0,0,0,1\n")
    t = read_tasks(p)
    assert t.task_id.tolist() == ["t1"] and t.desired[0, 0] == 0.1


def test_docs_example_parses(tmp_path):
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[1] / "docs" / "inhand.md").read_text()
    block = doc.split("```csv\n")[1].split("```")[0]
    p = tmp_path / "example.csv"
    p.write_text(block)
    r = read_results(p)
    assert len(r) == 2 and r.dropped.tolist() == [False, True] and r.has_setup.all()
