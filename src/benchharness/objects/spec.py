"""Typed description of a benchmark object: what was published, and how we model it.

The published facts (YCB id, dimensions, mass, their source) and our
simplified geometry live side by side so that a reader checking a number
finds its citation next to it, and a test can compare the generated model
against the published figure it claims to reproduce.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from .boxunion import AABox
from .swept import SweepProfile

__all__ = [
    "Citation",
    "SweepGeometry",
    "BoxGeometry",
    "Geometry",
    "MeshFrame",
    "ObjectSpec",
    "YcbScan",
]


@dataclass(frozen=True)
class Citation:
    """Where a figure comes from (``key`` is short, ``text`` the full reference)."""

    key: str
    text: str


@dataclass(frozen=True)
class SweepGeometry:
    """An elliptical-section sweep (see :mod:`.swept`).

    ``axis="z"`` turns the sweep axis from x to z (bodies of revolution stand
    on their axis, like the real can). ``collision`` picks the collision
    model: the exact primitive where the surface *is* one, otherwise convex
    hull pieces of ring stacks.
    """

    profile: SweepProfile
    axis: Literal["x", "z"] = "x"
    collision: Literal["sphere", "cylinder", "hull_pieces"] = "hull_pieces"


@dataclass(frozen=True)
class BoxGeometry:
    """A union of non-overlapping axis-aligned boxes (see :mod:`.boxunion`)."""

    boxes: tuple[AABox, ...]


Geometry = SweepGeometry | BoxGeometry

#: Where the published in-hand data puts the object's origin relative to the
#: YCB scan: ``"ycb"`` = the scan's own frame as distributed; ``"bbox_centre"``
#: = the same axes, origin moved to the centre of the scan's axis-aligned
#: bounding box.
MeshFrame = Literal["ycb", "bbox_centre"]


@dataclass(frozen=True)
class YcbScan:
    """The real YCB mesh of an object and the frame the published data uses it in.

    ``file`` names the vendored scan under ``objects/ycb_meshes/``.
    ``frame`` is measured from the data where the data fixes it (the Level
    III fingertip contacts of ``DMG.ods`` lie on the surface in that frame;
    ``tests/test_objects_ycb.py`` holds them to it), and ``frame_evidence``
    says what it rests on. ``collision`` is the collision model: the scan's
    convex hull where the object is (nearly) convex, the vendored V-HACD
    pieces where the hull would fill a concavity a finger can reach.
    """

    file: str
    frame: MeshFrame
    frame_evidence: str
    collision: Literal["hull", "decompose"]


@dataclass(frozen=True)
class ObjectSpec:
    """One object of the in-hand benchmark.

    ``name`` is spelled as in the published data files. ``published_mm`` is
    the YCB dimension string as published (diameter first for round objects).
    ``bbox_mm`` gives, per axis of *our* object frame, the extent the
    published dimensions fix (``None`` where nothing was published, e.g. the
    banana's curvature); tests hold the generated mesh to these.
    ``simplification`` says, for this object, how our shape departs from the
    real one.
    """

    name: str
    ycb_id: str
    ycb_name: str
    published_mm: tuple[float, ...]
    bbox_mm: tuple[float | None, float | None, float | None]
    mass_kg: float
    dimension_source: Citation
    mass_source: Citation
    simplification: str
    geometry: Geometry
    scan: YcbScan
    aliases: tuple[str, ...] = ()
    uncertain: str = ""  #: what could not be sourced or checked, empty when nothing

    @property
    def all_names(self) -> tuple[str, ...]:
        return (self.name, self.ycb_name, self.ycb_name.split("_", 1)[1], *self.aliases)
