"""numba kernels of a run's grid (:mod:`ruledmesh.skew.pq.runs`, :mod:`ruledmesh.skew.pq.maps`).

The rows are propagated hop by hop along the four chain ends exactly as
:func:`ruledmesh.skew.pq.maps.propagate` does (the same products, the same positive
rescaling every eighth hop), and the vertices, half-faces, poles and the
per-generator convexity counts of :func:`ruledmesh.skew.pq.runs._grid` come from one
pass over the grid instead of some forty array operations, each with its
temporaries.  The results are bit for bit those of the numpy path (the tests
compare both).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .geometry import angle_at

__all__ = ["grid", "propagate"]


@nb.njit(cache=True, nogil=True)
def _front(num, den, g0, step, fwd, bwd):
    """Advance one chain end from generator ``g0`` by ``step`` (+-2) hop by hop."""
    m, H = num.shape
    k = 0
    g = g0 + step
    while 0 <= g < m:
        Hm = fwd[g - 2] if step > 0 else bwd[g]
        src = g - step
        rescale = k % 8 == 7
        for h in range(H):
            ps, qs = num[src, h], den[src, h]
            nn = Hm[0, 0] * ps + Hm[0, 1] * qs
            dd = Hm[1, 0] * ps + Hm[1, 1] * qs
            if rescale:
                sc = max(abs(nn), abs(dd))
                if sc == 0.0:
                    sc = 1.0
                nn /= sc
                dd /= sc
            num[g, h] = nn
            den[g, h] = dd
        k += 1
        g += step


@nb.njit(cache=True, nogil=True)
def _propagate(primary, root, fwd, bwd, C, tau):
    m, H = tau.shape
    num = np.empty((m, H))
    den = np.empty((m, H))
    for h in range(H):
        num[primary, h] = tau[primary, h]
        den[primary, h] = 1.0
        num[root, h] = C[0, 0] * tau[root, h] + C[0, 1]
        den[root, h] = C[1, 0] * tau[root, h] + C[1, 1]
    for g0, step in ((primary, 2), (root, 2), (primary, -2), (root, -2)):
        _front(num, den, g0, step, fwd, bwd)
    return num, den


def propagate(primary: int, root: int, fwd: np.ndarray, bwd: np.ndarray, C: np.ndarray,
              tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`ruledmesh.skew.pq.maps.propagate`, bit for bit.

    Parameters
    ----------
    primary, root : int
        The chains' roots (``ChainMaps.primary``, ``ChainMaps.root``).
    fwd, bwd : (m-2, 2, 2) float64
        Hop maps forwards and backwards.
    C : (2, 2) float64
        Crossing map from the primary to the root.
    tau : (m, H) float64
        Root parameters of each generator's rows.

    Returns
    -------
    num, den : (m, H) float64
    """
    c = np.ascontiguousarray
    return _propagate(int(primary), int(root), c(fwd, dtype=np.float64), c(bwd, dtype=np.float64),
                      c(C, dtype=np.float64), c(tau, dtype=np.float64))


@nb.njit(cache=True, nogil=True)
def _vertices(a, d, num, den, tmax):
    m, H = num.shape
    X = np.empty((m * H, 3))
    t = np.empty(m * H)
    far = np.empty(m * H, np.bool_)
    for i in range(m):
        for h in range(H):
            v = i * H + h
            f = not (abs(num[i, h]) < tmax[i] * abs(den[i, h]))
            tv = 0.0 if f else num[i, h] / den[i, h]
            far[v] = f
            t[v] = tv
            for j in range(3):
                X[v, j] = a[i, j] + tv * d[i, j]
    return X, t, far


@nb.njit(cache=True)
def _thin(X, i0, i1, i2, i3, thin_deg):
    """``polygon_angles(X[[i0, i1, i2, i3]]).min() < thin_deg`` (a triangle when ``i3 < 0``).

    The smallest angle is NaN, and so not below, when any angle is.
    """
    if i3 < 0:
        a0, a1, a2 = angle_at(X, i2, i0, i1), angle_at(X, i0, i1, i2), angle_at(X, i1, i2, i0)
        a3 = a2
    else:
        a0, a1 = angle_at(X, i3, i0, i1), angle_at(X, i0, i1, i2)
        a2, a3 = angle_at(X, i1, i2, i3), angle_at(X, i2, i3, i0)
    if a0 != a0 or a1 != a1 or a2 != a2 or a3 != a3:
        return False
    return min(min(a0, a1), min(a2, a3)) < thin_deg


