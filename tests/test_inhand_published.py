"""The published in-hand data: Table III reproduction, Allegro medians computed
independently, and the committed conversion equal to a fresh one."""

from pathlib import Path

import numpy as np
import pytest

from benchharness.inhand.bih_import import OUTPUT_FILES, convert_bih
from benchharness.inhand.fileformat import read_results
from benchharness.metrics.inhand import score_trials, summarize_scores
from benchharness.metrics.pose import err_or_percent

REPO = Path(__file__).resolve().parents[1]
TASKS = REPO / "tasks" / "inhand"
SOURCE = REPO.parent / "shared" / "data" / "bih_dataset"
needs_source = pytest.mark.skipif(
    not SOURCE.is_dir(), reason=f"published dataset not found at {SOURCE}"
)

# Paper, Table III (DMG, YuMi, Level III): err_pos (cm), err_pos %, err_or %
TABLE_III = {
    "gelatin box": (0.505, 9.9, 0.016),
    "cracker box": (0.267, 2.7, 0.044),
    "spatula": (0.513, 8.8, 0.023),
    "potted meat can": (0.610, 11.0, 0.049),
}
DIGITS = (3, 1, 3)


@pytest.fixture(scope="module")
def dmg():
    r = read_results(TASKS / "published" / "yumi_lvl3_dmg.csv")
    s = score_trials(r.initial, r.desired, r.reached, dropped=r.dropped)
    return {
        o: (s.err_pos[i] * 100, s.err_pos_percent[i], s.err_or_percent[i])
        for i, o in enumerate(r.object)
    }


def printed_as(value, paper, digits, slack=0.5):
    """``value`` prints as ``paper`` at the paper's precision (within ``slack`` units)."""
    return abs(value - paper) <= slack * 10.0**-digits + 1e-12


POTTED_POS = pytest.mark.xfail(
    strict=True,
    reason="DMG.ods potted meat can gives 0.538 cm / 9.78 % with the fingertip midpoint; the paper prints "
    "0.610 / 11.0, which no fixed gripper-frame offset reproduces either (checked by least squares)",
)


@pytest.mark.parametrize(
    "obj, k",
    [(o, k) for o in TABLE_III for k in range(3) if not (o == "potted meat can" and k < 2)]
    + [
        pytest.param("potted meat can", 0, marks=POTTED_POS),
        pytest.param("potted meat can", 1, marks=POTTED_POS),
    ],
)
def test_table_iii(dmg, obj, k):
    value, paper = dmg[obj][k], TABLE_III[obj][k]
    # spatula err_pos is 0.51351 cm: printed as 0.513 it is truncated, not rounded,
    # so it is held to one unit of the last digit instead of half.
    slack = 1.0 if (obj, k) == ("spatula", 0) else 0.5
    assert printed_as(value, paper, DIGITS[k], slack), f"{obj}: {value} vs paper {paper}"


def test_table_iii_needs_unnormalised_quaternions():
    r = read_results(TASKS / "published" / "yumi_lvl3_dmg.csv")
    norm = err_or_percent(r.desired[:, 3:], r.reached[:, 3:], normalize=True)
    i = list(r.object).index("cracker box")
    assert not printed_as(norm[i], 0.044, 3)  # 0.030: normalising does not reproduce the paper


# ---------------------------------------------------------------- Allegro, independently


def rpy_matrix(r, p, y):
    """Extrinsic x-y-z (ROS RPY): R = Rz(y) Ry(p) Rx(r), written out by hand."""
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def or_percent_from_matrices(rd, rr):
    # relative angle from the trace; |cos(theta/2)| = sqrt((1 + cos theta) / 2)
    cos_t = np.clip((np.trace(rd.T @ rr) - 1) / 2, -1, 1)
    c_half = np.sqrt((1 + cos_t) / 2)
    return 100 * np.sqrt(max(2 - 2 * c_half, 0.0)) / np.sqrt(2)


def read_allegro_ods():
    from odf import teletype
    from odf.opendocument import load
    from odf.table import Table, TableCell, TableRow

    doc = load(str(SOURCE / "results" / "allegro_lvl_1" / "relaxed-rigidity-dataset.ods"))
    rows = []
    for tr in doc.spreadsheet.getElementsByType(Table)[0].getElementsByType(TableRow)[1:]:
        cells = [teletype.extractText(c) for c in tr.getElementsByType(TableCell)][:7]
        if cells and cells[0].strip():
            rows.append(cells)
    return rows


