"""How far a mesh's triangles lie off the generators they span.

A quad of §4.3 has a diagonal on a generator and its corners on the two beside it,
and a strip quad or triangle between two neighbouring generators spans none: the
smooth surface lies within the face's own sag of it.  A triangle whose corners lie on
generators further apart (a fill triangle across several strips, where rows were
taken out by collapses or never reached) passes over the generators between, which
may lie far off it, however exact its planarity: the gap to the smooth surface that a
fabricator's closeness figure measures.
"""

from __future__ import annotations

import numpy as np

from .._arrays import cross, median, norm, ranks
from ..tolerances import COLLINEAR, TINY
from .faces import triangle_distances

__all__ = ["off_spanned_generators"]

# A generator crossing a triangle's plane at more than 60 degrees is not under it.
_STEEP = float(np.sin(np.radians(60.0)))


def off_spanned_generators(V: np.ndarray, tri: np.ndarray, generator: np.ndarray, t: np.ndarray,
                           lines: tuple[np.ndarray, np.ndarray], faces: np.ndarray | None = None,
                           within: float = 0.0) -> np.ndarray:
    """(T,) how far the generators a triangle spans without a corner on them lie off it.

    A triangle whose corners lie on generators ``g0 < g2`` covers the surface of the
    generators between.  Of each such generator, take the stretch the mesh covers (between
    the lowest and highest ``t`` of its vertices) whose projection on the triangle's plane
    falls inside the triangle; the distance off the triangle is measured halfway along it.
    Stretches that project outside the triangle lie under the faces beside it, and so do
    generators that cross its plane at more than 60 degrees (a generator lies in the
    surface's tangent plane: such a one runs through another part of it, a fold or a pinch
    where the generators meet).

    With ``faces``, the distance to the mesh instead (:func:`_to_the_mesh`).  Two triangles
    across many strips sharing a long edge can both lie farthest off along it: between two
    such the quality checker found 2.4e-3 of the diagonal where halfway read 1.4e-3.  Off
    the plane at the ends, a mesh 1.2e-3 off read 3.0e-3; against the faces sharing an edge
    alone, one 6.9e-3 off read 1.1e-2 (where rows fold back, faces nearer cover the line).

    Parameters
    ----------
    V : (V, 3) float64
    tri : (T, 3) int
        Triangles as rows of vertex indices.
    generator, t : (V,) int64 and (V,) float64
        Each vertex's generator and parameter on it (``a_g + t d_g``).
    lines : ((m, 3), (m, 3)) float64
        ``a`` and ``d`` of the generators.
    faces : (F, 3) int, optional
        Every face of the mesh as triangles (fanned), for distances to the mesh.
    within : float
        With ``faces``: distances up to this need only be bounds from above (those of the
        nearest faces found first); only farther points are measured against every face.

    Returns
    -------
    (T,) float64
        The largest distance, 0 for a triangle that spans no generator or whose
        generators between pass beside it.
    """
    out = np.zeros(len(tri))
    g = generator[tri]
    lo, hi = g.min(axis=1), g.max(axis=1)
    span = np.maximum(hi - lo - 1, 0)
    if not span.any():
        return out
    row = np.repeat(np.arange(len(tri)), span)
    k = lo[row] + 1 + ranks(span)
    P = V[tri[row]]
    n = cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    area2 = norm(n)
    n /= np.maximum(area2, TINY)[:, None]
    a, d = lines[0][k], lines[1][k]
    d_len = np.maximum(norm(d), TINY)
    # The stretch of each generator the mesh covers: from the vertices on the generators
    # spanned only (a large mesh has few such triangles).
    on = np.zeros(len(lines[0]), bool)
    on[k] = True
    at = np.flatnonzero(on[generator])
    t_lo = np.full(len(lines[0]), np.inf)
    t_hi = np.full(len(lines[0]), -np.inf)
    np.minimum.at(t_lo, generator[at], t[at])
    np.maximum.at(t_hi, generator[at], t[at])
    low, high = t_lo[k], t_hi[k]
    # The barycentric coordinates of the projection of a + s d are affine in s:
    # lambda_i = alpha_i + beta_i s; the stretch inside is where all three are >= 0.
    for i in range(3):
        p, q = P[:, (i + 1) % 3], P[:, (i + 2) % 3]
        e = cross(q - p, n)                 # normal of the edge opposite corner i ...
        e *= np.where(np.einsum("ij,ij->i", P[:, i] - p, e) < 0, -1.0, 1.0)[:, None]   # ... inward
        alpha = np.einsum("ij,ij->i", a - p, e)
        beta = np.einsum("ij,ij->i", d, e)
        # Parallel to the edge (to COLLINEAR): the edge bounds the whole line or none of it
        # (and the division below stays finite at any coordinates).
        flat = np.abs(beta) <= COLLINEAR * np.maximum(d_len * norm(e), TINY)
        bound = -alpha / np.where(flat, 1.0, beta)
        low = np.where(~flat & (beta > 0), np.maximum(low, bound), low)
        high = np.where(~flat & (beta < 0), np.minimum(high, bound), high)
        high = np.where(flat & (alpha < 0), -np.inf, high)
    # A generator of the surface lies in its tangent plane: one crossing the triangle's plane
    # steeply runs through another part of the surface (a fold, or a pinch where the
    # generators meet, as a conoid's at its directrix) that other faces cover.
    steep = np.abs(np.einsum("ij,ij->i", d, n)) > _STEEP * d_len
    inside = (low <= high) & (area2 > TINY) & ~steep
    # Halfway along the stretch, the point deepest inside the triangle's footprint: nearer
    # its ends the faces beside it may lie nearer the generator than this one's plane (taken
    # at the ends, a mesh the quality checker finds 1.2e-3 off read 3.0e-3).
    # Only where the stretch is there: elsewhere low and high may be infinite.
    if faces is None:
        mid = np.zeros(row.size)
        mid[inside] = 0.5 * (low[inside] + high[inside])
        far = np.where(inside, np.abs(np.einsum("ij,ij->i", a + mid[:, None] * d - P[:, 0], n)), 0.0)
        np.maximum.at(out, row, far)
        return out
    pair = np.flatnonzero(inside)
    stretch = a[pair, None, :] + np.stack([low[pair], high[pair]], axis=1)[..., None] * d[pair, None, :]
    np.maximum.at(out, row[pair], _to_the_mesh(stretch, P[pair, 0], n[pair], V, faces, within))
    return out


