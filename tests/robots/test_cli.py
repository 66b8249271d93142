"""``benchharness robots`` and ``benchharness robot inspect`` through the real CLI entry point."""

from __future__ import annotations

import json

import matplotlib.image
import numpy as np
import pytest
from click.testing import CliRunner

from benchharness.cli.main import cli


def _run(args):
    res = CliRunner().invoke(cli, args, catch_exceptions=False)
    return res


def test_robots_lists_builtins_json():
    res = _run(["robots", "--json"])
    assert res.exit_code == 0
    rows = {r["name"]: r for r in json.loads(res.output)["robots"]}
    assert rows["pr2"]["dof"] == 19 and "left_gripper" in rows["pr2"]["groups"]
    assert rows["herb"]["dof"] == 30 and rows["allegro"]["dof"] == 16
    assert {r["distribution"] for r in rows.values()} == {"benchharness"}


@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
def test_inspect_json(backend):
    res = _run(["robot", "inspect", "pr2", "--backend", backend, "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.output[res.output.index("{") :])
    # 19 driven joints; the model has 23: each four-bar fingertip is a joint that follows its finger
    assert data["dof"] == 19 and len(data["joints"]) == 23
    lift = next(j for j in data["joints"] if j["name"] == "l_shoulder_lift_joint")
    assert (lift["lower"], lift["upper"]) == pytest.approx((-0.5236, 1.3963))
    assert data["tcp_frames"]["left_arm"]["link"] == "l_gripper_tcp"
    assert data["tcp_frames"]["left_arm"]["position"][2] == pytest.approx(0.793, abs=0.01)


def test_inspect_png_on_sapien_needs_no_camera(tmp_path):
    png = tmp_path / "allegro.png"
    res = _run(["robot", "inspect", "allegro", "--backend", "sapien", "--png", str(png)])
    assert res.exit_code == 0, res.output
    assert f"drawing: {png}" in " ".join(res.output.split())
    img = matplotlib.image.imread(str(png))
    # the robot is visible: a good share of pixels differ from the white background
    assert (np.abs(img[:, :, :3] - 1.0).sum(axis=2) > 0.1).mean() > 0.02


def test_inspect_unknown_robot_is_bad_input():
    res = CliRunner().invoke(cli, ["robot", "inspect", "nosuchbot"])
    assert res.exit_code == 2
    assert "no robot named 'nosuchbot'" in res.output
