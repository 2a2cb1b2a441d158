"""Patch corners re-cut where an end generator meets the border in a splinter.

With rows through the generators' end points (``rows_from`` ``c1``, ``c2`` or
``both``), the last row through an end point on a director curve leaves a gap at
the corner where the end generator meets that curve: the end generator carries
no vertex between the corner and the first row vertex, often half its length
away.  The border quad through the corner, whose diagonal lies on the next
generator, then has a side from the corner to a vertex far up that generator,
and the triangle closing the gap has its angle at the corner between that side
and the end generator: on a strongly twisted surface well under a degree, and no
flip can change it, for the side belongs to a quad.

Here the quad is cut along its generator diagonal and the region between the two
generators (the quad's half at the corner and the triangle) is cut again: a
zipper between the two generators' segments, with vertices added on both (on the
end generator nothing lies beyond; the quad's other half, a triangle, is fanned
from its far corner over the vertices added on its side), of the counts and
spacing whose smallest angle is the largest.  Every vertex added lies on its
generator and every new face is a triangle, so planarity is exact.  A corner is
re-cut only where that makes its smallest angle larger.
"""

from __future__ import annotations

import numpy as np

from ..._arrays import member, unique
from ...mesh import FaceKind, Mesh, offsets_from_valences
from ...tolerances import PARAMETER_SLACK
from .panels import _split_members

__all__ = ["rezip_corners"]

# Vertices tried on the next generator's segment and on the end generator's, evenly spaced
# or, on the end generator, graded towards its first row vertex (where the strip is narrowest).
_ON_NEXT = range(4)
_ON_END = range(9)
_GRADED_RATIO = 0.6


def rezip_corners(mesh: Mesh, below: float = 3.0) -> tuple[Mesh, int]:
    """Re-cut each patch corner whose triangle at the corner has an angle under ``below``.

    Parameters
    ----------
    mesh : Mesh
        A trimmed §4.3 mesh with ``vertex_data["generator"]`` and ``["t"]``.
    below : float
        Degrees: the corners with a triangle this thin are weighed.

    Returns
    -------
    Mesh
        ``mesh`` itself where no corner changed; else with the vertices added at the end of
        its vertex arrays (and on its members) and the corners' faces replaced by triangles
        of kind :attr:`FaceKind.FILL`.
    int
        Number of corners re-cut.
    """
    if mesh.n_faces == 0 or "generator" not in mesh.vertex_data or "t" not in mesh.vertex_data:
        return mesh, 0
    gen = np.asarray(mesh.vertex_data["generator"])
    t = np.asarray(mesh.vertex_data["t"])
    ends = (gen == gen.min()) | (gen == gen.max())
    # On the rim, not merely outside the patch: an untrimmed mesh (trim = false) has
    # thousands of vertices beyond the patch on its end generators, none of them a corner.
    rim = np.minimum(np.abs(t), np.abs(1.0 - t)) <= PARAMETER_SLACK
    corners = np.flatnonzero(ends & rim)
    if corners.size == 0:
        return mesh, 0
    # The faces at each corner, from one pass over the corners of all faces.
    at = np.flatnonzero(member(mesh.face_indices, corners))
    off, val = mesh.face_offsets, mesh.valences
    face_of = np.searchsorted(off, at, side="right") - 1      # no (N,) array for a few corners
    faces_at = {c: [(int(f), mesh.face_indices[off[f]:off[f] + val[f]])
                    for f in unique(face_of[mesh.face_indices[at] == c]).tolist()] for c in corners.tolist()}
    plans = []
    used: set[int] = set()
    for c in corners.tolist():
        plan = _corner_plan(mesh, faces_at[c], c, gen, t, below)
        if plan is not None and not (used & set(plan["faces"])):
            used |= set(plan["faces"])
            plans.append(plan)
    if not plans:
        return mesh, 0
    return _applied(mesh, plans), len(plans)


def _corner_plan(mesh: Mesh, faces: list[tuple[int, np.ndarray]], c: int, gen: np.ndarray, t: np.ndarray,
                 below: float) -> dict | None:
    """How to re-cut the corner at vertex ``c`` (``faces``: each face at it, with its corners),
    or None (no such corner, or no gain)."""
    from ...analysis.faces import polygon_angles

    V = mesh.vertices
    end = gen[c]
    for f, tri in faces:
        if tri.size != 3:
            continue
        k = int(np.flatnonzero(tri == c)[0])
        nxt, prv = int(tri[(k + 1) % 3]), int(tri[(k + 2) % 3])
        # (c, e, x) in the triangle's own order (forward) or (c, x, e): e on the end generator
        if (gen[nxt] == end) == (gen[prv] == end):
            continue
        forward = bool(gen[nxt] == end)
        e, x = (nxt, prv) if forward else (prv, nxt)
        old = float(polygon_angles(V[tri][None]).min())
        if old >= below:
            continue
        beyond = _beyond(faces, f, c, x, gen, t)
        if beyond is None:
            continue
        q, r, w, corners = beyond
        old = min(old, float(polygon_angles(V[corners][None]).min()))
        # The new triangles, in the order (a_i, a_i+1, b_j), face as the face beyond does.
        ref = _normal(V[corners]) * (1.0 if forward else -1.0)
        best = _best_cut(V, t, c, e, x, r, w, ref)
        if best is None or best[0] <= old:
            continue
        return {"faces": (f, q), "c": c, "e": e, "x": x, "r": r, "w": w, "forward": forward,
                "on_end": best[1], "on_next": best[2], "triangles": best[3]}
    return None


