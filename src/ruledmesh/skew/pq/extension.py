"""The primary's division beyond the patch: rows left out where they would bunch.

A run's rows are points of its primary generator, and every other generator's
rows are their images under Moebius maps.  Where a generator's part on the patch
is the image of a part of the primary far beyond the patch, even steps there
land ever closer together on it (a Moebius map's derivative falls like
``1 / tau**2`` far from its pole): the rows bunch into slivers and the run is
cut short.  On a strongly twisted surface (a hyperboloid between two half
circles turned by 120 degrees) that left two thirds of the generators without
rows.

Beyond the primary's part the rows of the even division that would bunch on
every generator they reach are left out (:func:`thinned_rows`): a run then
carries rows as far out as the generators need them, at a spacing they can use.
"""

from __future__ import annotations

import numpy as np

from ...tolerances import ROUNDING

__all__ = ["LANDING_SLACK", "thinned_rows"]

# Rows are spread where on every generator they would land closer than this share of a step.
_BUNCHING = 0.25
# a-rows measured at a time (the generators x rows temporaries stay small).
_CHUNK = 2048
# A row this far outside [0, 1] of a generator (in units of its length) still lands on the
# patch: a face spans two rows.  The b-rows' rooting counts faces on the patch the same way.
LANDING_SLACK = 0.05


def thinned_rows(M: np.ndarray, tau: np.ndarray, own: tuple[float, float], rows: int) -> np.ndarray:
    """The rows ``tau`` without those that would bunch on every generator beyond the primary's part.

    Each step between consecutive a-rows beyond the primary's own part ``own``
    counts by how far apart its two rows land, on the generator where they land
    farthest apart of those where they meet the patch, in units of :data:`_BUNCHING`
    of a division step and at most one.  Running from the primary's part outwards,
    an a-row is kept where the sum of the counts passes a whole number: rows that do
    not bunch are all kept, and bunched ones about that far apart.  The outermost
    a-rows stay: they are the margin.

    Parameters
    ----------
    M : (m, 2, 2) float64
        Composed row maps from the root parameter.
    tau : (2n,) float64
        Increasing root parameters, a-rows at even places.
    own : (float, float)
        The range of the root parameter whose a-rows are all kept.
    rows : int
        Division steps over a generator's part on the patch.

    Returns
    -------
    (2k,) float64
        Increasing; a-rows at even places.  A b-row between two a-rows that were
        neighbours is the one given, else their middle.
    """
    a = tau[0::2]
    n = len(a)
    if n < 3:
        return tau
    share = np.concatenate([_shares(M, a[k:k + _CHUNK + 1], rows)
                            for k in range(0, n - 1, _CHUNK)])
    keep = (a >= own[0]) & (a <= own[1])
    keep[[0, -1]] = True
    inside = np.flatnonzero(keep[1:-1]) + 1
    lo, hi = (int(inside[0]), int(inside[-1])) if inside.size else (n // 2, n // 2)
    keep[lo:hi + 1] = True
    # Above: gap j lies between a-rows j and j + 1; a row is kept where the running sum
    # from the primary's part passes a whole number.
    up = np.cumsum(share[hi:]) + ROUNDING
    keep[hi + 1:] |= np.floor(up) > np.floor(np.concatenate([[ROUNDING], up[:-1]]))
    down = np.cumsum(share[:lo][::-1]) + ROUNDING
    keep[:lo][::-1] |= np.floor(down) > np.floor(np.concatenate([[ROUNDING], down[:-1]]))
    if keep.all():
        return tau
    k = np.flatnonzero(keep)
    out = np.empty(2 * len(k))
    out[0::2] = a[k]
    neighbours = np.diff(k) == 1
    out[1:-1:2] = np.where(neighbours, tau[2 * k[:-1] + 1], 0.5 * (a[k[:-1]] + a[k[1:]]))
    out[-1] = tau[2 * k[-1] + 1]
    return out


def _shares(M: np.ndarray, a: np.ndarray, rows: int) -> np.ndarray:
    """(len(a) - 1,) each step's count in :func:`thinned_rows`, for a-rows ``a``."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        num = M[:, 0, 0, None] * a + M[:, 0, 1, None]
        den = M[:, 1, 0, None] * a + M[:, 1, 1, None]
        t = num / den
        lands = np.isfinite(t) & (t > -LANDING_SLACK) & (t < 1.0 + LANDING_SLACK)
        # A pole between two rows (the denominator's sign changes) makes them far apart.
        through = np.signbit(den[:, 1:]) != np.signbit(den[:, :-1])
        gap = np.where(through, np.inf, np.abs(np.diff(t, axis=1)))
        gap = np.where(lands[:, 1:] | lands[:, :-1], gap, 0.0)
        return np.minimum(np.nan_to_num(gap, nan=np.inf).max(axis=0) / (_BUNCHING * 2.0 / rows),
                          1.0)