@nb.njit(cache=True, nogil=True)
def _faces(num, den, t, far, parity, Xc, first, X, thin_deg):
    """Half-faces, poles, centre generators and failing counts of the grid's faces.

    A face on the patch fails when its crossing misses its generator diagonal
    (a bow-tie) or when it has an angle below ``thin_deg``; the notch halves
    on the end generators count against the generator next to the end, as
    :func:`ruledmesh.skew.pq.runs._failing_faces` counts them.
    """
    m, H = num.shape
    per = max(H - 1, 0)
    F = m * per
    left = np.empty((F, 3), np.int64)
    right = np.empty((F, 3), np.int64)
    pole = np.empty(F, np.bool_)
    cg = np.empty(F, np.int64)
    failing = np.zeros(m, np.int64)
    counted = np.zeros(m, np.int64)
    f = 0
    for i in range(m):
        p = parity[i]
        for c in range(p, per + p):
            hl = c - p
            lo_v = i * H + hl
            hi_v = lo_v + 1
            if i > 0:
                left[f, 0], left[f, 1], left[f, 2] = (i - 1) * H + c, lo_v, hi_v
            else:
                left[f, 0], left[f, 1], left[f, 2] = -1, -1, -1
            if i < m - 1:
                right[f, 0], right[f, 1], right[f, 2] = lo_v, (i + 1) * H + c, hi_v
            else:
                right[f, 0], right[f, 1], right[f, 2] = -1, -1, -1
            # np.signbit (zeros and NaNs carry a sign too).
            pl = (math.copysign(1.0, den[i, hl]) < 0.0) != (math.copysign(1.0, den[i, hl + 1]) < 0.0)
            pole[f] = pl
            cg[f] = i + first
            if 0 < i < m - 1:
                k = i - 1
                ts = t[(i - 1) * H + c]
                tn = Xc[k, 0, 0] * ts + Xc[k, 0, 1]
                td = Xc[k, 1, 0] * ts + Xc[k, 1, 1]
                # A zero denominator gives inf or NaN in numpy: off the patch either way.
                tc = tn / td if td != 0.0 else math.nan
                on = (math.isfinite(tc) and tc > 0.0 and tc < 1.0 and not pl and not far[lo_v]
                      and not far[hi_v] and not far[(i - 1) * H + c] and not far[(i + 1) * H + c])
                if on:
                    counted[i] += 1
                    if not ((tc - t[lo_v]) * (tc - t[hi_v]) < 0.0) \
                            or _thin(X, (i - 1) * H + c, lo_v, (i + 1) * H + c, hi_v, thin_deg):
                        failing[i] += 1
            elif m >= 3:
                # A notch half on an end generator: a triangle of the mesh.
                side = 1 if i == 0 else -1
                o = (i + side) * H + c
                if not far[lo_v] and not far[hi_v] and not far[o] and t[lo_v] >= 0.0 and t[hi_v] <= 1.0:
                    counted[i + side] += 1
                    if _thin(X, lo_v, o, hi_v, -1, thin_deg):
                        failing[i + side] += 1
            f += 1
    return left, right, pole, cg, failing, counted


def grid(a: np.ndarray, d: np.ndarray, num: np.ndarray, den: np.ndarray, tmax: np.ndarray,
         parity: np.ndarray, Xc: np.ndarray, first: int, thin_deg: float) -> tuple[np.ndarray, ...]:
    """The arrays of :func:`ruledmesh.skew.pq.runs._grid` from the propagated rows, bit for bit.

    Parameters
    ----------
    a, d : (m, 3) float64
        The run's generators.
    num, den : (m, H) float64
        Homogeneous row parameters (:func:`propagate`).
    tmax : (m,) float64
        Largest ``|t|`` kept on each generator (beyond: *far*).
    parity : (m,) int
        0 on chain *a*'s generators, 1 on chain *b*'s.
    Xc : (m-2, 2, 2) float64
        Crossing maps of the inner generators (any shape (0, 2, 2) when ``m < 3``).
    first : int
        Global index of the run's first generator.
    thin_deg : float
        A face with a smaller angle fails (:data:`~ruledmesh.tolerances.RESTART_ANGLE_DEG`).

    Returns
    -------
    X : (m H, 3) float64
    t : (m H,) float64
    far : (m H,) bool
    left, right : (F, 3) int64
    pole : (F,) bool
    centre_gen : (F,) int64
    failing, on_patch : (m,) int64
    """
    c = np.ascontiguousarray
    num, den = c(num, dtype=np.float64), c(den, dtype=np.float64)
    X, t, far = _vertices(c(a, dtype=np.float64), c(d, dtype=np.float64), num, den, c(tmax, dtype=np.float64))
    if len(a) < 3:
        Xc = np.zeros((0, 2, 2))
    left, right, pole, cg, failing, counted = _faces(num, den, t, far, c(parity, dtype=np.int64),
                                                    c(Xc, dtype=np.float64), int(first), X,
                                                    float(thin_deg))
    return X, t, far, left, right, pole, cg, failing, counted
