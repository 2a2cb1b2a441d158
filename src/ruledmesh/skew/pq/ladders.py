"""Ladders: points on generator edges that only triangles use, so the fill is well shaped.

Where the rows of §4.3 leave a stretch of a strip open (bands at torsal
generators, between runs, at the border), the gap is closed by triangles with
their corners on the two generators.  A long stretch of generator with no
vertex on it makes every triangle that spans it a splinter: its height is the
strip width, its length the stretch.  Where the faces on *both* sides of such
a generator edge are fill (the edge is free: no quad or half-face has it), the
edge can take more points of the generator, every vertex staying on a
generator and no face gaining a corner in the middle of an edge.  The points
are spaced so that a triangle of the ladder is no longer than about
``_ASPECT`` strip widths and no shorter than a share of the row step, which
bounds its smallest angle without flooding narrow strips with tiny panels.
"""

from __future__ import annotations

import numpy as np

from ..._arrays import ranks
from ...tolerances import TINY
from .strips import Gaps

__all__ = ["free_edges", "ladder_points"]

# A ladder triangle is at most this many strip widths long ...
_ASPECT = 16.0
# ... and its points are at least this share of the row step apart.
_MIN_STEP = 0.25
# An edge is divided only where it is this much longer than the target step.
_SLACK = 1.5
# At most this many points on one edge (bounds the work on degenerate strips).
_MAX_POINTS = 64
_RELAX = 4


def _covered(gaps: Gaps, gstart: np.ndarray, lower: bool) -> np.ndarray:
    """(n_chain,) int: edges (chain position of their first vertex) inside a gap on one side."""
    n = int(gstart[-1])
    cnt = np.zeros(n + 1, np.int64)
    steps = gaps.na if lower else gaps.nb
    first = gaps.k0 if lower else gaps.l0
    gen = gaps.strip if lower else gaps.strip + 1
    s = gstart[gen] + first
    np.add.at(cnt, s, 1)
    np.add.at(cnt, s + steps, -1)
    return np.cumsum(cnt)[:n] > 0


def free_edges(gaps: Gaps, gstart: np.ndarray, m: int) -> np.ndarray:
    """(n_chain,) bool: chain edges whose faces on both sides are fill (or beyond the patch).

    Edge ``j`` runs from ``chain[j]`` to ``chain[j + 1]`` (same generator).
    """
    n = int(gstart[-1])
    gch = np.repeat(np.arange(m), np.diff(gstart))
    above = _covered(gaps, gstart, lower=True)     # strip g (g is its lower generator)
    below = _covered(gaps, gstart, lower=False)    # strip g - 1 (g is its upper generator)
    above |= gch == m - 1
    below |= gch == 0
    last = np.zeros(n, bool)
    last[gstart[1:] - 1] = True
    return above & below & ~last


def ladder_points(V, T, G, chain, gstart, free, a, d, rows: int):
    """New vertices on the long free edges, and the chain with them in place.

    Returns
    -------
    V, T, G : arrays with the new points appended
    chain, gstart : the chains with the new points in t order
    added : int
    """
    m = len(a)
    j = np.flatnonzero(free)
    if j.size == 0 or m < 2:
        return V, T, G, chain, gstart, 0
    g = G[chain[j]]
    t0, t1 = T[chain[j]], T[chain[j + 1]]
    glen = np.linalg.norm(d, axis=1)
    mid = a[g] + 0.5 * (t0 + t1)[:, None] * d[g]
    # Strip width at the edge: distance to the neighbouring generator lines (the nearer);
    # and where the neighbour's edge facing it is not free, its length: points here would
    # only fan out towards that one long edge.
    keys = G[chain] * 4.0 + np.clip(T[chain], 0.0, 1.0)
    n_chain = len(chain)
    all_len = np.zeros(n_chain)
    all_len[:-1] = (T[chain[1:]] - T[chain[:-1]]) * glen[G[chain[:-1]]]
    step = glen[g] / max(rows, 1)
    width = np.full(j.size, np.inf)
    wide = np.zeros(j.size)
    facing = []
    for nb in (g - 1, g + 1):
        ok = (nb >= 0) & (nb < m)
        q = np.clip(nb, 0, m - 1)
        u = d[q] / np.maximum(glen[q], TINY)[:, None]
        r = mid - a[q]
        along = np.einsum("ij,ij->i", r, u)
        dist = np.linalg.norm(r - along[:, None] * u, axis=1)
        width = np.where(ok, np.minimum(width, dist), width)
        wide = np.where(ok, np.maximum(wide, dist), wide)
        tq = np.clip(along / np.maximum(glen[q], TINY), 0.0, 1.0)
        pos = np.clip(np.searchsorted(keys, q * 4.0 + tq, side="right") - 1, gstart[q],
                      gstart[q + 1] - 2)
        facing.append(np.where(ok, pos, -1))
    # Points closer than a share of the wider strip make slivers there (a short
    # base under a long apex), however narrow the other strip is.
    base_target = np.maximum(np.clip(_ASPECT * width, _MIN_STEP * step, step), wide / _ASPECT)
    length = (t1 - t0) * glen[g]
    # The edges facing this one across each strip: points here are worth their cost only
    # where the facing edge gets (or has) points as close, else they fan out towards it.
    # Relaxed a few times: targets only grow, so the divisions settle.
    spacing = all_len.copy()
    n_new = np.zeros(j.size, np.int64)
    for _ in range(_RELAX):
        target = base_target
        for pos in facing:
            target = np.where(pos >= 0, np.maximum(target, 0.5 * spacing[np.maximum(pos, 0)]),
                              target)
        n_new = np.where(length > _SLACK * target, np.ceil(length / target) - 1, 0)
        n_new = np.minimum(n_new, _MAX_POINTS).astype(np.int64)
        spacing[j] = length / (n_new + 1)
    if n_new.sum() == 0:
        return V, T, G, chain, gstart, 0
    e = np.repeat(np.arange(j.size), n_new)
    k = ranks(n_new) + 1
    tn = t0[e] + (t1[e] - t0[e]) * k / (n_new[e] + 1)
    gn = g[e]
    base = len(V)
    V = np.concatenate([V, a[gn] + tn[:, None] * d[gn]])
    T = np.concatenate([T, tn])
    G = np.concatenate([G, gn])
    new_ids = base + np.arange(e.size)
    # Insert after the edge's first vertex: chain order is generator, then t.
    pos = np.repeat(j + 1, n_new)
    chain = np.insert(chain, pos, new_ids)
    gstart = gstart + np.concatenate([[0], np.cumsum(np.bincount(gn, minlength=m))])
    return V, T, G, chain, gstart, int(e.size)
