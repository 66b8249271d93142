"""Where each engine's collision surface of a YCB object lies against the object model's own geometry.

An in-hand grasp is position-controlled: each fingertip's force is the hand's stiffness times how far
its target lies inside the surface it meets (~650 N/m at an Allegro fingertip, so 1 mm is ~0.65 N of a
3 N squeeze). So the engines must put the object's surface where the model says it is. The reference
is independent of both engines: the model's collision pieces (``ObjectModel.collision``, the scan's
convex hull or its convex parts) as one trimesh, ray-cast by trimesh.

For each object, ``--rays`` rays (seeded) from outside the object towards its centre are cast in each
engine (``Backend.ray_cast``) and against the reference; the difference of the hit distances is the
engine's surface offset along the ray: > 0 the engine's surface lies *outside* the model's (the object
is fatter), < 0 inside. A second check places a 12 mm sphere (the Allegro fingertip) overlapping the
surface by ``--overlap`` mm at ``--spheres`` points and compares the separation the engine reports for
that contact with the exact one (trimesh signed distance to the same reference).

    python bench/bench_object_surfaces.py                       # the twelve YCB objects, both engines
    python bench/bench_object_surfaces.py --objects apple,tuna_fish_can --engines sapien
"""

from __future__ import annotations

import argparse

import numpy as np
import trimesh

from benchharness.backends.interface import PhysicsConfig
from benchharness.geometry import Pose
from benchharness.objects import load_object
from benchharness.objects.surface_check import contact_separations, overlapping_spheres
from benchharness.plugin import get_manager

OBJECTS = (
    "apple",
    "banana",
    "gelatin_box",
    "lego_duplo",
    "fork",
    "orange",
    "airplane_toy",
    "phillips_head_screwdriver",
    "spatula",
    "tuna_fish_can",
    "potted_meat_can",
    "cracker_box",
)
TIP_RADIUS = 0.012


def reference(model) -> trimesh.Trimesh:
    """The model's collision pieces as one mesh (what the engines are given)."""
    parts = [trimesh.Trimesh(s.vertices, s.faces, process=False) for s in model.collision]
    return trimesh.util.concatenate(parts) if len(parts) > 1 else parts[0]


def rays(ref: trimesh.Trimesh, n: int, rng: np.random.Generator):
    """``n`` rays from outside towards the centre, and the reference's hit distances (NaN: miss)."""
    c = ref.bounds.mean(axis=0)
    span = float(np.linalg.norm(ref.extents))
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    origins = c - d * span + rng.normal(scale=0.2 * span / 3, size=(n, 3))
    u = c - origins
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    loc, idx, _ = ref.ray.intersects_location(origins, u, multiple_hits=True)
    hit = np.full(n, np.nan)
    for i, p in zip(idx, loc):
        dist = float(np.linalg.norm(p - origins[i]))
        hit[i] = dist if np.isnan(hit[i]) else min(hit[i], dist)
    return origins, u, hit, 2 * span


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--objects", default=",".join(OBJECTS))
    ap.add_argument("--engines", default="pybullet,sapien")
    ap.add_argument("--rays", type=int, default=400)
    ap.add_argument("--spheres", type=int, default=100)
    ap.add_argument("--overlap", type=float, default=1.0, help="mm")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    m = get_manager()
    print(
        "object / engine: surface offset along rays (mm; > 0 outside the model) median, 5th-95th pct, "
        "extremes | fingertip sphere overlapping by the given mm: contact separation error (mm) "
        "median |err|, worst; overlaps reported as no contact or separated"
    )
    for name in args.objects.split(","):
        model = load_object(name)
        ref = reference(model)
        rng = np.random.default_rng(args.seed)
        origins, u, ref_hit, max_d = rays(ref, args.rays, rng)
        centres, exact = overlapping_spheres(
            model, args.spheres, TIP_RADIUS, args.overlap * 1e-3, seed=args.seed
        )
        for engine in args.engines.split(","):
            # no gravity, the object free: a fixed-fixed pair makes no contacts in either engine
            be = m.create("backend", engine, config=PhysicsConfig(gravity=(0.0, 0.0, 0.0)))
            try:
                obj = be.add_body(pose=Pose(), **model.body_kwargs())
                be.step(1)
                h = be.ray_cast(origins, u, max_d)
                off = (ref_hit - np.where(h.hit, h.distance, np.nan)) * 1e3
                off = off[np.isfinite(off)]
                sep = contact_separations(be, obj, centres, TIP_RADIUS)
                err = (sep - exact) * 1e3
                fin = np.isfinite(err)
                missed = int(np.sum(~fin) + np.sum(sep[fin] > 0))
                print(
                    f"{name:26s} {engine:8s} rays {len(off):3d}: {np.median(off):+6.2f} "
                    f"[{np.percentile(off, 5):+6.2f}, {np.percentile(off, 95):+6.2f}] "
                    f"({off.min():+6.2f} .. {off.max():+6.2f}) | spheres: {np.median(np.abs(err[fin])):5.2f}, "
                    f"{np.abs(err[fin]).max():5.2f}; missed {missed}/{len(centres)}",
                    flush=True,
                )
            finally:
                be.close()


if __name__ == "__main__":
    main()