def _to_the_mesh(stretch: np.ndarray, corner: np.ndarray, normal: np.ndarray, V: np.ndarray,
                 faces: np.ndarray, within: float) -> np.ndarray:
    """(p,) how far the stretches of generators under triangles lie off the mesh.

    Off the triangle's own plane (through ``corner`` (p, 3), unit ``normal`` (p, 3)) is a
    bound from above of the distance to the mesh, largest at an end of the stretch
    (``stretch`` (p, 2, 3), its ends; the distance is affine along the line): the stretches
    within ``within`` of it are done.  The others are taken at five points, each measured
    against the faces (``V[faces]``, (F, 3, 3)) nearest by their centres, then, where still farther,
    against every face that can be nearer (a large face may be near a point its centre is
    far from).
    """
    bound = np.abs(np.einsum("pkj,pj->pk", stretch - corner[:, None, :], normal)).max(axis=1)
    out = np.minimum(bound, within)
    far = np.flatnonzero(bound > within)
    if far.size == 0:
        return out
    X = (stretch[far, :1] + _ALONG[:, None] * (stretch[far, 1:] - stretch[far, :1])).reshape(-1, 3)
    dist = np.abs(np.einsum("ij,ij->i", X - np.repeat(corner[far], _ALONG.size, axis=0),
                            np.repeat(normal[far], _ALONG.size, axis=0)))
    T = V[faces]                    # only here: most meshes have no stretch this far off
    centre = T.mean(axis=1)
    radius = norm(T - centre[:, None, :]).max(axis=1)
    hot = np.flatnonzero(dist > within)
    if hot.size * len(T) <= _CHUNK:
        # Few pairs (a small mesh): every face, without a search tree (nor scipy's import).
        _against(dist, hot, X, T, centre, radius, np.arange(len(T)))
    else:
        from scipy.spatial import cKDTree

        k = min(_NEAREST, len(T))
        near = cKDTree(centre).query(X[hot], k=k)[1].reshape(hot.size, k)
        dist[hot] = np.minimum(dist[hot], triangle_distances(np.repeat(X[hot], k, axis=0),
                                                        T[near.ravel()]).reshape(-1, k).min(axis=1))
        hot = hot[dist[hot] > within]
        if hot.size:
            _nearer(dist, hot, X, T, centre, radius)
    out[far] = dist.reshape(-1, _ALONG.size).max(axis=1)
    return out


def _nearer(dist: np.ndarray, hot: np.ndarray, X: np.ndarray, T: np.ndarray, centre: np.ndarray,
            radius: np.ndarray) -> None:
    """Lower ``dist`` (n,) of the points ``X[hot]`` to their distance to every face ``T``
    (F, 3, 3) that can be nearer: the faces of ordinary size whose centres (``centre``) lie
    within reach (``radius``: centre to farthest corner), and every large one (fill
    triangles across many strips; were they in the search radius, it would take in the
    whole mesh)."""
    from scipy.spatial import cKDTree

    large = radius > _LARGE * median(radius)
    small = np.flatnonzero(~large)
    if small.size:
        found = cKDTree(centre[small]).query_ball_point(X[hot], dist[hot] + radius[small].max())
        count = np.array([len(f) for f in found], np.int64)
        if count.sum():
            point = np.repeat(hot, count)
            face = small[np.concatenate([np.asarray(f, np.int64) for f in found])]
            np.minimum.at(dist, point, triangle_distances(X[point], T[face]))
    _against(dist, hot, X, T, centre, radius, np.flatnonzero(large))


def _against(dist: np.ndarray, hot: np.ndarray, X: np.ndarray, T: np.ndarray, centre: np.ndarray,
             radius: np.ndarray, faces: np.ndarray) -> None:
    """Lower ``dist`` of the points ``X[hot]`` to their distance to the faces ``T[faces]``
    whose bounding spheres (``centre``, ``radius``) come nearer, a chunk of pairs at a time."""
    step = max(1, _CHUNK // max(faces.size, 1))
    for k in range(0, faces.size and hot.size, step):
        point = np.repeat(hot[k:k + step], faces.size)
        face = np.tile(faces, point.size // faces.size)
        near = norm(X[point] - centre[face]) - radius[face] < dist[point]
        np.minimum.at(dist, point[near], triangle_distances(X[point[near]], T[face[near]]))


# Faces more than this many times the median size (centre to farthest corner) are measured
# against every point, not found by their centres; pairs of point and face at a time (and
# below this many pairs in all, every face against every point).
_LARGE = 4.0
_CHUNK = 1 << 18
# Where along a spanned generator's stretch its distance is taken, given the faces ...
_ALONG = np.linspace(0.0, 1.0, 5)
# ... and against how many faces, those whose centres are nearest.
_NEAREST = 16
