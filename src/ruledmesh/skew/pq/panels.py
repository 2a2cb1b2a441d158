"""Strip quads split to the size of the other panels.

Two coplanar generators carry planar quads of any division (paper §3.1), so a
strip quad far larger than the mesh's other panels (a torsal band spanned by one
coplanar pair, with the runs beside it leaving few vertices on its generators)
can be cut along lines between the two generators into smaller planar quads:
points are added on both generator edges at the same fractions.  The face on the
other side of each generator edge must take the new points too; a triangle is
fanned from its opposite corner (still planar, still a triangle); where a fan would
lower the mesh's smallest angle (or make a splinter), or the face is not a
triangle, the quad is cut into fewer pieces or not at all.  Every new point lies
on its generator, and members along the generators are split with the edges.
"""

from __future__ import annotations

import numpy as np

from ..._arrays import lookup, median, ranks
from ...mesh import FaceKind, Mesh, offsets_from_valences
from ...tolerances import RESTART_ANGLE_DEG

__all__ = ["faces_across", "split_strip_quads"]

# A strip quad is cut where its area is above this many times the median quad area, into
# pieces near that median (at most _MAX_PIECES).
_LARGE = 3.0
_MAX_PIECES = 8


def split_strip_quads(mesh: Mesh) -> tuple[Mesh, int]:
    """Cut strip quads much larger than the median quad into pieces along their generators.

    Parameters
    ----------
    mesh : Mesh
        A §4.3 mesh with ``vertex_data["generator"]`` and ``vertex_data["t"]``.

    Returns
    -------
    Mesh
        The mesh with the large strip quads cut (new faces at the end).
    int
        Number of strip quads cut.
    """
    from ...analysis.faces import face_min_angles, face_normals

    if mesh.n_faces == 0 or "generator" not in mesh.vertex_data:
        return mesh, 0
    quads = mesh.valences == 4
    strip = np.flatnonzero(quads & (mesh.face_kind == FaceKind.STRIP))
    if strip.size == 0:
        return mesh, 0
    area = face_normals(mesh)[1]
    usual = area[quads & (mesh.face_kind != FaceKind.STRIP)]
    middle = median(usual if usual.size else area[quads])
    big = strip[area[strip] > _LARGE * middle]
    if big.size == 0 or middle <= 0.0:
        return mesh, 0
    corners, two = _strip_corners(mesh, big)
    big, corners = big[two], corners[two]
    if big.size == 0:
        return mesh, 0
    pieces = np.clip(np.rint(area[big] / middle), 2, _MAX_PIECES).astype(np.int64)
    # The faces across the two generator edges a0 -> a1 and b1 -> b0.
    across = [faces_across(mesh, corners[:, 0], corners[:, 1]), faces_across(mesh, corners[:, 2], corners[:, 3])]
    # The fans never lower the mesh's smallest angle (nor go below the splinter bar).
    floor = max(RESTART_ANGLE_DEG, float(face_min_angles(mesh).min()))
    pieces = _fitting(mesh, corners, pieces, across, floor)
    keep = pieces > 1
    if not keep.any():
        return mesh, 0
    across = [(face[keep], apex[keep]) for face, apex in across]
    return _cut(mesh, big[keep], corners[keep], pieces[keep], across), int(keep.sum())


