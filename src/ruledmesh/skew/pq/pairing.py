"""Tolerance mode: pairs of triangles that make a quad planar within the tolerance.

Exact quads of §4.3 need a line meeting three consecutive generators; where the
rows cannot supply one (torsal bands, nearly developable stretches, the border
band between the last row and a director curve) the mesher leaves triangles.
With ``[mesh] planarity_tolerance`` the user accepts panels planar within a
stated relative tolerance, so two triangles sharing an edge become one quad
when that quad is planar within it (the paper's measure: distance between the
diagonal lines over the mean diagonal), convex with its diagonals crossing well
inside both, and no thinner than the thinner of the two triangles.

Pairs are chosen by rounds of mutual best choice (each triangle names its best
partner; pairs that name each other are taken), which is greedy matching in
whole-array steps: no loop over faces.
"""

from __future__ import annotations

import numpy as np

from ..._arrays import member, ranks, unique
from ...mesh import FaceKind, Mesh

__all__ = ["adjacent_triangles", "pair_triangles"]

# A paired quad's diagonals must cross at least this share of each diagonal from its ends.
_MIN_CROSSING = 0.05
_ROUNDS = 6


def adjacent_triangles(tri: np.ndarray, n: int):
    """Triangles sharing a manifold edge, consistently oriented.

    Parameters
    ----------
    tri : (T, 3) int
        Triangles as vertex indices below ``n``.
    n : int
        Number of vertices.

    Returns
    -------
    t1, t2, a, b, c, d : (P,) int
        Rows of the two triangles, ``t1 = (b, c, a)`` and ``t2 = (c, b, d)``:
        ``b c`` is the shared edge, ``a`` and ``d`` the corners opposite it.
    """
    return _adjacent(tri, n)[:6]