def independent_allegro_medians():
    per = {}
    for obj, _, _, _, ini, des, fin in read_allegro_ods():
        si, sd, sr = (np.array([float(v) for v in c.split(",")]) for c in (ini, des, fin))
        e = np.linalg.norm(sd[:3] - sr[:3])
        e_pct = 100 * e / np.linalg.norm(sd[:3] - si[:3])
        e_or = or_percent_from_matrices(rpy_matrix(*sd[3:]), rpy_matrix(*sr[3:]))
        per.setdefault(obj.strip(), []).append((e * 100, e_pct, e_or))
    return {o: np.median(np.array(v), axis=0) for o, v in per.items()}


def module_allegro_medians():
    r = read_results(TASKS / "published" / "allegro_lvl1_relaxed_rigidity.csv")
    s = score_trials(r.initial, r.desired, r.reached, dropped=r.dropped)
    groups = summarize_scores(s, {"object": r.object}, ["object"], r.dropped)
    return {
        g.key[0]: np.array(
            [
                g.stats["err_pos"].median * 100,
                g.stats["err_pos_percent"].median,
                g.stats["err_or_percent"].median,
            ]
        )
        for g in groups
    }


@needs_source
def test_allegro_medians_match_independent_computation():
    ours, theirs = module_allegro_medians(), independent_allegro_medians()
    assert sorted(ours) == sorted(theirs) and len(ours) == 10
    for obj in ours:
        np.testing.assert_allclose(ours[obj], theirs[obj], rtol=1e-6, atol=1e-9, err_msg=obj)


def test_allegro_orientation_error_by_dot_product():
    # a second quaternion route on the committed file: eq. 3 for unit quaternions
    # equals 100 * sqrt(2 - 2 |q_d . q_r|) / sqrt(2)
    r = read_results(TASKS / "published" / "allegro_lvl1_relaxed_rigidity.csv")
    dot = np.abs(np.sum(r.desired[:, 3:] * r.reached[:, 3:], axis=1))
    expected = 100 * np.sqrt(np.clip(2 - 2 * dot, 0, None)) / np.sqrt(2)
    got = score_trials(r.initial, r.desired, r.reached).err_or_percent
    # 2 - 2|dot| cancels: a 1e-12 error in dot (12-digit file values) is ~1e-4 % here
    np.testing.assert_allclose(got, expected, atol=2e-4)
    assert len(r) == 100 and set(r.extra["fingers"]) <= {"0;1;3", "0;1;2;3", "0;1;2"}
    assert "grasp_thumb_j3" in r.extra and "ar_tag_offset_z" in r.extra


# ---------------------------------------------------------------- conversion


@needs_source
def test_committed_files_equal_fresh_conversion(tmp_path):
    convert_bih(SOURCE, tmp_path)
    for name in OUTPUT_FILES:
        fresh, committed = (tmp_path / name).read_bytes(), (TASKS / name).read_bytes()
        assert fresh == committed, (
            f"tasks/inhand/{name} differs from a fresh conversion: re-run import-bih"
        )


def test_level1_file_holds_exactly_the_100_published_level1_tasks():
    """Paper IV-A1: 10 objects x 2 initial x 5 desired grasps = 100 Level I tasks; the four
    DMG hand-pose rows of hand_poses.ods live in their own Level III file."""
    from benchharness.inhand.fileformat import read_tasks

    t = read_tasks(TASKS / "level1_hand_poses.csv")
    assert len(t) == 100 and np.all(t.level == 1) and set(t.extra["set"]) == {"allegro-level1"}
    assert len(set(t.object)) == 10
    assert all(np.sum(t.object == o) == 10 for o in set(t.object))
    assert len(set(t.task_id)) == len(t)
    d = read_tasks(TASKS / "level3_dmg_hand_poses.csv")
    assert sorted(d.object) == sorted(TABLE_III)
    assert np.all(d.level == 3) and set(d.extra["set"]) == {"dmg-level3"}
    assert not set(d.task_id) & set(t.task_id)
