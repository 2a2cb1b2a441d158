"""Half-edge collapses that remove the splinters flips cannot.

Where two generators nearly meet (a conoid's generators close to its director
curve, the strips beside a torsal generator), the triangles between them are
needles whatever their diagonals: the two rows of vertices are a small share of
a row step apart.  A vertex that belongs to triangles only may go instead: its
triangles are re-pointed at a neighbour (``v`` collapses into ``u``), the one or
two triangles on the edge ``u v`` disappear, and every corner left is still a
vertex on a generator, so every face stays planar.  Quads and their corners are
never touched.

A collapse is taken only where it raises the smallest angle of the faces around
``v``, folds none of them (each new face's normal stays within
:data:`~ruledmesh.tolerances.FLIP_MAX_BEND_DEG` of its old one, or of the
area-weighted normal of the faces around ``v`` where the old one was a
splinter), keeps the surface (``v`` lies
within :data:`~ruledmesh.tolerances.COLLAPSE_MAX_SAG` of the diagonal from the
faces left around it), keeps the mesh a manifold (the link condition: ``u`` and
``v`` share no neighbour but the corners opposite their edge) and keeps the
border where it is (a border vertex collapses only along a border edge).
Collapses are chosen by rounds of best choice, whole arrays per round.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..._arrays import cross, diagonal, lookup, member, norm, unique
from ...analysis.faces import min_corner_angles, triangle_distances
from ...kernels import wanted
from ...mesh import FaceKind, Mesh
from ...tolerances import COLLAPSE_MAX_SAG, FLIP_MAX_BEND_DEG, FLIP_MIN_GAIN_DEG, RESTART_ANGLE_DEG, TINY
from .flips import _member, _unit_normals

__all__ = ["collapse_splinters", "warm"]

_ROUNDS = 12


def _angles(P: np.ndarray) -> np.ndarray:
    from ...analysis.faces import polygon_angles

    return polygon_angles(P)


def _normals(P: np.ndarray) -> np.ndarray:
    """(T, 3) unit normals of triangles ``P`` (T, 3, 3) (zero for degenerate ones)."""
    return _unit_normals(P[:, 0], P[:, 1], P[:, 2])


def _expand(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For groups of ``counts`` items: the group of each item and its rank within it."""
    rep = np.repeat(np.arange(counts.size), counts)
    start = np.cumsum(counts) - counts
    return rep, np.arange(rep.size) - start[rep]


