"""Hybrid HP-patch meshes from any set of generators (paper §4.1, Fig. 9).

The warped strip between two consecutive generators ``g_i = (a_i, b_i)`` and
``g_{i+1}`` is filled with the bilinear patch through ``a_i, a_{i+1},
b_{i+1}, b_i``, a hyperbolic paraboloid whose two families of isolines are
straight lines (its two reguli).  Each strip is sampled at ``u = r / n``
(``n - 1 = midpoints`` inserted generators, the paper uses one) and
``v = j / k`` (``k = divisions`` of the generators, the paper uses 8), which
gives one global node grid ``X[c, j]``, column ``c = i n + r``, row ``j``.

The faces are the checkerboard of that grid (the colour of ``X[0, 0]`` are the
vertices, a face is centred on every node of the other colour)::

    [X[c-1, j], X[c, j-1], X[c+1, j], X[c, j+1]]

* centred inside a strip, the face is a quad whose diagonals are a ``u``- and
  a ``v``-isoline of one HP meeting at ``X[c, j]``: planar by construction
  (it is even a parallelogram, since the isolines are affinely parametrised);
* centred on an input generator, its two halves lie on two different HPs
  whose tangent planes differ along ``g_i``: it becomes two triangles sharing
  the segment ``X[c, j-1] X[c, j+1]`` of ``g_i`` (or, with ``flip``, the
  other diagonal: the paper's "creative option");
* centred on the border, the half (or quarter) inside the patch is a triangle.

The end points of every input generator are always vertices (when the parity
of the grid would make them face centres, the border triangle is split
there), so each input segment ``a_i b_i`` is a chain of mesh edges, and the
strips share the division of their common generator: the mesh is conforming
by construction, its faces are indexed by grid node, and it is built in a
few broadcasts.

Degenerate input (generators sharing an end point, crossing at a division
point, a cone's apex) makes grid nodes coincide or faces collapse to zero
area; :func:`_repair` merges coincident vertices, drops the collapsed faces
and splits their neighbours so that no T-junction is left (a loop over the
degenerate faces only, which are rare).
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np

from .._arrays import diagonal, member, unique
from .._validation import check_bool, check_int, check_points
from ..budget import HYBRID_BYTES_PER_NODE, MAX_BUILD_BYTES, MAX_DIVISIONS, MAX_GRID_NODES, gib
from ..errors import GeometryError, ParameterError
from ..mesh import FaceKind, Mesh
from ..normalise import normalised
from ..tolerances import DEFAULT, TINY, Tolerances

__all__ = ["hybrid_mesh", "hybrid_grid", "orient_generators", "checkerboard_faces"]



# --------------------------------------------------------------------------- geometry
def orient_generators(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Which generators to reverse so that no strip is needlessly a bow-tie.

    Generator ``i + 1`` is reversed relative to ``i`` when that makes the two
    border edges of their strip shorter in sum (``|a_i a_{i+1}| + |b_i
    b_{i+1}|``); lines given in arbitrary order of their end points then
    give the strips a designer expects.  Generators from director curves are
    never reversed (their end points already follow the curves).

    Parameters
    ----------
    a, b : (m, 3) float64

    Returns
    -------
    (m,) bool
        True where the generator is to be traversed from ``b`` to ``a``.
    """
    keep = (np.linalg.norm(a[1:] - a[:-1], axis=1) + np.linalg.norm(b[1:] - b[:-1], axis=1))
    swap = (np.linalg.norm(a[1:] - b[:-1], axis=1) + np.linalg.norm(b[1:] - a[:-1], axis=1))
    relative = swap < keep
    # Reversal is relative to the (possibly reversed) previous generator: cumulative parity.
    return np.concatenate([[False], np.cumsum(relative) % 2 == 1])


