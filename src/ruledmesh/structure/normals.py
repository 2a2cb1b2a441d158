"""Vertex normals and the edge/corner incidence the support structure needs."""

from __future__ import annotations

import numpy as np

from ..analysis.faces import face_normals
from ..mesh import Mesh
from ..tolerances import TINY as _TINY

__all__ = ["face_edges", "vertex_normals"]


def vertex_normals(mesh: Mesh) -> np.ndarray:
    """Area-weighted vertex normals.

    The Newell vector areas of the faces around a vertex are summed, so large
    panels count more than slivers and a fill triangle does not tip the normal.

    Parameters
    ----------
    mesh : Mesh

    Returns
    -------
    normals : (V, 3) float64
        Unit normals; zero at vertices used by no face (or where the faces
        around a vertex cancel).
    """
    normals, area = face_normals(mesh)
    vec = normals * area[:, None]
    out = np.zeros((mesh.n_vertices, 3))
    np.add.at(out, mesh.face_indices, np.repeat(vec, mesh.valences, axis=0))
    length = np.linalg.norm(out, axis=1)
    return out / np.maximum(length, _TINY)[:, None]


def face_edges(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unique face edges and which edge each face corner starts.

    Returns
    -------
    edges : (E, 2) int64
        Sorted vertex pairs, as :meth:`Mesh.edges`.
    corner_edge : (N,) int64
        For every entry of ``mesh.face_indices``: the edge from that corner to
        the next one of its face.
    nxt : (N,) int64
        Position of the next corner of the same face in ``face_indices``.
    """
    idx = mesh.face_indices
    nxt = np.arange(idx.size) + 1
    nxt[mesh.face_offsets[1:] - 1] = mesh.face_offsets[:-1]
    lo = np.minimum(idx, idx[nxt])
    hi = np.maximum(idx, idx[nxt])
    n = np.int64(max(mesh.n_vertices, 1))
    key, inverse = np.unique(lo * n + hi, return_inverse=True)
    edges = np.stack([key // n, key % n], axis=1).astype(np.int64)
    return edges.reshape(-1, 2), inverse.reshape(-1), nxt
