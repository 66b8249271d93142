"""A real third-party distribution (examples/benchharness-example-plugin) plugs in
without any change to this repository.

The example is pip-installed into a temporary directory (no dependencies, no
network: it builds with the setuptools already installed) and put on
PYTHONPATH for a fresh interpreter, the way an installed package would be.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "benchharness-example-plugin"
CLI = [sys.executable, "-m", "benchharness.cli.main"]


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    target = tmp_path_factory.mktemp("site")
    build = tmp_path_factory.mktemp("build")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--quiet",
            "--no-deps",
            "--no-build-isolation",
            "--target",
            str(target),
            str(EXAMPLE),
        ],
        check=True,
        cwd=build,
    )
    # the target goes first; whatever PYTHONPATH already says (a source checkout under test) stays
    path = os.pathsep.join(p for p in (str(target), os.environ.get("PYTHONPATH", "")) if p)
    return dict(os.environ, PYTHONPATH=path)


def run(env, *args):
    return subprocess.run([*CLI, *args], capture_output=True, text=True, env=env, timeout=300)


def test_items_appear_with_the_example_distribution(installed):
    out = run(installed, "plugins", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    mine = {(i["kind"], i["name"]): i["distribution"] for i in data["items"]}
    assert mine[("robot", "example-gantry-gripper")] == "benchharness-example-plugin"
    assert mine[("task", "Example-Rubiks-2-3")] == "benchharness-example-plugin"
    assert data["errors"] == []
    robot = next(i for i in data["items"] if i["name"] == "example-gantry-gripper")
    # read off the plugin's RobotConfig: gantry_x/y/z and two fingers, the URDF's movable joints
    assert robot["meta"]["dof"] == 5
    assert robot["meta"]["groups"] == ["gantry", "gripper"]
    assert robot["meta"]["urdf"].endswith("benchharness_example/gantry_gripper.urdf")


def test_not_visible_without_installing():
    out = subprocess.run(
        [*CLI, "plugins", "--json"],
        capture_output=True,
        text=True,
        timeout=300,
        env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"},
    )
    names = {i["name"] for i in json.loads(out.stdout)["items"]}
    assert "example-gantry-gripper" not in names


def test_plugin_tier_works_with_the_protocol_cli(installed):
    out = run(installed, "rubiks", "sequence", "--tier", "Example-Rubiks-2-3", "--seed", "1")
    assert out.returncode == 0, out.stderr
    lines = out.stdout.strip().splitlines()
    assert len(lines) == 2 and all(len(line.split()) == 3 for line in lines)


@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
def test_plugin_robot_picks_up_a_cube(installed, backend):
    """The third-party robot gets IK and motion primitives on every backend for free."""
    code = f"""
import numpy as np
from benchharness.backends import Box
from benchharness.geometry import Pose
from benchharness.plugin import get_manager
m = get_manager()
b = m.create("backend", {backend!r}); b.add_ground()
robot = m.create("robot", "example-gantry-gripper"); robot.spawn(b)
cube = b.add_body([Box((0.0285,) * 3)], Pose(np.array([0.1, 0.05, 0.0285])), 0.094)
arm, grip = robot.arm("gantry"), robot.gripper("gripper")
reach = arm.move_to_pose(Pose(np.array([0.1, 0.05, 0.04])))
grasp = grip.close(obj=cube)
arm.move_to_pose(Pose(np.array([0.1, 0.05, 0.15])))
print(reach.pos_error, grasp.contact, b.get_pose(cube).p[2])
"""
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=installed, timeout=300
    )
    assert out.returncode == 0, out.stderr
    pos_error, contact, z = out.stdout.split()
    assert float(pos_error) < 0.005
    assert contact == "True"
    assert float(z) > 0.12  # lifted ~11 cm off the table (centre started at 0.0285)