def hybrid_grid(a: np.ndarray, b: np.ndarray, n: int, k: int) -> np.ndarray:
    """Nodes of the HP-patch grid of all strips.

    Parameters
    ----------
    a, b : (m, 3) float64
        Generator end points.
    n : int
        Columns per strip (``midpoints + 1``).
    k : int
        Rows (divisions of each generator).

    Returns
    -------
    X : ((m - 1) n + 1, k + 1, 3) float64
        ``X[i n, j] = a_i + (j / k) (b_i - a_i)`` exactly on the input generator
        (computed once, so neighbouring strips share it bit for bit) and
        ``X[i n + r, j]`` the bilinear patch of strip ``i`` at ``u = r / n``.
    """
    m = len(a)
    v = np.arange(k + 1) / k
    G = a[:, None, :] + v[None, :, None] * (b - a)[:, None, :]
    cols = (m - 1) * n + 1
    c = np.arange(cols)
    strip = np.minimum(c // n, m - 2)
    u = (c - strip * n) / n
    X = G[strip] + u[:, None, None] * (G[strip + 1] - G[strip])
    X[::n] = G
    return X


def checkerboard_faces(C: int, k: int, n: int, flip: bool = False
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Faces of the hybrid checkerboard on a ``(C + 1) x (k + 1)`` node grid.

    Node ``(c, j)`` has index ``c (k + 1) + j``.  Vertices are the nodes with
    ``c + j`` even plus the end points of every input generator (columns
    ``c = 0 mod n``, rows 0 and ``k``).

    Parameters
    ----------
    C, k, n : int
        Last column, last row, columns per strip.
    flip : bool
        Use the other diagonal of each pair of triangles straddling an
        interior input generator.

    Returns
    -------
    quads : (Q, 4) int64
    triangles : (T, 3) int64
        Node indices, counter-clockwise in the ``(c, j)`` plane.
    vertex : (C + 1, k + 1) bool
        The nodes that are vertices.
    """
    cc, jj = np.meshgrid(np.arange(C + 1), np.arange(k + 1), indexing="ij")
    gen_col = cc % n == 0
    forced = gen_col & ((jj == 0) | (jj == k))
    vertex = ((cc + jj) % 2 == 0) | forced
    c, j = np.nonzero((cc + jj) % 2 == 1)
    K = k + 1
    node = c * K + j
    L, R, B, T = node - K, node + K, node - 1, node + 1
    hasL, hasR, hasB, hasT = c > 0, c < C, j > 0, j < k
    M = forced[c, j]
    on_gen = gen_col[c, j]
    full = hasL & hasR & hasB & hasT
    quads = np.stack([L, B, R, T], axis=1)[full & ~on_gen]
    tris = []
    g = full & on_gen
    if flip:
        tris += [np.stack([L, B, R], 1)[g], np.stack([L, R, T], 1)[g]]
    else:
        tris += [np.stack([L, B, T], 1)[g], np.stack([B, R, T], 1)[g]]
    # Border halves: bottom / top rows (split at a forced end point), left / right columns.
    s = hasL & hasR & ~hasB
    tris += [np.stack([L, R, T], 1)[s & ~M], np.stack([L, node, T], 1)[s & M],
             np.stack([node, R, T], 1)[s & M]]
    s = hasL & hasR & ~hasT
    tris += [np.stack([L, B, R], 1)[s & ~M], np.stack([L, B, node], 1)[s & M],
             np.stack([B, R, node], 1)[s & M]]
    s = ~hasL & hasB & hasT
    tris += [np.stack([B, R, T], 1)[s]]
    s = ~hasR & hasB & hasT
    tris += [np.stack([L, B, T], 1)[s]]
    # Corner quarters (the corner node is a generator end point, hence a vertex).
    tris += [np.stack([L, node, T], 1)[~hasR & ~hasB & hasL & hasT],
             np.stack([B, R, node], 1)[~hasL & ~hasT & hasR & hasB],
             np.stack([L, B, node], 1)[~hasR & ~hasT & hasL & hasB],
             np.stack([node, R, T], 1)[~hasL & ~hasB & hasR & hasT]]
    return quads.astype(np.int64), np.concatenate(tris).astype(np.int64), vertex


def _generator_members(vertex: np.ndarray, n: int, K: int) -> tuple[np.ndarray, np.ndarray]:
    """Consecutive vertex nodes along every input generator column."""
    gv = vertex[::n]                                  # (m, k + 1)
    gi, gj = np.nonzero(gv)
    same = gi[1:] == gi[:-1]
    nodes = gi * n * K + gj
    return np.stack([nodes[:-1][same], nodes[1:][same]], axis=1), gi[:-1][same]


# --------------------------------------------------------------------------- repair
def _flat(V: np.ndarray, f: np.ndarray, tol: Tolerances) -> np.ndarray:
    """(F,) bool: faces ``f`` (F, k) of zero area relative to their longest edge."""
    P = V[f]
    cr = np.cross(P, np.roll(P, -1, axis=1)).sum(axis=1)
    area = 0.5 * np.linalg.norm(cr, axis=1)
    edge = np.linalg.norm(P - np.roll(P, -1, axis=1), axis=2).max(axis=1)
    return area <= tol.degenerate * np.maximum(edge, TINY) ** 2


def _edge_keys(f: np.ndarray, n: int) -> np.ndarray:
    e = np.stack([f, np.roll(f, -1, axis=1)], axis=2)
    e.sort(axis=2)
    return e[..., 0] * n + e[..., 1]


def _merge_coincident(V: np.ndarray, faces: list[np.ndarray], radius: float,
                      tol: Tolerances) -> np.ndarray:
    """(N,) int64: a representative vertex per vertex, merging where faces collapse.

    Two points within ``radius`` are merged when they are corners of one face,
    or of one connected set of flat faces (two collinear triangles back to
    back across a generator that both others cross at the same point).
    Coincident points far apart in the grid are a place where the input
    surface touches itself; merging them would change the topology.
    """
    from scipy.sparse import coo_matrix, csr_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    n = len(V)
    used = unique(np.concatenate([f.ravel() for f in faces]))
    pairs = used[cKDTree(V[used]).query_pairs(radius, output_type="ndarray")].reshape(-1, 2)
    if len(pairs) == 0:
        return np.arange(n)
    rows, cols, n_groups = [], [], 0
    flat_faces = []
    for f in faces:
        rows.append(np.repeat(np.arange(len(f)) + n_groups, f.shape[1]))
        cols.append(f.ravel())
        n_groups += len(f)
        flat_faces.append(f[_flat(V, f, tol)])
    # Connected sets of flat faces (sharing an edge) are groups too.
    flat_list = [(f, _edge_keys(f, n)) for f in flat_faces if len(f)]
    if flat_list:
        nf = sum(len(f) for f, _ in flat_list)
        fid = np.concatenate([np.repeat(np.arange(len(f)), f.shape[1]) + off for (f, _), off in
                              zip(flat_list, np.cumsum([0] + [len(f) for f, _ in flat_list[:-1]]))])
        keys = np.concatenate([k.ravel() for _, k in flat_list])
        order = np.argsort(keys, kind="stable")
        same = keys[order][1:] == keys[order][:-1]
        link = np.stack([fid[order][:-1][same], fid[order][1:][same]], axis=1)
        graph = coo_matrix((np.ones(len(link)), (link[:, 0], link[:, 1])), shape=(nf, nf))
        _, comp = connected_components(graph, directed=False)
        verts = np.concatenate([f.ravel() for f, _ in flat_list])
        rows.append(comp[fid] + n_groups)
        cols.append(verts)
        n_groups += int(comp.max()) + 1
    group, vertex = np.concatenate(rows), np.concatenate(cols)
    inc = csr_matrix((np.ones(len(vertex)), (vertex, group)), shape=(n, n_groups))
    share = np.asarray(inc[pairs[:, 0]].multiply(inc[pairs[:, 1]]).sum(axis=1)).ravel() > 0
    pairs = pairs[share]
    if len(pairs) == 0:
        return np.arange(n)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    # The smallest index of each component represents it.
    rep = np.full(label.max() + 1, n, dtype=np.int64)
    np.minimum.at(rep, label, np.arange(n))
    return rep[label]


def _fan(V: np.ndarray, poly: list[int]) -> list[list[int]]:
    """Triangulate a planar polygon (a face with vertices inserted on its edges).

    Tries a fan from every vertex and keeps the one whose triangles all turn
    like the polygon and whose smallest triangle is largest.
    """
    P = V[poly]
    normal = np.cross(P, np.roll(P, -1, axis=0)).sum(axis=0)
    best, best_score = None, -np.inf
    n = len(poly)
    for s in range(n):
        order = [poly[(s + t) % n] for t in range(n)]
        tri = np.array([[order[0], order[t], order[t + 1]] for t in range(1, n - 1)])
        Q = V[tri]
        cr = np.cross(Q[:, 1] - Q[:, 0], Q[:, 2] - Q[:, 0])
        signed = cr @ normal
        score = signed.min() if np.all(signed > 0) else signed.min() - 1e300
        if score > best_score:
            best, best_score = tri, score
    if best is None:
        # Every start vertex gives a fan and the first beats -inf, unless the corners are not finite.
        raise GeometryError(f"a polygon of {n} corners has corners that are not finite numbers")
    return best.tolist()


def _repair(V: np.ndarray, faces: list[np.ndarray], members: np.ndarray, member_id: np.ndarray,
            scale: float, tol: Tolerances):
    """Merge coincident vertices, drop collapsed faces, split neighbours (no T-junctions).

    Parameters
    ----------
    V : (N, 3) float64
    faces : [(Q, 4) int64, (T, 3) int64]
    members : (E, 2) int64
    member_id : (E,) int64
    scale : float
        Size of the input (coincidence and zero area are relative to it).

    Returns
    -------
    quads, triangles, members, member_id, dropped : arrays and the number of faces removed
    """
    rep = _merge_coincident(V, faces, tol.planarity * scale, tol)
    quads, tris = rep[faces[0]], rep[faces[1]]
    members = rep[members]
    keep_m = members[:, 0] != members[:, 1]
    members, member_id = members[keep_m], member_id[keep_m]
    quads, tris, dropped = _drop_repeated_corners(quads, tris)

    # Zero-area faces whose corners are distinct but collinear.
    flat_q, flat_t = _flat(V, quads, tol), _flat(V, tris, tol)
    if not (flat_q.any() or flat_t.any()):
        return quads, tris, members, member_id, dropped
    quads, tris, splits, removed = _remove_flat_faces(V, quads, tris, np.r_[flat_q, flat_t], tol)
    members, member_id = _split_members(members, member_id, splits)
    return quads, tris, members, member_id, dropped + removed


def _drop_repeated_corners(quads: np.ndarray, tris: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Quads with one repeated corner become triangles; slits and degenerate faces go.

    Returns the (Q', 4) quads, (T', 3) triangles and the number of faces removed.
    """
    # Quads losing a repeated corner become triangles; slits [A, B, A, D] and
    # faces with fewer than three corners vanish.
    nxt = quads == np.roll(quads, -1, axis=1)
    slit = (quads[:, 0] == quads[:, 2]) | (quads[:, 1] == quads[:, 3])
    n_dup = nxt.sum(axis=1)
    q_keep = (n_dup == 0) & ~slit
    q_tri = (n_dup == 1) & ~slit
    extra = quads[q_tri][~nxt[q_tri]].reshape(-1, 3)
    dropped = int(len(quads) - q_keep.sum() - q_tri.sum())
    quads = quads[q_keep]
    tris = np.concatenate([tris, extra])
    t_ok = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 2] != tris[:, 0])
    dropped += int((~t_ok).sum())
    tris = tris[t_ok]
    return quads, tris, dropped