class _Stars:
    """Vertex -> incident triangles (rows of ``tri``) and vertex -> neighbours (all faces)."""

    def __init__(self, tri: np.ndarray, keys: np.ndarray, n: int):
        flat = tri.reshape(-1)
        self.order = np.argsort(flat, kind="stable")
        self.tri_start = np.searchsorted(flat[self.order], np.arange(n + 1))
        lo, hi = keys // n, keys % n
        ends = np.concatenate([lo, hi])
        other = np.concatenate([hi, lo])
        o = np.argsort(ends, kind="stable")
        self.nbr = other[o]
        self.nbr_start = np.searchsorted(ends[o], np.arange(n + 1))

    def triangles(self, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per (candidate, incident triangle): candidate row, triangle row, corner of ``v``."""
        cnt = self.tri_start[v + 1] - self.tri_start[v]
        rep, rank = _expand(cnt)
        pos = self.order[self.tri_start[v][rep] + rank]
        return rep, pos // 3, pos % 3

    def neighbours(self, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per (candidate, neighbour of ``v``): candidate row and neighbour."""
        cnt = self.nbr_start[v + 1] - self.nbr_start[v]
        rep, rank = _expand(cnt)
        return rep, self.nbr[self.nbr_start[v][rep] + rank]


def _directed(tri: np.ndarray, free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directed edges ``v -> u`` of triangles ``tri`` whose ``v`` is free, once each."""
    v = np.concatenate([tri, np.roll(tri, -1, axis=1)], axis=0).reshape(-1)
    u = np.concatenate([np.roll(tri, -1, axis=1), tri], axis=0).reshape(-1)
    ok = free[v]
    n = np.int64(len(free))
    pairs = unique(v[ok] * n + u[ok])
    return pairs // n, pairs % n


def _touching(mesh: Mesh, mark: np.ndarray) -> np.ndarray:
    """(F,) bool: the faces with a corner where ``mark`` (V,) is true."""
    face_of = mesh.face_of
    return np.bincount(face_of[mark[mesh.face_indices]], minlength=mesh.n_faces) > 0


def _border_vertices(keys: np.ndarray, uses: np.ndarray, n: int) -> np.ndarray:
    """(n,) bool: the ends of the edges used once (:meth:`Mesh.edge_uses`'s ``keys, uses``)."""
    border = keys[uses == 1]
    out = np.zeros(n, bool)
    out[border // n] = out[border % n] = True
    return out


def _near(mesh: Mesh, vertices: np.ndarray) -> Mesh:
    """The faces with a corner among ``vertices`` and the members with an end there (all
    vertices kept).

    Every face around a candidate's two ends is there, so the edges at them,
    their uses and the neighbours they share are those of the whole mesh; so are
    the members at them (a vertex a member ends at outlives its faces).  The other
    members are left out: a large mesh has a million, and the collapses measured
    on this part of it would join and renumber every one.
    """
    mark = np.zeros(mesh.n_vertices, bool)
    mark[vertices] = True
    at = mark[mesh.members[:, 0]] | mark[mesh.members[:, 1]]
    return replace(mesh.select_faces(_touching(mesh, mark)), members=mesh.members[at],
                   member_id=mesh.member_id[at])


def _collapsed_star(tri, stars: _Stars, v, u):
    """The star of each ``v`` before and after collapsing it into its ``u``.

    Returns ``rep`` (candidate row per star triangle), ``old`` and ``new`` (the
    triangles, ``v`` replaced by ``u`` in ``new``) and ``gone`` (the triangles on
    the edge ``u v``, which the collapse removes).
    """
    rep, face, corner = stars.triangles(v)
    old = tri[face]
    new = old.copy()
    new[np.arange(face.size), corner] = u[rep]
    return rep, old, new, (old == u[rep][:, None]).any(axis=1)


def _evaluate(V, tri, stars: _Stars, keys, faces_at, v, u, scale) -> tuple[np.ndarray, np.ndarray]:
    """(C,) gain in smallest angle (degrees) of each collapse ``v -> u``, and whether it is
    allowed (it gains more than :data:`~ruledmesh.tolerances.FLIP_MIN_GAIN_DEG` too).

    :func:`ruledmesh.kernels.geometry.collapse_measures` is the same, bit for bit.
    """
    C = v.size
    cos = np.cos(np.radians(FLIP_MAX_BEND_DEG))
    kern = wanted(C)
    if kern is not None:
        return kern.collapse_measures(V, tri, stars.order, stars.tri_start, stars.nbr, stars.nbr_start,
                                      keys, faces_at, v, u, FLIP_MIN_GAIN_DEG, cos, RESTART_ANGLE_DEG,
                                      COLLAPSE_MAX_SAG * scale)
    rep, old, new, gone = _collapsed_star(tri, stars, v, u)
    old_ang = min_corner_angles(V, old)
    old_min = np.full(C, 180.0)
    np.minimum.at(old_min, rep, old_ang)
    keep = ~gone
    Pn = V[new[keep]]
    new_min = np.full(C, 180.0)
    np.minimum.at(new_min, rep[keep], _angles(Pn).min(axis=1))
    # Each new face keeps to its old normal; a needle's own normal is noise, so in
    # its place the star's normal (its faces weighed by area) is the reference.
    P0 = V[old]
    star = np.zeros((C, 3))
    np.add.at(star, rep, cross(P0[:, 1] - P0[:, 0], P0[:, 2] - P0[:, 0]))
    star /= np.maximum(norm(star), TINY)[:, None]
    n_new = _normals(Pn)
    bend = (np.einsum("ij,ij->i", _normals(P0[keep]), n_new) >= cos) | (
        (old_ang[keep] < RESTART_ANGLE_DEG) & (np.einsum("ij,ij->i", star[rep[keep]], n_new) >= cos))
    bad = ~bend | (norm(n_new) < 0.5)
    gain = new_min - old_min
    ok = (np.bincount(rep[keep][bad], minlength=C) == 0) & (gain > FLIP_MIN_GAIN_DEG)
    removed = np.bincount(rep[gone], minlength=C)
    # A corner opposite the edge u v must keep a face (else it and its area would go).
    third = np.where((old[gone] != v[rep[gone]][:, None]) & (old[gone] != u[rep[gone]][:, None]),
                     old[gone], -1).max(axis=1)
    ok &= np.bincount(rep[gone][faces_at[third] < 2], minlength=C) == 0
    # Link condition: the neighbours u and v share are the corners opposite their edge.
    n = len(V)
    r2, w = stars.neighbours(v)
    w_ok = w != u[r2]
    shared = _member(np.minimum(u[r2], w) * n + np.maximum(u[r2], w), keys)
    common = np.bincount(r2[w_ok & shared], minlength=C)
    ok &= (common == removed) & (removed >= 1) & (np.bincount(rep, minlength=C) > removed)
    # How far the surface moves: the removed vertex's distance from the faces left around
    # it, measured last, for the collapses every other test allows.
    at = keep & ok[rep]
    sag = np.full(C, np.inf)
    np.minimum.at(sag, rep[at], triangle_distances(V[v[rep[at]]], V[new[at]]))
    return gain, ok & (sag <= COLLAPSE_MAX_SAG * scale)


def _keeps_ghosts(V, tri, stars: _Stars, v, u, ghosts, anchors, scale) -> np.ndarray:
    """(C,) bool: the collapses ``v -> u`` that leave every earlier removed vertex (``ghosts``
    (k, 3), each with the vertex it went into, ``anchors`` (k,)) within the sag bound of a
    face: of one of the collapse's new faces, or of a triangle at its anchor that the
    collapse does not change.

    :func:`ruledmesh.kernels.geometry.ghosts_kept` is the same, bit for bit.
    """
    C = v.size
    kern = wanted(C)
    if kern is not None:
        return kern.ghosts_kept(V, tri, stars.order, stars.tri_start, v, u, ghosts, anchors,
                                COLLAPSE_MAX_SAG * scale)
    rep, face, _ = stars.triangles(v)
    order = np.argsort(anchors, kind="stable")
    sa = anchors[order]
    # Pairs (star triangle, ghost) where the triangle has the ghost's anchor for a corner.
    pairs_row, pairs_g = [], []
    for k in range(3):
        lo = np.searchsorted(sa, tri[face, k], side="left")
        hi = np.searchsorted(sa, tri[face, k], side="right")
        cnt = hi - lo
        row, rank = _expand(cnt)
        pairs_row.append(row)
        pairs_g.append(order[lo[row] + rank])
    row = np.concatenate(pairs_row)
    if row.size == 0:
        return np.ones(C, bool)
    g = np.concatenate(pairs_g)
    cand = rep[row]
    key = unique(cand * len(anchors) + g)
    cand, g = key // len(anchors), key % len(anchors)
    bound = COLLAPSE_MAX_SAG * scale
    # Distance to the collapse's new faces.
    c_rep, _, new, gone = _collapsed_star(tri, stars, v[cand], u[cand])
    live = ~gone
    near = np.full(cand.size, np.inf)
    np.minimum.at(near, c_rep[live], triangle_distances(ghosts[g[c_rep[live]]], V[new[live]]))
    # ... or to the triangles at the anchor that do not have v for a corner.
    a_rep, a_face, _ = stars.triangles(anchors[g])
    kept = ~(tri[a_face] == v[cand][a_rep][:, None]).any(axis=1)
    np.minimum.at(near, a_rep[kept], triangle_distances(ghosts[g[a_rep[kept]]], V[tri[a_face[kept]]]))
    return np.bincount(cand[near > bound], minlength=C) == 0


def _chosen(stars: _Stars, tri, v, gain) -> np.ndarray:
    """Rows of the collapses to take: each the best of every vertex its triangles touch."""
    rep, face, _ = stars.triangles(v)
    touched_v = tri[face].reshape(-1)
    touched_c = np.repeat(rep, 3)
    best = np.full(int(tri.max()) + 1, -np.inf)
    np.maximum.at(best, touched_v, gain[touched_c])
    top = np.bincount(touched_c[gain[touched_c] < best[touched_v]], minlength=v.size) == 0
    first = np.full(best.size, v.size)
    np.minimum.at(first, touched_v[top[touched_c]], touched_c[top[touched_c]])
    mine = first[touched_v] == touched_c
    return np.flatnonzero(top & (np.bincount(touched_c[~mine], minlength=v.size) == 0))


def _rejoined(members: np.ndarray, member_id: np.ndarray, removed: np.ndarray, n: int):
    """Members with the removed vertices taken out of their generator chains."""
    if members.size == 0 or not removed[members].any():
        return members, member_id
    m0, m1 = members[:, 0], members[:, 1]
    # The member that continues one along its generator: (id, start) = (id, its end).  Only
    # members ending at a removed vertex are continued, so only those starting at one are
    # looked up (a large mesh has millions of members and a few removed vertices).
    starts = np.flatnonzero(removed[m0])
    key0 = (member_id * n + m0)[starts]
    order = np.argsort(key0, kind="stable")
    end = m1.copy()
    rows = np.flatnonzero(removed[m1])
    row = rows
    nxt = lookup(member_id[row] * n + end[row], key0[order])
    while True:
        walk = (nxt >= 0) & removed[end[rows]]
        if not walk.any():
            break
        row = np.where(walk, starts[order[np.maximum(nxt, 0)]], row)
        end[rows] = np.where(walk, m1[row], end[rows])
        nxt = lookup(member_id[row] * n + end[rows], key0[order])
    keep = ~removed[m0] & ~removed[end]
    return np.stack([m0[keep], end[keep]], axis=1), member_id[keep]


def _apply(mesh: Mesh, v: np.ndarray, u: np.ndarray) -> tuple[Mesh, np.ndarray]:
    """The mesh with each ``v`` collapsed into its ``u`` and the emptied vertices dropped,
    and the new index of each old vertex (-1 for those dropped)."""
    n = mesh.n_vertices
    remap = np.arange(n)
    remap[v] = u
    removed = np.zeros(n, bool)
    removed[v] = True
    face_of = mesh.face_of
    kind = mesh.face_kind.copy()
    kind[face_of[removed[mesh.face_indices]]] = FaceKind.FILL
    members, member_id = _rejoined(mesh.members, mesh.member_id, removed, n)
    # The triangles on each edge u v now repeat u: they go with the repeated corner.
    out = Mesh(mesh.vertices, mesh.face_offsets, remap[mesh.face_indices], kind, members, member_id,
               mesh.vertex_data, mesh.info).drop_repeated_corners()
    # The compaction drops every vertex no face or member uses, not only the collapsed ones
    # (a part of a mesh, a face gone with its corner): its own new index says which.
    return out.compact_index()


def collapse_splinters(mesh: Mesh, removable: np.ndarray | None = None,
                       scale: float | None = None, *, report: dict | None = None) -> tuple[Mesh, int]:
    """Remove triangle-only vertices of splinters where that fattens the faces around them.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh; only triangles whose corners are in no other face
        change.
    removable : (V,) bool, optional
        The vertices that may go (default: every vertex only triangles use).
    scale : float, optional
        Length the sag bound is relative to (default: the mesh's bounding-box
        diagonal; a part of a mesh passes the whole one's).
    report : dict, optional
        Filled with ``"touched"``: (V_out,) bool, the vertices the removed ones went into.

    Returns
    -------
    Mesh
        Fewer vertices and triangles; quads, their corners and the border kept;
        changed triangles are of kind :attr:`FaceKind.FILL`; members joined
        across the removed vertices.
    int
        Number of vertices removed.
    """
    total = 0
    # Removing vertices can shrink the bounding box: the bound stays that of the mesh as given.
    size = scale or (diagonal(mesh.vertices) if mesh.n_vertices else 0.0) or 1.0
    # After the first round, the vertices whose candidates must be weighed again: those
    # allowed but not taken, and those near a collapse (every other candidate's star,
    # neighbours, edges and border are unchanged, so its verdict is too).
    watch = None
    ghosts, anchors = np.zeros((0, 3)), np.zeros(0, np.int64)
    into_kept = np.zeros(0, np.int64)           # the vertices collapsed into, numbered now
    for _ in range(_ROUNDS):
        val = mesh.valences
        if not (val == 3).any():
            break
        V, n = mesh.vertices, mesh.n_vertices
        ids = np.flatnonzero(val == 3)
        tri = mesh.face_indices[mesh.face_offsets[ids][:, None] + np.arange(3)].astype(np.int64)
        if watch is not None:
            tri = tri[watch[tri].any(axis=1)]
        thin = min_corner_angles(V, tri) < RESTART_ANGLE_DEG
        if not thin.any():
            break
        free = np.ones(n, bool) if removable is None else removable.copy()
        free[mesh.face_indices[np.repeat(val != 3, val)]] = False
        splinters = tri[thin]
        v, u = _directed(splinters, free)
        if v.size == 0:
            break
        # Only the faces around the candidates matter: a large mesh has few splinters.
        near = _near(mesh, np.concatenate([v, u]))
        keys, uses = near.edge_uses()
        border_v = _border_vertices(keys, uses, n)
        # A border vertex collapses only along the border.
        along = _member(np.minimum(v, u) * n + np.maximum(v, u), keys[uses == 1])
        ok = ~border_v[v] | along
        v, u = v[ok], u[ok]
        if v.size == 0:
            break
        nval = near.valences
        tri = near.face_indices[near.face_offsets[np.flatnonzero(nval == 3)][:, None]
                                + np.arange(3)].astype(np.int64)
        stars = _Stars(tri, keys, n)
        gain, ok = _evaluate(V, tri, stars, keys, np.bincount(mesh.face_indices, minlength=n), v, u, size)
        if not ok.any():
            break
        if ghosts.size:
            # Only the collapses allowed so far: the check costs the most of a round.
            at = np.flatnonzero(ok)
            ok[at] = _keeps_ghosts(V, tri, stars, v[at], u[at], ghosts, anchors, size)
        v, u, gain = v[ok], u[ok], gain[ok]
        take = _chosen(stars, tri, v, gain)
        if take.size == 0:
            break
        # The removed vertices stay within the bound of the faces left around them in later
        # rounds too (two rounds on neighbouring vertices left one 1.2e-3 of the diagonal
        # off): each is remembered with the vertex it went into, its anchor.
        into = np.arange(n)
        into[v[take]] = u[take]
        ghosts = np.concatenate([ghosts, V[v[take]]])
        anchors = into[np.concatenate([anchors, v[take]])]
        mesh, new_index = _apply(mesh, v[take], u[take])
        into_kept = _renumbered(new_index, np.concatenate([into_kept, u[take]]))
        anchors = new_index[anchors]
        ghosts, anchors = ghosts[anchors >= 0], anchors[anchors >= 0]
        if removable is not None:
            removable = _still_removable(removable, v[take], mesh.n_vertices)
        total += int(take.size)
        watch = _rings(mesh, new_index[u[take]], 2)
        waiting = np.ones(v.size, bool)
        waiting[take] = False
        waiting &= ~member(v, v[take])
        watch[new_index[v[waiting]]] = True
    if report is not None:
        report["touched"] = np.bincount(into_kept, minlength=mesh.n_vertices) > 0
    return mesh, total


def _renumbered(new_index: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """The vertices ``idx`` in the new numbers, those removed left out."""
    out = new_index[idx]
    return out[out >= 0]


def _still_removable(removable: np.ndarray, gone: np.ndarray, n_new: int) -> np.ndarray:
    """``removable`` (V,) bool without the vertices ``gone``, for the ``n_new`` vertices left;
    none where the compaction dropped others too (the marks no longer line up)."""
    keep = np.ones(removable.size, bool)
    keep[gone] = False
    removable = removable[keep]
    return removable if removable.size == n_new else np.zeros(n_new, bool)


def _rings(mesh: Mesh, seeds: np.ndarray, k: int) -> np.ndarray:
    """(V,) bool: the vertices within ``k`` face rings of ``seeds``."""
    mark = np.zeros(mesh.n_vertices, bool)
    mark[seeds] = True
    for _ in range(k):
        mark[mesh.face_indices[np.repeat(_touching(mesh, mark), mesh.valences)]] = True
    return mark


def warm() -> None:
    """Weigh one collapse on two triangles, after an earlier one: inside
    :func:`ruledmesh.kernels.everywhere` this compiles the collapses' kernels (or loads them
    from numba's cache), which a small design's build may not reach (no splinter to collapse,
    or none after another), so that a live application does not compile them inside an edit."""
    V = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]])
    tri = np.array([[0, 1, 2], [1, 3, 2]])
    keys, _ = Mesh(V, np.array([0, 3, 6]), tri.reshape(-1), np.full(2, FaceKind.FILL)).edge_uses()
    stars = _Stars(tri, keys, len(V))
    v, u = np.array([1]), np.array([2])
    _evaluate(V, tri, stars, keys, np.bincount(tri.reshape(-1)), v, u, 1.0)
    _keeps_ghosts(V, tri, stars, v, u, V[:1], np.array([0]), 1.0)
