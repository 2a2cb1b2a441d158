"""The transversal hop of paper §4.3 and its projective form.

Through a point ``P`` on generator ``g0`` passes exactly one line that meets
two further lines ``g1`` and ``g2``: it lies in the plane spanned by ``P`` and
``g1`` and so meets ``g2`` where that plane does.  That line belongs to the
other regulus of the quadric through ``g0, g1, g2``; hopping from generator to
generator along such lines gives the rows of the PQ mesh.

Because the plane through ``P(t) = a0 + t d0`` and ``g1`` depends linearly on
``t``, the parameter of the landing point on ``g2`` (and of the crossing on
``g1``) is a Moebius function of ``t``: a 2x2 matrix acting on homogeneous
``(t, 1)``.  Composing the matrices gives every row of the mesh at once
(:mod:`ruledmesh.pq`), and their poles say where a row runs to infinity.
See the paper, §4.3.
"""

from __future__ import annotations

import numpy as np

from ._arrays import cross as _cross
from .tolerances import ROUNDING, TINY

__all__ = ["hop", "landing_maps", "crossing_maps", "coplanarity", "sense_changes", "apply_map"]


def _dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", x, y)


def hop(points: np.ndarray, a1: np.ndarray, d1: np.ndarray, a2: np.ndarray, d2: np.ndarray,
        tol: float = ROUNDING) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The line through each point that meets two lines: where it meets them.

    Parameters
    ----------
    points : (..., 3) float64
        Starting points ``P``.
    a1, d1 : (..., 3) float64
        Point and direction of the first line crossed, ``g1``.
    a2, d2 : (..., 3) float64
        Point and direction of the line landed on, ``g2``.
    tol : float
        Relative size under which the plane (P, g1) counts as parallel to
        ``g2`` (landing at infinity) or P as lying on ``g1``.

    Returns
    -------
    landing : (..., 3) float64
        ``Q`` on ``g2``; where the hop fails, ``P`` itself (never inf/NaN).
    crossing : (..., 3) float64
        ``R`` on ``g1``, collinear with ``P`` and ``Q``.
    ok : (...,) bool
        False where the hop is degenerate (``Q`` at infinity or ``P`` on ``g1``).

    Examples
    --------
    Three generators of the hyperbolic paraboloid ``z = x y``: the hop from a
    point of the first lands on the other regulus's line through it.

    >>> import numpy as np
    >>> g = lambda x: (np.array([x, 0.0, 0.0]), np.array([0.0, 1.0, x]))
    >>> (a0, d0), (a1, d1), (a2, d2) = g(0.0), g(1.0), g(2.0)
    >>> P = a0 + 0.5 * d0
    >>> Q, R, ok = hop(P, a1, d1, a2, d2)
    >>> Q.round(12).tolist(), R.round(12).tolist(), bool(ok)
    ([2.0, 0.5, 1.0], [1.0, 0.5, 0.5], True)
    """
    n = _cross(d1, a1 - points)
    nd2 = _dot(n, d2)
    scale_n = np.linalg.norm(d1, axis=-1) * np.linalg.norm(a1 - points, axis=-1)
    nn = np.linalg.norm(n, axis=-1)
    ok_plane = nn > tol * np.maximum(scale_n, TINY)
    ok_land = np.abs(nd2) > tol * np.maximum(nn * np.linalg.norm(d2, axis=-1), TINY)
    ok = ok_plane & ok_land
    t2 = np.where(ok, _dot(n, a1 - a2) / np.where(ok, nd2, 1.0), 0.0)
    q = a2 + t2[..., None] * d2
    e = q - points
    c = _cross(d1, e)
    cc = _dot(c, c)
    ok &= cc > (tol * np.linalg.norm(d1, axis=-1) * np.linalg.norm(e, axis=-1)) ** 2
    t1 = np.where(ok, _dot(_cross(points - a1, e), c) / np.where(ok, cc, 1.0), 0.0)
    r = a1 + t1[..., None] * d1
    q = np.where(ok[..., None], q, points)
    r = np.where(ok[..., None], r, points)
    return q, r, ok


def landing_maps(a0, d0, a1, d1, a2, d2) -> np.ndarray:
    """Moebius maps from the parameter on ``g0`` to the landing parameter on ``g2``.

    A point ``a0 + t d0`` hops across ``g1`` to ``a2 + t2 d2`` with
    ``t2 = (H00 t + H01) / (H10 t + H11)``.

    Parameters
    ----------
    a0, d0, a1, d1, a2, d2 : (k, 3) float64
        Points and directions of the three generators of each hop.

    Returns
    -------
    H : (k, 2, 2) float64
        Not normalised; ``det H`` is the product of the coplanarity
        determinants of (g0, g1) and (g1, g2), zero for a torsal pair.
    """
    # Written with the differences d0 - d1 and d2 - d1 (d1 x d1 = 0 and both
    # normals are orthogonal to d1): for finely sampled generators these are
    # small and exact, where d1 x d0 of nearly parallel directions would lose
    # relative accuracy in proportion to the sampling step.
    n0 = _cross(d1, a1 - a0)
    n1 = _cross(d1, d0 - d1)
    w = a1 - a2
    dd = d2 - d1
    H = np.empty((len(a0), 2, 2))
    H[:, 0, 0] = -_dot(n1, w)
    H[:, 0, 1] = _dot(n0, w)
    H[:, 1, 0] = -_dot(n1, dd)
    H[:, 1, 1] = _dot(n0, dd)
    return H


def crossing_maps(a0, d0, a1, d1, a2, d2) -> np.ndarray:
    """Moebius maps from the parameter on ``g0`` to the crossing parameter on ``g1``.

    The hop line from ``a0 + t d0`` meets ``g1`` where the plane through the
    point and ``g2`` does, so the crossing parameter is again projective in ``t``.

    Parameters
    ----------
    a0, d0, a1, d1, a2, d2 : (k, 3) float64

    Returns
    -------
    C : (k, 2, 2) float64
    """
    return landing_maps(a0, d0, a2, d2, a1, d1)


def coplanarity(a: np.ndarray, d: np.ndarray, scale: float) -> np.ndarray:
    """Signed twist between consecutive generators (0: coplanar, a torsal pair).

    The sign is the sense in which the generators twist; it changes across a
    torsal generator of the surface, where hops across reverse the rows.

    Parameters
    ----------
    a, d : (m, 3) float64
        Generator points and directions.
    scale : float
        The patch size; the measure is ``det(d_k, d_k+1, a_k+1 - a_k)``
        divided by ``|d_k| |d_k+1| scale``, a scale-free volume.

    Returns
    -------
    (m - 1,) float64
    """
    vol = _dot(_cross(d[:-1], d[1:]), a[1:] - a[:-1])
    norms = np.linalg.norm(d, axis=1)
    return vol / np.maximum(norms[:-1] * norms[1:] * scale, TINY)


def sense_changes(twist: np.ndarray, flat: np.ndarray) -> np.ndarray:
    """(m - 1,) bool: strips that twist in the other sense than the strip before them.

    ``twist`` is :func:`coplanarity`; ``flat`` (m - 1,) bool marks the coplanar
    pairs, which have no sense: a change across one needs no cut of its own (the
    flat strip is one already, and a second beside it would leave that strip to
    triangles).
    """
    sign = np.sign(np.where(flat, 0.0, twist))
    change = np.zeros(len(sign), bool)
    change[1:] = (sign[1:] != sign[:-1]) & (sign[:-1] != 0) & (sign[1:] != 0)
    return change


def apply_map(M: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Homogeneous image of parameters under 2x2 maps.

    Parameters
    ----------
    M : (k, 2, 2) float64
    tau : (k, n) or (n,) float64

    Returns
    -------
    num, den : (k, n) float64
        ``t = num / den``; ``den`` changes sign at the map's pole.
    """
    num = M[:, 0, 0, None] * tau + M[:, 0, 1, None]
    den = M[:, 1, 0, None] * tau + M[:, 1, 1, None]
    return num, den
