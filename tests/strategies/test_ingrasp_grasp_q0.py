"""What the published Level I grasp ``q_0`` is: the fingers' set-point, not where they touch.

Independent references: the published file itself (the grasp joints are typed to two decimals,
the measured poses to ten); the PD law (a drive of stiffness ``K`` commanded to ``q_0`` holds the
torque ``K (q_0 - q)``) checked against pytorch-kinematics' own Jacobian; the friction cone
(``atan(mu)``, 45 deg at the default friction) for the grasp that dropped on SAPIEN.
"""

from __future__ import annotations

import csv

import numpy as np
import pytest
import torch
from ingrasp_helpers import trial_context

from benchharness.plugin import get_manager
from benchharness.strategies.ingrasp.execution import (
    ExecConfig,
    InGraspExecutor,
    touch_configuration,
)
from benchharness.strategies.ingrasp.hand import FINGERS, joint_indices
from benchharness.strategies.ingrasp.problem import problem_from_task
from benchharness.strategies.ingrasp.strategy import InGraspPlanner, _shared_hand
from benchharness.strategies.ingrasp.tasks import published_level1_path, published_tasks

KP = 3.0  #: N m/rad, the Allegro robot's joint stiffness (robots.allegro.KP)


def _decimals(text: str) -> int:
    return len(text.split(".")[1]) if "." in text else 0


def test_published_grasps_are_typed_set_points():
    """Every published grasp joint has at most two decimals (1,545 of 1,600 are multiples of 0.1
    rad); the palm poses, which were measured, carry up to ten. Encoder readings would not."""
    with open(published_level1_path(), newline="") as fh:
        rows = list(csv.DictReader(fh))
    joints = [r[f"grasp_{f}_j{j}"] for r in rows for f in FINGERS for j in range(4)]
    poses = [r[f"{w}_{a}"] for r in rows for w in ("initial", "desired") for a in "xyz"]
    assert max(_decimals(v) for v in joints) == 2
    tenths = sum(abs(float(v) * 10 - round(float(v) * 10)) < 1e-9 for v in joints)
    assert tenths / len(joints) > 0.95
    assert max(_decimals(v) for v in poses) >= 8


@pytest.fixture(scope="module")
def apple01():
    torch.set_num_threads(1)
    return {t.task_id: t for t in published_tasks()}["apple-01"]


def test_touch_configuration_balances_the_pd_drive(apple01):
    """At ``q_c`` the PD torque ``K (q_0 - q_c)`` is ``J(q_c)^T f`` for internal fingertip forces
    of mean 3 N (Jacobian from pytorch-kinematics' chain, not the executor's own); the fingertips
    touch farther out than at ``q_0`` (the squeeze holds them back)."""
    hand = _shared_hand()
    p = problem_from_task(apple01, hand)
    idx = joint_indices(p.fingers)
    lo, hi = hand.limits(FINGERS)
    q0 = p.q_rest
    qc = touch_configuration(hand, q0, p.fingers, 3.0, np.full(len(idx), KP), lo, hi)
    assert np.array_equal(np.delete(qc, idx), np.delete(q0, idx))  # unused fingers untouched
    tau = KP * (q0[idx] - qc[idx])
    forces = []
    for i, f in enumerate(p.fingers):
        q = torch.as_tensor(qc[idx][4 * i : 4 * i + 4][None], dtype=torch.float64)
        jac = hand.chains[f].jacobian(q)[0, :3].numpy()  # linear rows, palm frame
        forces.append(np.linalg.lstsq(jac.T, tau[4 * i : 4 * i + 4], rcond=None)[0])
    forces = np.array(forces)
    np.testing.assert_allclose(forces.sum(axis=0), 0.0, atol=1e-5)  # internal: no net push (N)
    assert np.mean(np.linalg.norm(forces, axis=1)) == pytest.approx(3.0, rel=1e-4)
    t0 = hand.tip_poses_np(q0[idx][None], p.fingers)[0][:, :3, 3]
    tc = hand.tip_poses_np(qc[idx][None], p.fingers)[0][:, :3, 3]
    out0 = np.linalg.norm(t0 - t0.mean(axis=0), axis=1)
    outc = np.linalg.norm(tc - tc.mean(axis=0), axis=1)
    assert np.all(outc > out0 + 0.002)  # every fingertip at least 2 mm farther out