def _strip_corners(mesh: Mesh, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, 4) corners ``a0, a1, b1, b0`` of strip quads: ``a0 a1`` and ``b1 b0`` on generators;
    (k,) bool: whether the quad has those two edges on two different generators.

    Only those are strip quads to cut: a pass before may have merged corners of different
    generators (coincident end points of a degenerate design), and points put on the other
    edges would not lie on their generators."""
    idx = mesh.face_indices[mesh.face_offsets[faces][:, None] + np.arange(4)]
    gen = np.asarray(mesh.vertex_data["generator"])[idx]
    turn = gen[:, 0] != gen[:, 1]
    idx[turn] = np.roll(idx[turn], -1, axis=1)
    gen[turn] = np.roll(gen[turn], -1, axis=1)
    return idx, (gen[:, 0] == gen[:, 1]) & (gen[:, 2] == gen[:, 3]) & (gen[:, 0] != gen[:, 2])


def faces_across(mesh: Mesh, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each edge ``a -> b`` of a face: the face using ``b -> a`` (-1: none) and its corner
    opposite the edge if it is a triangle (-1 otherwise)."""
    n = np.int64(mesh.n_vertices)
    idx = mesh.face_indices
    following = mesh.next_corners()
    key = idx * n + idx[following]
    order = np.argsort(key, kind="stable")
    pos = lookup(b.astype(np.int64) * n + a, key[order])
    found = pos >= 0
    corner = np.where(found, order[pos], -1)
    face_of = mesh.face_of
    face = np.where(found, face_of[np.maximum(corner, 0)], -1)
    tri = found & (mesh.valences[np.maximum(face, 0)] == 3)
    # In a triangle (b, a, x) the corner after a is x.
    after = following[following[np.maximum(corner, 0)]]
    apex = np.where(tri, idx[after], -1)
    return face, apex


def _fitting(mesh: Mesh, corners: np.ndarray, pieces: np.ndarray, across: list, floor: float) -> np.ndarray:
    """Pieces each quad can be cut into: its neighbours across the generator edges
    (``across``: :func:`faces_across` of each) are triangles (or the border) whose fans keep
    every angle at or above ``floor`` (degrees)."""
    from ...analysis.faces import min_corner_angles

    V = mesh.vertices
    out = pieces.copy()
    for (a, b), (face, apex) in zip(((corners[:, 0], corners[:, 1]), (corners[:, 2], corners[:, 3])), across,
                                    strict=True):
        out[(face >= 0) & (apex < 0)] = 1
        # The fan's triangles (apex, b_j, a_j) for each cut: the largest count that keeps them.
        for k in range(_MAX_PIECES, 1, -1):
            sel = np.flatnonzero((out >= k) & (apex >= 0))
            if sel.size == 0:
                continue
            s = np.arange(k + 1) / k
            P = V[a[sel], None, :] + s[None, :, None] * (V[b[sel]] - V[a[sel]])[:, None, :]
            tris = np.stack([np.broadcast_to(V[apex[sel], None, :], P[:, 1:].shape), P[:, 1:], P[:, :-1]],
                            axis=2)
            flat = tris.reshape(-1, 3)
            worst = min_corner_angles(flat, np.arange(len(flat)).reshape(-1, 3)).reshape(len(sel), k).min(axis=1)
            out[sel[worst < floor]] = k - 1
    return out


