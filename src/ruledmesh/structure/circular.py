"""Vertex offsets of circular meshes through the circumcircles' axes.

In a circular mesh every face has a circumcircle.  Reflecting a unit vector
``N_i`` at vertex ``i`` in the bisector plane of an edge ``i j`` gives
``N_j``; the offset edge ``(V_j + d N_j) - (V_i + d N_i)`` is then parallel to
the edge for every ``d``.  The bisector planes of a face's edges all contain
its circle's axis, so going round a circular face composes reflections that
return ``N_i`` to itself: the field is consistent, the offset mesh
``V + d N`` is parallel at the constant distance ``d``, and each face's node
axes meet on its circle's axis (Pottmann et al. 2007, *Geometry of
multi-layer freeform structures for architecture*).

The field is fixed by its value at one vertex per connected piece; that
value is chosen so the axes are as close to the vertex normals as possible
(in the least-squares sense, a closed form).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import breadth_first_order, connected_components

from ..tolerances import TINY as _TINY

__all__ = ["circular_axes"]


def _tree(n: int, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A breadth-first spanning forest: predecessor of every vertex and the piece it is in."""
    graph = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n)).tocsr()
    graph = graph + graph.T
    count, label = connected_components(graph, directed=False)
    pred = np.full(n, -9999, dtype=np.int64)
    # One search per connected piece (usually one), not per vertex.
    for piece in range(count):
        root = int(np.flatnonzero(label == piece)[0])
        _, p = breadth_first_order(graph, root, directed=False, return_predecessors=True)
        seen = p != -9999
        pred[seen] = p[seen]
        pred[root] = -1
    return pred, label


def _reflections(vertices: np.ndarray, pred: np.ndarray) -> np.ndarray:
    """(V, 3, 3): the product of edge reflections from each vertex's root to it.

    Pointer jumping composes the tree paths in ``log2(depth)`` vectorised steps.
    """
    n = len(vertices)
    has = pred >= 0
    e = np.zeros((n, 3))
    e[has] = vertices[has] - vertices[pred[has]]
    e /= np.maximum(np.linalg.norm(e, axis=1), _TINY)[:, None]
    # A vertex without predecessor (a root or an isolated vertex) gets the identity.
    step = np.eye(3)[None] - 2.0 * np.einsum("vi,vj->vij", e, e)
    up = np.where(has, pred, np.arange(n))
    while np.any(up != up[up]):
        step = np.einsum("vij,vjk->vik", step, step[up])
        up = up[up]
    return step


def circular_axes(vertices: np.ndarray, edges: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Unit node axes of a circular mesh (exact vertex offsets).

    Parameters
    ----------
    vertices : (V, 3) float64
    edges : (E, 2) int64
        Face edges of non-zero length.
    normals : (V, 3) float64
        Unit vertex normals: the axes are chosen closest to them.

    Returns
    -------
    axes : (V, 3) float64
        Unit vectors; ``V + d * axes`` is parallel to the mesh for every ``d``
        when the mesh is circular (check it: this function does not).
    """
    pred, label = _tree(len(vertices), edges)
    R = _reflections(vertices, pred)
    # N_v = R_v N_root; minimising sum |R_v N_root - n_v|^2 over unit N_root gives
    # N_root parallel to sum R_v^T n_v.
    pull = np.einsum("vji,vj->vi", R, normals)
    root = np.zeros((label.max() + 1 if label.size else 0, 3))
    np.add.at(root, label, pull)
    root /= np.maximum(np.linalg.norm(root, axis=1), _TINY)[:, None]
    return np.einsum("vij,vj->vi", R, root[label])
