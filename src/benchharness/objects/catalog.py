"""The twelve YCB objects of the in-hand manipulation benchmark, from published figures.

Each spec names its vendored YCB scan and the frame the published data uses
it in (``scan``, the default model, :mod:`.ycb`), and describes the
simplified model generated from the published dimensions and mass
(``geometry``, ``model="generated"``). Generated shapes are deliberately
simple; each spec's ``simplification`` says how. All lengths below are metres.

Sources (see :data:`CALLI_2015` and friends):

* Dimensions and masses are those of the YCB object list, Calli et al. 2015,
  Table 1 ("Object set items and properties"), which the YCB website's object
  list repeats. The stored copies of that table could not be opened in this
  offline environment, so the figures were taken from the YCB object list as
  recalled and cross-checked, where a public copy existed, against
  RobotLocomotion/models ``ycb_objects/*.sdf`` (Drake's YCB models, which
  copy the YCB figures): cracker box 0.06 x 0.158 x 0.21 m / 0.411 kg,
  gelatin box 0.028 x 0.085 x 0.073 m / 0.097 kg, potted meat can 0.05 x
  0.097 x 0.082 m / 0.370 kg. The banana's 66 g and the tuna can's
  85 x 33 mm / 171 g agree with several public YCB property tables.
* The Lego Duplo entry of YCB (073) is a *set* of bricks with no single
  published size or mass; we model one 2x4 brick from the Duplo system
  (twice the standard Lego module) and estimate its mass.
* Anything we had to choose (the banana's curvature, the fork's bend, the
  screwdriver's handle/shaft split...) is marked as an assumption in that
  spec's ``simplification``.

Object frames (ours): origin at the centre of the axis-aligned bounding box;
bodies of revolution (apple, orange, tuna can, screwdriver) have z on their
axis; boxes have x, y, z along the published dimensions in the published
order (depth, width, height, as in Drake's YCB models); elongated flat objects
(banana, fork, spatula) and the airplane have x along their length, z up
(the direction of their bend or tail). The published in-hand poses are
relative to the *real* YCB mesh frames (their origin is where the scanner put
it), so absolute positions in the published data need not match these
frames; relative hand motions (``T = H_d H_i^-1``) are unaffected.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .boxunion import AABox
from .spec import BoxGeometry, Citation, ObjectSpec, SweepGeometry, YcbScan
from .swept import Segment, SweepProfile, _dense_samples

__all__ = ["CATALOG", "CALLI_2015", "DRAKE_YCB", "DUPLO_SCALE", "ESTIMATE"]

CALLI_2015 = Citation(
    "Calli2015",
    "B. Calli, A. Walsman, A. Singh, S. Srinivasa, P. Abbeel, A. M. Dollar, "
    "'Benchmarking in manipulation research: Using the Yale-CMU-Berkeley object and "
    "model set', IEEE Robotics & Automation Magazine 22(3):36-52, 2015, Table 1; "
    "same figures in the object list of http://www.ycbbenchmarks.com",
)
DRAKE_YCB = Citation(
    "Calli2015+Drake",
    "Calli et al. 2015 Table 1, as copied in RobotLocomotion/models ycb_objects/*.sdf "
    "(github.com/RobotLocomotion/models, box size and <mass>)",
)
DUPLO_SCALE = Citation(
    "DuploModule",
    "Lego Duplo bricks are twice the standard Lego brick in every dimension "
    "(https://brickers.jp/pages/lego-size: standard 2x4 brick 16 x 32 mm, 9.6 mm body height, "
    "stud about 4.8 mm diameter x 1.7 mm; Duplo 2x4 = 32 x 64 mm); "
    "we use the Duplo nominal 31.7 x 63.7 x 19.2 mm body (0.1 mm play per side)",
)
ESTIMATE = Citation(
    "estimate",
    "our estimate (no published figure found): ABS shell about 1.5 mm thick, "
    "about 11 g for a Duplo 2x4 brick",
)


# ---------------------------------------------------------------------------- profile helpers


def _const(v: float) -> Callable[[np.ndarray], np.ndarray]:
    return lambda x: np.full_like(np.asarray(x, float), v)


def _sphere_profile(r: float) -> SweepProfile:
    def half(x: np.ndarray) -> np.ndarray:
        return np.sqrt(np.clip(r * r - np.asarray(x) ** 2, 0.0, None))

    return SweepProfile((Segment(-r, r, half, half),), max_piece_length=2 * r)


def _rounding(x0: float, x1: float, rho0: float, rho1: float) -> Callable[[np.ndarray], np.ndarray]:
    """Factor taking a section to zero like an ellipse quadrant over ``rho`` at each end."""

    def g(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, float)
        out = np.ones_like(x)
        d0 = np.clip((x0 + rho0 - x) / rho0, 0.0, 1.0)
        d1 = np.clip((x - (x1 - rho1)) / rho1, 0.0, 1.0)
        out = out * np.sqrt(np.clip(1 - d0**2, 0.0, 1.0)) * np.sqrt(np.clip(1 - d1**2, 0.0, 1.0))
        return out

    return g


def _piecewise(xs: list[float], vs: list[float]) -> Callable[[np.ndarray], np.ndarray]:
    return lambda x: np.interp(np.asarray(x, float), xs, vs)


def _bent(make: Callable[[float], SweepProfile], z_extent: float) -> SweepProfile:
    """The profile whose bend amplitude makes its z extent exactly ``z_extent``.

    The z extent grows monotonically with the (parabolic) bend amplitude, so
    bisection finds it; this is how a flat utensil reaches its published
    height with a realistic plate thickness.
    """

    def extent(kappa: float) -> float:
        s = _dense_samples(make(kappa), 2001)
        x, a, b, zc = s.T
        return float((zc + b).max() - (zc - b).min())

    lo, hi = 0.0, z_extent
    if extent(lo) > z_extent:
        raise ValueError("section already thicker than the published height")
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if extent(mid) < z_extent else (lo, mid)
    return make((lo + hi) / 2)


# ---------------------------------------------------------------------------- profiles


def _banana() -> SweepProfile:
    half_len, r, sagitta = 0.095, 0.018, 0.030
    g = _rounding(-half_len, half_len, r, r)
    sec = lambda x: r * g(x)  # noqa: E731
    return SweepProfile(
        (Segment(-half_len, half_len, sec, sec),),
        centre_z=lambda x: sagitta * (1 - (np.asarray(x) / half_len) ** 2),
        max_piece_length=0.025,
    )


def _screwdriver() -> SweepProfile:
    # along x here, turned to z; handle 100 mm at x < -7.5 mm, shaft, 10 mm cone tip
    x0, step, tip0, x1 = -0.1075, -0.0075, 0.0975, 0.1075
    r_handle, r_shaft = 0.0155, 0.003
    r_tip = 0.001  # blunt 2 mm end: a cone to a point would need slivers at its apex
    cone = lambda x: r_shaft + (r_tip - r_shaft) * (np.asarray(x) - tip0) / (x1 - tip0)  # noqa: E731
    return SweepProfile(
        (
            Segment(x0, step, _const(r_handle), _const(r_handle)),
            Segment(step, tip0, _const(r_shaft), _const(r_shaft)),
            Segment(tip0, x1, cone, cone),
        ),
        breaks=(step,),
        max_piece_length=0.035,
    )


def _fork(kappa: float) -> SweepProfile:
    x0, x1 = -0.099, 0.099
    width = _piecewise([x0, -0.020, 0.014, 0.039, x1], [0.006, 0.006, 0.0035, 0.010, 0.010])
    return SweepProfile(
        (Segment(x0, x1, width, _const(0.0015)),),
        centre_z=lambda x: kappa * (np.asarray(x) / x1) ** 2,
        max_piece_length=0.02,
    )


def _spatula(kappa: float) -> SweepProfile:
    x0, x1 = -0.175, 0.175
    width = _piecewise([x0, 0.030, 0.065, x1], [0.012, 0.012, 0.0415, 0.0415])
    thick = _piecewise([x0, 0.030, 0.065, x1], [0.005, 0.005, 0.0015, 0.0015])
    return SweepProfile(
        (Segment(x0, x1, width, thick),),
        centre_z=lambda x: kappa * (np.asarray(x) / x1) ** 2,
        breaks=(0.065,),
        max_piece_length=0.025,
    )


def _duplo_2x4() -> tuple[AABox, ...]:
    body = (0.0637, 0.0317, 0.0192)
    stud_side, stud_h = 0.0096, 0.0034
    z_top = (body[2] + stud_h) / 2  # bbox centred: body spans [-z_top, z_top - stud_h]
    body_box = AABox.centred(body, (0.0, 0.0, -stud_h / 2))
    studs = tuple(
        AABox.centred((stud_side, stud_side, stud_h), (x, y, z_top - stud_h / 2))
        for x in (-0.024, -0.008, 0.008, 0.024)
        for y in (-0.008, 0.008)
    )
    return (body_box, *studs)


def _airplane() -> tuple[AABox, ...]:
    mm = 1e-3

    def box(x: tuple[float, float], y: tuple[float, float], z: tuple[float, float]) -> AABox:
        return AABox((x[0] * mm, y[0] * mm, z[0] * mm), (x[1] * mm, y[1] * mm, z[1] * mm))

    return (
        box((-140, 140), (-25, 25), (-35.5, 14.5)),  # fuselage 280 x 50 x 50
        box((-10, 60), (25, 133), (-10, 0)),  # left wing, 70 mm chord
        box((-10, 60), (-133, -25), (-10, 0)),  # right wing
        box((-140, -100), (25, 70), (4.5, 12.5)),  # left tailplane
        box((-140, -100), (-70, -25), (4.5, 12.5)),  # right tailplane
        box((-140, -95), (-4, 4), (14.5, 85.5)),  # fin
        box((10, 50), (-40, 40), (-85.5, -35.5)),  # landing gear and wheels as one block
    )


def _box(size: tuple[float, float, float]) -> BoxGeometry:
    return BoxGeometry((AABox.centred(size),))


# ---------------------------------------------------------------------------- scan frames

# What each scan's frame rests on (measured by tests/test_objects_ycb.py against
# tasks/inhand/level3_dmg_tasks.csv, converted from DMG.ods).
_DMG_YCB = (
    "DMG.ods (Level III): the four published fingertip contacts lie within 4 mm of the scan "
    "in its own YCB frame and 21-85 mm off when it is centred on its bounding box"
)
_DMG_BBOX = (
    "DMG.ods (Level III): the four published fingertip contacts lie within 4.5 mm of the scan "
    "centred on its bounding box and 10-21 mm off in its own YCB frame"
)
_NOT_FIXED = (
    "not fixed by the published data (Level I gives palm poses, not contacts, and the "
    "simulated set-up solves the object's placement in the hand); the scan's own YCB frame"
)

# ---------------------------------------------------------------------------- the catalog

CATALOG: tuple[ObjectSpec, ...] = (
    ObjectSpec(
        name="apple",
        ycb_id="013",
        ycb_name="013_apple",
        scan=YcbScan("013_apple", "ycb", _NOT_FIXED, "hull"),
        published_mm=(75.0,),
        bbox_mm=(75.0, 75.0, 75.0),
        mass_kg=0.068,
        dimension_source=CALLI_2015,
        mass_source=CALLI_2015,
        simplification="sphere of the published 75 mm diameter (the plastic apple is not quite round; no stem)",
        geometry=SweepGeometry(_sphere_profile(0.0375), axis="z", collision="sphere"),
    ),
    ObjectSpec(
        name="banana",
        ycb_id="011",
        ycb_name="011_banana",
        scan=YcbScan("011_banana", "ycb", _NOT_FIXED, "decompose"),
        published_mm=(36.0, 190.0),
        bbox_mm=(190.0, 36.0, None),
        mass_kg=0.066,
        dimension_source=CALLI_2015,
        mass_source=CALLI_2015,
        simplification=(
            "36 mm round tube, 190 mm end to end, with rounded ends, bent in a parabolic arc "
            "(30 mm sagitta: our assumption, the curvature is not published); "
            "sections are vertical, not normal to the arc; collision: 8 convex pieces along the arc"
        ),
        geometry=SweepGeometry(_banana()),
        uncertain="curvature (sagitta 30 mm) assumed",
    ),
    ObjectSpec(
        name="gelatin box",
        ycb_id="009",
        ycb_name="009_gelatin_box",
        scan=YcbScan("009_gelatin_box", "bbox_centre", _DMG_BBOX, "hull"),
        published_mm=(28.0, 85.0, 73.0),
        bbox_mm=(28.0, 85.0, 73.0),
        mass_kg=0.097,
        dimension_source=DRAKE_YCB,
        mass_source=DRAKE_YCB,
        simplification="rectangular box (real edges slightly rounded, flaps ignored)",
        geometry=_box((0.028, 0.085, 0.073)),
    ),
    ObjectSpec(
        name="Lego Duplo",
        ycb_id="073",
        ycb_name="073_lego_duplo",
        scan=YcbScan("073-a_lego_duplo", "ycb", _NOT_FIXED, "decompose"),
        published_mm=(63.7, 31.7, 22.6),
        bbox_mm=(63.7, 31.7, 22.6),
        mass_kg=0.011,
        dimension_source=DUPLO_SCALE,
        mass_source=ESTIMATE,
        simplification=(
            "one Duplo 2x4 brick: solid 63.7 x 31.7 x 19.2 mm body with eight 9.6 mm *square* studs "
            "3.4 mm high (real studs are round and hollow, the body is a hollow shell with tubes)"
        ),
        geometry=BoxGeometry(_duplo_2x4()),
        aliases=("lego", "duplo", "073-a_lego_duplo"),
        uncertain=(
            "YCB 073 is a set of Duplo pieces: which piece the benchmark used, its size and mass are not "
            "published; mass 11 g is an estimate; stud size from the Duplo = 2x Lego rule"
        ),
    ),
    ObjectSpec(
        name="fork",
        ycb_id="030",
        ycb_name="030_fork",
        scan=YcbScan("030_fork", "ycb", _NOT_FIXED, "decompose"),
        published_mm=(14.0, 20.0, 198.0),
        bbox_mm=(198.0, 20.0, 14.0),
        mass_kg=0.034,
        dimension_source=CALLI_2015,
        mass_source=CALLI_2015,
        simplification=(
            "3 mm thick plate of elliptical section, 12 mm handle narrowing to a 7 mm neck and a "
            "20 mm head with the tines merged into a solid paddle, bent in a parabola so the height "
            "is the published 14 mm (thickness and bend are our assumptions); collision: convex pieces"
        ),
        geometry=SweepGeometry(_bent(_fork, 0.014)),
        uncertain="plate thickness and planform assumed; tines not modelled",
    ),
    ObjectSpec(
        name="orange",
        ycb_id="017",
        ycb_name="017_orange",
        scan=YcbScan("017_orange", "ycb", _NOT_FIXED, "hull"),
        published_mm=(73.0,),
        bbox_mm=(73.0, 73.0, 73.0),
        mass_kg=0.047,
        dimension_source=CALLI_2015,
        mass_source=CALLI_2015,
        simplification="sphere of the published 73 mm diameter (plastic orange)",
        geometry=SweepGeometry(_sphere_profile(0.0365), axis="z", collision="sphere"),
    ),
    ObjectSpec(
        name="airplane toy",
        ycb_id="072",
        ycb_name="072_toy_airplane",
        scan=YcbScan("072-a_toy_airplane", "ycb", _NOT_FIXED, "decompose"),
        published_mm=(171.0, 266.0, 280.0),
        bbox_mm=(280.0, 266.0, 171.0),
        mass_kg=0.570,
        dimension_source=CALLI_2015,
        mass_source=CALLI_2015,
        simplification=(
            "assembled toy as seven boxes: 280 x 50 x 50 mm fuselage, 70 mm-chord wings to the "
            "266 mm span, tailplanes, a fin reaching the 171 mm height and one block for the "
            "landing gear and wheels; solid with uniform density (the real toy is hollow)"
        ),
        geometry=BoxGeometry(_airplane()),
        aliases=("toy airplane", "airplane", "072-a_toy_airplane"),
        uncertain=(
            "published size and mass are for the assembled kit; part proportions are ours; "
            "whether the benchmark used the assembled plane or a sub-part is not stated"
        ),
    ),
    ObjectSpec(
        name="Phillips-head screwdriver",
        ycb_id="043",
        ycb_name="043_phillips_screwdriver",
        scan=YcbScan("043_phillips_screwdriver", "ycb", _NOT_FIXED, "decompose"),
        published_mm=(31.0, 215.0),
        bbox_mm=(31.0, 31.0, 215.0),
        mass_kg=0.097,
        dimension_source=CALLI_2015,
        mass_source=CALLI_2015,
        simplification=(
            "31 mm diameter x 100 mm cylindrical handle (no flutes), 6 mm x 105 mm shaft and a "
            "10 mm cone to a blunt 2 mm end for the Phillips tip, along z (handle/shaft split and shaft diameter "
            "assumed); uniform density, so the centre of mass sits further toward the shaft "
            "than in the real tool, whose plastic handle is lighter"
        ),
        geometry=SweepGeometry(_screwdriver(), axis="z"),
        aliases=("phillips screwdriver", "screwdriver"),
        uncertain="handle length 100 mm and shaft diameter 6 mm assumed",
    ),
    ObjectSpec(
        name="spatula",
        ycb_id="033",
        ycb_name="033_spatula",
        scan=YcbScan("033_spatula", "ycb", _DMG_YCB, "decompose"),
        published_mm=(35.0, 83.0, 350.0),
        bbox_mm=(350.0, 83.0, 35.0),
        mass_kg=0.0515,
        dimension_source=CALLI_2015,
        mass_source=CALLI_2015,
        simplification=(
            "24 x 10 mm elliptical handle, 35 mm neck, 110 mm long 83 mm wide 3 mm blade with "
            "rounded end, bent in a parabola so the height is the published 35 mm (section sizes "
            "and bend are our assumptions); collision: convex pieces"
        ),
        geometry=SweepGeometry(_bent(_spatula, 0.035)),
        uncertain="handle section, blade thickness and bend assumed",
    ),
    ObjectSpec(
        name="tuna fish can",
        ycb_id="007",
        ycb_name="007_tuna_fish_can",
        scan=YcbScan("007_tuna_fish_can", "ycb", _NOT_FIXED, "hull"),
        published_mm=(85.0, 33.0),
        bbox_mm=(85.0, 85.0, 33.0),
        mass_kg=0.171,
        dimension_source=CALLI_2015,
        mass_source=CALLI_2015,
        simplification="cylinder 85 mm diameter x 33 mm, axis z (no rims or ribs)",
        geometry=SweepGeometry(
            SweepProfile((Segment(-0.0165, 0.0165, _const(0.0425), _const(0.0425)),)),
            axis="z",
            collision="cylinder",
        ),
        aliases=("tuna can",),
    ),
    ObjectSpec(
        name="potted meat can",
        ycb_id="010",
        ycb_name="010_potted_meat_can",
        scan=YcbScan("010_potted_meat_can", "ycb", _DMG_YCB, "decompose"),
        published_mm=(50.0, 97.0, 82.0),
        bbox_mm=(50.0, 97.0, 82.0),
        mass_kg=0.370,
        dimension_source=DRAKE_YCB,
        mass_source=DRAKE_YCB,
        simplification="rectangular box (the real can has rounded corners and a lid rim), as in Drake's model",
        geometry=_box((0.050, 0.097, 0.082)),
        aliases=("spam",),
    ),
    ObjectSpec(
        name="cracker box",
        ycb_id="003",
        ycb_name="003_cracker_box",
        scan=YcbScan("003_cracker_box", "bbox_centre", _DMG_BBOX, "hull"),
        published_mm=(60.0, 158.0, 210.0),
        bbox_mm=(60.0, 158.0, 210.0),
        mass_kg=0.411,
        dimension_source=DRAKE_YCB,
        mass_source=DRAKE_YCB,
        simplification="rectangular box (the scanned box bulges a few mm; the published caliper size is used)",
        geometry=_box((0.060, 0.158, 0.210)),
    ),
)
