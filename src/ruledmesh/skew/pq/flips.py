"""Edge flips that fatten the triangles a PQ mesh has to keep.

Triangles are planar whatever their corners, so the triangles the mesher
leaves (zippers between runs, notch halves, the even bands next to torsal
generators) may be re-cut freely as long as every corner stays a vertex on a
generator.  Two triangles sharing an edge are re-cut along their other
diagonal when that raises the smaller of their smallest angles: Lawson's flip
with the max-min angle rule, in 3-D.  A flip is taken only where the two
triangles are nearly coplanar and stay so (no fold, no ridge cut off), so the
mesh keeps to the surface; quads and their edges are never touched.

Flips are chosen by rounds of mutual best choice (each triangle names the
flip that gains it most; flips that both triangles name are taken), whole
arrays per round: no loop over faces.
"""

from __future__ import annotations

import numpy as np

from ..._arrays import cross, diagonal, lookup, norm, unique
from ...analysis.faces import min_corner_angles
from ...kernels import wanted
from ...mesh import FaceKind, Mesh
from ...tolerances import (
    FLIP_ACTIVE_DEG,
    FLIP_MAX_BEND_DEG,
    FLIP_MAX_SAG,
    FLIP_MIN_GAIN_DEG,
    SPLINTER_FLIP_MAX_SAG,
    TINY,
)
from .pairing import _adjacent, _around, _at, _corners

__all__ = ["flip_splinters", "flip_triangles"]

_ROUNDS = 40
# A run ``near`` a change weighs the triangles this many corner-sharing steps from it: a
# flip there may make its neighbours' flips worth taking, two or three steps on.
NEAR_RINGS = 4


def _angles(P: np.ndarray) -> np.ndarray:
    """(F,) smallest interior angle, degrees, of triangles ``P`` (F, 3, 3)."""
    from ...analysis.faces import polygon_angles

    return polygon_angles(P).min(axis=1)


def _unit_normals(p, q, r) -> np.ndarray:
    n = cross(q - p, r - p)
    return n / np.maximum(norm(n), TINY)[:, None]


def _edge_keys(mesh_faces: list[np.ndarray], n: int, among: np.ndarray) -> np.ndarray:
    """Sorted undirected edge keys ``lo * n + hi`` of fixed-valence face arrays, of the edges
    whose two ends are both marked in ``among`` (n,) bool.

    A flip re-cuts triangles among their own corners, so only an edge between two corners
    of the triangles taking part can be made again: the others (most of a large mesh's
    quad edges) need not be sorted.
    """
    keys = []
    for F in mesh_faces:
        if len(F):
            a, b = F.reshape(-1), np.roll(F, -1, axis=1).reshape(-1)
            both = among[a] & among[b]
            a, b = a[both], b[both]
            keys.append(np.minimum(a, b) * n + np.maximum(a, b))
    return unique(np.concatenate(keys)) if keys else np.zeros(0, np.int64)


def _ring(t1: np.ndarray, t2: np.ndarray, mark: np.ndarray) -> np.ndarray:
    """``mark`` (T,) bool and the triangles sharing an edge with a marked one."""
    out = mark.copy()
    out[t2[mark[t1]]] = True
    out[t1[mark[t2]]] = True
    return out


