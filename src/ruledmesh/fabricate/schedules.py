"""Schedules: the nodes, edges and members a builder orders and checks.

* node schedule: every vertex used by a face or a member, with its valence
  (the number of distinct edges and members meeting there);
* edge schedule: every face edge with its length, the faces on either side,
  the dihedral angle between their planes (180 degrees = flat) and the signed
  bend (0 = flat, positive = a ridge seen from the side the normals point
  to, negative = a valley), and the generator it lies on, if any;
* member schedule: one row per generator (beam or cable): its two end nodes,
  end points, length and how many mesh segments it spans.

Tables are dicts of equal-length columns; :func:`csv_bytes` writes them with
full float precision (``repr``), so a CSV round trip is exact.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping

import numpy as np

from ..analysis.faces import face_normals
from ..mesh import Mesh
from ..tolerances import TINY
from .unroll import corner_structure

__all__ = ["node_schedule", "edge_schedule", "member_schedule", "csv_bytes"]


def _undirected(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unique undirected edges of faces and members.

    Returns
    -------
    edges : (E, 2) int64, sorted pairs
    face_edge_of_corner : (N,) int64
        The edge leaving each face corner.
    member_edge : (M,) int64
        The edge of each member.
    """
    _face, nxt, _ = corner_structure(mesh.face_offsets)
    a = mesh.face_indices
    b = a[nxt]
    pairs = np.concatenate([np.stack([a, b], 1), mesh.members])
    pairs.sort(axis=1)
    edges, inverse = np.unique(pairs, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    return edges.reshape(-1, 2), inverse[:a.size], inverse[a.size:]


def node_schedule(mesh: Mesh) -> dict[str, np.ndarray]:
    """Nodes with coordinates and valence.

    Returns
    -------
    dict with columns ``id`` (vertex index), ``x``, ``y``, ``z``, ``valence``
        Only vertices used by a face or a member, in index order.
    """
    edges, _, _ = _undirected(mesh)
    valence = np.bincount(edges.reshape(-1), minlength=mesh.n_vertices)
    used = np.zeros(mesh.n_vertices, dtype=bool)
    used[mesh.face_indices] = True
    used[mesh.members.reshape(-1)] = True
    ids = np.flatnonzero(used)
    v = mesh.vertices[ids]
    return {"id": ids, "x": v[:, 0], "y": v[:, 1], "z": v[:, 2], "valence": valence[ids]}


def edge_schedule(mesh: Mesh) -> dict[str, np.ndarray]:
    """Face edges with length, adjacent faces, dihedral and bend angles.

    Returns
    -------
    dict with columns
        ``id``; ``v0``, ``v1`` (vertex indices, ``v0 < v1``); ``length``;
        ``face0``, ``face1`` (``-1`` on the border); ``dihedral_deg`` (angle
        between the two panels, 180 = flat; NaN on the border or where more
        than two faces meet); ``bend_deg`` (180 - dihedral, signed: positive
        for a ridge seen from the normals' side); ``generator`` (the
        ``member_id`` of a member along this edge, ``-1`` if none).
    """
    face, nxt, _ = corner_structure(mesh.face_offsets)
    all_edges, corner_edge, member_edge = _undirected(mesh)
    # Keep face edges only (members through a face's interior are not panel edges).
    is_face_edge = np.zeros(len(all_edges), dtype=bool)
    is_face_edge[corner_edge] = True
    keep = np.flatnonzero(is_face_edge)
    renum = np.full(len(all_edges), -1, dtype=np.int64)
    renum[keep] = np.arange(keep.size)
    edges = all_edges[keep]
    ce = renum[corner_edge]
    ne = keep.size

    order = np.argsort(ce, kind="stable")
    count = np.bincount(ce, minlength=ne)
    start = np.r_[0, np.cumsum(count)[:-1]]
    first = order[start]
    has2 = count >= 2
    second = np.where(has2, order[np.minimum(start + 1, ce.size - 1)], -1)
    f0 = face[first]
    f1 = np.where(has2, face[np.maximum(second, 0)], -1)

    normals, _ = face_normals(mesh)
    v = mesh.vertices
    a0 = mesh.face_indices[first]
    b0 = mesh.face_indices[nxt[first]]
    n0 = normals[f0]
    n1 = normals[np.maximum(f1, 0)]
    # A neighbour running the shared edge the same way is oriented the other way round:
    # flip its normal so the angle is between the panels, not between arbitrary normals.
    same_way = has2 & (mesh.face_indices[np.maximum(second, 0)] == a0)
    n1 = np.where(same_way[:, None], -n1, n1)
    cr = np.cross(n0, n1)
    d = v[b0] - v[a0]
    length = np.linalg.norm(d, axis=1)
    bend = np.degrees(np.arctan2(np.linalg.norm(cr, axis=1), np.einsum("ij,ij->i", n0, n1)))
    # Turning from n0 to n1 about the edge as f0 runs it: positive = ridge (convex side out).
    bend = np.where(np.einsum("ij,ij->i", cr, d) < 0, -bend, bend)
    valid = has2 & (count == 2)
    bend = np.where(valid, bend, np.nan)
    dihedral = 180.0 - np.abs(bend)

    generator = np.full(ne, -1, dtype=np.int64)
    me = renum[member_edge]
    on_face_edge = me >= 0
    generator[me[on_face_edge]] = mesh.member_id[on_face_edge]
    return {"id": np.arange(ne), "v0": edges[:, 0], "v1": edges[:, 1], "length": length,
            "face0": f0, "face1": f1, "dihedral_deg": dihedral, "bend_deg": bend,
            "generator": generator}


def member_schedule(mesh: Mesh) -> dict[str, np.ndarray]:
    """One row per generator: end nodes, end points, length, segment count.

    The members sharing a ``member_id`` lie on one line; its ends are the
    extreme vertices along the line's direction (that of its longest segment).

    Returns
    -------
    dict with columns
        ``generator``, ``node0``, ``node1``, ``x0``, ``y0``, ``z0``, ``x1``,
        ``y1``, ``z1``, ``length``, ``segments``.
    """
    mem = mesh.members
    mid = mesh.member_id
    if len(mem) == 0:
        empty_i = np.zeros(0, dtype=np.int64)
        empty_f = np.zeros(0)
        return {"generator": empty_i, "node0": empty_i, "node1": empty_i,
                **dict.fromkeys(("x0", "y0", "z0", "x1", "y1", "z1", "length"), empty_f),
                "segments": empty_i}
    gens, g = np.unique(mid, return_inverse=True)
    g = g.reshape(-1)
    v = mesh.vertices
    seg = v[mem[:, 1]] - v[mem[:, 0]]
    seg_len = np.linalg.norm(seg, axis=1)
    order = np.lexsort((-seg_len, g))
    starts = np.r_[0, np.flatnonzero(np.diff(g[order])) + 1]
    longest = order[starts]
    direction = seg[longest] / np.maximum(seg_len[longest], TINY)[:, None]
    origin = v[mem[longest, 0]]
    ends = mem.reshape(-1)
    eg = np.repeat(g, 2)
    t = np.einsum("ij,ij->i", v[ends] - origin[eg], direction[eg])
    by_t = np.lexsort((t, eg))
    gstart = np.r_[0, np.flatnonzero(np.diff(eg[by_t])) + 1]
    gend = np.r_[gstart[1:], by_t.size] - 1
    n0 = ends[by_t[gstart]]
    n1 = ends[by_t[gend]]
    p0, p1 = v[n0], v[n1]
    return {"generator": gens, "node0": n0, "node1": n1,
            "x0": p0[:, 0], "y0": p0[:, 1], "z0": p0[:, 2],
            "x1": p1[:, 0], "y1": p1[:, 1], "z1": p1[:, 2],
            "length": np.linalg.norm(p1 - p0, axis=1),
            "segments": np.bincount(g, minlength=gens.size)}


def _cell(x) -> str:
    if isinstance(x, (float, np.floating)):
        return "" if np.isnan(x) else repr(float(x))
    return str(x)


def csv_bytes(table: Mapping[str, np.ndarray]) -> bytes:
    """A table as CSV bytes: a header row, then one row per entry.

    Floats are written with ``repr`` (shortest exact form); NaN as an empty
    cell.

    Parameters
    ----------
    table : mapping of str to (n,) arrays
    """
    out = io.StringIO(newline="")
    w = csv.writer(out, lineterminator="\n")
    keys = list(table)
    w.writerow(keys)
    cols = [np.asarray(table[k]).tolist() for k in keys]
    for row in zip(*cols):
        w.writerow([_cell(x) for x in row])
    return out.getvalue().encode("utf-8")
