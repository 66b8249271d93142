"""Benchmark: contact-region error (Algorithm 1) on a ~10k-vertex object mesh.

Measures, on an ellipsoid built from a trimesh icosphere (10,242 vertices at
5 subdivisions, semi-axes 5 x 3 x 8 cm, roughly a YCB object's size):

* time per contact-error evaluation with a *cold* heat solver (new
  ObjectSurface, so the factorisation is included), with the *cached*
  solver, and with exact geodesics (pygeodesic);
* agreement of the heat method with exact geodesics, on random vertex pairs
  and on the Algorithm-1 ``max_d`` of random region/contact pairs.

A script, not a test: ``python bench/bench_geodesic.py [--subdivisions 5]``.
Results are recorded in docs/benchmarks/geodesic.md.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np
import trimesh

from benchharness.metrics.contact import ObjectSurface, contact_region_error


def make_mesh(subdivisions: int) -> trimesh.Trimesh:
    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    m.apply_scale([0.05, 0.03, 0.08])
    return m


def random_case(surface: ObjectSurface, rng: np.random.Generator, radius: float = 0.012):
    """A desired patch (vertices within ``radius`` of a random vertex) and 3 contact points elsewhere."""
    v = surface.vertices
    c = rng.integers(len(v))
    region = np.flatnonzero(np.linalg.norm(v - v[c], axis=1) < radius)
    far = rng.integers(len(v))
    contacts = v[far] + rng.normal(0, 0.004, (3, 3))
    return region, contacts


def timeit(fn, repeats: int) -> tuple[float, float]:
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), float(np.min(ts))


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--subdivisions", type=int, default=5)
    ap.add_argument(
        "--pairs", type=int, default=40, help="random vertex pairs for the agreement check"
    )
    ap.add_argument("--cases", type=int, default=10, help="random region/contact cases")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)

    mesh = make_mesh(args.subdivisions)
    surf = ObjectSurface(mesh)
    cases = [random_case(surf, rng) for _ in range(args.cases)]
    print(
        f"mesh: {len(mesh.vertices)} vertices, {len(mesh.faces)} faces, "
        f"mean edge {surf.mean_edge * 1000:.2f} mm, G_min {surf.g_min * 1000:.2f} mm"
    )
    print(
        f"machine: {platform.processor() or platform.machine()}, python {platform.python_version()}"
    )

    region, contacts = cases[0]
    cold = timeit(
        lambda: contact_region_error(ObjectSurface(mesh), region, contacts, method="heat"), 5
    )
    contact_region_error(surf, region, contacts, method="heat")  # warm the cache
    warm = [
        timeit(lambda r=r, c=c: contact_region_error(surf, r, c, method="heat"), 5)[0]
        for r, c in cases
    ]
    contact_region_error(surf, region, contacts, method="exact")  # build the exact solver once
    exact = [
        timeit(lambda r=r, c=c: contact_region_error(surf, r, c, method="exact"), 1)[0]
        for r, c in cases
    ]

    print("\n| evaluation (Algorithm 1, one trial) | median time |")
    print("| --- | --- |")
    print(f"| heat, cold (factorisation included) | {cold[0] * 1000:.1f} ms |")
    print(f"| heat, cached solver | {np.median(warm) * 1000:.1f} ms |")
    print(f"| exact (pygeodesic) | {np.median(exact) * 1000:.1f} ms |")

    # agreement on random vertex pairs
    i = rng.integers(len(mesh.vertices), size=args.pairs)
    j = rng.integers(len(mesh.vertices), size=args.pairs)
    h = np.array([surf.geodesic_to_set([a], [b], "heat")[0] for a, b in zip(i, j)])
    e = np.array([surf.geodesic_to_set([a], [b], "exact")[0] for a, b in zip(i, j)])
    ok = e > 5 * surf.mean_edge  # relative error is meaningless for neighbours
    rel = np.abs(h[ok] - e[ok]) / e[ok]
    print(
        f"\nvertex pairs: n={ok.sum()} (exact distance > 5 edges), heat vs exact relative error: "
        f"mean {rel.mean() * 100:.2f} %, max {rel.max() * 100:.2f} %"
    )

    # agreement of Algorithm 1 max_d
    hd = np.array([contact_region_error(surf, r, c, method="heat").geo for r, c in cases])
    ed = np.array([contact_region_error(surf, r, c, method="exact").geo for r, c in cases])
    rel = np.abs(hd - ed) / ed
    print(
        f"Algorithm-1 max_d over {len(cases)} region/contact cases: heat vs exact relative error "
        f"mean {rel.mean() * 100:.2f} %, max {rel.max() * 100:.2f} %"
    )


if __name__ == "__main__":
    main()