def _pair_measures(V: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray,
                   old: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """(P,) the flipped pairs' smaller smallest angle, and whether each flip may be taken.

    Pairs of triangles ``(b, c, a)``, ``(c, b, d)`` with the smaller smallest
    angle ``old``; a flip gains, and keeps to the surface (no fold, no ridge
    cut off).  :func:`ruledmesh.kernels.geometry.flip_pairs` is the same, bit for bit.
    """
    bend = np.cos(np.radians(FLIP_MAX_BEND_DEG))
    kern = wanted(len(a))
    if kern is not None:
        return kern.flip_pairs(V, a, b, c, d, old, FLIP_MIN_GAIN_DEG, bend, FLIP_MAX_SAG * scale)
    A, B, C, D = V[a], V[b], V[c], V[d]
    new = np.minimum(_angles(np.stack([A, B, D], 1)), _angles(np.stack([A, D, C], 1)))
    n1, n2 = _unit_normals(A, B, C), _unit_normals(B, D, C)
    m1, m2 = _unit_normals(A, B, D), _unit_normals(A, D, C)
    mean = n1 + n2
    mean /= np.maximum(norm(mean), TINY)[:, None]
    # The flipped pair's height over the old one: how far the surface moves.
    sag = np.abs(np.einsum("ij,ij->i", 0.5 * (A + D) - 0.5 * (B + C), mean))
    ok = (new > old + FLIP_MIN_GAIN_DEG) & (np.einsum("ij,ij->i", n1, n2) >= bend) \
        & (np.einsum("ij,ij->i", m1, m2) >= bend) & (np.einsum("ij,ij->i", m1, mean) >= bend) \
        & (np.einsum("ij,ij->i", m2, mean) >= bend) & (sag <= FLIP_MAX_SAG * scale) & (a != d)
    return new, ok


def _round(V: np.ndarray, tri: np.ndarray, tmin: np.ndarray, fixed: np.ndarray, scale: float,
           changed: np.ndarray | None, adjacency: tuple | None = None) -> np.ndarray:
    """One round of mutual-best flips on ``tri`` (in place); (T,) bool, the triangles it changed.

    ``tmin`` (T,) holds the smallest angle of each triangle of ``tri`` and is
    kept up to date (in place).  ``fixed`` holds the sorted edge keys of every
    other face (quads, triangles left out of the rounds): a flip may not make
    one of those edges again.
    ``changed`` marks the triangles the previous round changed (None: the
    first round).  Only pairs near them can have gained or lost their best
    choice, so the round weighs the pairs touching them, their neighbours and
    the neighbours' neighbours (every pair of a triangle whose choice may have
    changed, so each such triangle's best is exact), and takes only pairs with
    a triangle that changed or borders one: the flips every pair would give.
    ``adjacency``: the first round's ``pairing._adjacent(tri, n)`` if known
    (its keys may hold edges of ``fixed`` too).
    """
    n = len(V)
    done = np.zeros(len(tri), bool)
    near: np.ndarray | None = None
    if changed is None:
        t1, t2, a, b, c, d, keys = _adjacent(tri, n) if adjacency is None else adjacency
    else:
        # Every pair weighed, and every edge a taken flip could make again, lies
        # among the triangles three corner-sharing steps from a change: the
        # adjacency of those (rows in order, so pairs come in the same order and
        # with the same sides) is the whole mesh's there.
        rows = np.flatnonzero(_around(tri, n, changed, 3))
        t1, t2, a, b, c, d, keys = _adjacent(tri[rows], n)
        t1, t2 = rows[t1], rows[t2]
    if t1.size == 0:
        return done
    if changed is not None:
        near = _ring(t1, t2, changed)              # choices that may have changed
        weigh = _ring(t1, t2, near)                # their partners: exact best choices
        sel = np.flatnonzero(weigh[t1] | weigh[t2])
        t1, t2, a, b, c, d = t1[sel], t2[sel], a[sel], b[sel], c[sel], d[sel]
    old = np.minimum(tmin[t1], tmin[t2])
    new, ok = _pair_measures(V, a, b, c, d, old, scale)
    if near is not None:
        # Pairs away from every change keep the choice they had: not taken then, nor now.
        ok &= near[t1] | near[t2]
    if not ok.any():
        return done
    # The new diagonal must not be an edge already (it would join three faces).
    new_key = np.minimum(a, d) * n + np.maximum(a, d)
    ok &= ~(_member(new_key, fixed) | _member(np.minimum(a, d) * (n + 1) + np.maximum(a, d), keys))
    cand = np.flatnonzero(ok)
    if cand.size == 0:
        return done
    take = cand[_mutual_best(t1[cand], t2[cand], (new - old)[cand], len(tri))]
    # Two flips of one round making the same diagonal: keep the first.
    _, keep = np.unique(new_key[take], return_index=True)
    take = take[keep]
    tri[t1[take]] = np.stack([a[take], b[take], d[take]], axis=1)
    tri[t2[take]] = np.stack([a[take], d[take], c[take]], axis=1)
    done[t1[take]] = done[t2[take]] = True
    tmin[done] = min_corner_angles(V, tri[done])
    return done


def _member(keys: np.ndarray, sorted_keys: np.ndarray) -> np.ndarray:
    """(k,) bool: which ``keys`` are in ``sorted_keys``."""
    return lookup(keys, sorted_keys) >= 0


def _active(V: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray, tuple | None]:
    """(T,) bool: triangles thinner than :data:`FLIP_ACTIVE_DEG` and their edge neighbours;
    (T,) the smallest angle of every triangle; the adjacency of the marked ones
    (as ``pairing._adjacent`` of ``tri[marked]``, its keys those of all ``tri``), or None.

    Only these take part in the rounds: a flip between two fat triangles gains
    little, and most of a large mesh's triangles are fat.
    """
    ang = min_corner_angles(V, tri)
    thin = ang < FLIP_ACTIVE_DEG
    if not thin.any():
        return thin, ang, None
    adjacency = _adjacent(tri, len(V))
    t1, t2 = adjacency[:2]
    near = thin.copy()
    near[t2[thin[t1]]] = True
    near[t1[thin[t2]]] = True
    # Two rings: a thin triangle's best partner may sit beside its neighbour.
    out = near.copy()
    out[t2[near[t1]]] = True
    out[t1[near[t2]]] = True
    return out, ang, _restricted(adjacency, out)


def _restricted(adjacency: tuple, live: np.ndarray) -> tuple | None:
    """The pairs of ``adjacency`` between ``live`` triangles, rows renumbered among those.

    They are the live triangles' own pairs, in the same order, when no edge has
    three triangles or more (else two live ones could share one): None then.
    """
    t1, t2, a, b, c, d, keys = adjacency
    if keys.size > 2 and bool((keys[2:] == keys[:-2]).any()):
        return None
    keep = np.flatnonzero(live[t1] & live[t2])
    rank = np.cumsum(live) - 1
    return rank[t1[keep]], rank[t2[keep]], a[keep], b[keep], c[keep], d[keep], keys


def _mutual_best(t1: np.ndarray, t2: np.ndarray, gain: np.ndarray, n: int) -> np.ndarray:
    """The pairs (indices into ``t1``, ``t2``) both of whose ``n`` triangles name them their
    best flip by ``gain``, ties to the first pair: no triangle is in two flips taken."""
    best = np.full(n, -np.inf)
    np.maximum.at(best, t1, gain)
    np.maximum.at(best, t2, gain)
    top = np.flatnonzero((gain >= best[t1]) & (gain >= best[t2]))
    first = np.full(n, len(t1))
    np.minimum.at(first, t1[top], top)
    np.minimum.at(first, t2[top], top)
    return top[(first[t1[top]] == top) & (first[t2[top]] == top)]


def _retriangulated(mesh: Mesh, ids: np.ndarray, tri: np.ndarray, before: np.ndarray) -> Mesh:
    """``mesh`` with its triangles ``ids`` now ``tri`` (were ``before``); those that changed
    are of kind :attr:`FaceKind.FILL` (no longer halves of a quad)."""
    changed = (tri != before).any(axis=1)
    kind = mesh.face_kind.copy()
    kind[ids[changed]] = FaceKind.FILL
    idx = mesh.face_indices.copy()
    idx[mesh.face_offsets[ids][:, None] + np.arange(3)] = tri
    return Mesh(mesh.vertices, mesh.face_offsets, idx, kind, mesh.members, mesh.member_id,
                mesh.vertex_data, mesh.info)


def flip_triangles(mesh: Mesh, changeable: np.ndarray | None = None,
                   scale: float | None = None, *, near: np.ndarray | None = None,
                   report: dict | None = None) -> tuple[Mesh, int]:
    """Re-cut pairs of adjacent triangles for a larger smallest angle.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh; only its triangles are changed.
    changeable : (F,) bool, optional
        The faces that may change (default: every triangle).
    scale : float, optional
        Length the sag bound is relative to (default: the mesh's bounding-box
        diagonal; a part of a mesh passes the whole one's).
    near : (V,) bool, optional
        Only the triangles within :data:`NEAR_RINGS` corner-sharing steps of a
        face at these vertices take part: a run after a local change to a mesh
        whose flips had settled, which finds the flips a run over the whole
        mesh would (no flip was left elsewhere), at the cost of the region.
    report : dict, optional
        Filled with ``"settled"`` (bool: the last round made no flip, so a later
        run may take ``near``), ``"touched"`` ((V,) bool: the corners of the
        flipped triangles) and ``"again"`` ((V,) bool: the corners of the
        triangles a later run weighs that this one did not, see :func:`_report`).

    Returns
    -------
    Mesh
        The same vertices, members and quads; flipped triangles are of kind
        :attr:`FaceKind.FILL` (they are no longer halves of a quad).
    int
        Number of flips made.
    """
    if report is not None:
        report.update(settled=True, touched=np.zeros(mesh.n_vertices, bool),
                      again=np.zeros(mesh.n_vertices, bool))
    val = mesh.valences
    is_tri = val == 3
    if is_tri.sum() < 2:
        return mesh, 0
    V = mesh.vertices
    scale = scale or diagonal(V) or 1.0
    ids = np.flatnonzero(is_tri)
    tri_all = mesh.face_indices[mesh.face_offsets[ids][:, None] + np.arange(3)].astype(np.int64)
    if near is not None:
        live, ang = _active_near(V, tri_all, near)
        adjacency = None
    else:
        live, ang, adjacency = _active(V, tri_all)
    if changeable is not None and not changeable[ids].all():
        live &= changeable[ids]
        adjacency = None        # the rounds find the pairs among the triangles left
    if not live.any():
        return mesh, 0
    tri = tri_all[live]
    fixed = _fixed_edges(mesh, ids, live, tri)
    tmin = ang[live]
    before = tri.copy()
    flips = 0
    made = 0
    changed = None
    for _ in range(_ROUNDS):
        changed = _round(V, tri, tmin, fixed, scale, changed, adjacency)
        made = int(changed.sum()) // 2
        flips += made
        if made == 0:
            break
    if report is not None:
        report["settled"] = made == 0
    if flips == 0:
        return mesh, 0
    if report is not None:
        _report(report, tri_all, live, tri, before, tmin)
    return _retriangulated(mesh, ids[live], tri, before), flips


def _report(report: dict, tri_all: np.ndarray, live: np.ndarray, tri: np.ndarray, before: np.ndarray,
            tmin: np.ndarray) -> None:
    """Mark in ``report`` the corners of the flipped triangles (``"touched"``) and of the
    triangles a later run over the whole mesh would weigh that this run did not (``"again"``).

    A run weighs the triangles near the thin ones it starts with.  A flip that leaves a
    triangle thin brings its neighbours into a later run's reach: those that were not
    ``live`` (T,) here may have flips to offer; every other pair was weighed and
    settled.  ``tri`` are the live triangles now (``before`` as they were, ``tmin``
    their smallest angles now).
    """
    flipped = (tri != before).any(axis=1)
    report["touched"][tri[flipped]] = True
    thin = np.zeros(len(tri_all), bool)
    thin[np.flatnonzero(live)[flipped & (tmin < FLIP_ACTIVE_DEG)]] = True
    if thin.any():
        now = tri_all.copy()
        now[live] = tri
        report["again"][now[_around(now, len(report["again"]), thin, 2) & ~live]] = True


def _active_near(V: np.ndarray, tri: np.ndarray, near: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_active`'s marks and angles for the triangles within :data:`NEAR_RINGS` steps
    of a triangle with a corner in ``near`` (V,) bool; the others unmarked (angles 0).

    The marks of those need the thin triangles two steps further: only that region is
    measured.
    """
    n = len(V)
    core = _around(tri, n, _at(tri, near), NEAR_RINGS)
    rows = np.flatnonzero(_around(tri, n, core, 2))
    live = np.zeros(len(tri), bool)
    ang = np.zeros(len(tri))
    if rows.size:
        live_r, ang[rows], _ = _active(V, tri[rows])
        live[rows] = live_r & core[rows]
    return live, ang


def _fixed_edges(mesh: Mesh, ids: np.ndarray, live: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Sorted edge keys of the faces other than the ``live`` triangles (``tri``; ``ids`` (T,)
    the faces of all triangles) that join two of their corners: the edges no flip may make
    again.

    Only faces with a corner among the live triangles' can have such an edge: the
    others (most of a large mesh) are not read.
    """
    n = len(mesh.vertices)
    corners = _corners(tri, n)
    faces = unique(mesh.face_of[np.flatnonzero(corners[mesh.face_indices])])
    is_live = np.zeros(mesh.n_faces, bool)
    is_live[ids[live]] = True
    faces = faces[~is_live[faces]]
    val = mesh.valences[faces]
    others = [mesh.face_indices[mesh.face_offsets[f][:, None] + np.arange(k)]
              for k in unique(val).tolist() for f in [faces[val == k]]]
    return _edge_keys(others, n, corners)


def _splinter_pairs(V: np.ndarray, tri: np.ndarray, tmin: np.ndarray, on_generator: np.ndarray,
                    fixed: np.ndarray, scale: float) -> tuple[np.ndarray, ...]:
    """The flips a splinter may take: (k,) first and second triangle, (k,) corners ``a, b, c, d``
    as in :func:`_pair_measures`, (k,) angle gained.

    Pairs of :func:`.pairing._adjacent` with a splinter among the two whose flip
    makes the pair's smaller smallest angle larger and keeps it flat and on the
    side of the fatter old triangle, moving the surface by at most
    :data:`SPLINTER_FLIP_MAX_SAG` of ``scale`` (the distance of the two diagonals);
    the edge given up is no generator segment (``on_generator`` (V,) int: the
    generator of each vertex) and the new one no edge of ``fixed``.
    """
    from ...analysis.faces import SPLINTER_DEG

    n = len(V)
    t1, t2, a, b, c, d, keys = _adjacent(tri, n)
    old = np.minimum(tmin[t1], tmin[t2])
    sel = np.flatnonzero((old < SPLINTER_DEG) & (a != d) & (on_generator[b] != on_generator[c]))
    t1, t2, a, b, c, d, old = t1[sel], t2[sel], a[sel], b[sel], c[sel], d[sel], old[sel]
    A, B, C, D = V[a], V[b], V[c], V[d]
    new = np.minimum(_angles(np.stack([A, B, D], 1)), _angles(np.stack([A, D, C], 1)))
    # A splinter's own normal says little (its corners nearly lie on a line): the
    # flipped pair is held to the fatter old triangle's.
    fat = np.where((tmin[t1] >= tmin[t2])[:, None], _unit_normals(A, B, C), _unit_normals(B, D, C))
    m1, m2 = _unit_normals(A, B, D), _unit_normals(A, D, C)
    bend = np.cos(np.radians(FLIP_MAX_BEND_DEG))
    across = cross(D - A, C - B)
    height = np.abs(np.einsum("ij,ij->i", B - A, across)) / np.maximum(norm(across), TINY)
    new_key = np.minimum(a, d) * n + np.maximum(a, d)
    ok = (new > old + FLIP_MIN_GAIN_DEG) & (np.einsum("ij,ij->i", m1, m2) >= bend) \
        & (np.einsum("ij,ij->i", m1, fat) >= bend) & (np.einsum("ij,ij->i", m2, fat) >= bend) \
        & (height <= SPLINTER_FLIP_MAX_SAG * scale) \
        & ~_member(new_key, fixed) & ~_member(np.minimum(a, d) * (n + 1) + np.maximum(a, d), keys)
    return t1[ok], t2[ok], a[ok], b[ok], c[ok], d[ok], (new - old)[ok]


def flip_splinters(mesh: Mesh, scale: float | None = None) -> tuple[Mesh, int]:
    """Flip the edges of the triangular splinters :func:`flip_triangles` leaves.

    Those rounds keep every pair within :data:`FLIP_MAX_BEND_DEG` before the
    flip; a splinter's normal is ill-defined, so a splinter bent against its
    neighbour stays.  Here a pair with a splinter is flipped where the new pair
    is flat and faces as the fatter old triangle does, and the two diagonals lie
    within :data:`SPLINTER_FLIP_MAX_SAG` of ``scale`` (default: the mesh's
    diagonal): the mesh moves that little, and only where it had a splinter.

    Returns the mesh (flipped triangles of kind :attr:`FaceKind.FILL`) and the
    number of flips.
    """
    from ...analysis.faces import SPLINTER_DEG

    val = mesh.valences
    ids = np.flatnonzero(val == 3)
    if ids.size < 2:
        return mesh, 0
    V = mesh.vertices
    tri_all = mesh.face_indices[mesh.face_offsets[ids][:, None] + np.arange(3)].astype(np.int64)
    ang = min_corner_angles(V, tri_all)
    if not (ang < SPLINTER_DEG).any():
        return mesh, 0
    scale = scale or diagonal(V) or 1.0
    # The triangles a few steps from a splinter take part; the others' edges stay.
    live = _around(tri_all, len(V), ang < SPLINTER_DEG, 3)
    ids, tri, tmin = ids[live], tri_all[live], ang[live]
    others = [tri_all[~live]] + [mesh.face_indices[mesh.face_offsets[f][:, None] + np.arange(k)]
                                 for k in unique(val[val != 3]).tolist() for f in [np.flatnonzero(val == k)]]
    fixed = _edge_keys(others, len(V), _corners(tri, len(V)))
    on_generator = np.asarray(mesh.vertex_data["generator"])
    before = tri.copy()
    flips = 0
    for _ in range(_ROUNDS):
        t1, t2, a, b, c, d, gain = _splinter_pairs(V, tri, tmin, on_generator, fixed, scale)
        if t1.size == 0:
            break
        take = _mutual_best(t1, t2, gain, len(tri))
        a, b, c, d = a[take], b[take], c[take], d[take]
        tri[t1[take]] = np.stack([a, b, d], axis=1)
        tri[t2[take]] = np.stack([a, d, c], axis=1)
        done = np.r_[t1[take], t2[take]]
        tmin[done] = min_corner_angles(V, tri[done])
        flips += take.size
    if flips == 0:
        return mesh, 0
    return _retriangulated(mesh, ids, tri, before), flips
