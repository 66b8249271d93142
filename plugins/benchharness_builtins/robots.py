"""Built-in robots: PR2, HERB and the Allegro hand, registered like any third-party robot.

The factories import torch and pytorch-kinematics only when a robot is
created, so listing plugins stays light.
"""

from __future__ import annotations

from benchharness.plugin import Registration, hookimpl


def _pr2(**kwargs):
    from benchharness.robots.pr2 import make_pr2

    return make_pr2(**kwargs)


def _herb(**kwargs):
    from benchharness.robots.herb import make_herb

    return make_herb(**kwargs)


def _allegro(**kwargs):
    from benchharness.robots.allegro import make_allegro

    return make_allegro(**kwargs)


def _pr2_gripper(**kwargs):
    from benchharness.robots.pr2_gripper import make_pr2_gripper

    return make_pr2_gripper(**kwargs)


@hookimpl
def benchharness_robots():
    return [
        Registration(
            "pr2",
            _pr2,
            "Willow Garage PR2: torso, two 7-DOF arms, parallel grippers",
            meta={
                "dof": 19,
                "groups": ["left_arm", "right_arm", "left_gripper", "right_gripper", "torso"],
                "urdf": "robots/pr2/pr2.urdf",
            },
        ),
        Registration(
            "herb",
            _herb,
            "CMU HERB: two Barrett WAM arms with BarrettHand BH8-280",
            meta={
                "dof": 30,
                "groups": ["left_arm", "right_arm", "left_hand", "right_hand"],
                "urdf": "robots/herb/herb.urdf",
            },
        ),
        Registration(
            "allegro",
            _allegro,
            "Allegro hand v4 (right), 16 joints",
            meta={
                "dof": 16,
                "groups": ["index", "middle", "ring", "thumb", "hand"],
                "urdf": "robots/allegro/allegro.urdf",
            },
        ),
        Registration(
            "pr2-gripper",
            _pr2_gripper,
            "PR2 parallel gripper on a 6-DOF stage (in-hand pivoting / DMG execution)",
            meta={
                "dof": 8,
                "groups": ["stage", "gripper"],
                "urdf": "robots/pr2_gripper/pr2_gripper.urdf",
            },
        ),
    ]