def _beyond(faces: list[tuple[int, np.ndarray]], f: int, c: int, x: int, gen: np.ndarray, t: np.ndarray):
    """``(q, r, w, corners)``: the face ``q`` at the patch corner ``c`` (of ``faces``; on the rim,
    as :func:`rezip_corners` picks it) across the edge ``c x`` from face ``f``, with its corners.
    A triangle ``(c, x, r)``: ``w`` None.  A quad through the corner whose diagonal ``r x`` lies
    on a generator, ``r`` on the border next to ``c`` (on the same rim): ``w`` its fourth corner
    (the quad is cut along that diagonal).  Else None."""
    for q, corners in faces:
        if q == f or x not in corners:
            continue
        if corners.size == 3:
            return q, int(next(v for v in corners.tolist() if v not in (c, x))), None, corners
        if corners.size != 4:
            return None
        k = int(np.flatnonzero(corners == c)[0])
        around = [int(corners[(k + i) % 4]) for i in range(4)]     # c, then on round
        if around[1] == x:
            r, w = around[3], around[2]
        elif around[3] == x:
            r, w = around[1], around[2]
        else:
            return None                      # x opposite c: not the quad through the corner
        if gen[r] != gen[x] or abs(t[r] - t[c]) > PARAMETER_SLACK:
            return None
        return q, r, w, corners
    return None


def _normal(P: np.ndarray) -> np.ndarray:
    """(3,) the Newell normal of the polygon ``P`` (k, 3)."""
    Q = np.roll(P, -1, axis=0)
    return np.cross(P, Q).sum(axis=0)


def _spaced(t0: float, t1: float, k: int, graded: bool) -> np.ndarray:
    """``k`` parameters strictly between ``t0`` and ``t1``: even, or graded towards ``t1``."""
    if k == 0:
        return np.zeros(0)
    if not graded:
        return t0 + (t1 - t0) * np.arange(1, k + 1) / (k + 1)
    steps = _GRADED_RATIO ** np.arange(k + 1)
    return t0 + (t1 - t0) * np.cumsum(steps)[:-1] / steps.sum()


def _best_cut(V: np.ndarray, t: np.ndarray, c: int, e: int, x: int, r: int, w: int | None, ref: np.ndarray):
    """``(smallest angle, end parameters, next parameters, triangles)`` of the best re-cut
    (the angle -1 where every cut turns a triangle over against ``ref``).

    Triangles index the chain points: ``("a", i)`` on the end generator from ``c`` (0) to
    ``e``, ``("b", j)`` from ``r`` (0) to ``x`` (on their generator, where ``w`` is a quad's
    corner; else just the two).
    """
    best = None
    for graded in (False, True):
        for ka in _ON_END:
            ta = _spaced(t[c], t[e], ka, graded)
            A = _points(V[c], V[e], t[c], t[e], ta)
            for kb in _ON_NEXT if w is not None else (0,):
                tb = _spaced(t[r], t[x], kb, False)
                B = _points(V[r], V[x], t[r], t[x], tb)
                fan = 180.0 if w is None else float(_angles_facing(
                    np.repeat(V[w][None], len(B) - 1, axis=0), B[:-1], B[1:], ref).min())
                if best is not None and fan <= best[0]:
                    continue
                zip_min, tris = _zipper(A, B, ref)
                score = min(fan, zip_min)
                if best is None or score > best[0]:
                    best = (score, ta, tb, tris)
    return best


def _points(p0: np.ndarray, p1: np.ndarray, t0: float, t1: float, ts: np.ndarray) -> np.ndarray:
    """The chain from ``p0`` to ``p1`` through the points at parameters ``ts`` on their line."""
    s = (ts - t0) / (t1 - t0)
    return np.concatenate([p0[None], p0 + s[:, None] * (p1 - p0), p1[None]])


