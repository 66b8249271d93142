"""Fixtures of the robot tests: robots from the plugin manager, one backend per parameter."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from benchharness.plugin import get_manager

# Batched IK on a 2-core machine shared with other jobs: more torch threads only contend.
torch.set_num_threads(1)

BACKENDS = ("pybullet", "sapien")
ROBOTS = ("pr2", "herb", "allegro")


@pytest.fixture(scope="session")
def manager():
    return get_manager()


@pytest.fixture(scope="session")
def robots(manager):
    """One kinematic robot object per name (spawning makes a fresh one: see ``make_robot``)."""
    return {n: manager.create("robot", n) for n in ROBOTS}


def rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)
