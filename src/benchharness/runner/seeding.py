"""Per-trial random streams derived from (run seed, task, trial index) alone.

Derived, not drawn from a shared generator, so a trial's randomness does
not depend on which trials ran before it, in which process, or how many
workers there are: resume and ``--workers N`` give the same results as one
uninterrupted serial run. No global random state is touched.

The Rubik's *sequences* are not drawn here: they come from the protocol's
own pinned generator (:mod:`benchharness.cube.sequences`) so they match what
a real-robot user gets for the same seed.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

__all__ = ["TrialStreams", "trial_streams"]


def _word(text: str) -> int:
    return int.from_bytes(hashlib.sha256(text.encode("utf-8")).digest()[:4], "little")


@dataclass(frozen=True)
class TrialStreams:
    """The generators of one trial: the strategy's, one per sensor, and the backend's seed."""

    strategy: np.random.Generator
    sensors: tuple[np.random.Generator, ...]
    backend_seed: int


def trial_streams(seed: int, task: str, trial_index: int, n_sensors: int = 0) -> TrialStreams:
    """Independent streams for one trial (NumPy ``SeedSequence`` spawning).

    The task enters through a hash of its name (case-folded, so ``rubiks-5-20``
    and ``Rubiks-5-20`` agree).
    """
    root = np.random.SeedSequence(
        entropy=int(seed), spawn_key=(_word(task.strip().lower()), int(trial_index))
    )
    children = root.spawn(2 + n_sensors)
    backend_seed = int(children[1].generate_state(1, dtype=np.uint32)[0])
    return TrialStreams(
        strategy=np.random.Generator(np.random.PCG64(children[0])),
        sensors=tuple(np.random.Generator(np.random.PCG64(c)) for c in children[2:]),
        backend_seed=backend_seed,
    )
