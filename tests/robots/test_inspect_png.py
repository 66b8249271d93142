"""``benchharness robot inspect NAME --png FILE``: the drawing a person checks a robot with.

The drawn geometry is checked against an independent model: yourdfpy's
collision scene of the same URDF at the same joint values (its own URDF
parser, FK and primitive meshes). Its bounding box, mapped to pixels through
each panel's stated limits, must match where the robot's coloured pixels
are in the PNG.
"""

from __future__ import annotations

import colorsys
import json
import warnings

import matplotlib.colors
import matplotlib.image
import numpy as np
import pytest
from click.testing import CliRunner

import benchharness.cli.robots as robots_cli
from benchharness.cli.main import cli
from benchharness.plugin import get_manager
from benchharness.robots.sketch import link_colours

pytestmark = pytest.mark.sim

SIZE = (1000, 500)
ROBOTS = ("pr2", "herb", "allegro", "pr2-gripper")


def _inspect(*args: str):
    return CliRunner().invoke(cli, ["robot", "inspect", *args], catch_exceptions=False)


def _draw(tmp_path, name: str, *extra: str) -> tuple[np.ndarray, dict]:
    png = tmp_path / f"{name}.png"
    res = _inspect(name, "--json", "--png", str(png), "--size", f"{SIZE[0]}x{SIZE[1]}", *extra)
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout[res.stdout.index("{") :])
    return matplotlib.image.imread(str(png))[:, :, :3], data


def _robot_mask(img: np.ndarray) -> np.ndarray:
    """Pixels of robot geometry: saturated colours (background, floor, grid, text are grey)."""
    hsv = matplotlib.colors.rgb_to_hsv(img)
    return (hsv[..., 1] > 0.3) & (hsv[..., 2] > 0.15)


def _panel(img: np.ndarray, box) -> tuple[np.ndarray, int, int]:
    x0, y0, x1, y1 = (round(v) for v in box)
    return img[y0:y1, x0:x1], x0, y0


