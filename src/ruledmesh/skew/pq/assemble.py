"""Assembly of the §4.3 mesh: join the runs, trim to the patch, close the strips.

Every vertex stays on a generator.  Faces wholly on the patch are kept; a face
whose generator diagonal reaches past the border takes the director point of
its generator instead (the point lies on the diagonal, so the face stays in its
plane: a *border quad*); what the faces leave open in each strip is closed by
strip quads where the two generators are coplanar within the planarity
tolerance and carry matched divisions, else by zipper triangles.
"""

from __future__ import annotations

import numpy as np

from ..._arrays import ranks
from ...mesh import FaceKind, Mesh
from ...tolerances import RESTART_ANGLE_DEG, ROUNDING, Tolerances
from .ladders import free_edges, ladder_points
from .runs import Run
from .strips import ON_BORDER, Gaps, chains, strip_paths, zippers

__all__ = ["assemble", "to_mesh"]

# A border quad's crossing must lie at least this share of its generator diagonal from either end.
_MIN_CROSSING = 0.15


def _join(parts: list[Run]):
    """Concatenate the runs; vertices two runs share (same generator, same t) become one."""
    V = np.concatenate([r.vertices for r in parts])
    T = np.concatenate([r.t for r in parts])
    G = np.concatenate([r.gen for r in parts])
    FAR = np.concatenate([r.far for r in parts])
    offs = np.cumsum([0] + [len(r.vertices) for r in parts])
    L = np.concatenate([np.where(r.left >= 0, r.left + o, -1) for r, o in zip(parts, offs)])
    R = np.concatenate([np.where(r.right >= 0, r.right + o, -1) for r, o in zip(parts, offs)])
    POLE = np.concatenate([r.pole for r in parts])
    CG = np.concatenate([r.centre_gen for r in parts])
    order = np.lexsort((T, G))
    same = (G[order][1:] == G[order][:-1]) & (np.abs(T[order][1:] - T[order][:-1]) <= ON_BORDER) \
        & ~FAR[order][1:] & ~FAR[order][:-1]
    if same.any():
        # Runs that meet on a generator share its division (matched, or both
        # reaching a director curve), so parameters equal to rounding mean the
        # same point: keep the first of each group.
        first = np.maximum.accumulate(np.where(np.concatenate([[True], ~same]), np.arange(len(order)), 0))
        remap = np.arange(len(V))
        remap[order] = order[first]
        L = np.where(L >= 0, remap[np.maximum(L, 0)], -1)
        R = np.where(R >= 0, remap[np.maximum(R, 0)], -1)
        dup = np.zeros(len(V), bool)
        dup[order[1:][same]] = True
        FAR = FAR | dup          # never emitted, never in a chain
    return V, T, G, FAR, L, R, POLE, CG


def _crossing_t(V, T, L, R, lo, hi, both):
    """Parameter on its generator where each face's hop diagonal crosses it (nan without both halves)."""
    from ...analysis.faces import quad_diagonal_crossing

    tc = np.full(len(L), np.nan)
    f = np.flatnonzero(both)
    if f.size:
        _, tq, _ = quad_diagonal_crossing(V[np.stack([L[f, 0], lo[f], R[f, 1], hi[f]], axis=1)])
        tc[f] = T[lo[f]] + tq * (T[hi[f]] - T[lo[f]])
    return tc


