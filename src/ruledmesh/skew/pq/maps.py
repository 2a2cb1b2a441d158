"""Row maps of the §4.3 mesher: Moebius maps of the line parameter along the chains.

A hop from ``g_k`` across ``g_k+1`` to ``g_k+2`` maps the parameter of the
start point to that of the landing point by a 2x2 matrix (see
:mod:`ruledmesh.hop`).  Chain *a* starts at the identity on the primary
generator; chain *b* starts on its neighbour, at the crossing of chain *a*'s
first hop.  Composed, the maps give every row's parameter on every generator
(used to choose rows); applied hop by hop they give the vertices (one rounding
per hop, so planarity does not drift).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...hop import crossing_maps, landing_maps
from ...tolerances import TINY

__all__ = [
    "ChainMaps",
    "HopMaps",
    "apply",
    "chain_maps",
    "compose",
    "drift_maps",
    "hop_maps",
    "inverse",
    "patch_preimage",
    "propagate",
    "row_maps",
    "unit_det",
]


@dataclass(frozen=True)
class ChainMaps:
    """What both the composed maps and the hop-by-hop rows start from."""

    primary: int            # the a-chain's root (moved to 0 for three generators)
    root: int               # the b-chain's root, next to the primary
    fwd: np.ndarray         # (m-2, 2, 2) g_k -> g_k+2, |det| = 1
    bwd: np.ndarray         # (m-2, 2, 2) g_k+2 -> g_k, |det| = 1
    crossing: np.ndarray    # (2, 2) primary -> root, |det| = 1


def unit_det(H: np.ndarray) -> np.ndarray:
    """Scale 2x2 maps to |det| = 1 (rows then neither grow nor shrink on average)."""
    det = np.abs(H[:, 0, 0] * H[:, 1, 1] - H[:, 0, 1] * H[:, 1, 0])
    scale = np.sqrt(np.where(det > 0, det, np.abs(H).max(axis=(1, 2)) ** 2 + TINY))
    return H / scale[:, None, None]


@dataclass(frozen=True)
class HopMaps:
    """The maps of the hops between consecutive generators, measured once for every run.

    Runs restart on the same generators several times; each hop's maps depend
    on its three generators only, so a run takes its rows of these (the same
    numbers as measuring its own).
    """

    fwd: np.ndarray         # (m-2, 2, 2) g_k -> g_k+2, |det| = 1
    bwd: np.ndarray         # (m-2, 2, 2) g_k+2 -> g_k, |det| = 1
    crossing: np.ndarray    # (m-2, 2, 2) g_k -> g_k+1 (crossing_maps), not scaled

    def part(self, first: int, m: int) -> HopMaps:
        """The maps of the run of the ``m`` generators from ``first``."""
        sl = slice(first, first + max(m - 2, 0))
        return HopMaps(self.fwd[sl], self.bwd[sl], self.crossing[sl])


def _landing(a: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Landing maps of consecutive generators, forwards and backwards, scaled to |det| = 1."""
    return (unit_det(landing_maps(a[:-2], d[:-2], a[1:-1], d[1:-1], a[2:], d[2:])),
            unit_det(landing_maps(a[2:], d[2:], a[1:-1], d[1:-1], a[:-2], d[:-2])))


def hop_maps(a: np.ndarray, d: np.ndarray) -> HopMaps:
    """The :class:`HopMaps` of generators ``a``, ``d`` (m, 3)."""
    return HopMaps(*_landing(a, d), crossing_maps(a[:-2], d[:-2], a[1:-1], d[1:-1], a[2:], d[2:]))


def chain_maps(a: np.ndarray, d: np.ndarray, primary: int, hops: HopMaps | None = None) -> ChainMaps:
    """Landing maps in both directions and the crossing map that roots chain *b*.

    ``hops``: the run's own :class:`HopMaps` (``HopMaps.part``), if measured already.
    """
    m = len(a)
    if primary + 2 >= m and primary - 2 < 0:
        # Three generators with the primary in the middle: no hop starts there.
        primary = 0
    fwd, bwd = _landing(a, d) if hops is None else (hops.fwd, hops.bwd)
    # Chain b starts where chain a's first hop crosses the neighbour (towards the longer side).
    root = primary + 1 if primary + 2 < m else primary - 1
    far = root + 1 if root > primary else root - 1
    C = unit_det(crossing_maps(a[primary:primary + 1], d[primary:primary + 1], a[root:root + 1],
                               d[root:root + 1], a[far:far + 1], d[far:far + 1]))[0]
    return ChainMaps(primary, root, fwd, bwd, C)