def _angles_facing(P: np.ndarray, Q: np.ndarray, R: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """(k,) the smallest angle, degrees, of each triangle ``P[i], Q[i], R[i]`` (each (k, 3)),
    -1 where it faces against ``ref`` (3,)."""
    from ...analysis.faces import polygon_angles

    if len(P) == 0:
        return np.zeros(0)
    facing = np.cross(Q - P, R - P) @ ref > 0.0
    return np.where(facing, polygon_angles(np.stack([P, Q, R], axis=1)).min(axis=1), -1.0)


def _zipper(A: np.ndarray, B: np.ndarray, ref: np.ndarray) -> tuple[float, list]:
    """The zipper between chains ``A`` and ``B`` (both from the border) with the largest
    smallest angle, its triangles facing as ``ref``: (that angle, -1 if none; its triangles
    as chain references, in the order ``(a_i, a_i+1, b_j)`` and ``(a_i, b_j+1, b_j)``)."""
    na, nb = len(A), len(B)
    i, j = np.meshgrid(np.arange(na - 1), np.arange(nb), indexing="ij")
    up_a = _angles_facing(A[i.ravel()], A[i.ravel() + 1], B[j.ravel()], ref).reshape(na - 1, nb)
    i, j = np.meshgrid(np.arange(na), np.arange(nb - 1), indexing="ij")
    up_b = _angles_facing(A[i.ravel()], B[j.ravel() + 1], B[j.ravel()], ref).reshape(na, nb - 1)
    score = np.full((na, nb), -1.0)
    came = np.zeros((na, nb), np.int8)
    score[0, 0] = 180.0
    # Best path through the grid of cross edges (a_i, b_j), by the smallest angle on the way.
    for i0 in range(na):
        for j0 in range(nb):
            if i0 and score[i0 - 1, j0] >= 0:
                s = min(score[i0 - 1, j0], up_a[i0 - 1, j0])
                if s > score[i0, j0]:
                    score[i0, j0], came[i0, j0] = s, 1
            if j0 and score[i0, j0 - 1] >= 0:
                s = min(score[i0, j0 - 1], up_b[i0, j0 - 1])
                if s > score[i0, j0]:
                    score[i0, j0], came[i0, j0] = s, 2
    if score[-1, -1] < 0:
        return -1.0, []
    tris = []
    i0, j0 = na - 1, nb - 1
    while i0 or j0:
        if came[i0, j0] == 1:
            tris.append((("a", i0 - 1), ("a", i0), ("b", j0)))
            i0 -= 1
        else:
            tris.append((("a", i0), ("b", j0), ("b", j0 - 1)))
            j0 -= 1
    return float(score[-1, -1]), tris[::-1]


def _applied(mesh: Mesh, plans: list[dict]) -> Mesh:
    """``mesh`` with each planned corner re-cut."""
    t = np.asarray(mesh.vertex_data["t"])
    V = [mesh.vertices]
    n = mesh.n_vertices
    data = {name: [np.asarray(v)] for name, v in mesh.vertex_data.items()}
    faces: list[list[int]] = []
    chains: list[list[int]] = []        # from one end of a generator segment to the other
    drop = np.zeros(mesh.n_faces, bool)
    for plan in plans:
        drop[list(plan["faces"])] = True
        ids: dict[tuple[str, int], int] = {}
        for side, (p, q, ts) in {"a": (plan["c"], plan["e"], plan["on_end"]),
                                 "b": (plan["r"], plan["x"], plan["on_next"])}.items():
            V.append(_points(mesh.vertices[p], mesh.vertices[q], t[p], t[q], ts)[1:-1])
            for name, values in mesh.vertex_data.items():
                values = np.asarray(values)
                added = ts if name == "t" else np.full(len(ts), values[p])
                data[name].append(np.asarray(added, dtype=values.dtype))
            chain = [p, *range(n, n + len(ts)), q]
            n += len(ts)
            chains.append(chain)
            ids.update({(side, i): v for i, v in enumerate(chain)})
        new_faces = [[ids[k] for k in tri] for tri in plan["triangles"]]
        b = [ids[("b", j)] for j in range(len(plan["on_next"]) + 2)]
        if plan["w"] is not None:
            new_faces += [[plan["w"], b[j], b[j + 1]] for j in range(len(b) - 1)]
        if not plan["forward"]:
            new_faces = [f[::-1] for f in new_faces]
        faces += new_faces
    kept = np.repeat(~drop, mesh.valences)
    indices = np.concatenate([mesh.face_indices[kept], np.asarray(faces, np.int64).reshape(-1)])
    offsets = offsets_from_valences(np.concatenate([mesh.valences[~drop], np.full(len(faces), 3)]))
    kind = np.concatenate([mesh.face_kind[~drop], np.full(len(faces), FaceKind.FILL, mesh.face_kind.dtype)])
    # The members along the segments the vertices went on, in their pieces (panels' split).
    start = np.r_[0, np.cumsum([len(chain) for chain in chains])]
    members, member_id = _split_members(mesh, start, np.concatenate(chains).astype(np.int64))
    return Mesh(np.concatenate(V), offsets.astype(mesh.face_offsets.dtype), indices.astype(mesh.face_indices.dtype),
                kind, members, member_id, {name: np.concatenate(parts) for name, parts in data.items()}, mesh.info)