def _substitute_border(V, T, FAR, L, R, CG, good_v, bottom, top):
    """Faces whose generator diagonal ends beyond the border end at the director point instead.

    The director point of ``g_i`` lies on the face's generator diagonal, hence
    in the face's plane: the face stays planar, and every vertex on a generator.
    """
    has_l, has_r = L[:, 0] >= 0, R[:, 0] >= 0
    lo = np.where(has_r, R[:, 0], L[:, 1])
    hi = np.where(has_r, R[:, 2], L[:, 2])
    side_ok = np.where(has_l, good_v[np.maximum(L[:, 0], 0)], True) \
        & np.where(has_r, good_v[np.maximum(R[:, 1], 0)], True)
    valid = (has_l | has_r) & side_ok & ~FAR[lo] & ~FAR[hi]
    below = valid & ~good_v[lo] & (T[lo] < 0.0) & (good_v[hi] | (T[hi] > 1.0))
    above = valid & ~good_v[hi] & (T[hi] > 1.0) & (good_v[lo] | (T[lo] < 0.0))
    # A whole face only where its crossing stays well inside the shortened
    # diagonal (else it would be a needle or a bow-tie); halves of notches always.
    tc = _crossing_t(V, T, L, R, lo, hi, has_l & has_r & (below | above))
    top_t = np.where(above, 1.0, T[hi])
    bot_t = np.where(below, 0.0, T[lo])
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = (tc - bot_t) / (top_t - bot_t)
        inside = ~(has_l & has_r) | ((frac > _MIN_CROSSING) & (frac < 1 - _MIN_CROSSING))
    below &= inside
    above &= inside
    new_lo = np.where(below, bottom[CG], lo)
    new_hi = np.where(above, top[CG], hi)
    L = L.copy()
    R = R.copy()
    L[:, 1] = np.where(has_l, new_lo, L[:, 1])
    L[:, 2] = np.where(has_l, new_hi, L[:, 2])
    R[:, 0] = np.where(has_r, new_lo, R[:, 0])
    R[:, 2] = np.where(has_r, new_hi, R[:, 2])
    return L, R, below | above


def _strip_quads(V, chain, gstart, gaps: Gaps, ptol: float):
    """Gaps planar within ``ptol`` and evenly matched, and their strip quads.

    Returns
    -------
    use : (n_gaps,) bool
    quads : (q, 4) int64
    """
    from ...analysis.faces import gap_planarity, quad_diagonal_crossing

    even = (gaps.na == gaps.nb) & (gaps.na > 0)
    ge = np.flatnonzero(even)
    n = gaps.na[ge]
    gid = np.repeat(np.arange(len(ge)), n)
    q = ranks(n)
    s = gaps.strip[ge][gid]
    ka = gstart[s] + gaps.k0[ge][gid] + q
    lb = gstart[s + 1] + gaps.l0[ge][gid] + q
    quads = np.stack([chain[ka], chain[ka + 1], chain[lb + 1], chain[lb]], axis=1)
    ok_q = np.zeros(len(quads), bool)
    if len(quads):
        P = V[quads]
        sq, tq, gap = quad_diagonal_crossing(P)
        ok_q = (gap_planarity(P, gap) <= ptol) & (sq > 0.02) & (sq < 0.98) & (tq > 0.02) & (tq < 0.98)
    bad = np.bincount(gid[~ok_q], minlength=len(ge)) if len(ge) else np.zeros(0, np.int64)
    use = np.zeros(len(gaps.strip), bool)
    use[ge[bad == 0]] = True
    strip_quads = quads[np.repeat(bad == 0, n)] if len(quads) else np.zeros((0, 4), np.int64)
    return use, strip_quads


def _zipped(V, T, chain, gstart, gaps: Gaps, use: np.ndarray) -> np.ndarray:
    """Zipper triangles for the gaps that strip quads do not close (``~use``)."""
    z = ~use
    return zippers(V, T, chain, gstart, gaps.strip[z], gaps.k0[z], gaps.l0[z], gaps.na[z],
                   gaps.nb[z])


def _with_ladders(V, T, G, FAR, good_v, chain, gstart, gaps: Gaps, use: np.ndarray, a, d,
                  rows: int):
    """Points on the long generator edges that only fill triangles use (see :mod:`.ladders`).

    Gaps that strip quads close (``use``) keep their divisions (a ladder would unmatch them).
    """
    open_gaps = Gaps(*(x[~use] for x in (gaps.strip, gaps.k0, gaps.l0, gaps.na, gaps.nb)))
    free = free_edges(open_gaps, gstart, len(a))
    n0 = len(V)
    V, T, G, chain, gstart, added = ladder_points(V, T, G, chain, gstart, free, a, d, rows)
    FAR = np.concatenate([FAR, np.zeros(len(V) - n0, bool)])
    good_v = np.concatenate([good_v, np.ones(len(V) - n0, bool)])
    return V, T, G, FAR, good_v, chain, gstart, added