def _remove_flat_faces(V: np.ndarray, quads: np.ndarray, tris: np.ndarray, flat: np.ndarray,
                       tol: Tolerances) -> tuple[np.ndarray, np.ndarray, dict, int]:
    """Remove the zero-area faces ``flat`` (quads first, then triangles); split their neighbours.

    A neighbour sharing an edge of a flat face gets the flat face's corners that lie on
    that edge inserted (no T-junctions) and is fanned into triangles.  Returns the quads,
    the triangles, the splits ``{(p, q): [inserted vertices]}`` and the faces removed.
    """
    dropped = 0
    # Rare path: a loop over the collapsed faces and the few neighbours they touch.
    polys: dict[int, list[int]] = {}          # faces edited (ids: quads first, then triangles)
    nq = len(quads)
    pad = np.concatenate([quads, np.column_stack([tris, np.full(len(tris), -1)])])
    val = np.r_[np.full(nq, 4), np.full(len(tris), 3)]
    nxt_col = np.where(np.arange(4)[None, :] + 1 < val[:, None], np.arange(4)[None, :] + 1, 0)
    src = pad
    dst = np.take_along_axis(pad, nxt_col, axis=1)
    alive = np.ones(len(pad), dtype=bool)
    splits: dict[tuple[int, int], list[int]] = {}

    def current(f: int) -> list[int]:
        return polys[f] if f in polys else pad[f, :val[f]].tolist()

    def faces_with_edge(p: int, q: int, exclude: int) -> list[int]:
        hit = np.nonzero((((src == p) & (dst == q)) | ((src == q) & (dst == p))).any(axis=1))[0]
        out = [int(f) for f in hit if alive[f] and f != exclude and f not in polys]
        for f, poly in polys.items():
            if f != exclude and alive[f]:
                ring = list(zip(poly, poly[1:] + poly[:1]))
                if (p, q) in ring or (q, p) in ring:
                    out.append(f)
        return out

    flat_ids = np.nonzero(flat)[0]
    # Flat faces back to back with the same corners (two triangles across a generator
    # that both neighbours cross at one point) simply vanish together: their other
    # neighbours then share the edges, and splitting by each other would stack faces.
    sets = [tuple(sorted(set(current(int(z))))) for z in flat_ids]
    seen: dict[tuple, int] = {}
    for s_ in sets:
        seen[s_] = seen.get(s_, 0) + 1
    for z, s_ in zip(flat_ids.tolist(), sets):
        if seen[s_] > 1:
            alive[z] = False
            dropped += 1
    for z in flat_ids.tolist():
        if not alive[z]:
            continue
        poly = current(z)
        P = V[poly]
        alive[z] = False
        dropped += 1
        for e in range(len(poly)):
            p, q = poly[e], poly[(e + 1) % len(poly)]
            d = V[q] - V[p]
            dd = float(d @ d)
            if dd == 0.0:
                continue
            s = (P - V[p]) @ d / dd
            off = np.linalg.norm(P - V[p] - s[:, None] * d, axis=1)
            inner = [(s[r], poly[r]) for r in range(len(poly))
                     if 0 < s[r] < 1 and off[r] <= tol.degenerate * np.sqrt(dd)
                     and poly[r] not in (p, q)]
            if not inner:
                continue
            chain = [w for _, w in sorted(set(inner))]
            splits[(p, q)] = chain
            for f in faces_with_edge(p, q, z):
                ring = current(f)
                i = ring.index(p)
                if ring[(i + 1) % len(ring)] == q:
                    ring = ring[:i + 1] + chain + ring[i + 1:]
                else:
                    i = ring.index(q)
                    ring = ring[:i + 1] + chain[::-1] + ring[i + 1:]
                polys[f] = ring

    keep = alive.copy()
    keep[list(polys)] = False
    new_tris = [t for f, ring in polys.items() if alive[f]
                for t in (_fan(V, ring) if len(ring) > 3 else [ring])]
    quads = pad[:nq][keep[:nq]]
    tris = np.concatenate([pad[nq:, :3][keep[nq:]],
                           np.asarray(new_tris, dtype=np.int64).reshape(-1, 3)])
    return quads, tris, splits, dropped


