"""Surface discretisation: the DMG's "small areas" of the object surface.

The original DMG uses super-voxels of the object's point cloud. We group the
mesh faces instead, which gives the same kind of ~1 cm patches directly on
the surface the metrics use: faces are binned by the cell of a regular
``patch_size`` grid that contains their centroid, each cell's faces are split
by normal (greedy, seeded at the lowest face index, ``patch_normal_angle``
tolerance) and each group is split into edge-connected pieces. On a box
this yields square patches on a 1 cm lattice, never straddling an edge; on a
thin plate the two sides are separate patches.

Every step is a pure function of the mesh and the config, so the patches --
and everything downstream -- are deterministic.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Patches", "discretise_surface", "tangent_frames"]


@dataclass(frozen=True)
class Patches:
    """The patches of one mesh.

    ``centers`` are points on the surface (the area-weighted centroid of the
    patch's faces, projected onto the mesh) where a finger is placed when it
    is on that patch; ``normals`` are outward unit normals (area-weighted);
    ``tangent1``/``tangent2`` with the normal form a right-handed frame in
    which gripper angles are measured. ``face_patch[f]`` is the patch of face
    ``f``; ``adjacency`` lists patch pairs ``(i, j)``, ``i < j``, that share a
    mesh edge.
    """

    centers: np.ndarray
    normals: np.ndarray
    tangent1: np.ndarray
    tangent2: np.ndarray
    areas: np.ndarray
    face_patch: np.ndarray
    adjacency: np.ndarray

    def __len__(self) -> int:
        return len(self.centers)


def tangent_frames(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A tangent frame per normal, from a fixed world axis.

    ``tangent1`` is the world z axis projected onto the tangent plane (world
    x where the normal is within ~25 degrees of z), so coplanar patches share
    one frame and angles carry over between them unchanged; where the choice
    of axis flips, the graph's translation edges carry the angle offset.
    """
    n = np.asarray(normals, float)
    ref = np.tile([0.0, 0.0, 1.0], (len(n), 1))
    ref[np.abs(n[:, 2]) > 0.9] = [1.0, 0.0, 0.0]
    t1 = ref - np.sum(ref * n, axis=1, keepdims=True) * n
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(n, t1)
    return t1, t2


def _split_by_normal(faces: np.ndarray, normals: np.ndarray, cos_tol: float) -> list[np.ndarray]:
    groups = []
    left = np.asarray(faces)
    while len(left):
        seed = normals[left[0]]
        member = normals[left] @ seed >= cos_tol
        groups.append(left[member])
        left = left[~member]
    return groups


def discretise_surface(mesh, patch_size: float, patch_normal_angle: float = 30.0) -> Patches:
    """Group the faces of ``mesh`` into patches of about ``patch_size`` (m)."""
    import trimesh
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    fn = np.asarray(mesh.face_normals, float)
    degenerate = int(np.count_nonzero(~(np.einsum("ij,ij->i", fn, fn) >= 0.5)))  # NaN counts too
    if degenerate:
        # a zero-area face has no normal, so no patch to join (and no area to weigh a centre by):
        # its normal would match no seed, not even its own, and the grouping below never end
        raise ValueError(
            f"the mesh has {degenerate} degenerate (zero-area) faces; drop them first: "
            "mesh.update_faces(mesh.nondegenerate_faces())"
        )
    centroids = np.asarray(mesh.triangles_center, float)
    area = np.asarray(mesh.area_faces, float)
    cells = np.floor((centroids - mesh.bounds[0]) / patch_size).astype(np.int64)
    _, cell_of_face = np.unique(cells, axis=0, return_inverse=True)
    cell_of_face = cell_of_face.reshape(-1)
    order = np.argsort(cell_of_face, kind="stable")
    bounds = np.flatnonzero(np.diff(cell_of_face[order])) + 1
    label = np.empty(len(fn), np.int64)
    n_labels = 0
    cos_tol = float(np.cos(np.deg2rad(patch_normal_angle)))
    for faces in np.split(order, bounds):
        for group in _split_by_normal(faces, fn, cos_tol):
            label[group] = n_labels
            n_labels += 1

    # edge-connected pieces of each group
    adj = np.asarray(mesh.face_adjacency)
    same = label[adj[:, 0]] == label[adj[:, 1]]
    a, b = adj[same, 0], adj[same, 1]
    g = coo_matrix((np.ones(len(a)), (a, b)), shape=(len(fn), len(fn)))
    _, comp = connected_components(g, directed=False)
    # number patches by their lowest face index (deterministic, mesh order)
    first = np.full(comp.max() + 1, len(fn))
    np.minimum.at(first, comp, np.arange(len(fn)))
    rank = np.empty_like(first)
    rank[np.argsort(first, kind="stable")] = np.arange(len(first))
    face_patch = rank[comp]
    n = len(first)

    w = np.zeros(n)
    np.add.at(w, face_patch, area)
    c = np.zeros((n, 3))
    np.add.at(c, face_patch, centroids * area[:, None])
    c /= w[:, None]
    nrm = np.zeros((n, 3))
    np.add.at(nrm, face_patch, fn * area[:, None])
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    c, _, _ = trimesh.proximity.closest_point(mesh, c)

    pa, pb = face_patch[adj[:, 0]], face_patch[adj[:, 1]]
    diff = pa != pb
    pairs = np.unique(np.sort(np.stack([pa[diff], pb[diff]], axis=1), axis=1), axis=0)
    t1, t2 = tangent_frames(nrm)
    return Patches(
        centers=np.asarray(c, float),
        normals=nrm,
        tangent1=t1,
        tangent2=t2,
        areas=w,
        face_patch=face_patch,
        adjacency=pairs.reshape(-1, 2),
    )
