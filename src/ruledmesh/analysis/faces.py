"""Per-face measures: planarity, convexity, areas, angles, edge lengths.

Every function is vectorised over faces.  Quads use the paper's own criterion
(§2.1: a quad is planar iff its diagonals intersect), so a quad's planarity is
the distance between its two diagonal lines divided by the mean diagonal
length.  Other polygons use the largest distance from their best-fit plane
divided by their diameter.  Triangles are planar by definition (0).
"""

from __future__ import annotations

import numpy as np

from .._arrays import corner_angle, cross, norm, unique
from ..kernels import wanted
from ..mesh import Mesh
from ..tolerances import DEFAULT, ROUNDING_SQ
from ..tolerances import TINY as _TINY

__all__ = [
    "quad_planarity",
    "quad_diagonal_crossing",
    "gap_planarity",
    "polygon_planarity",
    "planarity",
    "convexity",
    "crossing_inside",
    "polygon_convexity",
    "face_areas",
    "face_normals",
    "face_centroids",
    "corner_angles",
    "edge_lengths",
    "degenerate_faces",
    "face_min_angles",
    "min_corner_angles",
    "area_shares",
    "segment_distances",
    "triangle_distances",
]


def quad_diagonal_crossing(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest points of the two diagonals of quads.

    Parameters
    ----------
    corners : (F, 4, 3) float64
        Quad corners in boundary order; the diagonals are 0-2 and 1-3.

    Returns
    -------
    s, t : (F,) float64
        Parameters of the closest points on diagonal 0->2 and 1->3; a convex
        quad has both strictly inside (0, 1).
    gap : (F,) float64
        Distance between the diagonal lines (0 for a planar quad).
    """
    kern = wanted(len(corners))
    if kern is not None and corners.ndim == 3 and corners.shape[1:] == (4, 3):
        return kern.crossing(corners)
    # Each quad moved to its first corner and scaled to unit size: the products of squared
    # lengths below would overflow for coordinates beyond about 1e77.
    origin = corners[:, :1]
    scale = np.maximum(np.abs(corners - origin).max(axis=(1, 2), initial=0.0), _TINY)
    corners = (corners - origin) / scale[:, None, None]
    p, q = corners[:, 0], corners[:, 1]
    d1 = corners[:, 2] - p
    d2 = corners[:, 3] - q
    w = p - q
    a = np.einsum("ij,ij->i", d1, d1)
    b = np.einsum("ij,ij->i", d1, d2)
    c = np.einsum("ij,ij->i", d2, d2)
    d = np.einsum("ij,ij->i", d1, w)
    e = np.einsum("ij,ij->i", d2, w)
    den = a * c - b * b
    parallel = den <= ROUNDING_SQ * np.maximum(a * c, _TINY)
    safe = np.where(parallel, 1.0, den)
    s = np.where(parallel, 0.0, (b * e - c * d) / safe)
    t = np.where(parallel, e / np.maximum(c, _TINY), (a * e - b * d) / safe)
    normal = cross(d1, d2)
    ncross = norm(normal)
    gap_skew = np.abs(np.einsum("ij,ij->i", w, normal)) / np.maximum(ncross, _TINY)
    # Parallel diagonals: distance from q to the line of d1.
    gap_par = norm(cross(w, d1)) / np.sqrt(np.maximum(a, _TINY))
    gap = np.where(parallel, gap_par, gap_skew)
    return s, t, gap * scale


def quad_planarity(corners: np.ndarray) -> np.ndarray:
    """Planarity of quads: distance between the diagonal lines / mean diagonal length.

    Parameters
    ----------
    corners : (F, 4, 3) float64

    Returns
    -------
    (F,) float64
        0 for a planar quad; scale-free.

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    >>> float(quad_planarity(square)[0])
    0.0
    >>> bent = square.copy(); bent[0, 2, 2] = 0.1
    >>> round(float(quad_planarity(bent)[0]), 4)
    0.0352
    """
    kern = wanted(len(corners))
    if kern is not None and corners.ndim == 3 and corners.shape[1:] == (4, 3):
        return kern.quad_planarity(corners)
    return gap_planarity(corners, quad_diagonal_crossing(corners)[2])


def gap_planarity(corners: np.ndarray, gap: np.ndarray) -> np.ndarray:
    """(F,) float64: :func:`quad_planarity` of quads whose diagonal gap is known.

    Parameters
    ----------
    corners : (F, 4, 3) float64
    gap : (F,) float64
        The third result of :func:`quad_diagonal_crossing` (``corners``), so that a
        caller needing the crossing too measures it once.
    """
    l1 = norm(corners[:, 2] - corners[:, 0])
    l2 = norm(corners[:, 3] - corners[:, 1])
    return gap / np.maximum(0.5 * (l1 + l2), _TINY)


def _padded_corners(mesh: Mesh, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Corners of faces ``ids`` padded by repeating each face's first vertex."""
    val = mesh.valences[ids]
    k = int(val.max())
    cols = np.arange(k)
    start = mesh.face_offsets[ids][:, None]
    mask = cols[None, :] < val[:, None]
    idx = np.where(mask, start + cols, start)
    return mesh.vertices[mesh.face_indices[idx]], mask


def polygon_planarity(mesh: Mesh, ids: np.ndarray | None = None) -> np.ndarray:
    """Largest distance of a face's vertices from its best-fit plane / its diameter.

    Parameters
    ----------
    mesh : Mesh
    ids : (k,) int, optional
        Faces to measure (all by default).

    Returns
    -------
    (k,) float64
    """
    ids = np.arange(mesh.n_faces) if ids is None else np.asarray(ids)
    if ids.size == 0:
        return np.zeros(0)
    pts, mask = _padded_corners(mesh, ids)
    w = mask.astype(float)
    n = w.sum(axis=1)
    centroid = (pts * w[..., None]).sum(axis=1) / n[:, None]
    rel = (pts - centroid[:, None, :]) * w[..., None]
    cov = np.einsum("fki,fkj->fij", rel, rel)
    _, vecs = np.linalg.eigh(cov)
    normal = vecs[:, :, 0]
    dist = np.abs(np.einsum("fki,fi->fk", rel, normal)).max(axis=1)
    diff = pts[:, :, None, :] - pts[:, None, :, :]
    diam = np.sqrt(np.einsum("fabi,fabi->fab", diff, diff).max(axis=(1, 2)))
    out = dist / np.maximum(diam, _TINY)
    out[mesh.valences[ids] == 3] = 0.0
    return out


def planarity(mesh: Mesh) -> np.ndarray:
    """(F,) float64: planarity of every face (quads by diagonals, others by plane fit)."""
    out = np.zeros(mesh.n_faces)
    qid, quads = mesh.faces_of_valence(4)
    if qid.size:
        kern = wanted(qid.size)
        out[qid] = quad_planarity(mesh.vertices[quads]) if kern is None \
            else kern.quad_planarity(mesh.vertices, quads)
    other = np.flatnonzero(mesh.valences > 4)
    if other.size:
        out[other] = polygon_planarity(mesh, other)
    return out


def face_normals(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Newell vector area of every face.

    Returns
    -------
    normals : (F, 3) float64
        Unit normals (zero for a degenerate face).
    areas : (F,) float64
        Face areas (exact for planar faces).
    """
    kern = wanted(mesh.n_faces)
    done = kern.newell(mesh.vertices, mesh.face_indices, mesh.face_offsets) if kern is not None else None
    if done is not None:
        return done
    v = mesh.vertices
    idx = mesh.face_indices
    nxt = np.arange(idx.size) + 1
    nxt[mesh.face_offsets[1:] - 1] = mesh.face_offsets[:-1]
    # Relative to each face's first corner: cross products of site coordinates
    # (1e6 and more) would cancel catastrophically.
    origin = v[idx[np.repeat(mesh.face_offsets[:-1], mesh.valences)]]
    cr = cross(v[idx] - origin, v[idx[nxt]] - origin)
    vec = 0.5 * np.add.reduceat(cr, mesh.face_offsets[:-1], axis=0) if idx.size else np.zeros((0, 3))
    area = norm(vec)
    normals = vec / np.maximum(area, _TINY)[:, None]
    return normals, area


def face_areas(mesh: Mesh) -> np.ndarray:
    """(F,) float64: area of every face."""
    return face_normals(mesh)[1]


def face_centroids(mesh: Mesh) -> np.ndarray:
    """(F, 3) float64: mean of each face's vertices."""
    sums = np.add.reduceat(mesh.vertices[mesh.face_indices], mesh.face_offsets[:-1], axis=0)
    return sums / mesh.valences[:, None]


def segment_distances(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k,) distance of points ``p`` from segments ``a b`` (all (k, 3)), each from its own."""
    ab = b - a
    s = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), _TINY), 0, 1)
    return norm(p - a - s[:, None] * ab)


def triangle_distances(p: np.ndarray, P: np.ndarray) -> np.ndarray:
    """(k,) distance of points ``p`` (k, 3) from triangles ``P`` (k, 3, 3), each from its own."""
    A, B, C = P[:, 0], P[:, 1], P[:, 2]
    n = cross(B - A, C - A)
    n = n / np.maximum(norm(n), _TINY)[:, None]          # zero for degenerate triangles
    h = np.einsum("ij,ij->i", p - A, n)
    q = p - h[:, None] * n
    # Inside when q is on the inner side of all three edges.
    inside = np.ones(len(p), bool)
    for x, y in ((A, B), (B, C), (C, A)):
        inside &= np.einsum("ij,ij->i", cross(y - x, q - x), n) >= 0
    out = np.abs(h)
    # Outside: the nearest edge (only there, where most points are inside).
    o = np.flatnonzero(~inside)
    if o.size:
        p, A, B, C = p[o], A[o], B[o], C[o]
        out[o] = np.minimum(np.minimum(segment_distances(p, A, B), segment_distances(p, B, C)),
                            segment_distances(p, C, A))
    return out


def polygon_angles(corners: np.ndarray) -> np.ndarray:
    """(F, k) float64: interior angles in degrees of polygons given by their corners.

    Parameters
    ----------
    corners : (F, k, 3) float64
        Corners in order around each polygon.
    """
    corners = np.asarray(corners)
    if corners.ndim == 3 and corners.shape[1] and corners.shape[2] == 3 and corners.dtype == np.float64:
        kern = wanted(corners.shape[0] * corners.shape[1])
        if kern is not None:
            return kern.polygon_angles(corners)
    # The edges to the previous and the next corner, as ``np.roll(corners, +-1, axis=1) -
    # corners`` by slices (the same differences, without roll's copies), and the norm as
    # ``np.linalg.norm`` computes it: this runs on a few faces many times per build.
    e1 = np.empty_like(corners)
    e2 = np.empty_like(corners)
    np.subtract(corners[:, -1:], corners[:, :1], out=e1[:, :1])
    np.subtract(corners[:, :-1], corners[:, 1:], out=e1[:, 1:])
    np.subtract(corners[:, 1:], corners[:, :-1], out=e2[:, :-1])
    np.subtract(corners[:, :1], corners[:, -1:], out=e2[:, -1:])
    cosang = np.einsum("fkc,fkc->fk", e1, e2)
    sinang = norm(cross(e1, e2))
    return corner_angle(sinang, cosang)


def min_corner_angles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F,) float64: the smallest interior angle, degrees, of each polygon ``vertices[faces]``.

    ``polygon_angles(vertices[faces]).min(axis=1)``, bit for bit, without the
    (F, k, 3) copy of the corners where the kernels run.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (F, k) int
        Corners of each polygon, in order around it.
    """
    F, k = faces.shape
    if F and k:
        kern = wanted(F * k)
        if kern is not None:
            return kern.min_angles(vertices, faces.reshape(-1), np.arange(0, F * k + 1, k))
    return polygon_angles(vertices[faces]).min(axis=1)


def corner_angles(mesh: Mesh) -> np.ndarray:
    """(N,) float64: interior angle in degrees at every face corner, in face_indices order."""
    v = mesh.vertices
    idx = mesh.face_indices
    pos = np.arange(idx.size)
    nxt = pos + 1
    nxt[mesh.face_offsets[1:] - 1] = mesh.face_offsets[:-1]
    prv = pos - 1
    prv[mesh.face_offsets[:-1]] = mesh.face_offsets[1:] - 1
    e1 = v[idx[prv]] - v[idx]
    e2 = v[idx[nxt]] - v[idx]
    cosang = np.einsum("ij,ij->i", e1, e2)
    sinang = norm(cross(e1, e2))
    return corner_angle(sinang, cosang)


def convexity(mesh: Mesh, tol: float = DEFAULT.convexity) -> np.ndarray:
    """(F,) bool: every face convex (no bow-tie, no reflex corner).

    A quad is convex when its diagonals cross strictly inside both (by
    ``tol`` relative to the diagonal); a polygon when all its corners turn the
    same way about its normal.
    """
    ok = np.ones(mesh.n_faces, dtype=bool)
    qid, quads = mesh.faces_of_valence(4)
    if qid.size:
        s, t, _ = quad_diagonal_crossing(mesh.vertices[quads])
        ok[qid] = crossing_inside(s, t, tol)
    other = np.flatnonzero(mesh.valences > 4)
    if other.size:
        ok[other] = polygon_convexity(mesh, other, face_normals(mesh)[0][other], tol)
    return ok


def crossing_inside(s: np.ndarray, t: np.ndarray, tol: float = DEFAULT.convexity) -> np.ndarray:
    """(F,) bool: quads whose diagonals cross strictly inside both, from their crossing.

    Parameters
    ----------
    s, t : (F,) float64
        The first two results of :func:`quad_diagonal_crossing`.
    tol : float
        Margin from the diagonals' ends, relative to their lengths.
    """
    return (s > tol) & (s < 1 - tol) & (t > tol) & (t < 1 - tol)


def polygon_convexity(mesh: Mesh, ids: np.ndarray, normals: np.ndarray,
                      tol: float = DEFAULT.convexity) -> np.ndarray:
    """(k,) bool: the faces ``ids`` whose corners all turn the same way about their normals.

    Parameters
    ----------
    mesh : Mesh
    ids : (k,) int
        Faces of any valence (meant for those of 5 or more corners).
    normals : (k, 3) float64
        Their unit normals (:func:`face_normals`).
    tol : float
        A corner may turn back by this much relative to the product of its edges.
    """
    pts, mask = _padded_corners(mesh, ids)
    val = mesh.valences[ids]
    k = pts.shape[1]
    cols = np.arange(k)
    nxt = np.where(cols[None, :] + 1 < val[:, None], cols[None, :] + 1, 0)
    prv = np.where(cols[None, :] > 0, cols[None, :] - 1, val[:, None] - 1)
    rows = np.arange(len(ids))[:, None]
    e1 = pts - pts[rows, prv]
    e2 = pts[rows, nxt] - pts
    turn = np.einsum("fki,fi->fk", cross(e1, e2), normals)
    scale = (np.linalg.norm(e1, axis=2) * np.linalg.norm(e2, axis=2))
    return np.all((turn >= -tol * scale) | ~mask, axis=1)


def edge_lengths(mesh: Mesh) -> np.ndarray:
    """(E,) float64: length of every unique edge (see :meth:`Mesh.edges`)."""
    e = mesh.edges()
    return np.linalg.norm(mesh.vertices[e[:, 1]] - mesh.vertices[e[:, 0]], axis=1)


def degenerate_faces(mesh: Mesh, tol: float = DEFAULT.degenerate) -> np.ndarray:
    """(F,) bool: faces with no area, by the rule :mod:`ruledmesh.fabricate` refuses them by.

    A face is degenerate when its (Newell) area is at most ``tol`` times the
    square of its longest edge: a needle or a collapsed polygon, which cannot be
    cut from a sheet.
    """
    _, area = face_normals(mesh)
    return area <= tol * np.maximum(longest_edges(mesh), _TINY) ** 2


def longest_edges(mesh: Mesh) -> np.ndarray:
    """(F,) float64: the longest edge of every face."""
    v = mesh.vertices
    idx = mesh.face_indices
    nxt = np.arange(idx.size) + 1
    nxt[mesh.face_offsets[1:] - 1] = mesh.face_offsets[:-1]
    length = np.linalg.norm(v[idx[nxt]] - v[idx], axis=1)
    if length.size == 0:
        return np.zeros(mesh.n_faces)
    return np.maximum.reduceat(length, mesh.face_offsets[:-1])


SPLINTER_DEG = 3.0
"""Degrees: a face (quad or triangle) with a smaller interior angle is a splinter for fabrication."""


def face_min_angles(mesh: Mesh) -> np.ndarray:
    """(F,) float64: the smallest interior angle of every face, degrees."""
    kern = wanted(mesh.n_faces)
    if kern is not None and mesh.n_faces and mesh.valences.min() > 0:
        return kern.min_angles(mesh.vertices, mesh.face_indices, mesh.face_offsets)
    ang = corner_angles(mesh)
    if ang.size == 0:
        return np.zeros(mesh.n_faces)
    return np.minimum.reduceat(ang, mesh.face_offsets[:-1])


def area_shares(mesh: Mesh) -> dict:
    """Shares of the mesh area: by face kind, and in quads (4 corners) vs the rest.

    Returns
    -------
    dict
        ``by_kind`` (label -> share), ``quads``, ``triangles`` and ``polygons``
        (5 or more corners) as shares of the total area.
    """
    from ..mesh import FaceKind

    _, area = face_normals(mesh)
    total = float(area.sum()) or 1.0
    val = mesh.valences
    by_kind = np.bincount(mesh.face_kind, weights=area, minlength=len(FaceKind))
    return {
        "by_kind": {FaceKind(k).label: float(by_kind[k] / total) for k in unique(mesh.face_kind)},
        "quads": float(area[val == 4].sum() / total),
        "triangles": float(area[val == 3].sum() / total),
        "polygons": float(area[val > 4].sum() / total),
    }