def _split_members(members: np.ndarray, member_id: np.ndarray,
                   splits: dict) -> tuple[np.ndarray, np.ndarray]:
    """(E', 2) members and (E',) ids with every member along a split edge made a chain."""
    for _ in range(8):
        changed = False
        out_m, out_id = [], []
        for (p, q), chain in splits.items():
            hit = ((members[:, 0] == p) & (members[:, 1] == q)) | ((members[:, 0] == q) & (members[:, 1] == p))
            for h in np.nonzero(hit)[0]:
                path = [p] + chain + [q]
                if members[h, 0] == q:
                    path = path[::-1]
                out_m += list(itertools.pairwise(path))
                out_id += [member_id[h]] * (len(path) - 1)
                members[h] = -1
                changed = True
        if not changed:
            break
        ok = members[:, 0] >= 0
        members = np.concatenate([members[ok], np.asarray(out_m, np.int64).reshape(-1, 2)])
        member_id = np.concatenate([member_id[ok], np.asarray(out_id, np.int64)])
    return members, member_id


def _grid_data(n_vertices: int, n: int, k: int, reversed_: np.ndarray) -> dict[str, np.ndarray]:
    """Per-vertex ``t`` (along the generator as given), ``generator`` (-1 between) and ``u``."""
    col = np.arange(n_vertices) // (k + 1)
    v = (np.arange(n_vertices) % (k + 1)) / k
    on_gen = col % n == 0
    gen = np.where(on_gen, col // n, -1)
    t = np.where(on_gen & reversed_[np.maximum(gen, 0)], 1.0 - v, v)
    return {"t": t, "generator": gen, "u": col / n}


def _warnings(dropped: int, bare_gens: list[int]) -> list[str]:
    out = []
    if dropped:
        out.append(f"hybrid: removed {dropped} collapsed faces where generators meet "
                   "(shared end points or crossings at division points)")
    if bare_gens:
        out.append(f"hybrid: generators {bare_gens}: a segment is not a mesh edge (a "
                   "neighbouring generator ends inside it or folds onto it); it stays a member")
    return out


def _bare_generators(quads: np.ndarray, tris: np.ndarray, members: np.ndarray,
                     member_id: np.ndarray, n_vertices: int) -> list[int]:
    """Generators with a member segment that is no mesh edge.

    Where the end of a neighbour lies inside a generator the strip has zero width along
    part of it; that part bounds no face and cannot be a chain of mesh edges there.
    """
    e = np.concatenate([np.stack([quads, np.roll(quads, -1, axis=1)], axis=2).reshape(-1, 2),
                        np.stack([tris, np.roll(tris, -1, axis=1)], axis=2).reshape(-1, 2)])
    e.sort(axis=1)
    mm = np.sort(members, axis=1)
    is_edge = member(mm[:, 0] * n_vertices + mm[:, 1], e[:, 0] * n_vertices + e[:, 1])
    return sorted(set(member_id[~is_edge].tolist()))


def _check_grid(m: int, n: int, k: int) -> None:
    """Refuse a grid of ``(m - 1) n + 1`` columns by ``k + 1`` rows above :data:`MAX_GRID_NODES`."""
    nodes = ((m - 1) * n + 1) * (k + 1)
    if nodes > MAX_GRID_NODES:
        need = gib(nodes * HYBRID_BYTES_PER_NODE)
        raise ParameterError(f"expected at most {MAX_GRID_NODES:,} grid nodes, got "
                             f"{nodes:,} ({m} generators x {n} columns x {k + 1} "
                             f"rows), about {need} of memory (limit {gib(MAX_BUILD_BYTES)}); "
                             "reduce the divisions, the midpoints or the generator count",
                             "divisions")


# --------------------------------------------------------------------------- public
@normalised  # meshes in a unit frame: results do not depend on scale
def hybrid_mesh(a: Any, b: Any, *, midpoints: int = 1, divisions: int = 8, flip: bool = False,
                orient: bool = True, tol: Tolerances = DEFAULT) -> Mesh:
    """Hybrid mesh of planar quads and triangles from any set of generators (§4.1).

    Parameters
    ----------
    a, b : (m, 3) array_like, m >= 2
        End points of the generators ``g_i = a_i b_i`` (``t = 0`` at ``a``).
        Any lines: skew, intersecting, parallel, sharing end points.
    midpoints : int, >= 0
        Generators inserted in every strip, evenly (the paper uses 1).
    divisions : int, >= 1
        Regular division of the generators (the paper uses 8): rows of the
        isoline grid.  Each input generator becomes a chain of mesh edges
        through its division points of one parity (and its end points).
    flip : bool
        The paper's "creative option": use the other diagonal of each pair of
        triangles across an interior generator.  The generators are then no
        longer chains of mesh edges (they stay as members).
    orient : bool
        Reverse generators whose end points are listed the other way round
        than their neighbour's (see :func:`orient_generators`).
    tol : Tolerances
        ``planarity`` (relative to the input's size) is the radius under which
        vertices are merged; ``degenerate`` the relative height under which a
        face counts as flat and is removed.

    Returns
    -------
    Mesh
        Faces tagged ``QUAD`` (inside the strips) and ``TRIANGLE`` (along the
        generators and the border); members: the segments of every input
        generator between consecutive vertices, ``member_id`` = generator
        index; vertex data ``t`` (parameter on the vertex's generator, in the
        input's direction for the input generators), ``generator`` (input
        generator index, or -1 for an inserted one) and ``u`` (strip index
        plus position across the strip).  ``info`` lists the reversed
        generators and how many collapsed faces were removed.

    Raises
    ------
    ParameterError
        Malformed arrays or options.
    GeometryError
        A generator of zero length.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.5]])
    >>> b = np.array([[0, 1, 0.3], [1, 1, 0], [2, 1, 0]])
    >>> mesh = hybrid_mesh(a, b)
    >>> mesh.count_kinds()
    {'quad': 6, 'triangle': 20}
    >>> mesh.euler_characteristic()
    1
    """
    a = check_points(a, "a", min_count=2)
    b = check_points(b, "b", min_count=2)
    if a.shape != b.shape:
        raise ParameterError(f"expected as many points as a ({len(a)}), got {len(b)}", "b")
    midpoints = check_int(midpoints, "midpoints", lo=0, hi=10_000)
    divisions = check_int(divisions, "divisions", lo=1, hi=MAX_DIVISIONS)
    flip = check_bool(flip, "flip")
    orient = check_bool(orient, "orient")
    pts = np.concatenate([a, b])
    scale = max(diagonal(pts), TINY)
    short = np.nonzero(np.linalg.norm(b - a, axis=1) <= tol.degenerate * scale)[0]
    if short.size:
        raise GeometryError(f"generator {int(short[0])} has zero length: a line needs two "
                            "distinct end points")
    m, n, k = len(a), midpoints + 1, divisions
    C = (m - 1) * n
    _check_grid(m, n, k)
    reversed_ = orient_generators(a, b) if orient else np.zeros(m, bool)
    A = np.where(reversed_[:, None], b, a)
    B = np.where(reversed_[:, None], a, b)
    X = hybrid_grid(A, B, n, k).reshape(-1, 3)
    quads, tris, vertex = checkerboard_faces(C, k, n, flip)
    members, member_id = _generator_members(vertex, n, k + 1)
    quads, tris, members, member_id, dropped = _repair(X, [quads, tris], members, member_id,
                                                       scale, tol)

    bare_gens = [] if flip else _bare_generators(quads, tris, members, member_id, len(X))
    warnings = _warnings(dropped, bare_gens)
    info = {"construction": "hybrid", "midpoints": midpoints, "divisions": divisions,
            "flip": flip, "reversed_generators": np.nonzero(reversed_)[0].tolist(),
            "collapsed_faces": dropped, "bare_generators": bare_gens, "warnings": warnings}
    faces = np.concatenate([quads.ravel(), tris.ravel()]).astype(np.int64)
    offsets = np.r_[np.arange(len(quads) + 1) * 4,
                    4 * len(quads) + np.arange(1, len(tris) + 1) * 3].astype(np.int64)
    kinds = np.r_[np.full(len(quads), FaceKind.QUAD),
                  np.full(len(tris), FaceKind.TRIANGLE)].astype(np.uint8)
    mesh = Mesh(X, offsets, faces, kinds, members.astype(np.int64), member_id.astype(np.int64),
                _grid_data(len(X), n, k, reversed_), info)
    return mesh.compact()
