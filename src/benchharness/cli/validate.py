"""Checks of command-line values that no single dataclass owns, shared by the commands.

Each raises :class:`ValueError` with one line naming the option and the
value; the commands turn it into exit 2 (``common.fail``) *before* any trial
runs or any file is written. Physics settings are checked by
:class:`~benchharness.backends.interface.PhysicsConfig` itself, so the
Python API is guarded too.
"""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["SEED_MAX", "check_backends", "check_seed", "check_video_trial"]

#: The store keeps a run's seed in an SQLite ``INTEGER`` (signed 64-bit), and
#: NumPy's ``SeedSequence`` takes no negative entropy: seeds are 0..2**63-1,
#: for ``rubiks sequence`` too, since its seed is the one a run stores.
SEED_MAX = 2**63 - 1


def check_seed(seed: int, option: str = "--seed") -> int:
    if not 0 <= seed <= SEED_MAX:
        raise ValueError(f"{option} {seed}: must be an integer in 0..{SEED_MAX} (2**63 - 1)")
    return seed


def check_backends(names: Sequence[str], option: str = "--backends") -> tuple[str, ...]:
    """At least two backends, each named once (the same backend twice compares nothing)."""
    if len(names) < 2:
        raise ValueError(f"{option}: name at least two backends, comma-separated")
    seen: set[str] = set()
    for n in names:
        if n in seen:
            raise ValueError(f"{option} {','.join(names)}: backend {n!r} is named twice")
        seen.add(n)
    return tuple(names)


def check_video_trial(video_trial: int, trial_sel: str | None) -> None:
    """``--video-trial`` must be one of the trials ``--trials`` runs."""
    from ..runner.tasks import parse_trial_indices

    if video_trial < 1:
        raise ValueError(f"--video-trial {video_trial}: trials are numbered from 1")
    if trial_sel:
        chosen = parse_trial_indices(trial_sel)
        if video_trial not in chosen:
            raise ValueError(
                f"--video-trial {video_trial} is not among --trials {trial_sel} "
                "(the video records a trial this run runs)"
            )