def _yourdfpy_bounds(name: str) -> np.ndarray:
    """World bounding box of the robot's collision geometry at home, by yourdfpy."""
    yourdfpy = pytest.importorskip("yourdfpy")
    rob = get_manager().create("robot", name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        u = yourdfpy.URDF.load(
            str(rob.urdf_path),
            build_scene_graph=False,
            load_meshes=False,
            build_collision_scene_graph=True,
            load_collision_meshes=True,
        )
        u.update_cfg(dict(zip(rob.joint_names, rob.home())))
        b = np.asarray(u.collision_scene.bounds, dtype=float)
    base = rob.config.base_pose
    assert np.allclose(base.q, [0, 0, 0, 1]), "test assumes a translated, unrotated base"
    return b + base.p


@pytest.mark.parametrize("name", ROBOTS)
def test_png_frames_the_robot_as_the_urdf_says(tmp_path, name):
    img, data = _draw(tmp_path, name)
    assert img.shape[:2] == (SIZE[1], SIZE[0])
    drawing = data["drawing"]
    want = _yourdfpy_bounds(name)
    # our tessellation's extent equals yourdfpy's to within facet sagitta (mm)
    assert np.allclose(drawing["bounds_m"], want, atol=3e-3), (drawing["bounds_m"], want)
    mask = _robot_mask(img)
    assert mask.mean() > 0.03  # not blank
    axes = {"side": (0, 2), "top": (0, 1)}
    for view, (iu, iv) in axes.items():
        panel = drawing["panels"][view]
        sub, x0, y0 = _panel(mask, panel["pixels"])
        ys, xs = np.nonzero(sub)
        h, w = sub.shape
        got_w, got_h = xs.max() - xs.min() + 1, ys.max() - ys.min() + 1
        # the robot fills its panel
        assert got_w > 0.6 * w or got_h > 0.6 * h, (view, got_w, w, got_h, h)
        # ... exactly where the independent bounding box says, through the panel's limits
        (ul, uh), (vl, vh) = panel["limits_m"]
        px_per_m = w / (uh - ul)
        assert h / (vh - vl) == pytest.approx(px_per_m, rel=0.01)  # equal scale on both axes
        left = (want[0, iu] - ul) * px_per_m
        right = (want[1, iu] - ul) * px_per_m
        top = (vh - want[1, iv]) * px_per_m
        bottom = (vh - want[0, iv]) * px_per_m
        tol = 4.0  # px: outlines, antialiasing
        assert abs(xs.min() - left) < tol and abs(xs.max() + 1 - right) < tol, (
            view,
            xs.min(),
            left,
        )
        assert abs(ys.min() - top) < tol and abs(ys.max() + 1 - bottom) < tol, (view, ys.min(), top)


@pytest.mark.parametrize(("name", "min_hues"), [("pr2", 12), ("herb", 12)])
def test_links_get_distinct_colours(tmp_path, name, min_hues):
    img, data = _draw(tmp_path, name)
    hsv = matplotlib.colors.rgb_to_hsv(img)
    hues = hsv[..., 0][_robot_mask(img)]
    # 2-degree hue bins holding a visible area each (one colour for all would fill one or two)
    counts, _ = np.histogram(hues, bins=180, range=(0.0, 1.0))
    assert (counts >= 100).sum() >= min_hues
    # every link drawn has its own hue
    cols = link_colours([f"l{i}" for i in range(data["drawing"]["links_drawn"])])
    h = sorted(colorsys.rgb_to_hsv(*c)[0] for c in cols.values())
    assert min(np.diff(h)) > 0.005


def test_frames_change_the_image(tmp_path):
    plain, _ = _draw(tmp_path, "pr2")
    (tmp_path / "f").mkdir()
    framed, data = _draw(tmp_path / "f", "pr2", "--frames", "--frame-labels")
    assert data["drawing"]["frames"][0] == "torso_lift_joint"
    changed = np.abs(framed - plain).sum(axis=2) > 0.05
    assert changed.mean() > 0.002
    # the triads' pure red, green and blue are there
    for rgb in ((0.878, 0.0, 0.0), (0.0, 0.69, 0.0), (0.0, 0.25, 1.0)):
        assert (np.abs(framed - rgb).max(axis=2) < 0.08).sum() > 20, rgb


def test_joint_values_move_the_drawing_and_output_is_deterministic(tmp_path):
    a = tmp_path / "a.png"
    b = tmp_path / "b.png"
    c = tmp_path / "c.png"
    assert _inspect("pr2-gripper", "--png", str(a)).exit_code == 0
    assert _inspect("pr2-gripper", "--png", str(b)).exit_code == 0
    assert a.read_bytes() == b.read_bytes()
    res = _inspect("pr2-gripper", "--json", "--png", str(c), "--joints", "stage_z_joint=0.5")
    assert res.exit_code == 0, res.output
    bounds = json.loads(res.stdout[res.stdout.index("{") :])["drawing"]["bounds_m"]
    assert a.read_bytes() != c.read_bytes() and bounds[1][2] > 0.6


def test_missing_png_folder_is_bad_input_before_any_work(tmp_path, monkeypatch):
    def no_work():
        raise AssertionError("a robot or backend was built before the --png check")

    monkeypatch.setattr(robots_cli, "get_manager", no_work)
    target = tmp_path / "no" / "such" / "pr2.png"
    res = _inspect("pr2", "--png", str(target))
    assert res.exit_code == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and str(target) in lines[0] and "does not exist" in lines[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("joints", "words"),
    [
        ("nosuch=1", "no movable joint 'nosuch'"),
        ("torso_lift_joint=2", "outside"),
        ("x", "name=value"),
    ],
)
def test_bad_joints_are_bad_input_and_write_nothing(tmp_path, joints, words):
    png = tmp_path / "pr2.png"
    res = _inspect("pr2", "--png", str(png), "--joints", joints)
    assert res.exit_code == 2 and words in res.stderr
    assert not png.exists()
