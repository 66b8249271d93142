"""Differentiable fingertip kinematics of the Allegro hand in the palm frame.

The kinematic parameters come from pytorch-kinematics serial chains
(``palm_link`` -> tip link, parsed from the URDF); the forward kinematics the
optimiser differentiates is a small product-of-transforms over all used
fingers at once (one batched Rodrigues rotation per joint), because the
optimiser evaluates it thousands of times per plan and the generic chain
walk costs ~1 ms per finger and call. ``tip_poses_pk`` keeps the generic
path so tests can check the two agree.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import torch

__all__ = ["FINGERS", "TIP_LINKS", "HandKinematics", "default_urdf", "joint_indices"]

DTYPE = torch.float64
#: Benchmark finger numbering (dataset column ``fingers``) -> name.
FINGERS = ("index", "middle", "ring", "thumb")
TIP_LINKS = {
    "index": "link_3_tip",
    "middle": "link_7_tip",
    "ring": "link_11_tip",
    "thumb": "link_15_tip",
}


def joint_indices(fingers: Sequence[str]) -> np.ndarray:
    """Where ``fingers``' joints sit in the 16-joint hand vector (four per finger, in ``fingers``'
    order; the hand's order is :data:`FINGERS`)."""
    return np.concatenate(
        [np.arange(4 * FINGERS.index(f), 4 * FINGERS.index(f) + 4) for f in fingers]
    )


def default_urdf() -> Path:
    """The Allegro description the in-grasp planner and its set-up placement read (``robots/allegro``)."""
    from benchharness.paths import robots_dir

    return robots_dir() / "allegro" / "allegro.urdf"