def _notch_fans(chain, gstart, L, R, sel_l, sel_r, CG, jump_l, jump_r) -> np.ndarray:
    """Notch halves whose base passes over vertices of another run, as fans of triangles.

    The points passed over lie on the half's base (the generator), so the fan
    from its apex covers exactly the half and the strips stay conforming.
    """
    if chain is None or not (sel_l.any() or sel_r.any()):
        return np.zeros((0, 3), np.int64)
    rank_of = np.full(int(chain.max()) + 1, -1, np.int64)
    rank_of[chain] = np.arange(len(chain)) - np.repeat(gstart[:-1], np.diff(gstart))
    out = []
    for half, sel, jump, apex_col, lo_col in ((L, sel_l, jump_l, 0, 1), (R, sel_r, jump_r, 1, 0)):
        f = np.flatnonzero(sel)
        n = jump[f]
        fid = np.repeat(f, n)
        q = ranks(n)
        lo = gstart[CG[fid]] + rank_of[half[fid, lo_col]] + q
        apex = half[fid, apex_col]
        # Left halves run apex, lo, hi; right halves lo, apex, hi (the same orientation).
        tri = np.stack([apex, chain[lo], chain[lo + 1]], axis=1) if apex_col == 0 else \
            np.stack([chain[lo], apex, chain[lo + 1]], axis=1)
        out.append(tri)
    return np.concatenate(out)


def assemble(parts: list[Run], a, d, trim: bool, tol: Tolerances, ptol: float,
             warnings: list[str], scale: float, meet: np.ndarray | None = None,
             rows: int = 20) -> Mesh:
    """Join the runs; keep convex quads and valid halves; close the strips; add members.

    ``parts`` is emptied once the runs are joined, so their arrays are freed before the
    faces are made (a 1000 x 1000 build peaks 47 MB lower)."""
    m = len(a)
    if not parts:
        parts = [Run(np.zeros((0, 3)), np.zeros(0), np.zeros(0, np.int64), np.zeros(0, bool),
                     np.zeros((0, 3), np.int64), np.zeros((0, 3), np.int64), np.zeros(0, bool),
                     np.zeros(0, np.int64), np.zeros(m, np.int64), np.zeros(m, np.int64))]
    V, T, G, FAR, L, R, POLE, CG = _join(parts)
    parts.clear()
    # A vertex within rounding of the border counts as on it, so the decisions do
    # not flip when the design is scaled or moved (t is scale-free up to rounding).
    lo_t, hi_t = (-ON_BORDER, 1.0 + ON_BORDER) if trim else (-np.inf, np.inf)
    good_v = ~FAR & (lo_t <= T) & (hi_t >= T)
    strip_quads = np.zeros((0, 4), np.int64)
    substituted = np.zeros(len(L), bool)
    if trim:
        n0 = len(V)
        V, T, G, chain, gstart = chains(V, T, G, good_v, a, d, m, scale)
        FAR = np.concatenate([FAR, np.zeros(len(V) - n0, bool)])
        good_v = np.concatenate([good_v, np.ones(len(V) - n0, bool)])
        L, R, substituted = _substitute_border(V, T, FAR, L, R, CG, good_v, chain[gstart[:-1]],
                                               chain[gstart[1:] - 1])
    cand_l = (L[:, 0] >= 0) & ~POLE & good_v[np.maximum(L, 0)].all(axis=1)
    cand_r = (R[:, 0] >= 0) & ~POLE & good_v[np.maximum(R, 0)].all(axis=1)
    if trim:
        ok_l, ok_r, gaps, jump_l, jump_r = strip_paths(T, chain, gstart, m, L, R, cand_l, cand_r, CG)
        use, strip_quads = _strip_quads(V, chain, gstart, gaps, ptol)
        V, T, G, FAR, good_v, chain, gstart, added = _with_ladders(
            V, T, G, FAR, good_v, chain, gstart, gaps, use, a, d, rows)
        if added:
            # The ladders renumber the chains: the gaps (and their strip quads) anew.
            ok_l, ok_r, gaps, jump_l, jump_r = strip_paths(T, chain, gstart, m, L, R, cand_l,
                                                           cand_r, CG)
            use, strip_quads = _strip_quads(V, chain, gstart, gaps, ptol)
        fill = _zipped(V, T, chain, gstart, gaps, use)
    else:
        chain = gstart = None
        jump_l = np.ones(len(L), np.int64)
        jump_r = np.ones(len(R), np.int64)
        # Untrimmed: rows must still increase along each generator inside a face.
        ok_l = cand_l & (T[np.maximum(L[:, 2], 0)] > T[np.maximum(L[:, 1], 0)])
        ok_r = cand_r & (T[np.maximum(R[:, 2], 0)] > T[np.maximum(R[:, 0], 0)])
        fill = np.zeros((0, 3), np.int64)
    both = ok_l & ok_r
    quads = np.stack([L[both, 0], L[both, 1], R[both, 1], L[both, 2]], axis=1)
    convex, nsplit = _whole(V, quads, tol)
    whole = np.zeros(len(L), bool)
    whole[np.flatnonzero(both)[convex]] = True
    interior = (L[:, 0] >= 0) & (R[:, 0] >= 0)
    kind_half = np.where(interior, np.where(both, FaceKind.SPLIT, FaceKind.BORDER),
                         FaceKind.FILL).astype(np.uint8)
    half_l, half_r = ok_l & ~whole & (jump_l == 1), ok_r & ~whole & (jump_r == 1)
    fans = _notch_fans(chain, gstart, L, R, ok_l & (jump_l > 1), ok_r & (jump_r > 1), CG,
                       jump_l, jump_r)
    quad_kind = np.where(substituted[np.flatnonzero(both)[convex]], FaceKind.BORDER, FaceKind.QUAD)
    faces = [quads[convex], strip_quads, np.concatenate([L[half_l], R[half_r], fill, fans])]
    kinds = [quad_kind.astype(np.uint8), np.full(len(strip_quads), FaceKind.STRIP, np.uint8),
             np.concatenate([kind_half[half_l], kind_half[half_r],
                             np.full(len(fill) + len(fans), FaceKind.FILL, np.uint8)])]
    if nsplit:
        warnings.append(f"{nsplit} quads were not convex (the two chains of §4.3 drifted apart) "
                        "and were kept as two triangles split along their generator diagonal; "
                        "sample the generators more finely there")
    dropped = int(np.count_nonzero(cand_l & ~ok_l) + np.count_nonzero(cand_r & ~ok_r))
    if dropped:
        warnings.append(f"{dropped} half-faces ran against the order of their strip (rows reversing "
                        "or overlapping) and were replaced by fill triangles")
    # The faces hold what they need of these: freed before the mesh is made, where a large
    # build's memory peaks (1000 x 1000: 48 MB less).
    del L, R, quads
    return to_mesh(V, T, G, faces, kinds, warnings, chain, gstart, scale, meet)


