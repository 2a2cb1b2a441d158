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

from .._arrays import cross, norm, ranks
from ..tolerances import COLLINEAR, TINY

__all__ = ["off_spanned_generators"]

# A generator crossing a triangle's plane at more than 60 degrees is not under it.
_STEEP = float(np.sin(np.radians(60.0)))


def off_spanned_generators(V: np.ndarray, tri: np.ndarray, generator: np.ndarray, t: np.ndarray,
                           lines: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """(T,) how far the generators a triangle spans without a corner on them lie off it.

    A triangle whose corners lie on generators ``g0 < g2`` covers the surface of the
    generators between.  Of each such generator, take the stretch the mesh covers (between
    the lowest and highest ``t`` of its vertices) whose projection on the triangle's plane
    falls inside the triangle; the distance off the triangle is measured halfway along it.
    Stretches that project outside the triangle lie under the faces beside it, and so do
    generators that cross its plane at more than 60 degrees (a generator lies in the
    surface's tangent plane: such a one runs through another part of it, a fold or a pinch
    where the generators meet).

    Parameters
    ----------
    V : (V, 3) float64
    tri : (T, 3) int
        Triangles as rows of vertex indices.
    generator, t : (V,) int64 and (V,) float64
        Each vertex's generator and parameter on it (``a_g + t d_g``).
    lines : ((m, 3), (m, 3)) float64
        ``a`` and ``d`` of the generators.

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
    mid = np.zeros(row.size)
    mid[inside] = 0.5 * (low[inside] + high[inside])
    far = np.where(inside, np.abs(np.einsum("ij,ij->i", a + mid[:, None] * d - P[:, 0], n)), 0.0)
    np.maximum.at(out, row, far)
    return out
