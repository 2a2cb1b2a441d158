"""numba kernel of the strip trimming of :func:`ruledmesh.skew.pq.strips.strip_paths`.

The same decisions in the same order: each kept PQ half-face is one step of
its strip's monotone lattice path, a step claiming a path position already
claimed replaces the earlier one (numpy's scatter keeps the last write), a step
is kept when it starts at or beyond where every earlier step of its strip
ended, and the gaps are listed first-of-strip, between-steps, last-of-strip,
then empty strips.  Integer logic only, so the results are those of numpy
exactly; it runs in one pass per stage instead of some sixty array operations
with their int64 temporaries (the trimming was the build's peak of memory).
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = ["near_border", "strip_paths"]


@nb.njit(cache=True, nogil=True)
def _ranks(V_len, chain, gstart):
    rank = np.full(V_len, -1, np.int64)
    for g in range(gstart.shape[0] - 1):
        for i in range(gstart[g], gstart[g + 1]):
            rank[chain[i]] = i - gstart[g]
    return rank


@nb.njit(cache=True, nogil=True)
def _steps(rank, L, R, ok_l, ok_r, CG):
    """Steps in numpy's concatenation order: right halves, then left halves, by face."""
    F = L.shape[0]
    cap = 0
    for f in range(F):
        cap += ok_r[f] + ok_l[f]
    strip = np.empty(cap, np.int64)
    k = np.empty(cap, np.int64)
    l = np.empty(cap, np.int64)
    a = np.empty(cap, np.bool_)
    n = np.empty(cap, np.int64)
    sid = np.empty(cap, np.int64)
    c = 0
    for f in range(F):
        if ok_r[f]:
            r0, r1, r2 = rank[R[f, 0]], rank[R[f, 1]], rank[R[f, 2]]
            j = r2 - r0
            if j == 1 or (j > 1 and L[f, 0] < 0):
                strip[c], k[c], l[c], a[c], n[c], sid[c] = CG[f], r0, r1, True, j, f
                c += 1
    for f in range(F):
        if ok_l[f]:
            r0, r1, r2 = rank[L[f, 0]], rank[L[f, 1]], rank[L[f, 2]]
            j = r2 - r1
            if j == 1 or (j > 1 and R[f, 0] < 0):
                strip[c], k[c], l[c], a[c], n[c], sid[c] = CG[f] - 1, r0, r1, False, j, f
                c += 1
    return strip[:c], k[:c], l[:c], a[:c], n[:c], sid[:c]


@nb.njit(cache=True, nogil=True)
def _ordered_kept(strip, k, l, a, n, pstart):
    """Steps by path position (the last claim of a slot wins), then the monotone ones."""
    slot = np.full(pstart[-1], -1, np.int64)
    for i in range(strip.shape[0]):
        slot[pstart[strip[i]] + k[i] + l[i]] = i
    order = np.empty(strip.shape[0], np.int64)
    c = 0
    for s in range(slot.shape[0]):
        if slot[s] >= 0:
            order[c] = slot[s]
            c += 1
    keep = np.empty(c, np.int64)
    kept = 0
    prev_k = prev_l = -1
    for q in range(c):
        i = order[q]
        if q == 0 or strip[order[q - 1]] != strip[i]:
            prev_k = prev_l = -1
        if k[i] >= prev_k and l[i] >= prev_l:
            keep[kept] = i
            kept += 1
        # Dropped steps count too (conservative), as in numpy's running maximum.
        end_k = k[i] + n[i] if a[i] else k[i]
        end_l = l[i] if a[i] else l[i] + n[i]
        prev_k = max(prev_k, end_k)
        prev_l = max(prev_l, end_l)
    return keep[:kept]


@nb.njit(cache=True, nogil=True)
def _gaps(strip, k, l, a, n, clen, nstrip):
    """Gaps before, between and after the kept steps, and whole empty strips."""
    S = strip.shape[0]
    ek = np.empty(S, np.int64)
    el = np.empty(S, np.int64)
    for i in range(S):
        ek[i] = k[i] + n[i] if a[i] else k[i]
        el[i] = l[i] if a[i] else l[i] + n[i]
    has = np.zeros(nstrip, np.bool_)
    for i in range(S):
        has[strip[i]] = True
    cap = 2 * S + nstrip
    g_s = np.empty(cap, np.int64)
    k0 = np.empty(cap, np.int64)
    l0 = np.empty(cap, np.int64)
    k1 = np.empty(cap, np.int64)
    l1 = np.empty(cap, np.int64)
    c = 0
    for i in range(S):                                   # before the first step of a strip
        if i == 0 or strip[i] != strip[i - 1]:
            g_s[c], k0[c], l0[c], k1[c], l1[c] = strip[i], 0, 0, k[i], l[i]
            c += 1
    for i in range(1, S):                                # between steps that do not meet
        if strip[i] == strip[i - 1] and (ek[i - 1] != k[i] or el[i - 1] != l[i]):
            g_s[c], k0[c], l0[c], k1[c], l1[c] = strip[i], ek[i - 1], el[i - 1], k[i], l[i]
            c += 1
    for i in range(S):                                   # after the last step
        if i == S - 1 or strip[i + 1] != strip[i]:
            s = strip[i]
            g_s[c], k0[c], l0[c], k1[c], l1[c] = s, ek[i], el[i], clen[s] - 1, clen[s + 1] - 1
            c += 1
    for s in range(nstrip):                              # strips without steps
        if not has[s]:
            g_s[c], k0[c], l0[c], k1[c], l1[c] = s, 0, 0, clen[s] - 1, clen[s + 1] - 1
            c += 1
    na = np.maximum(k1[:c] - k0[:c], 0)
    nb_ = np.maximum(l1[:c] - l0[:c], 0)
    return g_s[:c].copy(), k0[:c].copy(), l0[:c].copy(), na, nb_