def _whole(V: np.ndarray, quads: np.ndarray, tol: Tolerances) -> tuple[np.ndarray, int]:
    """(n,) bool: the quads ``quads`` (n, 4) kept whole, and how many are bow-ties.

    A bow-tie's diagonals do not cross inside both; it is kept as its two halves, and so
    is a quad with a splinter's corner: the flips and collapses may fatten triangles
    (with their fill neighbours), never a quad.
    """
    from ...analysis.faces import polygon_angles, quad_diagonal_crossing

    Q = V[quads]
    sq, tq, _ = quad_diagonal_crossing(Q)
    eps = tol.convexity
    convex = (sq > eps) & (sq < 1 - eps) & (tq > eps) & (tq < 1 - eps)
    sliver = convex & (polygon_angles(Q).min(axis=1) < RESTART_ANGLE_DEG)
    return convex & ~sliver, int(np.count_nonzero(~convex))


def _first_of_equal_rows(key: np.ndarray) -> np.ndarray:
    """(n,) int: for each row of ``key`` (n, k) int, the first row equal to it.

    ``first[inverse]`` of ``np.unique(key, axis=0, return_index=True,
    return_inverse=True)``, by one stable lexicographic sort (np.unique sorts
    rows as structured values, several times slower on the few rows of a build).
    """
    n = len(key)
    order = np.lexsort(key.T[::-1])
    ks = key[order]
    start = np.ones(n, bool)
    start[1:] = (ks[1:] != ks[:-1]).any(axis=1)
    # Stable: the first of each group of equal rows has the smallest index.
    lead = order[np.maximum.accumulate(np.where(start, np.arange(n), 0))]
    out = np.empty(n, np.int64)
    out[order] = lead
    return out


