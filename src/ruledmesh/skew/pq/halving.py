"""Triangles across many strips halved on the generators they span.

A fill triangle whose corners lie on generators far apart passes over the generators
between, which may lie far off it (:mod:`ruledmesh.analysis.spans`): the mesh is exact,
but not near the smooth surface there.  Its edge across the most strips is halved at
the point of the generator halfway between that lies on the edge in the parameter plane
(generator index, ``t``), so both halves cover what the triangle covered; the triangle
across that edge is halved with it, so no corner lies on another face's edge.  That
corner pins the mesh to the surface in the middle of the span, and the sag of an edge
over a curved surface falls with the square of its length.  Rounds go on while a
triangle lies farther off than the goal and can be halved without an angle below the
splinter bar (or below the two faces' own smallest angle, where that is lower); a
quad across the edge is never cut (it would become a pentagon), so such a triangle
halves another of its edges.  Every new point lies on its generator, and the member
along that generator is split there.
"""

from __future__ import annotations

import numpy as np

from ..._arrays import cross
from ...analysis.faces import SPLINTER_DEG, min_corner_angles
from ...analysis.spans import off_spanned_generators
from ...mesh import Mesh, offsets_from_valences
from .panels import _chains, _split_members, faces_across

__all__ = ["halve_spanning_triangles"]

# Rounds of halving: each halves the span of the triangles it cuts, so eight take a
# triangle across 256 strips down to single strips.
_ROUNDS = 8


def halve_spanning_triangles(mesh: Mesh, lines: tuple[np.ndarray, np.ndarray], goal: float
                             ) -> tuple[Mesh, int, np.ndarray, np.ndarray]:
    """Halve the triangles of ``mesh`` lying farther than ``goal`` off the generators they span.

    Parameters
    ----------
    mesh : Mesh
        A §4.3 mesh with ``vertex_data["generator"]`` and ``vertex_data["t"]``.
    lines : ((m, 3), (m, 3)) float64
        ``a`` and ``d`` of the generators (``a_g + t d_g``).
    goal : float
        The largest distance off the spanned generators left as it is (absolute units).

    Returns
    -------
    Mesh
        The mesh with the triangles halved (new faces at the end, new vertices after the old).
    int
        Number of edges halved.
    (T, 3) int64
        The triangles of the mesh returned with generators between their corners.
    (T,) float64
        How far each of those lies off the generators it spans
        (:func:`~ruledmesh.analysis.spans.off_spanned_generators`, against the mesh).
    """
    halved = 0
    for last in range(_ROUNDS + 1):
        ids, tri = _spanning(mesh)
        off = _off(mesh, tri, lines, goal)
        far = off > goal
        if last == _ROUNDS or not far.any():
            break
        cut = _halvable(mesh, ids[far], tri[far])
        if cut is None:
            break
        mesh, count = _halve(mesh, lines, *cut)
        if count == 0:
            break
        halved += count
    return mesh, halved, tri, off