class HandKinematics:
    """Fingertip FK for a subset of fingers; joint vectors are the fingers' joints concatenated.

    The chains are built once (URDF parsing dominates construction), so keep
    one instance per process and pass it to every plan.
    """

    def __init__(self, urdf: str | Path | None = None, fingers: Sequence[str] = FINGERS) -> None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import pytorch_kinematics as pk

            from_text = str(urdf or "").lstrip().startswith("<")
            #: the description file (None when built from URDF text): the set-up placement reads
            #: the same file's collision shapes
            self.urdf_path: str | None = None if from_text else str(urdf or default_urdf())
            text = str(urdf) if from_text else Path(str(self.urdf_path)).read_text()
            self.fingers = tuple(fingers)
            self.chains = {
                f: pk.build_serial_chain_from_urdf(text.encode(), TIP_LINKS[f], "palm_link").to(
                    dtype=DTYPE
                )
                for f in FINGERS
            }
        lo, hi = [], []
        self.joint_names: dict[str, list[str]] = {}
        for f in FINGERS:
            c = self.chains[f]
            self.joint_names[f] = list(c.get_joint_parameter_names(exclude_fixed=True))
            low, high = c.get_joint_limits()
            lo.append(np.asarray(low, float))
            hi.append(np.asarray(high, float))
        self._lower = dict(zip(FINGERS, lo))
        self._upper = dict(zip(FINGERS, hi))
        self._stacked: dict[tuple[str, ...], tuple[torch.Tensor, ...]] = {}
        self._offsets: dict[str, torch.Tensor] = {}
        self._axes: dict[str, torch.Tensor] = {}
        self._tail: dict[str, torch.Tensor] = {}
        for f in FINGERS:
            offs, axes, pending = [], [], torch.eye(4, dtype=DTYPE)
            for name in self.chains[f].get_frame_names(exclude_fixed=False):
                joint = self.chains[f].find_frame(name).joint
                off = (
                    torch.eye(4, dtype=DTYPE)
                    if joint.offset is None
                    else joint.offset.get_matrix()[0].to(DTYPE)
                )
                pending = pending @ off
                if joint.joint_type == "revolute":
                    offs.append(pending)
                    axes.append(torch.as_tensor(joint.axis, dtype=DTYPE))
                    pending = torch.eye(4, dtype=DTYPE)
                elif joint.joint_type != "fixed":
                    raise ValueError(f"{f}: unsupported joint type {joint.joint_type}")
            if len(offs) != 4:
                raise ValueError(f"{f}: expected 4 revolute joints, found {len(offs)}")
            self._offsets[f], self._axes[f], self._tail[f] = (
                torch.stack(offs),
                torch.stack(axes),
                pending,
            )

    def limits(self, fingers: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper joint limits of ``fingers``' joints, concatenated (rad)."""
        return (
            np.concatenate([self._lower[f] for f in fingers]),
            np.concatenate([self._upper[f] for f in fingers]),
        )

    def tip_poses(self, q: torch.Tensor, fingers: Sequence[str]) -> torch.Tensor:
        """Fingertip transforms in the palm frame: ``q`` (B, 4 k) -> (B, k, 4, 4), differentiable."""
        return self._walk(q, fingers, links=False)

    def link_poses(self, q: torch.Tensor, fingers: Sequence[str]) -> torch.Tensor:
        """Every link of ``fingers`` in the palm frame: ``q`` (B, 4 k) -> (B, k, 5, 4, 4), differentiable.

        Per finger the four links each revolute joint moves (the frame of joint ``i``'s child,
        e.g. ``link_0`` ... ``link_3``) and the fingertip (as :meth:`tip_poses`); the planner's
        collision term places the links' collision boxes with them.
        """
        return self._walk(q, fingers, links=True)

    def _walk(self, q: torch.Tensor, fingers: Sequence[str], links: bool) -> torch.Tensor:
        k = len(fingers)
        q = q.reshape(-1, k, 4)
        key = tuple(fingers)
        if key not in self._stacked:
            offs = torch.stack([self._offsets[f] for f in fingers])  # (k, 4, 4, 4): joint origins
            tail = torch.stack([self._tail[f] for f in fingers])  # (k, 4, 4): last joint -> tip
            axes = torch.stack([self._axes[f] for f in fingers])  # (k, 4, 3)
            kx = torch.zeros(k, 4, 3, 3, dtype=DTYPE)
            kx[..., 0, 1], kx[..., 0, 2], kx[..., 1, 2] = -axes[..., 2], axes[..., 1], -axes[..., 0]
            kx = kx - kx.transpose(-1, -2)
            nxt = torch.cat([offs[:, 1:], tail[:, None]], dim=1)  # transform after each joint
            self._stacked[key] = (offs[:, 0], kx, kx @ kx, nxt[..., :3, :3], nxt[..., :3, 3])
        first, kx, kx2, nr, np_ = self._stacked[key]
        r = first[None, :, :3, :3].expand(q.shape[0], k, 3, 3)
        p = first[None, :, :3, 3].expand(q.shape[0], k, 3)
        s, c = torch.sin(q)[..., None, None], torch.cos(q)[..., None, None]
        rots = torch.eye(3, dtype=DTYPE) + s * kx + (1.0 - c) * kx2  # (B, k, 4, 3, 3) Rodrigues
        frames = []
        for i in range(4):
            r = r @ rots[:, :, i]
            if links:  # joint i's child link: the joint's origin, turned by the joint
                frames.append((r, p))
            p = p + (r @ np_[None, :, i, :, None])[..., 0]
            r = r @ nr[None, :, i]
        frames.append((r, p))
        bottom = torch.tensor([0.0, 0.0, 0.0, 1.0], dtype=DTYPE).expand(q.shape[0], k, 1, 4)
        out = [
            torch.cat([torch.cat([ri, pi[..., None]], dim=-1), bottom], dim=-2) for ri, pi in frames
        ]
        return torch.stack(out, dim=2) if links else out[0]

    def tip_poses_pk(self, q: torch.Tensor, fingers: Sequence[str]) -> torch.Tensor:
        """As :meth:`tip_poses`, through pytorch-kinematics' generic chain walk (reference for tests)."""
        q = q.reshape(-1, 4 * len(fingers))
        out = [
            self.chains[f].forward_kinematics(q[:, 4 * i : 4 * i + 4]).get_matrix()
            for i, f in enumerate(fingers)
        ]
        return torch.stack(out, dim=1)

    def tip_poses_np(self, q: np.ndarray, fingers: Sequence[str]) -> np.ndarray:
        with torch.no_grad():
            return self.tip_poses(
                torch.as_tensor(np.asarray(q, float), dtype=DTYPE), fingers
            ).numpy()
