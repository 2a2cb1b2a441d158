"""Strips between consecutive generators: each one conforming zipper (paper §4.3 borders).

In strip s (between g_s and g_s+1) the vertices of each generator inside the
patch, plus the director points at t = 0 and t = 1, form two chains sorted by
t.  A triangulation of the strip is a monotone lattice path through
(rank on g_s, rank on g_s+1); each PQ half-face is one step of it.  Steps that
do not fit a monotone path are dropped; the gaps are closed by zipper steps, or,
between two generators that are (nearly) coplanar and carry matched divisions,
by the planar strip quads of §3.1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._arrays import ranks
from ...kernels import wanted
from ...tolerances import ON_BORDER, SNAP_GAP, TINY

__all__ = ["ON_BORDER", "Gaps", "chains", "group_starts", "strip_paths", "zippers"]

# A vertex nearer a director curve than this share of the step to the next
# vertex on its generator is taken as the border point of its generator.
SNAP_STEP = 0.06
# ... and the border it makes stays SNAP_GAP (tolerances) close to the director curve.


def group_starts(keys: np.ndarray) -> np.ndarray:
    """(n,) bool: first element of each run of equal sorted keys."""
    return np.r_[True, keys[1:] != keys[:-1]] if keys.size else np.zeros(0, bool)


def _near_border(gi: np.ndarray, ti: np.ndarray, m: int, rel_len: np.ndarray,
                 upper: bool) -> np.ndarray:
    """(m,) bool: the generator's vertex nearest a director curve is within ``SNAP_STEP`` of
    the step to the next vertex along the generator, and within ``SNAP_GAP`` of the
    diagonal (``rel_len``: generator lengths over the diagonal) of the curve."""
    kern = wanted(len(gi), "strips")
    done = kern.near_border(gi, ti, m, rel_len, upper, SNAP_STEP, SNAP_GAP) if kern is not None else None
    if done is not None:
        return done
    t = 1.0 - ti if upper else ti
    order = np.lexsort((t, gi))
    g, t = gi[order], t[order]
    first = group_starts(g)
    out = np.zeros(m, bool)
    idx = np.flatnonzero(first)
    nxt = idx + 1
    ok = (nxt < len(g)) & (g[np.minimum(nxt, len(g) - 1)] == g[idx])
    idx, nxt = idx[ok], nxt[ok]
    near = (t[idx] < SNAP_STEP * (t[nxt] - t[idx])) & (t[idx] * rel_len[g[idx]] < SNAP_GAP)
    out[g[idx][near]] = True
    return out


def chains(V, T, G, good_v, a, d, m, scale):
    """Each generator's vertices inside the patch, with director points, sorted by t.

    Returns
    -------
    V, T, G : arrays with the director points appended
    chain : (n,) int64
        Vertex ids, generator by generator, increasing t.
    gstart : (m + 1,) int64
        Start of each generator's chain in ``chain``.
    """
    eps = ON_BORDER
    inside = np.flatnonzero(good_v)
    gi, ti = G[inside], T[inside]
    has0 = np.zeros(m, bool)
    has1 = np.zeros(m, bool)
    has0[gi[ti <= eps]] = True
    has1[gi[ti >= 1 - eps]] = True
    # A vertex this close to the director curve, against the step to the next
    # vertex on its generator, is the border point of its generator itself: a
    # director point beside it would leave a splinter.  (Parameters along a
    # generator: the decision commutes with affine maps.)
    glen = np.linalg.norm(d, axis=1)
    has0 |= _near_border(gi, ti, m, glen / scale, upper=False)
    has1 |= _near_border(gi, ti, m, glen / scale, upper=True)
    new0, new1 = np.flatnonzero(~has0), np.flatnonzero(~has1)
    base = len(V)
    V = np.concatenate([V, a[new0], a[new1] + d[new1]])
    T = np.concatenate([T, np.zeros(len(new0)), np.ones(len(new1))])
    G = np.concatenate([G, new0, new1])
    # Grid vertices are stored generator by generator in row order; when t grows
    # with the row on every generator (the usual case) that order is the chain.
    same = gi[1:] == gi[:-1]
    if np.all(gi[1:] >= gi[:-1]) and np.all(ti[1:][same] > ti[:-1][same]):
        counts = np.bincount(gi, minlength=m)
        first = np.cumsum(counts) - counts
        need0, need1 = (~has0).astype(np.int64), (~has1).astype(np.int64)
        clen = counts + need0 + need1
        gstart = np.zeros(m + 1, np.int64)
        np.cumsum(clen, out=gstart[1:])
        chain = np.empty(int(gstart[-1]), np.int64)
        chain[gstart[:-1][gi] + need0[gi] + np.arange(len(inside)) - first[gi]] = inside
        chain[gstart[new0]] = base + np.arange(len(new0))
        chain[gstart[new1 + 1] - 1] = base + len(new0) + np.arange(len(new1))
    else:
        ids = np.concatenate([inside, base + np.arange(len(new0) + len(new1))])
        chain = ids[np.lexsort((T[ids], G[ids]))]
        gstart = np.searchsorted(G[chain], np.arange(m + 1))
    return V, T, G, chain, gstart


@dataclass(frozen=True)
class Gaps:
    """Stretches of strips that no PQ half-face covers, to be closed.

    Gap ``g`` runs in strip ``strip[g]`` from rank ``k0`` on the lower
    generator and ``l0`` on the upper one, ``na`` and ``nb`` steps along them.
    """

    strip: np.ndarray
    k0: np.ndarray
    l0: np.ndarray
    na: np.ndarray
    nb: np.ndarray


def strip_paths(T, chain, gstart, m, L, R, ok_l, ok_r, CG):
    """Make every strip between consecutive generators one conforming zipper.

    In strip s (between g_s and g_s+1) the vertices of each generator inside the
    patch, plus the director points at t = 0 and t = 1, form two chains sorted
    by t.  A triangulation of the strip is a monotone lattice path through
    (rank on g_s, rank on g_s+1); each PQ half-face is one step of it.  Steps
    that do not fit a monotone path are dropped, and every gap between the kept
    runs (and from the director curves to them) is filled by zipper steps.
    """
    kern = wanted(len(L), "strips")
    done = kern.strip_paths(T, chain, gstart, m, L, R, ok_l, ok_r, CG) if kern is not None else None
    if done is not None:
        # The same decisions in one pass per stage (ruledmesh.kernels.strips).
        keep_l, keep_r, gaps, jump_l, jump_r = done
        return keep_l, keep_r, Gaps(*gaps), jump_l, jump_r
    V_len = len(T)
    rank = np.full(V_len, -1, np.int64)
    rank[chain] = np.arange(len(chain)) - np.repeat(gstart[:-1], np.diff(gstart))
    clen = np.diff(gstart)                       # chain length per generator (>= 2)
    # Steps: right halves [A_k, B_l, A_k+1] in strip CG; left halves [A_k, B_l, B_l+1] in CG-1.
    ir = np.flatnonzero(ok_r)
    il = np.flatnonzero(ok_l)
    rk = rank[R[ir]]
    lk = rank[L[il]]
    # A half-face's base is two consecutive vertices of its generator; a half
    # without a partner (a notch where a run ends) may pass over vertices of the
    # run on the other side of the generator: they lie on its base, so it becomes
    # a planar polygon with those points on one edge, and the strips stay conforming.
    jr, jl = rk[:, 2] - rk[:, 0], lk[:, 2] - lk[:, 1]
    gr = (jr == 1) | ((jr > 1) & (L[ir, 0] < 0))
    gl = (jl == 1) | ((jl > 1) & (R[il, 0] < 0))
    ir, il, rk, lk, jr, jl = ir[gr], il[gl], rk[gr], lk[gl], jr[gr], jl[gl]
    st_strip = np.concatenate([CG[ir], CG[il] - 1])
    st_k = np.concatenate([rk[:, 0], lk[:, 0]])
    st_l = np.concatenate([rk[:, 1], lk[:, 1]])
    st_a = np.concatenate([np.ones(len(ir), bool), np.zeros(len(il), bool)])
    st_n = np.concatenate([jr, jl])
    st_id = np.concatenate([ir, il])
    # Order steps along each strip's path by scattering them to their path
    # position (one slot per position; a second step claiming a slot overlaps).
    nstrip = m - 1
    plen = clen[:-1] + clen[1:] - 2                # steps in a full path of each strip
    pstart = np.zeros(nstrip + 1, np.int64)
    np.cumsum(plen, out=pstart[1:])
    slot = np.full(int(pstart[-1]), -1, np.int64)
    slot[pstart[st_strip] + st_k + st_l] = np.arange(len(st_id))
    order = slot[slot >= 0]
    st_strip, st_k, st_l, st_a, st_n, st_id = (
        x[order] for x in (st_strip, st_k, st_l, st_a, st_n, st_id))
    end_k = st_k + st_a * st_n
    end_l = st_l + ~st_a * st_n
    # Keep a step only if it starts at or beyond where every earlier step of its
    # strip ended (a monotone path); counting dropped steps too is conservative.
    big = np.int64(1) << 40
    prev_k = np.maximum.accumulate(st_strip * big + end_k) - st_strip * big
    prev_l = np.maximum.accumulate(st_strip * big + end_l) - st_strip * big
    first = group_starts(st_strip)
    pk = np.where(first, -1, np.r_[-1, prev_k[:-1]])
    pl = np.where(first, -1, np.r_[-1, prev_l[:-1]])
    keep = (st_k >= pk) & (st_l >= pl)
    st_strip, st_k, st_l, st_a, st_n, st_id, end_k, end_l = (
        x[keep] for x in (st_strip, st_k, st_l, st_a, st_n, st_id, end_k, end_l))
    keep_r = np.zeros(len(R), bool)
    keep_l = np.zeros(len(L), bool)
    keep_r[st_id[st_a]] = True
    keep_l[st_id[~st_a]] = True
    jump_r = np.ones(len(R), np.int64)
    jump_l = np.ones(len(L), np.int64)
    jump_r[st_id[st_a]] = st_n[st_a]
    jump_l[st_id[~st_a]] = st_n[~st_a]
    # Gaps, in one sweep: before the first step of a strip, between two steps that
    # do not meet, after the last step, and whole strips without steps.
    first = group_starts(st_strip)
    last = np.r_[first[1:], True] if len(first) else first
    between = ~first
    between[1:] &= (end_k[:-1] != st_k[1:]) | (end_l[:-1] != st_l[1:])
    btw = np.flatnonzero(between)
    fst = np.flatnonzero(first)
    lst = np.flatnonzero(last)
    # The strips without steps, in order (np.setdiff1d's result, without its sorts).
    no_step = np.ones(nstrip, bool)
    no_step[st_strip] = False
    empty = np.flatnonzero(no_step)
    g_strip = np.concatenate([st_strip[fst], st_strip[btw], st_strip[lst], empty])
    g_k0 = np.concatenate([np.zeros(len(fst), np.int64), end_k[btw - 1], end_k[lst],
                           np.zeros(len(empty), np.int64)])
    g_l0 = np.concatenate([np.zeros(len(fst), np.int64), end_l[btw - 1], end_l[lst],
                           np.zeros(len(empty), np.int64)])
    g_k1 = np.concatenate([st_k[fst], st_k[btw], clen[st_strip[lst]] - 1, clen[empty] - 1])
    g_l1 = np.concatenate([st_l[fst], st_l[btw], clen[st_strip[lst] + 1] - 1, clen[empty + 1] - 1])
    na = np.maximum(g_k1 - g_k0, 0)
    nb = np.maximum(g_l1 - g_l0, 0)
    return keep_l, keep_r, Gaps(g_strip, g_k0, g_l0, na, nb), jump_l, jump_r


def zippers(V, T, chain, gstart, strip, k0, l0, na, nb) -> np.ndarray:
    """Zipper triangles of many gaps at once.

    Gap g runs from (k0, l0) to (k0 + na, l0 + nb) in strip ``strip[g]``;
    chain A is generator ``strip``, chain B is ``strip + 1``.  The two chains
    are merged in the order of their points along generator A (chain B's
    points projected onto it), so each triangle joins points that lie side by
    side, whatever the parametrisation of the two generators.
    """
    ng = len(strip)
    if ng == 0 or (na.sum() + nb.sum()) == 0:
        return np.zeros((0, 3), np.int64)
    gid_a = np.repeat(np.arange(ng), na)
    gid_b = np.repeat(np.arange(ng), nb)
    ka = ranks(na)   # 0..na-1 within the gap
    lb = ranks(nb)
    A = lambda g, k: chain[gstart[strip[g]] + k]
    B = lambda g, l: chain[gstart[strip[g] + 1] + l]
    key_a = T[A(gid_a, k0[gid_a] + ka + 1)]
    # Generator A through its first and last chain points (t = 0 and 1 of the patch, or the
    # ends of the trimmed chain: the line is the same).
    s_b = strip[gid_b]
    p0 = V[chain[gstart[s_b]]]
    p1 = V[chain[gstart[s_b + 1] - 1]]
    t0, t1 = T[chain[gstart[s_b]]], T[chain[gstart[s_b + 1] - 1]]
    dir_ = p1 - p0
    pb = V[B(gid_b, l0[gid_b] + lb + 1)]
    w = np.einsum("ij,ij->i", pb - p0, dir_) / np.maximum(np.einsum("ij,ij->i", dir_, dir_), TINY)
    key_b = t0 + w * (t1 - t0)
    gid = np.concatenate([gid_a, gid_b])
    is_a = np.concatenate([np.ones(gid_a.size, bool), np.zeros(gid_b.size, bool)])
    key = np.concatenate([key_a, key_b])
    order = np.lexsort((key, gid))
    gid, is_a = gid[order], is_a[order]
    # Position before each step: gap start plus the steps of each kind already taken.
    first = group_starts(gid)
    ca = np.cumsum(is_a) - is_a
    cb = np.cumsum(~is_a) - ~is_a
    start_idx = np.flatnonzero(first)
    run = np.cumsum(first) - 1
    ca = ca - ca[start_idx][run]
    cb = cb - cb[start_idx][run]
    k = k0[gid] + ca
    l = l0[gid] + cb
    a_k, b_l = A(gid, k), B(gid, l)
    # Evaluate each branch only where it applies (the other index may be past the chain end).
    third = np.where(is_a, A(gid, np.where(is_a, k + 1, k)), B(gid, np.where(is_a, l, l + 1)))
    return np.stack([a_k, b_l, third], axis=1)