@nb.njit(cache=True, nogil=True)
def _strip_paths(V_len, chain, gstart, m, L, R, ok_l, ok_r, CG):
    rank = _ranks(V_len, chain, gstart)
    clen = gstart[1:] - gstart[:-1]
    strip, k, l, a, n, sid = _steps(rank, L, R, ok_l, ok_r, CG)
    nstrip = m - 1
    pstart = np.zeros(nstrip + 1, np.int64)
    for s in range(nstrip):
        pstart[s + 1] = pstart[s] + clen[s] + clen[s + 1] - 2
    keep = _ordered_kept(strip, k, l, a, n, pstart)
    strip, k, l, a, n, sid = strip[keep], k[keep], l[keep], a[keep], n[keep], sid[keep]
    F_r, F_l = R.shape[0], L.shape[0]
    keep_r = np.zeros(F_r, np.bool_)
    keep_l = np.zeros(F_l, np.bool_)
    jump_r = np.ones(F_r, np.int64)
    jump_l = np.ones(F_l, np.int64)
    for i in range(strip.shape[0]):
        if a[i]:
            keep_r[sid[i]] = True
            jump_r[sid[i]] = n[i]
        else:
            keep_l[sid[i]] = True
            jump_l[sid[i]] = n[i]
    g_s, k0, l0, na, nb_ = _gaps(strip, k, l, a, n, clen, nstrip)
    return keep_l, keep_r, g_s, k0, l0, na, nb_, jump_l, jump_r


@nb.njit(cache=True, nogil=True)
def _all_ranked(rank_len, chain, gstart, L, R, ok_l, ok_r):
    """Every vertex of a candidate half lies on a chain (else numpy's negative ranks wrap)."""
    seen = np.zeros(rank_len, np.bool_)
    for i in range(gstart[-1]):
        seen[chain[i]] = True
    for f in range(L.shape[0]):
        for j in range(3):
            if ok_r[f] and not seen[R[f, j]]:
                return False
            if ok_l[f] and not seen[L[f, j]]:
                return False
    return True


def strip_paths(T: np.ndarray, chain: np.ndarray, gstart: np.ndarray, m: int, L: np.ndarray,
                R: np.ndarray, ok_l: np.ndarray, ok_r: np.ndarray, CG: np.ndarray):
    """:func:`ruledmesh.skew.pq.strips.strip_paths`, the same results; None where it does not apply.

    Parameters
    ----------
    T : (V,) float64
        Vertex parameters (only their count is used).
    chain : (n,) int
        Vertex ids generator by generator; ``gstart`` (m + 1,) the chains' starts.
    m : int
        Generators.
    L, R : (F, 3) int
        Left and right half-faces; ``ok_l``, ``ok_r`` (F,) bool the candidates.
    CG : (F,) int
        Centre generator of each face.

    Returns
    -------
    tuple or None
        ``(keep_l, keep_r, (strip, k0, l0, na, nb), jump_l, jump_r)``; None when a
        candidate half has a vertex on no chain (numpy's result then rests on
        negative indices wrapping: the caller runs numpy).
    """
    c = np.ascontiguousarray
    chain, gstart = c(chain, dtype=np.int64), c(gstart, dtype=np.int64)
    L, R, CG = c(L, dtype=np.int64), c(R, dtype=np.int64), c(CG, dtype=np.int64)
    ok_l, ok_r = c(ok_l, dtype=np.bool_), c(ok_r, dtype=np.bool_)
    if not _all_ranked(len(T), chain, gstart, L, R, ok_l, ok_r):
        return None
    keep_l, keep_r, g_s, k0, l0, na, nb_, jump_l, jump_r = _strip_paths(len(T), chain, gstart, int(m), L, R,
                                                                        ok_l, ok_r, CG)
    return keep_l, keep_r, (g_s, k0, l0, na, nb_), jump_l, jump_r


@nb.njit(cache=True, nogil=True)
def _near_border(gi, ti, m, rel_len, upper, snap_step, snap_gap):
    lo1 = np.full(m, np.inf)
    lo2 = np.full(m, np.inf)
    count = np.zeros(m, np.int64)
    for i in range(gi.shape[0]):
        g = gi[i]
        t = 1.0 - ti[i] if upper else ti[i]
        count[g] += 1
        if t < lo1[g]:
            lo2[g] = lo1[g]
            lo1[g] = t
        elif t < lo2[g]:
            lo2[g] = t
    out = np.zeros(m, np.bool_)
    for g in range(m):
        if count[g] >= 2:
            out[g] = (lo1[g] < snap_step * (lo2[g] - lo1[g])) and (lo1[g] * rel_len[g] < snap_gap)
    return out


def near_border(gi: np.ndarray, ti: np.ndarray, m: int, rel_len: np.ndarray, upper: bool,
                snap_step: float, snap_gap: float) -> np.ndarray | None:
    """:func:`ruledmesh.skew.pq.strips._near_border` without sorting: the two smallest per generator.

    Parameters
    ----------
    gi : (n,) int
        Generator of each vertex inside the patch; ``ti`` (n,) float64 its parameter.
    m : int
    rel_len : (m,) float64
    upper : bool
        Measure from ``t = 1`` instead of ``t = 0``.
    snap_step, snap_gap : float

    Returns
    -------
    (m,) bool, or None where a parameter is NaN (numpy's sort order then decides).
    """
    ti = np.ascontiguousarray(ti, dtype=np.float64)
    if np.isnan(ti).any():
        return None
    return _near_border(np.ascontiguousarray(gi, dtype=np.int64), ti, int(m),
                        np.ascontiguousarray(rel_len, dtype=np.float64), bool(upper), float(snap_step),
                        float(snap_gap))
