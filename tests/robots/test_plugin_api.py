"""Robots as plugins: the built-ins' registrations, a user's own URDF, a third-party robot."""

from __future__ import annotations

import re

import numpy as np
import pytest

from benchharness.paths import robots_dir
from benchharness.plugin import Registration, hookimpl
from benchharness.plugin.manager import PluginManager
from benchharness.robots import ArmConfig, GripperConfig, Robot, RobotConfig
from benchharness.robots.pr2 import PR2_FULL_URDF_JOINT_MAP, PR2_FULL_URDF_LINK_MAP


def test_builtins_registered_with_meta(manager):
    for name, dof in (("pr2", 19), ("herb", 30), ("allegro", 16)):
        item = manager.get("robot", name)
        assert item.distribution == "benchharness" and item.meta["dof"] == dof
        r = item.create()
        assert r.driven_dof == dof and sorted(r.groups()) == sorted(item.meta["groups"])


def _renamed_pr2(tmp_path):
    """A stand-in for a full pr2_description URDF: our file with its tool frames renamed."""
    text = (robots_dir() / "pr2" / "pr2.urdf").read_text()
    text = text.replace('"l_gripper_tcp"', '"l_gripper_tool_frame"').replace(
        '"r_gripper_tcp"', '"r_gripper_tool_frame"'
    )
    path = tmp_path / "my_pr2.urdf"
    path.write_text(text)
    return path


def test_user_urdf_with_name_map(tmp_path, make_robot):
    path = _renamed_pr2(tmp_path)
    # keep our grippers (the renamed file still has our finger joints)
    link_map = dict(PR2_FULL_URDF_LINK_MAP)
    r = make_robot("pr2", urdf=path, link_map=link_map)
    assert r.urdf_path == path
    assert r.arm("left_arm").config.tcp_link == "l_gripper_tool_frame"
    assert "left_gripper" in r.grippers
    ours = make_robot("pr2")
    q = ours.arm("left_arm").chain.sample(3, __import__("torch").Generator().manual_seed(0))
    np.testing.assert_allclose(r.arm("left_arm").fk(q), ours.arm("left_arm").fk(q), atol=1e-12)
    # the documented full-URDF map drops the two-finger grippers (the real one is a mimic linkage)
    r2 = make_robot("pr2", urdf=path, joint_map=PR2_FULL_URDF_JOINT_MAP, link_map=link_map)
    assert set(r2.grippers) == set() and set(r2.arms) == {"left_arm", "right_arm"}


def test_user_urdf_with_missing_joint_fails_clearly(tmp_path, make_robot):
    path = _renamed_pr2(tmp_path)
    with pytest.raises(ValueError, match=re.escape("not movable joints")):
        make_robot("pr2", urdf=path, joint_map={"l_elbow_flex_joint": "l_elbow"})


class ThirdPartyArm:
    """What a third-party distribution's plugin module would contain."""

    @staticmethod
    @hookimpl
    def benchharness_robots():
        def make(**kwargs):
            cfg = RobotConfig(
                name="allegro-finger",
                urdf=robots_dir() / "allegro" / "allegro.urdf",
                arms=(
                    ArmConfig(
                        "index",
                        ("joint_0", "joint_1", "joint_2", "joint_3"),
                        "palm_link",
                        "link_3_tip",
                        (3.0,) * 4,
                        (0.1,) * 4,
                        position_only=True,
                    ),
                ),
                grippers=(
                    GripperConfig(
                        "pinch",
                        ("joint_1", "joint_13"),
                        ("close",),
                        ((1.0,), (1.0,)),
                        (0.0,),
                        (1.2,),
                        ("close",),
                        (3.0, 3.0),
                        (0.1, 0.1),
                        (0.7, 0.7),
                        ("link_3_tip", "link_15_tip"),
                        kind="multifinger",
                    ),
                ),
            )
            return Robot(cfg)

        return [
            Registration(
                "allegro-finger", make, "an Allegro index finger as a robot", meta={"dof": 16}
            )
        ]


def test_third_party_robot_plugin():
    pm = PluginManager()
    pm.register_module(
        ThirdPartyArm, entry_point="third_party = my_pkg.robots", distribution="my-pkg"
    )
    assert pm.errors == []
    r = pm.create("robot", "allegro-finger")
    assert r.arm("index").fk(np.zeros(4)).shape == (1, 4, 4)
    assert pm.get("robot", "allegro-finger").distribution == "my-pkg"
