"""The splinters the flips and collapses leave: border snaps and opened quads.

Two patterns account for most of what remains after
:func:`~ruledmesh.skew.pq.flips.flip_triangles` and
:func:`~ruledmesh.skew.pq.collapses.collapse_splinters`:

- **A corner a sliver away from the border.**  A row that meets a generator
  just inside the patch leaves a quad corner a hair from the generator's end
  point, and the two triangles on that short edge are needles.  The corner may
  slide along its generator when it is the end of a generator *diagonal* of
  every quad it belongs to: the diagonal stays on the generator, the other
  diagonal still crosses it, so the quad stays planar (to rounding) and
  convex.  The corner moves onto the end point; the needles disappear.
- **A splinter walled in by quads.**  Its edges are quad edges, so no flip can
  reach it.  The quads beside it are cut into triangles along their better
  diagonal and the neighbourhood is flipped and collapsed again; the cut quads
  that end up unchanged are joined again.  The result is kept only if fewer
  faces are splinters (or the smallest angle grows): a few quads become
  well-shaped triangles where one splinter was.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ..._arrays import diagonal, ranks, unique
from ...analysis.faces import face_min_angles, face_normals, segment_distances
from ...mesh import FaceKind, Mesh, offsets_from_valences
from ...tolerances import (
    BORDER_TRIM_MAX_GAP,
    ON_BORDER,
    RESTART_ANGLE_DEG,
    SNAP_MIN_GAIN_DEG,
    SPLINTER_AREA_WORTH,
)
from .collapses import _apply, _border_vertices, _near, _rejoined, _rings, _touching
from .pairing import _rebuilt

__all__ = ["open_walled_splinters", "snap_to_border", "trim_border_needles"]

# Rounds of opening the quads beside the splinters left ...
_OPEN_ROUNDS = 5
# ... each piece kept only if it moves at most this share of the area out of quads per
# splinter it removes.
_OPEN_MAX_SHARE = SPLINTER_AREA_WORTH
# Opening is tried only where at most this share of the faces are splinters.
_OPEN_MAX_SPLINTERS = 0.05


def _splinter_edges(mesh: Mesh, amin: np.ndarray) -> np.ndarray:
    """Sorted undirected edge keys of the triangles below the splinter bar."""
    n = np.int64(mesh.n_vertices)
    bad = np.flatnonzero((amin < RESTART_ANGLE_DEG) & (mesh.valences == 3))
    T = mesh.face_indices[mesh.face_offsets[bad][:, None] + np.arange(3)]
    a, b = T.reshape(-1), T[:, [1, 2, 0]].reshape(-1)
    return unique(np.minimum(a, b) * n + np.maximum(a, b))


def snap_to_border(mesh: Mesh) -> tuple[Mesh, int]:
    """Move quad corners that make needles with a generator's end point onto it.

    Parameters
    ----------
    mesh : Mesh
        A PQ mesh with ``vertex_data`` ``t`` and ``generator``.

    Returns
    -------
    Mesh
        Moved corners merged into the end points; the faces on each short edge
        gone, quads that now reach the border of kind :attr:`FaceKind.BORDER`.
    int
        Number of corners moved.
    """
    if "t" not in mesh.vertex_data or mesh.n_faces == 0:
        return mesh, 0
    t = np.asarray(mesh.vertex_data["t"])
    gen = np.asarray(mesh.vertex_data["generator"])
    n = np.int64(mesh.n_vertices)
    amin = _triangle_min_angles(mesh)
    keys = _splinter_edges(mesh, amin)
    if keys.size == 0:
        return mesh, 0
    p, q = keys // n, keys % n
    end = (t <= ON_BORDER) | (t >= 1.0 - ON_BORDER)
    same = gen[p] == gen[q]
    # v: the inner corner, b: the end point of the same generator.
    v = np.where(end[p], q, p)
    b = np.where(end[p], p, q)
    ok = same & (end[p] ^ end[q])
    v, b = v[ok], b[ok]
    if v.size == 0:
        return mesh, 0
    # v may slide only if it ends a generator diagonal in every polygon it is in:
    # the corner two places on lies on its generator, and no other polygon has it.
    idx = mesh.face_indices
    val = np.repeat(mesh.valences, mesh.valences)
    nxt = mesh.next_corners()
    opposite = idx[nxt[nxt]]
    blocked = np.zeros(mesh.n_vertices, bool)
    blocked[idx[(val > 4) | ((val == 4) & (gen[opposite] != gen[idx]))]] = True
    ok = ~blocked[v]
    v, b = v[ok], b[ok]
    # One move per vertex and per end point.
    _, first = np.unique(v, return_index=True)
    v, b = v[first], b[first]
    _, first = np.unique(b, return_index=True)
    v, b = v[first], b[first]
    if v.size == 0:
        return mesh, 0
    # The moves are measured together (neighbouring ones change each other's faces), so
    # once some are left out the rest are measured again, until every one left gains.
    while v.size:
        _, gain = _snapped(_near(mesh, np.concatenate([v, b])), v, b)
        keep = gain > SNAP_MIN_GAIN_DEG
        if keep.all():
            break
        v, b = v[keep], b[keep]
    if v.size == 0:
        return mesh, 0
    moved, _ = _snapped(mesh, v, b, measure=False)
    return moved, int(v.size)


def trim_border_needles(mesh: Mesh, scale: float | None = None, *,
                        report: dict | None = None) -> tuple[Mesh, int]:
    """Drop border vertices whose faces are all needles, where the border moves by a hair.

    Where the generators meet a director curve at a grazing angle, an end
    point can sit a sliver from the line through its neighbours, its only
    faces needles that no flip or collapse fattens (the vertex opposite is a
    quad corner).  Taking the end point and its needles away lets the border
    run along their far edges; every vertex left is still on its generator and
    no quad changes.  Taken only where the end point lies within
    :data:`~ruledmesh.tolerances.BORDER_TRIM_MAX_GAP` of the diagonal from those
    edges (the patch stays that close to the mesh) and the mesh stays a
    manifold.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh.
    scale : float, optional
        Length the bound is relative to (default: the mesh's bounding-box diagonal).

    report : dict, optional
        Filled with ``"touched"``: (V_out,) bool, the rim vertices of the fans dropped.

    Returns
    -------
    Mesh
        The mesh without those vertices and their triangles.
    int
        Number of vertices dropped.
    """
    if report is not None:
        report["touched"] = np.zeros(mesh.n_vertices, bool)
    if mesh.n_faces == 0:
        return mesh, 0
    n = np.int64(mesh.n_vertices)
    idx = mesh.face_indices
    face_of = mesh.face_of
    needle = _triangle_min_angles(mesh) < RESTART_ANGLE_DEG
    faces_at = np.bincount(idx, minlength=n)
    cand = (faces_at > 0) & (np.bincount(idx[needle[face_of]], minlength=n) == faces_at)
    if not cand.any():
        return mesh, 0
    keys, uses = mesh.edge_uses()
    on_border = _border_vertices(keys, uses, int(n))
    cand &= on_border
    if not cand.any():
        return mesh, 0
    tid, T = mesh.faces_of_valence(3)
    at = cand[T]
    rows = np.flatnonzero(at.sum(axis=1) == 1)       # a fan's triangles, one candidate each
    owner = T[rows][at[rows]]
    # The far edge of each fan triangle, and the candidate's distance from it.
    corner = np.argmax(at[rows], axis=1)
    p, q = T[rows, (corner + 1) % 3], T[rows, (corner + 2) % 3]
    V = mesh.vertices
    dist = segment_distances(V[owner], V[p], V[q])
    far = np.zeros(n)
    np.maximum.at(far, owner, dist)
    fan_size = np.bincount(owner, minlength=n)
    ok = cand & (fan_size == faces_at) & (far <= BORDER_TRIM_MAX_GAP * (scale or diagonal(V) or 1.0))
    # The fan's inner rim vertices turn into border vertices: they must not be on it already,
    # nor on the inner rim of another fan (the border would pinch there).  A fan's triangles
    # have no other candidate, so fans share at most rim vertices.
    rim = np.concatenate([p, q])
    rim_owner = np.concatenate([owner, owner])
    edge_of_fan = np.concatenate([np.minimum(owner, p) * n + np.maximum(owner, p),
                                  np.minimum(owner, q) * n + np.maximum(owner, q)])
    along = uses[np.searchsorted(keys, edge_of_fan)] == 1     # rim vertex beside it on the border
    pinch = np.zeros(n, bool)
    pinch[rim_owner[on_border[rim] & ~along]] = True
    ok &= ~pinch
    inner = ok[rim_owner] & ~along
    pairs = unique(rim_owner[inner] * n + rim[inner])
    fans = np.bincount(pairs % n, minlength=n)            # fans each vertex is inside the rim of
    ok &= np.bincount(rim_owner[inner & (fans[rim] > 1)], minlength=n) == 0
    if not ok.any():
        return mesh, 0
    drop = np.zeros(mesh.n_faces, bool)
    drop[tid[rows[ok[owner]]]] = True
    members, member_id = _rejoined(mesh.members, mesh.member_id, ok, int(n))
    out, new_index = replace(mesh.select_faces(~drop), members=members, member_id=member_id).compact_index()
    if report is not None:
        rim = new_index[np.concatenate([p, q])[np.tile(ok[owner], 2)]]
        report["touched"] = np.zeros(out.n_vertices, bool)
        report["touched"][rim[rim >= 0]] = True
    return out, int(ok.sum())


def _triangle_min_angles(mesh: Mesh) -> np.ndarray:
    """(F,) smallest corner angle of the triangles, degrees (180 for other faces)."""
    from ...analysis.faces import min_corner_angles

    out = np.full(mesh.n_faces, 180.0)
    f, F = mesh.faces_of_valence(3)
    out[f] = min_corner_angles(mesh.vertices, F)
    return out


def _snapped(mesh: Mesh, v: np.ndarray, b: np.ndarray, measure: bool = True) -> tuple[Mesh, np.ndarray]:
    """The mesh with each ``v`` merged into its ``b``, and (k,) the change of the smallest
    angle around each ``b`` (the faces of ``v`` and ``b`` before, of ``b`` after)."""
    out, new_index = _apply(mesh, v, b)
    # The merge marks the faces it changed as fill; the quads among them reach the border.
    kind = out.face_kind.copy()
    kind[(kind == FaceKind.FILL) & (out.valences == 4)] = FaceKind.BORDER
    out = replace(out, face_kind=kind)
    if not measure:
        return out, np.zeros(v.size)
    before, thin_before = _around_min(mesh, [v, b])
    # An end point whose faces the merge removed all of is left with none: no gain, a hole.
    kept = new_index[b]
    gone = kept < 0
    after, thin_after = _around_min(out, [kept])
    # A move that fattens the thinnest face but leaves more splinters around is no gain.
    return out, np.where(gone | (thin_after > thin_before), -1.0, after - before)


def _around_min(mesh: Mesh, groups: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(k,) the smallest angle of the faces at any of ``groups[j][i]``, per ``i``, and
    (k,) how many of those faces are splinters (each counted once)."""
    slot = np.full(mesh.n_vertices, -1)
    for g in groups:
        there = g >= 0                          # (-1: a vertex the mesh no longer has)
        slot[g[there]] = np.arange(g.size)[there]
    face_of = mesh.face_of
    s = slot[mesh.face_indices]
    out = np.full(groups[0].size, 180.0)
    angles = face_min_angles(mesh)
    np.minimum.at(out, s[s >= 0], angles[face_of[s >= 0]])
    n = np.int64(mesh.n_faces)
    pairs = unique(s[s >= 0] * n + face_of[s >= 0])
    thin = np.bincount((pairs // n)[angles[pairs % n] < RESTART_ANGLE_DEG], minlength=groups[0].size)
    return out, thin


def _cut_quads(mesh: Mesh, which: np.ndarray) -> tuple[Mesh, np.ndarray, np.ndarray]:
    """The quads marked in ``which`` (F,) cut along their fatter diagonal.

    Returns the mesh, the cut quads (k, 4) and their kinds (k,).
    """
    from ...analysis.faces import polygon_angles

    qid, Q = mesh.faces_of_valence(4)
    sel = which[qid]
    Q = Q[sel]
    V = mesh.vertices

    def fat(T):
        return polygon_angles(V[T]).min(axis=1)

    a1, a2, b1, b2 = Q[:, [0, 1, 2]], Q[:, [0, 2, 3]], Q[:, [0, 1, 3]], Q[:, [1, 2, 3]]
    use = np.minimum(fat(a1), fat(a2)) >= np.minimum(fat(b1), fat(b2))
    tris = np.concatenate([np.where(use[:, None], a1, b1), np.where(use[:, None], a2, b2)])
    keep = np.ones(mesh.n_faces, bool)
    keep[qid[sel]] = False
    cut = _rebuilt(mesh, keep, np.zeros((0, 4), np.int64), np.zeros(0, np.uint8))
    cut = _with_triangles(cut, tris, FaceKind.SPLIT)
    return cut, Q, mesh.face_kind[qid[sel]]


def _with_triangles(mesh: Mesh, tris: np.ndarray, kind: int) -> Mesh:
    """``mesh`` with triangles ``tris`` (k, 3) of one kind appended."""
    off = np.concatenate([mesh.face_offsets, mesh.face_offsets[-1] + 3 * np.arange(1, len(tris) + 1)])
    return Mesh(mesh.vertices, off, np.concatenate([mesh.face_indices, tris.reshape(-1)]),
                np.concatenate([mesh.face_kind, np.full(len(tris), kind, np.uint8)]), mesh.members,
                mesh.member_id, mesh.vertex_data, mesh.info)


def _joined_again(mesh: Mesh, quads: np.ndarray, kinds: np.ndarray) -> Mesh:
    """The cut quads whose two triangles are both still faces, joined again."""
    tid, T = mesh.faces_of_valence(3)
    if not len(quads) or not len(tid):
        return mesh
    n = np.int64(mesh.n_vertices)

    def key(X):
        X = np.sort(X, axis=1)
        return (X[:, 0] * n + X[:, 1]) * n + X[:, 2]

    have = key(T)
    order = np.argsort(have)
    table = have[order]

    def find(X):
        pos = np.clip(np.searchsorted(table, key(X)), 0, len(table) - 1)
        return pos, table[pos] == key(X)

    keep = np.ones(mesh.n_faces, bool)
    back = np.zeros(len(quads), bool)
    for first, second in (([0, 1, 2], [0, 2, 3]), ([0, 1, 3], [1, 2, 3])):
        pa, ha = find(quads[:, first])
        pb, hb = find(quads[:, second])
        both = ha & hb & ~back
        keep[tid[order[pa[both]]]] = False
        keep[tid[order[pb[both]]]] = False
        back |= both
    if not back.any():
        return mesh
    return _rebuilt(mesh, keep, quads[back], kinds[back])


def _short_edges(mesh: Mesh, bad: np.ndarray) -> np.ndarray:
    """(k, 2) the shortest edge of each triangle marked in ``bad`` (F,)."""
    tid, T = mesh.faces_of_valence(3)
    T = T[bad[tid]]
    P = mesh.vertices[T]
    length = np.linalg.norm(P - np.roll(P, -1, axis=1), axis=2)
    k = np.argmin(length, axis=1)
    r = np.arange(len(T))
    return np.stack([T[r, k], T[r, (k + 1) % 3]], axis=1)


def open_walled_splinters(mesh: Mesh, fatten: Callable[[Mesh, np.ndarray, float], Mesh],
                          measured: tuple[np.ndarray, np.ndarray] | None = None, *,
                          report: dict | None = None) -> tuple[Mesh, int]:
    """Cut the quads beside the splinters left into triangles and fatten again.

    Only a neighbourhood of the splinters is re-cut: the faces within two
    vertex rings of the opened quads and the splinters (the region); faces
    with a corner that a face outside the region also has stay as they are.
    Each connected piece of the region is kept as re-cut only if it has fewer
    faces below the splinter bar (or as many, with a larger smallest angle)
    and moved at most :data:`_OPEN_MAX_SHARE` of the area out of quads per
    splinter removed.

    Parameters
    ----------
    mesh : Mesh
    fatten : callable
        (Mesh, frozen vertices (V,) bool, scale) -> Mesh: the flips and collapses
        to run on the opened region, leaving the faces at frozen vertices alone,
        their sag bounds relative to ``scale`` (the whole mesh's diagonal).  The
        region mesh numbers its vertices in ``mesh`` by ``vertex_data["_id"]``.
    measured : ((F,) float64, (F,) float64), optional
        ``face_min_angles(mesh)`` and ``face_normals(mesh)[1]`` if the caller has them.
    report : dict, optional
        Filled with ``"touched"``: (V_out,) bool, the corners of the re-cut faces kept.

    Returns
    -------
    Mesh
    int
        Number of quads opened (net of those joined again).
    """
    opened = 0
    touched = np.zeros(mesh.n_vertices, bool)
    if report is not None:
        report["touched"] = touched
    if mesh.n_faces == 0:
        return mesh, 0
    amin, area = measured if measured is not None else (face_min_angles(mesh), face_normals(mesh)[1])
    total = float(area.sum())
    scale = diagonal(mesh.vertices) or 1.0
    for k in range(_OPEN_ROUNDS):
        bad = (amin < RESTART_ANGLE_DEG) & (mesh.valences == 3)
        # A mesh that is mostly splinters (rows far beyond an untrimmed patch) would be
        # opened everywhere for nothing: opening is for the few left among good faces.
        if not bad.any() or bad.sum() > _OPEN_MAX_SPLINTERS * mesh.n_faces:
            break
        # The quads on a splinter's edges first; then also those at its shortest edge.
        beside = _beside(mesh, amin, bad, ends=k > 0)
        if not beside.any():
            continue
        # The faces within two vertex rings of them.
        corners = mesh.face_indices[np.repeat(beside | bad, mesh.valences)]
        region = _touching(mesh, _rings(mesh, corners, 1))
        sub, frozen = _region(mesh, region)
        cut, quads, kinds = _cut_quads(sub, beside[region])
        done = fatten(cut, frozen, scale)
        # The collapses renumber the vertices: the cut quads in the new numbers.
        ids = np.asarray(sub.vertex_data["_id"])
        new_of = np.full(mesh.n_vertices, -1)
        new_of[np.asarray(done.vertex_data["_id"])] = np.arange(done.n_vertices)
        quads = new_of[ids[quads]]
        whole = (quads >= 0).all(axis=1)
        done = _joined_again(done, quads[whole], kinds[whole])
        mesh, amin, n_open, new_index, spliced = _kept_pieces(mesh, amin, region, sub, done, total)
        if new_index is not None:
            moved = new_index[np.flatnonzero(touched)]
            touched = np.zeros(mesh.n_vertices, bool)
            touched[moved[moved >= 0]] = True
            touched[spliced] = True
        opened += n_open
        if n_open == 0 and k > 0:
            break       # nothing changed: a further round would open the same quads
    if report is not None:
        report["touched"] = touched
    return mesh, opened


def _region(mesh: Mesh, region: np.ndarray) -> tuple[Mesh, np.ndarray]:
    """The faces marked ``region`` (F,) as a mesh of their own vertices, numbered in
    ``mesh`` by ``vertex_data["_id"]`` (no members), and (V,) the vertices of ``mesh``
    that a face outside the region also has.

    Read from the region's faces alone (the region is small, the mesh may be large),
    but for one count of the faces at every vertex.
    """
    faces = np.flatnonzero(region)
    val = mesh.valences[faces]
    corners = mesh.face_indices[np.repeat(mesh.face_offsets[faces], val) + ranks(val)]
    ids = unique(corners)
    local = np.searchsorted(ids, corners)
    faces_at = np.bincount(mesh.face_indices, minlength=mesh.n_vertices)
    frozen = faces_at > 0
    frozen[ids] = faces_at[ids] > np.bincount(local, minlength=ids.size)
    sub = Mesh(mesh.vertices[ids], offsets_from_valences(val), local, mesh.face_kind[faces],
               np.zeros((0, 2), np.int64), np.zeros(0, np.int64),
               {**{k: v[ids] for k, v in mesh.vertex_data.items()}, "_id": ids}, mesh.info)
    return sub, frozen


def _components(n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n,) int: connected components of the graph on ``n`` vertices with edges ``a b``,
    numbered from 0 (each vertex labelled by the smallest vertex it reaches, then ranked).

    Minimum labels spread along the edges with pointer jumping: a few whole-array
    steps for the small regions around splinters (scipy is not imported for a build).
    """
    label = np.arange(n)
    while True:
        low = label.copy()
        np.minimum.at(low, a, label[b])
        np.minimum.at(low, b, label[a])
        low = low[low]
        if np.array_equal(low, label):
            break
        label = low
    return np.unique(label, return_inverse=True)[1].reshape(-1)


def _kept_pieces(mesh: Mesh, amin: np.ndarray, region: np.ndarray, sub: Mesh, done: Mesh,
                 total: float) -> tuple[Mesh, np.ndarray, int, np.ndarray | None, np.ndarray]:
    """``mesh`` with the pieces of ``region`` (``sub``) where ``done``, their re-cut faces, is
    better.

    Returns the mesh, its (F,) smallest face angles, the number of quads opened, the new
    index of each old vertex (-1: removed; None: the mesh is unchanged) and the corners
    of the faces put in (new numbers).
    """

    n = sub.n_vertices
    idx = sub.face_indices
    label = _components(n, idx, idx[sub.next_corners()])
    ids = np.asarray(sub.vertex_data["_id"])
    sub_of = np.full(mesh.n_vertices, -1)
    sub_of[ids] = np.arange(n)
    done_ids = np.asarray(done.vertex_data["_id"])
    old_piece = label[idx[sub.face_offsets[:-1]]]
    new_piece = label[sub_of[done_ids[done.face_indices[done.face_offsets[:-1]]]]] if done.n_faces \
        else np.zeros(0, np.int64)
    k = int(label.max()) + 1 if n else 0
    old_min = amin[region]
    new_min = face_min_angles(done)
    _, old_area = face_normals(sub)
    _, new_area = face_normals(done)
    was = np.bincount(old_piece, weights=(old_min < RESTART_ANGLE_DEG).astype(float), minlength=k)
    now = np.bincount(new_piece, weights=(new_min < RESTART_ANGLE_DEG).astype(float), minlength=k)
    lo_old = np.full(k, 180.0)
    np.minimum.at(lo_old, old_piece, old_min)
    lo_new = np.full(k, 180.0)
    np.minimum.at(lo_new, new_piece, new_min)
    lost = np.bincount(old_piece, weights=np.where(sub.valences == 4, old_area, 0.0), minlength=k) \
        - np.bincount(new_piece, weights=np.where(done.valences == 4, new_area, 0.0), minlength=k)
    better = (now < was) | ((now == was) & (lo_new > lo_old))
    take = better & (lost <= _OPEN_MAX_SHARE * np.maximum(was - now, 0) * total)
    if not take.any():
        return mesh, amin, 0, None, np.zeros(0, np.int64)
    swap = np.zeros(mesh.n_faces, bool)
    swap[np.flatnonzero(region)[take[old_piece]]] = True
    part = done.select_faces(take[new_piece])
    # The vertices the collapses removed in the pieces taken.
    kept = np.zeros(mesh.n_vertices, bool)
    kept[done_ids] = True
    removed = np.zeros(mesh.n_vertices, bool)
    removed[ids] = ~kept[ids] & take[label]
    out, new_index = _spliced(mesh, swap, part, removed)
    out_min = np.concatenate([amin[~swap], new_min[take[new_piece]]])
    n_open = int((mesh.valences[swap] == 4).sum() - (part.valences == 4).sum())
    put_in = new_index[np.asarray(part.vertex_data["_id"])[part.face_indices]]
    return out, out_min, n_open, new_index, put_in


def _beside(mesh: Mesh, amin: np.ndarray, bad: np.ndarray, ends: bool = True) -> np.ndarray:
    """(F,) bool: the quads sharing an edge with a splinter or a corner with its shortest edge."""
    keys = _splinter_edges(mesh, amin)
    n = np.int64(mesh.n_vertices)
    idx = mesh.face_indices
    face_of = mesh.face_of
    # Only the corners of faces at a splinter's corners can be on its edges.
    at = np.zeros(mesh.n_vertices, bool)
    at[keys // n] = True
    at[keys % n] = True
    near = np.flatnonzero(at[idx] & at[idx[mesh.next_corners()]])
    nxt = idx[mesh.next_corners()[near]]
    edge = np.minimum(idx[near], nxt) * n + np.maximum(idx[near], nxt)
    pos = np.clip(np.searchsorted(keys, edge), 0, keys.size - 1)
    beside = np.zeros(mesh.n_faces, bool)
    beside[face_of[near[keys[pos] == edge]]] = True
    # With the quads at the ends of a splinter's shortest edge open, a collapse may
    # remove that edge.
    if ends:
        short = np.zeros(mesh.n_vertices, bool)
        short[_short_edges(mesh, bad)] = True
        beside[face_of[short[idx]]] = True
    return beside & (mesh.valences == 4)


def _spliced(mesh: Mesh, replaced: np.ndarray, part: Mesh, removed: np.ndarray) -> tuple[Mesh, np.ndarray]:
    """``mesh`` with its faces marked ``replaced`` (F,) swapped for the faces of ``part``
    (appended, in order) and the vertices marked ``removed`` (V,) taken out; (V,) the new
    index of each vertex (-1: dropped).

    ``part`` came from ``mesh`` with ``vertex_data["_id"]`` numbering its vertices in
    ``mesh``; the members are joined across the removed vertices.
    """
    ids = np.asarray(part.vertex_data["_id"])
    kept = mesh.select_faces(~replaced)
    off = np.concatenate([kept.face_offsets, kept.face_offsets[-1] + part.face_offsets[1:]])
    members, member_id = _rejoined(mesh.members, mesh.member_id, removed, mesh.n_vertices)
    out = Mesh(mesh.vertices, off, np.concatenate([kept.face_indices, ids[part.face_indices]]),
               np.concatenate([kept.face_kind, part.face_kind]), members, member_id,
               mesh.vertex_data, mesh.info)
    return out.compact_index()
