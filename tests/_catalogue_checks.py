"""Independent predicates for the catalogue tests (not the library's own measures).

Planarity uses the triple product of a quad's edges, circularity the circumcentre
solved as a linear system, parallelograms the diagonals' midpoints: each a
different computation from the one in ``ruledmesh.analysis`` it checks.
"""

from __future__ import annotations

import numpy as np


def quads_of(vertices, faces):
    """(Q, 4, 3) corners of the four-sided faces of a list/array of faces."""
    quads = [f for f in faces if len(f) == 4]
    return np.asarray(vertices)[np.asarray(quads, dtype=np.int64).reshape(-1, 4)]


def polygons_of(vertices, faces):
    return [np.asarray(vertices)[np.asarray(f)] for f in faces if len(f) > 4]


def planarity(q):
    """(Q,) volume of the tetrahedron of a quad / (mean diagonal)^3: 0 when planar."""
    a, b, c, d = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    vol = np.abs(np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a))
    diag = 0.5 * (np.linalg.norm(c - a, axis=1) + np.linalg.norm(d - b, axis=1))
    return vol / diag ** 3


def polygon_planarity(p):
    """Largest distance from the least-squares plane / diameter, for one (k, 3) polygon."""
    rel = p - p.mean(axis=0)
    n = np.linalg.svd(rel)[2][-1]
    diam = max(np.linalg.norm(p[i] - p[j]) for i in range(len(p)) for j in range(len(p)))
    return np.abs(rel @ n).max() / diam


def circularity(q):
    """(Q,) distance of corner 3 from the circle through corners 0, 1, 2, relative to its radius."""
    out = []
    for a, b, c, d in q:
        # Relative to a: |b|^2 - |a|^2 would cancel catastrophically far from the origin.
        a, b, c, d = 0 * a, b - a, c - a, d - a
        n = np.cross(b - a, c - a)
        m = np.array([2 * (b - a), 2 * (c - a), n])
        rhs = np.array([b @ b - a @ a, c @ c - a @ a, n @ a])
        center = np.linalg.solve(m, rhs)
        radius = np.linalg.norm(a - center)
        nh = n / np.linalg.norm(n)
        h = (d - center) @ nh
        radial = np.linalg.norm(d - center - h * nh)
        out.append(np.hypot(h, radial - radius) / radius)
    return np.array(out)


def parallelogram(q):
    """(Q,) distance between the diagonals' midpoints / mean diagonal."""
    mid = 0.5 * (q[:, 0] + q[:, 2]) - 0.5 * (q[:, 1] + q[:, 3])
    diag = 0.5 * (np.linalg.norm(q[:, 2] - q[:, 0], axis=1) + np.linalg.norm(q[:, 3] - q[:, 1], axis=1))
    return np.linalg.norm(mid, axis=1) / diag


def sampson(value, gradient, points, scale):
    """First-order distance |F| / |grad F| from an implicit surface, relative to ``scale``."""
    f = value(points)
    g = np.linalg.norm(gradient(points), axis=1)
    return np.abs(f) / g / scale


def diagonal(points):
    points = np.asarray(points)
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
