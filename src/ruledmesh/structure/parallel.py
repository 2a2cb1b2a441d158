"""Parallel meshes: the linear space of offsets whose edges stay parallel.

A mesh ``W`` with the combinatorics of ``V`` is *parallel* to it when every
edge ``W_j - W_i`` is parallel to ``V_j - V_i``.  With two unit vectors
``b1, b2`` orthogonal to an edge this is two linear equations per edge,
``b . (W_j - W_i) = 0``, so the parallel meshes form a linear space; it
always contains the translations and scalings ``c V + t``.  Writing
``W = V + X``, the offset vectors ``X`` satisfy the same equations ``C X = 0``
(``C V = 0`` holds by construction), and the node axes ``X_i`` are
torsion-free: the edge ``V_i V_j`` and its offset ``W_i W_j`` are parallel,
so ``V_i, V_j, W_j, W_i`` is a planar trapezoid.  The faces of ``W`` are then
planar and parallel to those of ``V``, whatever their number of sides.

:func:`closest_parallel_offset` picks the member of the space closest to a
target offset (``d`` times the vertex normals): a quadratic objective under
the linear constraints, solved with one sparse factorisation of the
regularised KKT matrix and iterative refinement towards the exact
constraints.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from ..tolerances import KKT_REGULARISATION, ULPS
from ..tolerances import TINY as _TINY

__all__ = ["ParallelFit", "closest_parallel_offset", "edge_bases", "parallel_constraints"]

_DELTA = KKT_REGULARISATION


def edge_bases(directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors orthogonal to each direction and to each other.

    Parameters
    ----------
    directions : (E, 3) float64
        Non-zero edge vectors.

    Returns
    -------
    b1, b2 : (E, 3) float64
    """
    e = directions / np.maximum(np.linalg.norm(directions, axis=1), _TINY)[:, None]
    # Cross with the coordinate axis least aligned with the edge: never near zero.
    helper = np.eye(3)[np.argmin(np.abs(e), axis=1)]
    b1 = np.cross(e, helper)
    b1 /= np.maximum(np.linalg.norm(b1, axis=1), _TINY)[:, None]
    return b1, np.cross(e, b1)


def parallel_constraints(vertices: np.ndarray, edges: np.ndarray) -> sp.csr_matrix:
    """The sparse matrix ``C`` of the parallel-mesh equations ``C X = 0``.

    Parameters
    ----------
    vertices : (V, 3) float64
    edges : (E, 2) int64
        Edges of non-zero length.

    Returns
    -------
    C : (2 E, 3 V) scipy.sparse.csr_matrix
        Row ``2 k + m`` is ``b_m . (X_j - X_i)`` for edge ``k = (i, j)``; rows
        have norm sqrt(2), so the system is scaled independently of the mesh.
    """
    i, j = edges[:, 0], edges[:, 1]
    b1, b2 = edge_bases(vertices[j] - vertices[i])
    basis = np.stack([b1, b2], axis=1)                       # (E, 2, 3)
    ne = len(edges)
    rows = np.broadcast_to(np.arange(2 * ne).reshape(ne, 2, 1, 1), (ne, 2, 2, 3))
    cols = np.stack([3 * i[:, None] + np.arange(3), 3 * j[:, None] + np.arange(3)], axis=1)
    cols = np.broadcast_to(cols[:, None, :, :], (ne, 2, 2, 3))
    vals = np.stack([-basis, basis], axis=2)                 # (E, 2 rows, 2 ends, 3)
    return sp.csr_matrix((vals.reshape(-1), (rows.reshape(-1), cols.reshape(-1))),
                         shape=(2 * ne, 3 * len(vertices)))


@dataclass(frozen=True)
class ParallelFit:
    """The member of the parallel space closest to a target offset.

    Attributes
    ----------
    offset : (V, 3) float64
        The offset vectors ``X`` (``W = V + X``).
    residual : float
        ``max |C X|`` relative to the largest offset length: how far from
        parallel the solution is after refinement.
    steps : int
        Refinement steps taken.
    """

    offset: np.ndarray
    residual: float
    steps: int


def _objective(normals: np.ndarray, distance_weight: float) -> sp.csr_matrix:
    """Block diagonal ``Q``: full weight across the normal, ``distance_weight`` along it."""
    nn = np.einsum("vi,vj->vij", normals, normals)
    blocks = np.eye(3)[None] - (1.0 - distance_weight) * nn
    v = len(normals)
    rows = np.repeat(np.arange(3 * v).reshape(v, 3, 1), 3, axis=2)
    cols = np.repeat(np.arange(3 * v).reshape(v, 1, 3), 3, axis=1)
    return sp.csr_matrix((blocks.reshape(-1), (rows.reshape(-1), cols.reshape(-1))),
                         shape=(3 * v, 3 * v))


def closest_parallel_offset(vertices: np.ndarray, edges: np.ndarray, normals: np.ndarray,
                            distance: float, *, distance_weight: float = 1.0,
                            rtol: float = ULPS, max_steps: int = 60) -> ParallelFit:
    """The parallel offset closest to ``distance * normals``.

    Minimises ``sum_i |P_i (X_i - d N_i)|^2`` subject to ``C X = 0``, where
    ``P_i`` weighs the part of the offset across the normal fully and the part
    along it by ``distance_weight``: the axes are held close to the normals
    while the offset distances may vary.  The default weight 1 is the
    orthogonal projection of ``d N`` onto the parallel space.

    Parameters
    ----------
    vertices : (V, 3) float64
    edges : (E, 2) int64
        Face edges of non-zero length.
    normals : (V, 3) float64
        Unit vertex normals (the target directions).
    distance : float
        Target offset distance ``d`` (non-zero).
    distance_weight : float
        Weight of the distance term, in (0, 1]; 1 (the default) is the plain
        least-squares distance to ``V + d N``.  Smaller weights let the
        offset shrink towards the vertices to turn its axes towards the
        normals, which is rarely what a frame needs.
    rtol : float
        Refinement stops when ``max |C X|`` is below ``rtol`` times the
        largest offset.
    max_steps : int
        Refinement steps at most.

    Returns
    -------
    ParallelFit
    """
    nv = len(vertices)
    C = parallel_constraints(vertices, edges)
    Q = _objective(normals, distance_weight)
    q = Q @ (distance * normals.reshape(-1))
    m = C.shape[0]
    K = sp.bmat([[Q, C.T], [C, -_DELTA * sp.identity(m)]], format="csc")
    lu = splu(K)
    x = np.zeros(3 * nv)
    lam = np.zeros(m)
    scale = abs(distance)
    residual = np.inf
    steps = 0
    for steps in range(1, max_steps + 1):  # noqa: B007 - the count is returned
        r1 = q - Q @ x - C.T @ lam
        r2 = -(C @ x)
        dx = lu.solve(np.concatenate([r1, r2]))
        x += dx[:3 * nv]
        lam += dx[3 * nv:]
        scale = max(float(np.max(np.abs(x))) if x.size else 0.0, _TINY)
        residual = float(np.max(np.abs(C @ x))) / scale if m else 0.0
        if residual <= rtol:
            break
    return ParallelFit(x.reshape(nv, 3), residual, steps)