def _cut(mesh: Mesh, faces: np.ndarray, corners: np.ndarray, pieces: np.ndarray, across: list) -> Mesh:
    """The mesh with each strip quad ``a0 a1 b1 b0`` cut into ``pieces`` and the triangles
    across its generator edges (``across``) fanned (new faces at the end, each face's sense kept)."""
    V = mesh.vertices
    t = np.asarray(mesh.vertex_data["t"])
    gen = np.asarray(mesh.vertex_data["generator"])
    a0, a1, b1, b0 = corners.T
    # Points along a0 -> a1 and b0 -> b1 at the same fractions, ends included.
    m = pieces
    inner = m - 1
    first = mesh.n_vertices + np.r_[0, np.cumsum(2 * inner)[:-1]]
    owner = np.repeat(np.arange(len(m)), inner)
    s = (ranks(inner) + 1) / m[owner]

    def points(p, q):
        return V[p[owner]] + s[:, None] * (V[q[owner]] - V[p[owner]]), t[p[owner]] + s * (t[q[owner]] - t[p[owner]])

    pa, ta = points(a0, a1)
    pb, tb = points(b0, b1)
    ia = first[owner] + ranks(inner)           # new points on a, then those on b, per quad
    ib = ia + inner[owner]
    vertices = np.empty((mesh.n_vertices + 2 * len(s), 3))
    vertices[:mesh.n_vertices] = V
    vertices[ia], vertices[ib] = pa, pb
    tt = np.empty(len(vertices))
    tt[:mesh.n_vertices] = t
    tt[ia], tt[ib] = ta, tb
    gg = np.empty(len(vertices), dtype=gen.dtype)
    gg[:mesh.n_vertices] = gen
    gg[ia], gg[ib] = gen[a0[owner]], gen[b0[owner]]
    # Both chains of quad j, ends included, at the same places of two flat arrays.
    start, chain_a = _chains(a0, ia, a1, inner)
    _, chain_b = _chains(b0, ib, b1, inner)
    step = np.delete(np.arange(len(chain_a)), start[1:] - 1)   # every point but a chain's last
    piece_of = np.repeat(np.arange(len(m)), m)   # the quad each piece (and fan triangle) comes from
    drop = np.zeros(mesh.n_faces, bool)
    drop[faces] = True
    polys = [np.stack([chain_a[step], chain_a[step + 1], chain_b[step + 1], chain_b[step]], axis=1)]
    kinds = [np.full(len(step), FaceKind.STRIP)]
    for chain, (face, apex), forward in zip((chain_a, chain_b), across, (False, True), strict=True):
        fanned = apex[piece_of] >= 0            # the pieces beside a triangle that is fanned
        at = step[fanned]
        fan = np.stack([apex[piece_of][fanned], chain[at], chain[at + 1]], axis=1)
        polys.append(fan if forward else fan[:, [0, 2, 1]])
        kinds.append(mesh.face_kind[face[piece_of][fanned]])
        drop[face[apex >= 0]] = True
    members, member_id = _split_members(mesh, np.r_[start[:-1], start + start[-1]],
                                        np.r_[chain_a, chain_b])
    kept = mesh.select_faces(~drop)
    sizes = np.concatenate([kept.valences] + [np.full(len(p), p.shape[1]) for p in polys])
    indices = np.concatenate([kept.face_indices] + [p.reshape(-1) for p in polys])
    kind = np.concatenate([kept.face_kind] + [k.astype(mesh.face_kind.dtype) for k in kinds])
    return Mesh.from_arrays(vertices, offsets_from_valences(sizes), indices, kind, members=members,
                            member_id=member_id, vertex_data={"t": tt, "generator": gg},
                            info=dict(mesh.info))


def _chains(first: np.ndarray, inner: np.ndarray, last: np.ndarray, counts: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """Chains ``first[j], inner[...], last[j]`` (``counts[j]`` inner points each, in order) as
    one flat array; returns the offsets of the chains ((k + 1,): the last is the length) and it."""
    start = np.r_[0, np.cumsum(counts + 2)]
    flat = np.empty(start[-1], dtype=np.int64)
    flat[start[:-1]] = first
    flat[start[1:] - 1] = last
    flat[np.repeat(start[:-1] + 1, counts) + ranks(counts)] = inner
    return start, flat


def _split_members(mesh: Mesh, start: np.ndarray, flat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Members along the cut generator edges replaced by their pieces (same member ids).

    ``flat[start[j]:start[j + 1]]`` is chain ``j`` (as :func:`_chains` lays them out), from
    one end of a member to its other end."""
    members, ids = mesh.members, mesh.member_id
    if members.size == 0:
        return members, ids
    n = np.int64(mesh.n_vertices)
    key = np.minimum(members[:, 0], members[:, 1]) * n + np.maximum(members[:, 0], members[:, 1])
    order = np.argsort(key)
    first, last = start[:-1], start[1:] - 1
    p, q = flat[first], flat[last]
    pos = lookup(np.minimum(p, q) * n + np.maximum(p, q), key[order])
    found = pos >= 0
    if not found.any():
        return members, ids
    row = order[pos[found]]
    gone = np.zeros(len(members), bool)
    gone[row] = True
    # Each found chain's points in the member's own sense, then its consecutive pairs.
    forward = members[row, 0] == p[found]
    lengths = last[found] - first[found] + 1
    rank = ranks(lengths)
    at = np.repeat(first[found], lengths) + np.where(np.repeat(forward, lengths), rank,
                                                     np.repeat(lengths - 1, lengths) - rank)
    seq = flat[at]
    pair = np.delete(np.arange(len(seq)), np.cumsum(lengths) - 1)
    return (np.concatenate([members[~gone], np.stack([seq[pair], seq[pair + 1]], axis=1)]),
            np.concatenate([ids[~gone], np.repeat(ids[row], lengths - 1)]))
