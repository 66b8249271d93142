"""Edges from a pre-touch sweep: where the range steps as the beam leaves (or meets) a face.

A fingertip ToF sensor moved sideways across a cube face reads a nearly
constant range while its beam is on the face and jumps (to nothing, or to
something much farther) when the beam passes the face's edge. The sensor's
position at that step is an observation of the edge along the sweep direction
— of the cube's position *across* the beam, which a range on the face alone
never gives (Yang et al., ICRA 2017, located the cube's edges this way).

:func:`find_edges` reads one emitter's readings in time order (a :class:`~.pretouch.Scan`
of a single-emitter sensor, or the three arrays) and returns an
:class:`EdgeObservation` per face edge crossed: the point on the face at the
transition, the direction of motion there, and the standard deviations the
filter (:mod:`.pose6`) needs. Only what the robot has is used: the believed
ray origins and directions and the measured ranges.

Rules (each with why):

* readings group into *runs* of consecutive returns whose ranges differ by
  less than ``jump`` (10 mm: ~7 σ of the VL6180X's range noise, and under
  the 57 mm face a beam can only step off); a face is a run of at least
  ``min_run`` readings over at least ``min_face_length`` of travel whose
  fitted range slope is at most ``max_face_slope`` (a few readings grazing the
  adjacent face of a turned cube are neither);
* an edge is a face run's end next to at least ``min_run`` readings with no
  return (inf) or ranges more than ``jump`` *farther*; NaN (too close, or a
  reading the caller masked) is neither face nor beyond; a neighbour that is nearer is
  something in front of the face (the other hand's finger), whose edge is not
  the cube's, and is skipped;
* the transition lies between the last face reading and the first off
  reading: its position is their midpoint, with the uniform quantisation
  std ``spacing / √12`` plus ``edge_std`` for the beam's footprint
  (:class:`~.config.SweepConfig`); the range at the edge is the mean of the
  last ``min_run`` face readings (the face is flat over a few mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .config import SweepConfig, ToFConfig

__all__ = ["EdgeObservation", "find_edges"]


@dataclass(frozen=True)
class EdgeObservation:
    """A face edge crossed by a sweeping beam (world frame, as the robot believes it)."""

    point: np.ndarray  #: (3,) the point on the ranged face at the transition (m)
    step: np.ndarray  #: (3,) unit direction the beam moved in at the transition
    direction: np.ndarray  #: (3,) unit ray direction
    entering: bool  #: the beam came onto the face (else it left it)
    std_along: float  #: std (m) of the transition along ``step``
    std_range: float  #: std (m) of ``point`` along ``direction``
    index: int  #: index of the face-side reading at the transition


def _runs(z: np.ndarray, jump: float, exclude: np.ndarray) -> list[tuple[int, int]]:
    """Half-open index ranges of consecutive finite, not excluded readings that differ by less than ``jump``."""
    out: list[tuple[int, int]] = []
    start: int | None = None
    for i in range(len(z)):
        if not np.isfinite(z[i]) or exclude[i]:
            if start is not None:
                out.append((start, i))
                start = None
            continue
        if start is None:
            start = i
        elif abs(z[i] - z[i - 1]) >= jump:
            out.append((start, i))
            start = i
    if start is not None:
        out.append((start, len(z)))
    return out


def find_edges(
    origins: np.ndarray,
    directions: np.ndarray,
    distances: np.ndarray,
    *,
    config: SweepConfig | None = None,
    tof: ToFConfig | None = None,
    exclude: np.ndarray | None = None,
) -> list[EdgeObservation]:
    """Face edges crossed by one emitter's readings (in time order; see the module docstring).

    ``exclude`` (n,) marks readings that may come from something other than
    the cube (a self-filter's verdict: the robot's own other hand): they are
    never part of a face, but still count as beyond an edge when farther
    than the face by ``jump`` (a finger 28 mm behind the face edge is still
    an edge's far side).
    """
    cfg = config or SweepConfig()
    tof = tof or ToFConfig()
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    z = np.asarray(distances, dtype=float).reshape(-1)
    if not (len(o) == len(d) == len(z)):
        raise ValueError("origins, directions and distances must have one row per reading")
    n_min = int(cfg.min_run)
    excl = np.zeros(len(z), dtype=bool) if exclude is None else np.asarray(exclude, dtype=bool)
    if excl.shape != z.shape:
        raise ValueError(f"exclude must have shape {z.shape}, got {excl.shape}")
    runs = _runs(z, cfg.jump, excl)

    def is_face(a: int, b: int) -> bool:
        if b - a < n_min:
            return False
        s = (o[a:b] - o[a]) @ (o[b - 1] - o[a]) / max(float(np.linalg.norm(o[b - 1] - o[a])), 1e-12)
        if s[-1] < cfg.min_face_length:
            return False
        slope = np.polyfit(s, z[a:b], 1)[0]
        return bool(abs(slope) <= cfg.max_face_slope)

    faces = [r for r in runs if is_face(*r)]

    def far_side(face_range: float, idx: range) -> bool:
        """``idx`` (at least min_run readings) all without a return or farther than the face by ``jump``."""
        if len(idx) < n_min:
            return False
        zz = z[list(idx)]
        # no return (inf) or a farther surface; NaN (too close, or masked by the caller) is neither
        return bool(np.all((zz == np.inf) | (np.isfinite(zz) & (zz > face_range + cfg.jump))))

    out: list[EdgeObservation] = []
    for a, b in faces:
        for entering in (True, False):
            if entering:
                face_i, off_i = a, a - 1
                side = range(a - n_min, a)
                near = range(a, a + n_min)
            else:
                face_i, off_i = b - 1, b
                side = range(b, b + n_min)
                near = range(b - n_min, b)
            if off_i < 0 or off_i >= len(z) or side.start < 0 or side.stop > len(z):
                continue
            r_face = float(np.mean(z[list(near)]))
            if not far_side(r_face, side):
                continue
            mid = 0.5 * (o[face_i] + o[off_i])
            step = o[face_i] - o[off_i] if entering else o[off_i] - o[face_i]
            spacing = float(np.linalg.norm(step))
            if spacing < 1e-9:
                continue
            ray = d[face_i]
            out.append(
                EdgeObservation(
                    point=mid + r_face * ray,
                    step=step / spacing,
                    direction=ray.copy(),
                    entering=entering,
                    std_along=math.hypot(spacing / math.sqrt(12.0), cfg.edge_std),
                    std_range=tof.std_at(r_face) / math.sqrt(n_min),
                    index=int(face_i),
                )
            )
    out.sort(key=lambda e: e.index)
    return out
