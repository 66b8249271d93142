"""The torch-free kinematic chain (issue 12) against pytorch-kinematics, its oracle.

:mod:`benchharness.robots.urdf_chain` reads each chain from the URDF as
pytorch-kinematics does (origins through float32), and
:mod:`benchharness.robots.uniform_stream` reproduces ``torch.rand`` of a seeded
``torch.Generator``; together they keep every IK result, and so every trial,
bit-identical to the pytorch-kinematics build while a Rubik's trial never
imports torch. Each check here is exact equality, not a tolerance.
"""

from __future__ import annotations

import itertools
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import torch

from benchharness.plugin import get_manager
from benchharness.robots.kinematics import KinematicChain, UniformStream, _SerialModel
from benchharness.robots.urdf_chain import read_serial_chain


def _all_chains():
    """Every arm/finger chain of every registered robot, with the re-centred continuous-joint copies."""
    m = get_manager()
    out = []
    for name in m.names("robot"):
        robot = m.create("robot", name)
        for arm in robot.arms.values():
            chains = [arm.chain]
            mid = [int(i) for i in np.flatnonzero(arm.continuous[:-1])]
            for r in range(1, len(mid) + 1):
                for sub in itertools.combinations(mid, r):
                    chains.append(arm._recentred_chain(tuple(sub)))
            out += [(f"{name}:{c.tip_link}:{i}", c) for i, c in enumerate(chains)]
    return out


CHAINS = _all_chains()


@pytest.mark.parametrize("label, chain", CHAINS, ids=[c[0] for c in CHAINS])
def test_the_urdf_reader_gives_pytorch_kinematics_chain_bit_for_bit(label, chain):
    pk_chain = chain.chain  # the pytorch-kinematics build of the same URDF text
    spec = read_serial_chain(chain._text, chain.root_link, chain.tip_link)
    statics = np.stack([np.eye(4)] + [j.offset for j in spec.joints])
    np.testing.assert_array_equal(statics, pk_chain._static_offsets.numpy())
    np.testing.assert_array_equal(np.stack([j.axis for j in spec.movable]), pk_chain.axes.numpy())
    assert [j.name for j in spec.movable] == pk_chain.get_joint_parameter_names(exclude_fixed=True)
    ours, theirs = _SerialModel.from_urdf(spec), _SerialModel.from_pk(pk_chain)
    q = chain.sample(16, UniformStream(3))
    for a, b in zip(ours.fk_jacobian(q), theirs.fk_jacobian(q)):
        np.testing.assert_array_equal(a, b)
    # and the model agrees with pytorch-kinematics' own FK (its float64 evaluation)
    np.testing.assert_allclose(ours.fk_jacobian(q)[0], chain._fk_pk(q), atol=1e-12)
    low, high = pk_chain.get_joint_limits()
    urdf = np.array([(j.lower, j.upper) for j in spec.movable], dtype=float)
    pk = np.array([low, high], dtype=float).T
    finite = np.isfinite(pk) & np.isfinite(urdf)
    np.testing.assert_array_equal(urdf[finite], pk[finite])


@pytest.mark.parametrize("seed", [0, 1, 12345, 2**31 + 7, 2**32 - 1, 2**32, 2**40 + 3])
def test_uniform_stream_is_torch_rand_bit_for_bit(seed):
    g, u = torch.Generator().manual_seed(seed), UniformStream(seed)
    for shape in ((37, 7), (5, 7), (1, 1), (400, 4)):
        expected = torch.rand(*shape, generator=g, dtype=torch.float64).numpy()
        np.testing.assert_array_equal(u.rand(*shape), expected)


def test_ik_restarts_from_either_generator_are_identical():
    arm = next(iter(get_manager().create("robot", "pr2").arms.values()))
    targets = arm.fk(arm.chain.sample(12, UniformStream(5)))
    a = arm.chain.ik(targets, generator=UniformStream(9))
    b = arm.chain.ik(targets, generator=torch.Generator().manual_seed(9))
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.success, b.success)


def test_a_link_not_below_the_root_is_refused():
    arm = next(iter(get_manager().create("robot", "pr2").arms.values()))
    with pytest.raises(ValueError, match="is not below"):
        read_serial_chain(arm.chain._text, arm.chain.tip_link, arm.chain.root_link)
    with pytest.raises(ValueError, match="'l_gripper_tcp' is not below 'no_such_link'"):
        KinematicChain(arm.chain._text, "no_such_link", "l_gripper_tcp")


def test_a_rubiks_robot_builds_and_solves_ik_without_importing_torch():
    code = textwrap.dedent(
        """
        import sys
        import numpy as np
        from benchharness.plugin import get_manager
        for name in ("pr2", "herb"):
            robot = get_manager().create("robot", name)
            for arm in robot.arms.values():
                q = arm.chain.sample(3, __import__("benchharness.robots.kinematics",
                                                   fromlist=["x"]).UniformStream(1))
                res = arm.ik(arm.fk(q), seed_q=q[0])
                assert res.success.all(), name
        print(sorted(m for m in ("torch", "pytorch_kinematics") if m in sys.modules))
        """
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True
    )
    assert out.stdout.strip().splitlines()[-1] == "[]", out.stdout + out.stderr


def test_the_dls_solve_is_numpy_linalg_solve_bit_for_bit():
    """The IK's direct LAPACK call (issue 12) gives np.linalg.solve's result, bit for bit."""
    from benchharness.robots.kinematics import _solve

    rng = np.random.default_rng(3)
    for b in (1, 7, 64):
        j = rng.normal(size=(b, 6, 7))
        a = j @ j.transpose(0, 2, 1) + 1e-9 * np.eye(6)  # the DLS system: J J^T + damping
        x = rng.normal(size=(b, 6, 1))
        np.testing.assert_array_equal(_solve(a, x), np.linalg.solve(a, x))


def test_the_numpy_fk_and_jacobian_are_independent_of_the_batch():
    """A row's FK and Jacobian in a batch are those it has alone (each 4x4 product is its own GEMM)."""
    arm = next(iter(get_manager().create("robot", "pr2").arms.values()))
    q = arm.chain.sample(20, UniformStream(2))
    tip, jac = arm.chain._np.fk_jacobian(q)
    for i in (0, 7, 19):
        t1, j1 = arm.chain._np.fk_jacobian(q[i : i + 1])
        np.testing.assert_array_equal(t1[0], tip[i])
        np.testing.assert_array_equal(j1[0], jac[i])