def test_command_mode_sets_a_round_grasp_inside_the_friction_cone(apple01):
    """apple-01: touching at ``q_0`` the squeeze meets the apple 40.7 deg off its normals, at the
    edge of the 45 deg cone (SAPIEN dropped it, docs/ingrasp.md); touching where the squeeze
    holds the fingers back from ``q_0``, 28.0 deg, well inside."""
    planner = InGraspPlanner("relaxed-rigidity")
    p = planner.problem(apple01)
    contact = InGraspExecutor(planner.hand, ExecConfig(grasp_q0="contact")).placement(
        p, apple01.object, 1.0
    )
    hand = planner.hand
    lo, hi = hand.limits(FINGERS)
    qc = touch_configuration(
        hand, p.q_rest, p.fingers, 3.0, np.full(4 * len(p.fingers), KP), lo, hi
    )
    command = InGraspExecutor(hand, ExecConfig(grasp_q0="command")).placement(
        p, apple01.object, 1.0, qc
    )
    assert max(contact.grip_angles_deg) == pytest.approx(40.7, abs=0.1)
    assert max(command.grip_angles_deg) == pytest.approx(28.0, abs=0.1)
    assert command.max_gap < 1e-4 and command.penetration == 0.0


@pytest.mark.sim
@pytest.mark.parametrize("backend", ["pybullet", "sapien"])
def test_command_mode_holds_the_apple(apple01, backend):
    """The same grasp executed with ``grasp_q0="command"`` on both engines: held through the plan
    and the hold, the fingers settled where the model put the contact (within 0.06 rad, while it
    lies 0.08 rad from ``q_0``)."""
    be = get_manager().create("backend", backend)
    try:
        out = InGraspPlanner(
            "relaxed-rigidity", exec_config=ExecConfig(grasp_q0="command", hold_s=1.0)
        ).run_trial(trial_context(apple01, be))
    finally:
        be.close()
    assert out.failure is None, out.message
    assert out.extra["touch_offset_rad"] == pytest.approx(0.082, abs=0.001)
    assert out.extra["setup_joint_error_rad"] < 0.06


def test_grasp_q0_is_validated():
    with pytest.raises(ValueError, match="grasp_q0 must be 'contact' or 'command', not 'measured'"):
        ExecConfig(grasp_q0="measured")  # type: ignore[arg-type]


def test_grasp_q0_from_the_command_line(tmp_path):
    """``--strategy-option exec_config.grasp_q0=...``: listed with its default, a wrong value refused
    in one line (exit 2) before any trial and without creating the store."""
    import json

    from click.testing import CliRunner

    from benchharness.cli.main import cli

    r = CliRunner().invoke(cli, ["plugins", "--options", "relaxed-rigidity", "--json"])
    assert r.exit_code == 0, r.output
    keys = {o["key"]: o for o in json.loads(r.output)["options"]}
    assert keys["exec_config.grasp_q0"]["default"] == "command"
    store = tmp_path / "s.sqlite"
    args = [
        "run",
        "--task",
        "inhand-level1",
        "--robot",
        "allegro",
        "--strategy",
        "relaxed-rigidity",
    ]
    opt = ["--strategy-option", "exec_config.grasp_q0=measured", "--store", str(store)]
    r = CliRunner().invoke(cli, [*args, "--backend", "pybullet", "--trials", "1", *opt])
    assert r.exit_code == 2, r.output
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "exec_config.grasp_q0=measured" in lines[0], r.stderr
    assert not store.exists()