def _product(h: list, m: list) -> list:
    """2x2 product ``h @ m`` of nested lists, scaled to unit max-norm (a zero map stays zero)."""
    (h00, h01), (h10, h11) = h
    (m00, m01), (m10, m11) = m
    r = (h00 * m00 + h01 * m10, h00 * m01 + h01 * m11, h10 * m00 + h11 * m10, h10 * m01 + h11 * m11)
    s = max(map(abs, r)) or 1.0
    return [[r[0] / s, r[1] / s], [r[2] / s, r[3] / s]]


def compose(maps: ChainMaps, m: int) -> np.ndarray:
    """The maps of :func:`row_maps` from a :class:`ChainMaps`."""
    out: list = [None] * m
    out[maps.primary] = [[1.0, 0.0], [0.0, 1.0]]
    out[maps.root] = _product(maps.crossing.tolist(), out[maps.primary])
    fwd, bwd = maps.fwd.tolist(), maps.bwd.tolist()
    # Sequential only along the generators (m small 2x2 products), never per vertex.
    for start in (maps.primary, maps.root):
        for i in range(start + 2, m, 2):
            out[i] = _product(fwd[i - 2], out[i - 2])
        for i in range(start - 2, -1, -2):
            out[i] = _product(bwd[i], out[i + 2])
    return np.array(out)


def row_maps(a: np.ndarray, d: np.ndarray, primary: int) -> np.ndarray:
    """Moebius maps from the primary generator's parameter to every generator's.

    Chain *a* lives on the generators of the primary's parity and starts at
    the identity; chain *b* starts where chain *a*'s first hop crosses the
    neighbouring generator (towards the longer side) and hops both ways.

    Parameters
    ----------
    a, d : (m, 3) float64
        Generator points and directions, ``m >= 3``, no torsal pair.
    primary : int
        Index of the primary generator.

    Returns
    -------
    M : (m, 2, 2) float64
        ``t_i = (M[i,0,0] tau + M[i,0,1]) / (M[i,1,0] tau + M[i,1,1])``;
        each matrix scaled to unit max-norm.
    """
    return compose(chain_maps(a, d, primary), len(a))


