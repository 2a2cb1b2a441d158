"""T-junctions: vertices lying inside an edge of a neighbouring face.

A mesh can be conforming by connectivity (every edge shared by at most two
faces, no face listing a vertex it does not own) and still not geometrically:
a vertex of one face may sit in the middle of another face's edge, which then
appears twice as a border edge of the mesh.  Fabricated panels still fit there,
but the long edge meets two short ones, and a mesh processor that welds or
smooths will tear or kink it.  Such an edge is always used by one face only, so
only those edges are searched (with a k-d tree, not against every vertex).
"""

from __future__ import annotations

import numpy as np

from .._arrays import unique
from ..mesh import Mesh
from ..tolerances import DEFAULT, TINY

__all__ = ["t_junctions"]


def _single_edges(mesh: Mesh) -> np.ndarray:
    """(B, 2) int64: the edges used by exactly one face."""
    if mesh.face_indices.size == 0:
        return np.zeros((0, 2), np.int64)
    key, count = mesh.edge_uses()
    key = key[count == 1]
    return np.stack([key // mesh.n_vertices, key % mesh.n_vertices], axis=1)


# Below this many (edge, vertex) pairs the search is brute force in numpy (no scipy import).
_BRUTE_PAIRS = 4_000_000


def _near_pairs(centre: np.ndarray, radius: np.ndarray, pts: np.ndarray):
    """(edge, point) index pairs with the point within ``radius`` of the edge's ``centre``."""
    if len(centre) * len(pts) <= _BRUTE_PAIRS:
        d2 = ((centre[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2)
        e, w = np.nonzero(d2 <= (radius ** 2)[:, None])
        return e.astype(np.int64), w.astype(np.int64)
    from scipy.spatial import cKDTree

    near = cKDTree(pts).query_ball_point(centre, radius)
    counts = np.fromiter((len(n) for n in near), np.int64, len(near))
    if counts.sum() == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return (np.repeat(np.arange(len(centre)), counts),
            np.concatenate([np.asarray(n, np.int64) for n in near if n]))


def t_junctions(mesh: Mesh, tol: float = DEFAULT.degenerate) -> np.ndarray:
    """Vertices lying strictly inside a border edge of the mesh.

    Parameters
    ----------
    mesh : Mesh
    tol : float
        Distance from the edge, relative to its length, within which a vertex
        counts as on it.

    Returns
    -------
    (k, 3) int64
        Rows ``(vertex, edge start, edge end)``, sorted.
    """
    edges = _single_edges(mesh)
    # A vertex hanging on a border edge is itself on the border (the end of two
    # border edges of the faces beside it): only border vertices are candidates.
    used = unique(edges)
    if edges.size == 0 or used.size == 0:
        return np.zeros((0, 3), np.int64)
    v = mesh.vertices
    p, q = v[edges[:, 0]], v[edges[:, 1]]
    length = np.linalg.norm(q - p, axis=1)
    e, w = _near_pairs(0.5 * (p + q), 0.5 * length * (1 + tol), v[used])
    if e.size == 0:
        return np.zeros((0, 3), np.int64)
    w = used[w]
    keep = (w != edges[e, 0]) & (w != edges[e, 1])
    e, w = e[keep], w[keep]
    d = q[e] - p[e]
    L2 = np.maximum(length[e] ** 2, TINY)
    t = np.einsum("ij,ij->i", v[w] - p[e], d) / L2
    off = np.linalg.norm(v[w] - p[e] - t[:, None] * d, axis=1)
    inside = (t > tol) & (t < 1 - tol) & (off <= tol * length[e])
    out = np.stack([w[inside], edges[e[inside], 0], edges[e[inside], 1]], axis=1)
    return np.unique(out, axis=0) if out.size else np.zeros((0, 3), np.int64)