def _spanning(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """The triangles of ``mesh`` with generators between their corners: ids and (T, 3) corners."""
    ids, tri = mesh.faces_of_valence(3)
    g = np.asarray(mesh.vertex_data["generator"], np.int64)[tri]
    keep = np.ptp(g, axis=1) > 1 if len(tri) else np.zeros(0, bool)
    return ids[keep], tri[keep]


def _off(mesh: Mesh, tri: np.ndarray, lines: tuple[np.ndarray, np.ndarray], goal: float) -> np.ndarray:
    """(T,) how far triangles ``tri`` lie off the generators they span, against the mesh."""
    if len(tri) == 0:
        return np.zeros(0)
    return off_spanned_generators(mesh.vertices, tri, np.asarray(mesh.vertex_data["generator"], np.int64),
                                  np.asarray(mesh.vertex_data["t"], np.float64), lines,
                                  faces=mesh.fan_triangles()[0], within=goal)


def _halvable(mesh: Mesh, faces: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, ...] | None:
    """The edges to halve this round.

    For each triangle ``faces`` (corners ``tri``), its edge across the most strips whose
    other side is the border or a triangle; then at most one cut per face, the widest
    spans first.  Returns ``(u, v, face, apex, other, far)``, each (k,): the directed edge
    ``u -> v`` of ``face`` with ``apex`` the corner opposite it, the face across (-1: the
    border) and its corner opposite the edge; or None.
    """
    g = np.asarray(mesh.vertex_data["generator"], np.int64)
    k = len(tri)
    u = tri.reshape(-1)
    v = tri[:, [1, 2, 0]].reshape(-1)
    apex = tri[:, [2, 0, 1]].reshape(-1)
    face = np.repeat(faces, 3)
    other, far = faces_across(mesh, u, v)
    span = np.abs(g[u] - g[v])
    ok = (span > 1) & ((other < 0) | (far >= 0)) & (g[u] >= 0) & (g[v] >= 0)
    score = np.where(ok, span, 0).reshape(k, 3)
    best = np.argmax(score, axis=1)
    pick = (np.arange(k) * 3 + best)[score[np.arange(k), best] > 0]
    if pick.size == 0:
        return None
    cut = [x[pick] for x in (u, v, face, apex, other, far, span)]
    # An edge chosen from both its sides is cut once.
    n = np.int64(mesh.n_vertices)
    _, first = np.unique(np.minimum(cut[0], cut[1]) * n + np.maximum(cut[0], cut[1]), return_index=True)
    u, v, face, apex, other, far, span = (x[first] for x in cut)
    # Each face is cut once a round: the widest span touching it wins (ties: the lower face).
    prio = span * np.int64(mesh.n_faces + 1) + (mesh.n_faces - face)
    top = np.full(mesh.n_faces, -1, np.int64)
    has = other >= 0
    np.maximum.at(top, face, prio)
    np.maximum.at(top, other[has], prio[has])
    win = (top[face] == prio) & (~has | (top[np.maximum(other, 0)] == prio))
    return tuple(x[win] for x in (u, v, face, apex, other, far))


def _halve(mesh: Mesh, lines: tuple[np.ndarray, np.ndarray], u: np.ndarray, v: np.ndarray,
           face: np.ndarray, apex: np.ndarray, other: np.ndarray, far: np.ndarray) -> tuple[Mesh, int]:
    """``mesh`` with each edge ``u -> v`` halved where the generator halfway between its
    corners' crosses it in the parameter plane, the faces on both sides split through the
    new point (new faces at the end, each with its face's kind and sense); and how many.
    Cuts that would make an angle below the splinter bar (or below the two faces' own
    smallest, where that is lower) or turn a half against its face are left out."""
    a, d = lines
    g = np.asarray(mesh.vertex_data["generator"])
    t = np.asarray(mesh.vertex_data["t"], np.float64)
    gi = g.astype(np.int64)
    k = (gi[u] + gi[v]) // 2
    tk = t[u] + (k - gi[u]) / (gi[v] - gi[u]) * (t[v] - t[u])
    P = a[k] + tk[:, None] * d[k]
    good = _kept_shape(mesh.vertices, P, u, v, apex, far, other >= 0)
    if not good.any():
        return mesh, 0
    u, v, face, apex, other, far, k, tk, P = (x[good] for x in (u, v, face, apex, other, far, k, tk, P))
    has = other >= 0
    m = mesh.n_vertices + np.arange(len(u))
    polys = [np.stack([u, m, apex], 1), np.stack([m, v, apex], 1),
             np.stack([v, m, far], 1)[has], np.stack([m, u, far], 1)[has]]
    kinds = [mesh.face_kind[face]] * 2 + [mesh.face_kind[other[has]]] * 2
    drop = np.zeros(mesh.n_faces, bool)
    drop[face] = True
    drop[other[has]] = True
    kept = mesh.select_faces(~drop)
    sizes = np.concatenate([kept.valences, np.full(sum(len(p) for p in polys), 3)])
    indices = np.concatenate([kept.face_indices] + [p.reshape(-1) for p in polys])
    members, member_id = _members_cut(mesh, k, tk, m)
    halved = Mesh.from_arrays(np.concatenate([mesh.vertices, P]), offsets_from_valences(sizes), indices,
                              np.concatenate([kept.face_kind, *kinds]), members=members, member_id=member_id,
                              vertex_data={"t": np.r_[t, tk], "generator": np.r_[g, k.astype(g.dtype)]},
                              info=dict(mesh.info))
    return halved, len(u)


def _kept_shape(V: np.ndarray, P: np.ndarray, u, v, apex, far, has) -> np.ndarray:
    """(k,) bool: the halves of ``(u, v, apex)`` and ``(v, u, far)`` (where ``has``) through
    points ``P`` keep their angles (see :func:`_halve`) and face as their faces did."""
    W = np.concatenate([V, P])
    m = len(V) + np.arange(len(P))
    x = np.where(has, far, apex)            # without a face across: the face itself again
    whole = [np.stack([u, v, apex], 1), np.stack([v, u, x], 1)]
    halves = [[np.stack([u, m, apex], 1), np.stack([m, v, apex], 1)],
              [np.stack([v, m, x], 1), np.stack([m, u, x], 1)]]
    good = np.ones(len(P), bool)
    floor = np.minimum(SPLINTER_DEG, np.minimum(*(min_corner_angles(V, w) for w in whole)))
    for w, (h1, h2) in zip(whole, halves, strict=True):
        good &= np.minimum(min_corner_angles(W, h1), min_corner_angles(W, h2)) >= floor
        n = _normals(W, w)
        good &= (np.einsum("ij,ij->i", _normals(W, h1), n) > 0) & (np.einsum("ij,ij->i", _normals(W, h2), n) > 0)
    return good


def _normals(W: np.ndarray, f: np.ndarray) -> np.ndarray:
    return cross(W[f[:, 1]] - W[f[:, 0]], W[f[:, 2]] - W[f[:, 0]])


def _members_cut(mesh: Mesh, k: np.ndarray, tk: np.ndarray, new: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Members along generator ``k[j]`` whose stretch holds ``tk[j]`` cut at the new vertex
    ``new[j]`` (several new vertices on one member in their order along it)."""
    members, ids = mesh.members, mesh.member_id
    if members.size == 0:
        return members, ids
    t = np.asarray(mesh.vertex_data["t"], np.float64)
    g = np.asarray(mesh.vertex_data["generator"], np.int64)
    p, q = members[:, 0], members[:, 1]
    lo, hi, gen = np.minimum(t[p], t[q]), np.maximum(t[p], t[q]), g[p]
    # The members of one generator do not overlap: the one holding tk[j] is the last of
    # generator k[j] starting below it (keys: generator + fraction of the t range).
    base = min(lo.min(), tk.min())
    width = max(hi.max(), tk.max()) - base + 1.0
    key = gen + (lo - base) / width
    order = np.argsort(key, kind="stable")
    pos = np.searchsorted(key[order], k + (tk - base) / width, side="right") - 1
    row = order[np.maximum(pos, 0)]
    row = np.where((pos >= 0) & (gen[row] == k) & (lo[row] < tk) & (tk < hi[row]), row, -1)
    hit = row >= 0
    if not hit.any():
        return members, ids
    row, at, along = row[hit], new[hit], tk[hit]
    # Each member's chain from its first end to its second through the new vertices on it.
    rising = t[q[row]] >= t[p[row]]
    seq = np.lexsort((np.where(rising, along, -along), row))
    row, at = row[seq], at[seq]
    cut, counts = np.unique(row, return_counts=True)
    start, flat = _chains(p[cut], at, q[cut], counts)
    return _split_members(mesh, start, flat)