def _adjacent(tri: np.ndarray, n: int):
    """:func:`adjacent_triangles`, and the (3T,) sorted edge keys ``lo * (n + 1) + hi`` (repeats kept)."""
    e_from = tri.reshape(-1)
    e_to = np.roll(tri, -1, axis=1).reshape(-1)
    key = np.minimum(e_from, e_to) * (n + 1) + np.maximum(e_from, e_to)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    pair = np.flatnonzero(ks[1:] == ks[:-1])
    # An edge used by more than two triangles is not a manifold edge: never pair across it.
    if len(pair) > 1:
        pair = pair[np.r_[True, pair[1:] != pair[:-1] + 1] & np.r_[pair[:-1] + 1 != pair[1:], True]]
    s1, s2 = order[pair], order[pair + 1]
    ok = (s1 // 3 != s2 // 3) & (e_from[s1] == e_to[s2])      # opposite orientation: consistent sides
    s1, s2 = s1[ok], s2[ok]
    t1, j1, t2, j2 = s1 // 3, s1 % 3, s2 // 3, s2 % 3
    return (t1, t2, tri[t1, (j1 + 2) % 3], tri[t1, j1], tri[t1, (j1 + 1) % 3],
            tri[t2, (j2 + 2) % 3], ks)


def _corners(tri: np.ndarray, n: int) -> np.ndarray:
    """(n,) bool: the vertices that are corners of the triangles ``tri`` (T, 3)."""
    out = np.zeros(n, bool)
    out[tri.reshape(-1)] = True
    return out


def _at(tri: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """(T,) bool: the triangles ``tri`` with a corner marked in ``vertices`` (n,) bool."""
    return vertices[tri[:, 0]] | vertices[tri[:, 1]] | vertices[tri[:, 2]]


def _around(tri: np.ndarray, n: int, mark: np.ndarray, times: int) -> np.ndarray:
    """(T,) bool: ``mark`` and the triangles ``times`` corner-sharing steps from a marked one.

    A triangle sharing an edge with another shares a corner with it, so this
    holds every triangle ``times`` edge-sharing steps away (and some more).
    """
    for _ in range(times):
        mark = _at(tri, _corners(tri[mark], n))
    return mark


def pair_triangles(mesh: Mesh, ptol: float, kinds: tuple[int, ...] | None = None, *,
                   near: np.ndarray | None = None, report: dict | None = None) -> tuple[Mesh, int]:
    """Merge pairs of triangles into quads planar within ``ptol``.

    Parameters
    ----------
    mesh : Mesh
    ptol : float
        Relative planarity tolerance (distance between the diagonal lines over
        the mean diagonal length).
    kinds : tuple of int, optional
        Face kinds whose triangles may be paired (default: fill, border and
        split halves).
    near : (V,) bool, optional
        Only the triangles two corner-sharing steps or fewer from a triangle with a
        corner here take part: a run after a local change to a mesh whose pairing had
        settled (no pair was left that both triangles could take), which finds the
        pairs a run over the whole mesh would.
    report : dict, optional
        Filled with ``"settled"`` (bool: every pair that passes was taken or lost a
        triangle to another, rather than the rounds running out), ``"touched"``
        ((V,) bool: the corners of the quads made) and ``"again"`` (none: a pair
        made leaves the other triangles as they were).

    Returns
    -------
    Mesh
        The same vertices and members; paired triangles replaced by quads of
        kind :attr:`FaceKind.STRIP` when all four corners lie on two generators,
        else :attr:`FaceKind.QUAD`.
    int
        Number of quads made.
    """
    from ...analysis.faces import SPLINTER_DEG, min_corner_angles, quad_diagonal_crossing, quad_planarity

    if report is not None:
        report.update(settled=True, touched=np.zeros(mesh.n_vertices, bool),
                      again=np.zeros(mesh.n_vertices, bool))
    if kinds is None:
        kinds = (FaceKind.FILL, FaceKind.BORDER, FaceKind.SPLIT)
    val = mesh.valences
    ids = np.flatnonzero((val == 3) & member(mesh.face_kind, np.asarray(kinds, np.uint8)))
    if ids.size < 2 or ptol <= 0:
        return mesh, 0
    V = mesh.vertices
    tri = mesh.face_indices[mesh.face_offsets[ids][:, None] + np.arange(3)]
    if near is not None:
        # Rows in order: the pairs come in the same order and with the same sides.
        rows = np.flatnonzero(_around(tri, len(V), _at(tri, near), 2))
        ids, tri = ids[rows], tri[rows]
    t1, t2, a, b, c, d = adjacent_triangles(tri, len(V))
    quad = np.stack([a, b, d, c], axis=1)
    if t1.size == 0:
        return mesh, 0
    # The planarity first: in exact mode few pairs pass, and only those are measured further.
    flat = quad_planarity(V[quad]) <= ptol
    t1, t2, quad = t1[flat], t2[flat], quad[flat]
    P = V[quad]
    sq, tq, _ = quad_diagonal_crossing(P)
    ang = min_corner_angles(V, quad)
    tri_min = np.zeros(len(tri))
    paired = unique(np.concatenate([t1, t2]))
    tri_min[paired] = min_corner_angles(V, tri[paired])
    ok = (sq > _MIN_CROSSING) & (sq < 1 - _MIN_CROSSING) \
        & (tq > _MIN_CROSSING) & (tq < 1 - _MIN_CROSSING) \
        & (ang >= np.minimum(tri_min[t1], tri_min[t2])) & (ang >= SPLINTER_DEG)
    t1, t2, quad, score = t1[ok], t2[ok], quad[ok], ang[ok]
    chosen, taken, settled = _matched(t1, t2, score, len(tri))
    made = np.flatnonzero(chosen)
    if report is not None:
        report["settled"] = settled
        report["touched"][quad[made]] = True
    if made.size == 0:
        return mesh, 0
    g = np.sort(np.asarray(mesh.vertex_data["generator"])[quad[made]], axis=1)
    on_two = (g[:, 1:] != g[:, :-1]).sum(axis=1) <= 1
    keep = np.ones(mesh.n_faces, bool)
    keep[ids[taken]] = False
    return _rebuilt(mesh, keep, quad[made], np.where(on_two, FaceKind.STRIP, FaceKind.QUAD)), int(made.size)


def _matched(t1: np.ndarray, t2: np.ndarray, score: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, bool]:
    """Pairs ``t1, t2`` (P,) of ``n`` triangles taken by rounds of mutual best ``score``.

    Returns (P,) bool the pairs taken, (n,) bool the triangles in them, and whether
    every pair left has a triangle taken (else the rounds ran out first).
    """
    taken = np.zeros(n, bool)
    chosen = np.zeros(len(t1), bool)
    for _ in range(_ROUNDS):
        live = ~taken[t1] & ~taken[t2] & ~chosen
        if not live.any():
            return chosen, taken, True
        best = np.full(n, -1.0)
        np.maximum.at(best, t1[live], score[live])
        np.maximum.at(best, t2[live], score[live])
        # Ties: the first candidate of each triangle wins, so both ends agree.
        top = live & (score >= best[t1]) & (score >= best[t2])
        first_of = np.full(n, len(t1))
        cand = np.flatnonzero(top)
        np.minimum.at(first_of, t1[cand], cand)
        np.minimum.at(first_of, t2[cand], cand)
        mutual = cand[(first_of[t1[cand]] == cand) & (first_of[t2[cand]] == cand)]
        if mutual.size == 0:
            break
        chosen[mutual] = True
        taken[t1[mutual]] = True
        taken[t2[mutual]] = True
    return chosen, taken, not (~taken[t1] & ~taken[t2] & ~chosen).any()


def _rebuilt(mesh: Mesh, keep: np.ndarray, quads: np.ndarray, quad_kind: np.ndarray) -> Mesh:
    """``mesh`` with the faces not kept dropped and ``quads`` added (vertices unchanged)."""
    val = mesh.valences
    kept = np.flatnonzero(keep)
    starts = mesh.face_offsets[kept]
    n = val[kept]
    flat = np.repeat(starts, n) + ranks(n)
    idx = np.concatenate([mesh.face_indices[flat], quads.reshape(-1)]).astype(np.int64)
    counts = np.concatenate([n, np.full(len(quads), 4)])
    off = np.zeros(len(counts) + 1, np.int64)
    np.cumsum(counts, out=off[1:])
    kind = np.concatenate([mesh.face_kind[kept], quad_kind.astype(np.uint8)])
    return Mesh(mesh.vertices, off, idx, kind, mesh.members, mesh.member_id, mesh.vertex_data,
                mesh.info)