def _one_sense(faces: list[np.ndarray], T: np.ndarray, G: np.ndarray) -> list[np.ndarray]:
    """The face arrays with every face turning the way the first non-empty one's faces do
    in the (generator, t) plane.

    The surface is an immersion of that plane, so one sense there is one orientation of
    the mesh; the strip quads and the fill between runs are laid out by their strips,
    not by the runs' rows, and came out turned the other way where the rows run down
    the generators (their normals flipped against their neighbours').
    """
    signed = []
    for f in faces:
        g, t = G[f].astype(np.float64), T[f]
        signed.append((g * np.roll(t, -1, axis=1) - np.roll(g, -1, axis=1) * t).sum(axis=1))
    ref = next((np.sign(s[s != 0].sum()) for s in signed if np.any(s != 0)), 0.0)
    if ref == 0.0:
        return faces
    # Reversed from the same first corner: (a, b, c, d) -> (a, d, c, b).
    return [np.where((s * ref < 0)[:, None], np.roll(f[:, ::-1], 1, axis=1), f) if f.size else f
            for f, s in zip(faces, signed, strict=True)]


def to_mesh(V, T, G, faces, kinds, warnings, chain, gstart, scale, meet=None) -> Mesh:
    """Mesh from fixed-valence face arrays; members along the generators.

    ``meet`` (m,) bool marks generators that meet a neighbour (a coplanar pair):
    their vertices may coincide with the neighbour's and are merged with them.
    """
    faces = _one_sense(faces, T, G)
    starts = [np.zeros(1, np.int64)]
    total = 0
    for f in faces:
        starts.append(np.arange(1, len(f) + 1, dtype=np.int64) * f.shape[1] + total)
        total += f.size
    off = np.concatenate(starts)
    idx = np.concatenate([f.reshape(-1) for f in faces]).astype(np.int64)
    kind = np.concatenate(kinds).astype(np.uint8)
    # Generators that share an end point (a torsal pair meeting on a director
    # curve) give coincident points at t = 0 or 1, and generators that meet
    # inside the patch (a cone's apex) coincident points there: merge those,
    # nothing else; faces that collapse go.
    used0 = np.zeros(len(V), bool)
    used0[idx] = True
    near = (T <= ON_BORDER) | (T >= 1 - ON_BORDER)
    if meet is not None and np.any(meet):
        near |= np.asarray(meet)[np.clip(G, 0, len(meet) - 1)] & (G >= 0)
    ends = np.flatnonzero(used0 & near)
    if len(ends) > 1:
        key = np.round(V[ends] / (ROUNDING * scale)).astype(np.int64)
        group_first = _first_of_equal_rows(key)
        if (group_first != np.arange(len(ends))).any():
            remap = np.arange(len(V))
            remap[ends] = ends[group_first]
            idx = remap[idx]
            if chain is not None:
                chain = remap[chain]
    used = np.zeros(len(V), bool)
    used[idx] = True
    if chain is not None:
        # Members: consecutive chain vertices of a generator, both used by faces.
        gch = np.repeat(np.arange(len(gstart) - 1), np.diff(gstart))
        pair = (gch[1:] == gch[:-1]) & used[chain[1:]] & used[chain[:-1]] & (chain[1:] != chain[:-1])
        members = np.stack([chain[:-1][pair], chain[1:][pair]], axis=1)
        member_id = gch[:-1][pair]
    else:
        ids = np.flatnonzero(used & (G >= 0))
        order = ids[np.lexsort((T[ids], G[ids]))]
        same = G[order[1:]] == G[order[:-1]]
        members = np.stack([order[:-1][same], order[1:][same]], axis=1)
        member_id = G[order[:-1][same]]
    # Renumber to the used vertices only.
    new = np.cumsum(used) - 1
    mesh = Mesh(V[used], off, new[idx], kind, new[members].astype(np.int64),
                member_id.astype(np.int64), {"t": T[used], "generator": G[used]},
                {"construction": "pq (paper §4.3)", "warnings": warnings})
    return mesh.drop_repeated_corners()