def apply(M: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``M[k](x[k, ...])`` for (k, 2, 2) maps and (k, ...) parameters (inf at a pole)."""
    shape = (slice(None),) + (None,) * (x.ndim - 1)
    num = M[:, 0, 0][shape] * x + M[:, 0, 1][shape]
    den = M[:, 1, 0][shape] * x + M[:, 1, 1][shape]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den != 0, num / np.where(den != 0, den, 1.0), np.inf)


def inverse(M: np.ndarray) -> np.ndarray:
    """Inverse Moebius maps (adjugates; a map and its multiples are the same map)."""
    out = np.empty_like(M)
    out[:, 0, 0], out[:, 0, 1] = M[:, 1, 1], -M[:, 0, 1]
    out[:, 1, 0], out[:, 1, 1] = -M[:, 1, 0], M[:, 0, 0]
    return out


def drift_maps(a: np.ndarray, d: np.ndarray, M: np.ndarray, X: np.ndarray | None = None) -> np.ndarray:
    """How far the two chains have drifted apart, generator by generator.

    For a face centred on ``g_i`` the hop line of its row (from ``g_i-1`` to
    ``g_i+1``) crosses ``g_i``; ``N[i] = M_i^-1 X_i M_i-1`` takes the row's
    root parameter to the root parameter of the point it crosses, in the units
    of the rows living on ``g_i``.  Without drift ``N[i]`` is the identity; the
    face is convex when ``tau[r-1] < N[i](tau[r]) < tau[r+1]``.

    Parameters
    ----------
    a, d : (m, 3) float64
    M : (m, 2, 2) float64
        Composed row maps (:func:`compose`).
    X : (m-2, 2, 2) float64, optional
        The crossing maps of the inner generators (``HopMaps.crossing``), if measured already.

    Returns
    -------
    N : (m, 2, 2) float64
        Rows 0 and m-1 (no face crosses there) are the identity.
    """
    m = len(a)
    N = np.tile(np.eye(2), (m, 1, 1))
    if m < 3:
        return N
    if X is None:
        X = crossing_maps(a[:-2], d[:-2], a[1:-1], d[1:-1], a[2:], d[2:])
    inner = np.einsum("kij,kjl->kil", inverse(M[1:-1]), np.einsum("kij,kjl->kil", X, M[:-2]))
    N[1:-1] = inner / np.maximum(np.abs(inner).max(axis=(1, 2)), TINY)[:, None, None]
    return N


def propagate(maps: ChainMaps, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Homogeneous row parameters on every generator, hop by hop.

    Each vertex is the exact image (one rounding) of its neighbour two
    generators back, so the hop-line diagonal of every face meets its generator
    to rounding, however many generators the chain crosses.  (The composed
    maps are used only to choose the rows: evaluated directly they let
    rounding drift between neighbours.)

    Parameters
    ----------
    maps : ChainMaps
    tau : (m, H) float64
        Root parameter of each generator's rows (chain *b*'s in the units of
        the primary, mapped to the root by the crossing map).

    Returns
    -------
    num, den : (m, H) float64
        ``t = num / den``; ``den`` changes sign where a row passes infinity.
    """
    m = len(tau)
    primary, root, fwd, bwd, C = maps.primary, maps.root, maps.fwd, maps.bwd, maps.crossing
    num = np.empty_like(tau)
    den = np.empty_like(tau)
    num[primary], den[primary] = tau[primary], 1.0
    num[root] = C[0, 0] * tau[root] + C[0, 1]
    den[root] = C[1, 0] * tau[root] + C[1, 1]
    # Fronts: (generator, step) for the four chain ends, advanced together.
    fronts = [(primary, 2), (root, 2), (primary, -2), (root, -2)]
    k = 0
    while True:
        src, dst, Hs = [], [], []
        for g0, step in fronts:
            g = g0 + step * (k + 1)
            if 0 <= g < m:
                src.append(g - step)
                dst.append(g)
                Hs.append(fwd[g - 2] if step > 0 else bwd[g])
        if not dst:
            break
        Hm = np.array(Hs)
        ps, qs = num[src], den[src]
        nn = Hm[:, 0, 0, None] * ps + Hm[:, 0, 1, None] * qs
        dd = Hm[:, 1, 0, None] * ps + Hm[:, 1, 1, None] * qs
        if k % 8 == 7:
            # Positive rescaling per row keeps the homogeneous pair finite and its sign.
            sc = np.maximum(np.abs(nn), np.abs(dd))
            sc[sc == 0] = 1.0
            nn /= sc
            dd /= sc
        num[dst], den[dst] = nn, dd
        k += 1
    return num, den


def patch_preimage(M: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each map, the tau interval that lands on 0 <= t <= 1.

    Returns
    -------
    lo, hi : (m,) float64
        Interval ends (finite where ``bounded``).
    bounded : (m,) bool
        False where the interval passes through tau = infinity (or the map is
        degenerate), so no finite division of the primary covers that generator.
    """
    m00, m01, m10, m11 = M[:, 0, 0], M[:, 0, 1], M[:, 1, 0], M[:, 1, 1]
    # tau(t) = (m11 t - m01) / (m00 - m10 t), the inverse map, at t = 0 and t = 1.
    den0 = m00
    den1 = m00 - m10
    small = tol * np.abs(M).max(axis=(1, 2))
    finite = (np.abs(den0) > small) & (np.abs(den1) > small)
    tau0 = np.where(finite, -m01 / np.where(finite, den0, 1.0), 0.0)
    tau1 = np.where(finite, (m11 - m01) / np.where(finite, den1, 1.0), 0.0)
    lo, hi = np.minimum(tau0, tau1), np.maximum(tau0, tau1)
    # The map's pole (t = inf) inside [lo, hi] means the preimage of [0, 1] is the outside.
    pole_den = np.abs(m10) > small
    pole = np.where(pole_den, -m11 / np.where(pole_den, m10, 1.0), np.inf)
    wraps = pole_den & (pole > lo) & (pole < hi)
    return lo, hi, finite & ~wraps
