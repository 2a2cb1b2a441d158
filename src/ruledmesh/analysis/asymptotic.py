"""How steeply the rows of §4.3 can cross the generators: slender regions of a ruled surface.

Every exact face of the §4.3 mesh has one diagonal on a generator ``g_i`` and
the other on the transversal through a point of ``g_i`` that meets ``g_{i-1}``
and ``g_{i+1}`` (the hop line: a line of the other regulus of the quadric
through the three generators, the discrete second asymptotic direction).  Two
lines through the face's crossing point, at the angle ``alpha`` between them,
bound its shape: a planar quad whose diagonals cross at ``alpha`` has
``diameter**2 / (2 area) >= 1 / sin(alpha)`` (equality for a rectangle), so it
is at least ``1 / sin(alpha)`` times as elongated as a square, whatever the
rows and the spacing of the generators.

Near a torsal generator, and over a nearly developable surface, ``alpha``
tends to zero (both asymptotic directions turn into the generator): there the
exact faces are slivers or long slender panels, and a planarity tolerance
(strip quads) is what makes quads of good shape.  :func:`slender_share`
measures how much of a patch is like that, from its generators alone.
"""

from __future__ import annotations

import numpy as np

from .._arrays import cross
from ..hop import hop
from ..tolerances import TINY

__all__ = ["SLENDER_DEG", "SLENDER_ELONGATION", "crossing_angles", "least_elongation", "slender_share"]

#: A face at least this many times as elongated as a square (``diameter**2 / (2 area)``)
#: is slender: a 10:1 panel.  Its diagonals cross at less than asin(1/10) = 5.7 degrees ...
SLENDER_ELONGATION = 10.0
#: ... this angle, in degrees.
SLENDER_DEG = float(np.degrees(np.arcsin(1.0 / SLENDER_ELONGATION)))


def crossing_angles(a: np.ndarray, b: np.ndarray, t: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Angle between each inner generator and the hop line through its points, and area weights.

    Parameters
    ----------
    a, b : (m, 3) float64
        The generators' end points (``t = 0`` and ``t = 1``), ``m >= 3``.
    t : (k,) float64, optional
        Parameters of the points on each generator (default: 17 from 0 to 1).

    Returns
    -------
    angles : (m - 2, k) float64
        Degrees in ``[0, 90]`` at generator ``i + 1``: the angle at which the
        diagonals of the exact face centred there would cross.  0 where the hop
        degenerates (the line runs off to infinity: a torsal pair).
    weights : (m - 2, k) float64
        The area of the patch each angle stands for (half the strips on either
        side of the generator, times its share of the generator's length).
    """
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if a.ndim != 2 or a.shape != b.shape or a.shape[1] != 3 or len(a) < 3:
        raise ValueError(f"expected two (m, 3) arrays with m >= 3, got {a.shape} and {b.shape}")
    t = np.linspace(0.0, 1.0, 17) if t is None else np.asarray(t, dtype=np.float64)
    d = b - a
    P = a[1:-1, None, :] + t[None, :, None] * d[1:-1, None, :]                   # (m-2, k, 3)
    shape = P.shape
    prev = np.broadcast_to(a[:-2, None, :], shape), np.broadcast_to(d[:-2, None, :], shape)
    nxt = np.broadcast_to(a[2:, None, :], shape), np.broadcast_to(d[2:, None, :], shape)
    q, r, ok = hop(P, prev[0], prev[1], nxt[0], nxt[1])
    e = q - r
    g = np.broadcast_to(d[1:-1, None, :], shape)
    # atan2 of |e x g| and |e . g|: exact near 0 and 90 degrees alike.
    sin = np.linalg.norm(cross(e, g), axis=-1)
    cos = np.abs(np.einsum("...i,...i->...", e, g))
    angles = np.where(ok, np.degrees(np.arctan2(sin, cos)), 0.0)
    # The patch around each point: half the way to both neighbours across (the parallelogram
    # of that span and the generator), times its share of the generator along (trapezoid
    # weights of t).
    span = (a[2:, None, :] + t[None, :, None] * d[2:, None, :]) \
        - (a[:-2, None, :] + t[None, :, None] * d[:-2, None, :])
    dt = np.gradient(t) if len(t) > 1 else np.ones(1)
    weights = 0.5 * np.linalg.norm(cross(span, g), axis=-1) * np.abs(dt)[None, :]
    return angles, weights


def least_elongation(angles: np.ndarray) -> np.ndarray:
    """``1 / sin(alpha)``: how many times as elongated as a square (``diameter**2 / (2
    area)``) a planar face whose diagonals cross at ``angles`` (degrees) must be; inf at 0."""
    s = np.sin(np.radians(np.asarray(angles, dtype=np.float64)))
    with np.errstate(divide="ignore"):
        return np.where(s > 0.0, 1.0 / np.maximum(s, TINY), np.inf)


def slender_share(a: np.ndarray, b: np.ndarray, elongation: float = SLENDER_ELONGATION,
                  t: np.ndarray | None = None) -> float:
    """Share of the patch (by area) where every exact §4.3 face is at least ``elongation``
    times as elongated as a square: its hop line crosses the generators at less than
    ``asin(1 / elongation)``.

    Parameters
    ----------
    a, b : (m, 3) float64
        The generators' end points, ``m >= 3``.
    elongation : float
        The bar (default :data:`SLENDER_ELONGATION`: 10:1 panels, 5.7 degrees).
    t : (k,) float64, optional
        Parameters sampled on each generator (as :func:`crossing_angles`).

    Returns
    -------
    float
        In ``[0, 1]``; 0 where the patch has no area.

    Examples
    --------
    A hyperbolic paraboloid ``z = x y`` over the unit square: its two families of
    lines cross at 45 degrees or more, nothing is slender.

    >>> import numpy as np
    >>> x = np.linspace(0.0, 1.0, 11)
    >>> a = np.stack([x, 0 * x, 0 * x], 1); b = np.stack([x, 1 + 0 * x, x], 1)
    >>> slender_share(a, b)
    0.0
    """
    if not elongation > 1.0:
        raise ValueError(f"expected an elongation above 1, got {elongation!r}")
    angles, weights = crossing_angles(a, b, t)
    total = float(weights.sum())
    if total <= 0.0:
        return 0.0
    bar = np.degrees(np.arcsin(1.0 / elongation))
    return float(weights[angles < bar].sum()) / total
