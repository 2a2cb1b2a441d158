"""Circularity and the parallelogram check (paper §2.1, §2.3).

A quad is *circular* when its four vertices lie on a circle; a mesh of such
quads stays circular (hence planar) under inversion in a sphere.  The measure
is the distance of one vertex from the circle through the other three,
divided by that circle's radius; of the four choices the best-conditioned
(smallest circumradius) triple is used, so a thin quad does not hide behind
a huge circle.  Polygons with more vertices are measured against the circle
through three well-spread vertices; triangles are circular by definition.

A *parallelogram* quad has ``p0 - p1 + p2 - p3 = 0`` (its diagonals bisect each
other); the measure is that vector's length over the mean diagonal length.

Both appear in ``ruledmesh analyze`` for meshes with quads (the report
registers :func:`circularity_report` and :func:`parallelogram_report`); the
measures themselves depend on the mesh only, so the meshers and transforms
may use them.
"""

from __future__ import annotations

import numpy as np

from .._arrays import unique
from ..mesh import Mesh
from ..tolerances import COLLINEAR_SQ, DEFAULT, Tolerances
from ..tolerances import TINY as _TINY

__all__ = ["circle_through", "quad_circularity", "circularity", "quad_parallelogram",
           "parallelogram", "circularity_report", "parallelogram_report"]


def circle_through(a: np.ndarray, b: np.ndarray, c: np.ndarray):
    """Circles through three points each.

    Parameters
    ----------
    a, b, c : (F, 3) float64

    Returns
    -------
    center : (F, 3) float64
    normal : (F, 3) float64
        Unit normal of the circle's plane (zero for collinear points).
    radius : (F,) float64
        ``inf`` for collinear points.
    """
    u, w = b - a, c - a
    n = np.cross(u, w)
    nn = np.einsum("ij,ij->i", n, n)
    uu = np.einsum("ij,ij->i", u, u)
    ww = np.einsum("ij,ij->i", w, w)
    degenerate = nn <= COLLINEAR_SQ * np.maximum(uu * ww, _TINY)
    safe = np.where(degenerate, 1.0, nn)
    center = a + (np.cross(n, u) * ww[:, None] + np.cross(w, n) * uu[:, None]) / (2 * safe[:, None])
    radius = np.where(degenerate, np.inf, np.linalg.norm(center - a, axis=1))
    normal = np.where(degenerate[:, None], 0.0, n / np.sqrt(safe)[:, None])
    return center, normal, radius


def _distance_from_circle(q, center, normal, radius):
    rel = q - center
    h = np.einsum("ij,ij->i", rel, normal)
    radial = np.linalg.norm(rel - h[:, None] * normal, axis=1)
    # A circle of zero radius (three coincident corners, e.g. a design scaled
    # to nothing) defines no circle: as a straight line through them, infinite.
    finite = np.isfinite(radius) & (radius > 0)
    r = np.where(finite, radius, 1.0)
    out = np.sqrt(h * h + (radial - r) ** 2) / r
    return np.where(finite, out, np.inf)


def quad_circularity(corners: np.ndarray) -> np.ndarray:
    """How far quads are from having a circumcircle.

    Parameters
    ----------
    corners : (F, 4, 3) float64

    Returns
    -------
    (F,) float64
        Distance of the remaining vertex from the circle through the
        best-conditioned three, relative to that circle's radius; 0 for a
        circular quad, 1 when every triple is collinear.

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    >>> float(quad_circularity(square)[0]) < 1e-15
    True
    >>> kite = np.array([[[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0.5]]], float)
    >>> float(quad_circularity(kite)[0]) > 0.1
    True
    """
    corners = np.asarray(corners, dtype=np.float64)
    best = np.full(len(corners), np.inf)
    best_r = np.full(len(corners), np.inf)
    for k in range(4):  # the four triples, each vectorised over faces
        tri = [corners[:, (k + i) % 4] for i in (1, 2, 3)]
        center, normal, radius = circle_through(*tri)
        d = _distance_from_circle(corners[:, k], center, normal, radius)
        better = radius < best_r
        best = np.where(better, d, best)
        best_r = np.where(better, radius, best_r)
    return np.where(np.isfinite(best), best, 1.0)


def circularity(mesh: Mesh) -> np.ndarray:
    """(F,) float64: circularity of every face (0 for triangles).

    Faces with more than four vertices: the largest distance of any vertex
    from the circle through vertices ``0, k/3, 2k/3``, relative to its radius.
    """
    out = np.zeros(mesh.n_faces)
    qid, quads = mesh.faces_of_valence(4)
    if qid.size:
        out[qid] = quad_circularity(mesh.vertices[quads])
    for k in unique(mesh.valences[mesh.valences > 4]):
        ids, faces = mesh.faces_of_valence(int(k))
        pts = mesh.vertices[faces]
        center, normal, radius = circle_through(pts[:, 0], pts[:, k // 3], pts[:, (2 * k) // 3])
        d = np.stack([_distance_from_circle(pts[:, i], center, normal, radius)
                      for i in range(k)], axis=1).max(axis=1)
        out[ids] = np.where(np.isfinite(d), d, 1.0)
    return out


def quad_parallelogram(corners: np.ndarray) -> np.ndarray:
    """(F,) float64: ``|p0 - p1 + p2 - p3|`` / mean diagonal length (0 for a parallelogram)."""
    corners = np.asarray(corners, dtype=np.float64)
    gap = np.linalg.norm(corners[:, 0] - corners[:, 1] + corners[:, 2] - corners[:, 3], axis=1)
    l1 = np.linalg.norm(corners[:, 2] - corners[:, 0], axis=1)
    l2 = np.linalg.norm(corners[:, 3] - corners[:, 1], axis=1)
    return gap / np.maximum(0.5 * (l1 + l2), _TINY)


def parallelogram(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Parallelogram measure of the mesh's quads.

    Returns
    -------
    face_ids : (Q,) int64
    measure : (Q,) float64
    """
    qid, quads = mesh.faces_of_valence(4)
    return qid, quad_parallelogram(mesh.vertices[quads])


def circularity_report(mesh: Mesh, tol: Tolerances = DEFAULT) -> dict | None:
    """The ``circularity`` figures of ``ruledmesh analyze`` (``None`` without quads)."""
    qid, _ = mesh.faces_of_valence(4)
    if qid.size == 0:
        return None
    c = circularity(mesh)
    return {"max": float(c.max()), "mean": float(c.mean()), "tolerance": tol.circularity,
            "above_tolerance": int(np.count_nonzero(c > tol.circularity)),
            "circular": bool(np.all(c <= tol.circularity))}


def parallelogram_report(mesh: Mesh, tol: Tolerances = DEFAULT) -> dict | None:
    """The ``parallelogram`` figures of ``ruledmesh analyze`` (``None`` without quads)."""
    qid, m = parallelogram(mesh)
    if qid.size == 0:
        return None
    # Parallelograms of a construction are exact up to rounding, like planarity.
    return {"max": float(m.max()), "tolerance": tol.planarity,
            "above_tolerance": int(np.count_nonzero(m > tol.planarity)),
            "all_quads": bool(np.all(m <= tol.planarity))}

