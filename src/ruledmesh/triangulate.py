"""Triangulation for rendering and printing, without splinters (paper §6).

Renderers and printers want triangles.  The paper's point (§6) is that the
standard tessellation of a ruled surface is full of *splinters*, triangles
with one or two tiny angles, while a PQ mesh only has to split planar faces
that are already well shaped.  The rules here:

* triangles are kept;
* a quad is split along its shorter diagonal (the split that keeps both
  halves fat for the near-rectangular faces of a PQ mesh); where that diagonal
  lies outside a non-convex quad the other one is used;
* a polygon of 5 to :data:`MAX_TEMPLATE_VALENCE` vertices gets the
  triangulation with the largest smallest angle among all its valid
  triangulations (every triangle turning the same way as the polygon), which
  is the optimal "no sliver where a better split exists" split;
* a larger polygon is ear-clipped, always cutting the ear whose triangle has
  the largest smallest angle.

Small polygons are done by *templates*: all triangulations of a convex
``k``-gon (a Catalan number of them, 14 for ``k = 6``) evaluated at once for
every face of valence ``k``, so the work is vectorised by valence.

The triangles of face ``f`` are ``triangles[offsets[f]:offsets[f + 1]]``,
``valence - 2`` of them, in face order; with ``face_of`` this keeps the polygon
structure recoverable (:func:`recover_polygons` rebuilds the polygons from
the triangles alone).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import Enum
from functools import cache

import numpy as np

from ._arrays import corner_angle, unique
from ._validation import check_choice
from .mesh import Mesh
from .tolerances import ROUNDING
from .tolerances import TINY as _TINY

__all__ = [
    "QuadSplit",
    "Triangulation",
    "MAX_TEMPLATE_VALENCE",
    "triangulate",
    "triangle_angles",
    "polygon_templates",
    "recover_polygons",
]

# Above this valence the Catalan number of templates (1430 for 10) outgrows
# greedy ear clipping; polygons that large are rare caps, not panels.
MAX_TEMPLATE_VALENCE = 9


class QuadSplit(str, Enum):
    """How quads are split.

    ``SHORTER``: along the shorter diagonal (the default, the usual rule for
    planar quads).  ``BEST``: along the diagonal with the larger smallest angle.
    """

    SHORTER = "shorter"
    BEST = "best"


@dataclass(frozen=True, eq=False)
class Triangulation:
    """Triangles of a polygon mesh, with the face each one came from.

    Attributes
    ----------
    triangles : (T, 3) int64
        Vertex indices (into the source mesh's vertices), each triangle
        turning the same way as its face.
    face_of : (T,) int64
        Source face of each triangle; non-decreasing.
    offsets : (F + 1,) int64
        Triangles of face ``f`` are ``triangles[offsets[f]:offsets[f + 1]]``.
    """

    triangles: np.ndarray
    face_of: np.ndarray
    offsets: np.ndarray

    @property
    def n_triangles(self) -> int:
        """Number of triangles."""
        return int(self.triangles.shape[0])

    def to_mesh(self, mesh: Mesh) -> Mesh:
        """A triangle :class:`Mesh` with the source's vertices, kinds and members.

        Each triangle keeps the :class:`FaceKind` of its face; ``info["face_of"]``
        holds :attr:`face_of` as a list-free array.
        """
        n = self.n_triangles
        return replace(
            mesh,
            face_offsets=np.arange(n + 1, dtype=np.int64) * 3,
            face_indices=self.triangles.reshape(-1).copy(),
            face_kind=mesh.face_kind[self.face_of],
            info={**mesh.info, "triangulated": True, "face_of": self.face_of},
        )


def triangle_angles(points: np.ndarray) -> np.ndarray:
    """Interior angles of triangles, in degrees.

    Parameters
    ----------
    points : (..., 3, 3) float64
        Corners of each triangle (last axis: coordinates).

    Returns
    -------
    (..., 3) float64
        Angle at each corner; a degenerate triangle has angles 0 (or 180).

    Examples
    --------
    >>> import numpy as np
    >>> tri = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> triangle_angles(tri).round(6).tolist()
    [90.0, 45.0, 45.0]
    """
    p = np.asarray(points, dtype=np.float64)
    e1 = np.roll(p, -1, axis=-2) - p
    e2 = np.roll(p, 1, axis=-2) - p
    cos = np.einsum("...i,...i->...", e1, e2)
    sin = np.linalg.norm(np.cross(e1, e2), axis=-1)
    return corner_angle(sin, cos)


@cache
def polygon_templates(k: int) -> np.ndarray:
    """All triangulations of a convex ``k``-gon by diagonals.

    Parameters
    ----------
    k : int
        Valence, at least 3.

    Returns
    -------
    (C_{k-2}, k - 2, 3) int64
        Corner positions (0..k-1) of the triangles of each triangulation, each
        triangle in the polygon's turning order.

    Examples
    --------
    >>> polygon_templates(4).tolist()
    [[[0, 1, 3], [1, 2, 3]], [[0, 1, 2], [0, 2, 3]]]
    >>> [len(polygon_templates(k)) for k in range(3, 8)]
    [1, 2, 5, 14, 42]
    """

    def tris(i: int, j: int) -> list[list[tuple[int, int, int]]]:
        # Triangulations of the sub-polygon i..j: edge (i, j) lies in exactly
        # one triangle (i, m, j); recurse on both sides of it.
        if j - i < 2:
            return [[]]
        out = []
        for m in range(i + 1, j):
            for left in tris(i, m):
                for right in tris(m, j):
                    out.append(left + right + [(i, m, j)])
        return out

    all_t = tris(0, k - 1)
    arr = np.array([sorted(t) for t in all_t], dtype=np.int64).reshape(len(all_t), k - 2, 3)
    arr.setflags(write=False)
    return arr


def _newell(points: np.ndarray) -> np.ndarray:
    """(F, 3) vector area of polygons ``points`` (F, k, 3)."""
    return 0.5 * np.cross(points, np.roll(points, -1, axis=1)).sum(axis=1)


def _best_template(points: np.ndarray, templates: np.ndarray) -> np.ndarray:
    """Index of the best valid template for each polygon.

    A template is valid for a face when each of its triangles turns the same
    way as the face (positive along the face's Newell normal): for a simple
    polygon the triangles then cover it exactly once, since the number of
    triangles over a point equals the winding number of the boundary there.
    Among valid templates the one with the largest smallest angle wins; if
    none is valid (a self-intersecting face) the one with the fewest
    reversed triangles.
    """
    normal = _newell(points)
    scale = np.einsum("fi,fi->f", normal, normal)
    # (F, C, k-2, 3, 3): corners of every triangle of every template.
    tri = points[:, templates]
    cross = np.cross(tri[..., 1, :] - tri[..., 0, :], tri[..., 2, :] - tri[..., 0, :])
    turn = np.einsum("fctj,fj->fct", cross, normal)
    # Relative threshold: a triangle with area below ~1e-12 of the face's
    # is as good as reversed (it would be a zero-area sliver).
    positive = turn > ROUNDING * np.maximum(scale, _TINY)[:, None, None]
    valid = positive.all(axis=2)
    min_angle = triangle_angles(tri).min(axis=(2, 3))
    score = np.where(valid, min_angle, -1.0 - (~positive).sum(axis=2))
    return np.argmax(score, axis=1)


def _quads_shorter(points: np.ndarray) -> np.ndarray:
    """Template index (into ``polygon_templates(4)``) of the shorter-diagonal split."""
    # Template 0 cuts along 1-3, template 1 along 0-2.
    d02 = np.einsum("fi,fi->f", points[:, 2] - points[:, 0], points[:, 2] - points[:, 0])
    d13 = np.einsum("fi,fi->f", points[:, 3] - points[:, 1], points[:, 3] - points[:, 1])
    choice = np.where(d02 <= d13, 1, 0)
    normal = _newell(points)
    tmpl = polygon_templates(4)
    tri = points[:, tmpl]
    cross = np.cross(tri[..., 1, :] - tri[..., 0, :], tri[..., 2, :] - tri[..., 0, :])
    turn = np.einsum("fctj,fj->fct", cross, normal)
    scale = np.einsum("fi,fi->f", normal, normal)
    valid = (turn > ROUNDING * np.maximum(scale, _TINY)[:, None, None]).all(axis=2)
    rows = np.arange(len(points))
    # The shorter diagonal of a non-convex quad may lie outside it; then the
    # other diagonal (through the reflex corner) is the only valid cut.
    flip = ~valid[rows, choice] & valid[rows, 1 - choice]
    return np.where(flip, 1 - choice, choice)


def _ear_clip(points: np.ndarray) -> np.ndarray:
    """Greedy best-ear clipping of one polygon (k, 3); returns (k-2, 3) corner positions."""
    normal = _newell(points[None])[0]
    scale = float(normal @ normal)
    left = list(range(len(points)))
    out = []
    while len(left) > 3:
        idx = np.array(left)
        prv, nxt = np.roll(idx, 1), np.roll(idx, -1)
        tri = np.stack([points[prv], points[idx], points[nxt]], axis=1)
        cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        convex = cross @ normal > ROUNDING * max(scale, _TINY)
        # An ear contains no other remaining vertex.
        ear = convex.copy()
        for e in np.flatnonzero(convex):
            a, b, c = tri[e]
            others = points[np.setdiff1d(idx, [prv[e], idx[e], nxt[e]])]
            inside = np.ones(len(others), dtype=bool)
            for p, q in ((a, b), (b, c), (c, a)):
                inside &= np.cross(q - p, others - p) @ normal >= 0
            ear[e] = not inside.any()
        score = np.where(ear, triangle_angles(tri).min(axis=1), -1.0)
        best = int(np.argmax(score))
        out.append((prv[best], idx[best], nxt[best]))
        del left[best]
    out.append((left[0], left[1], left[2]))
    return np.array(out, dtype=np.int64)


def triangulate(mesh: Mesh, quads: QuadSplit | str = QuadSplit.SHORTER) -> Triangulation:
    """Split every face of ``mesh`` into triangles, avoiding slivers.

    Parameters
    ----------
    mesh : Mesh
    quads : QuadSplit or str
        ``"shorter"`` (default) or ``"best"``; see :class:`QuadSplit`.

    Returns
    -------
    Triangulation
        ``valence - 2`` triangles per face, grouped by face in face order.

    Examples
    --------
    >>> import numpy as np
    >>> from ruledmesh.mesh import Mesh
    >>> quad = Mesh.from_faces([[0, 0, 0], [3, 0, 0], [2, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]])
    >>> triangulate(quad).triangles.tolist()  # diagonal 0-2 is the shorter one
    [[0, 1, 2], [0, 2, 3]]
    """
    quads = check_choice(quads, QuadSplit, "quads")
    val = mesh.valences
    offsets = np.zeros(mesh.n_faces + 1, dtype=np.int64)
    np.cumsum(val - 2, out=offsets[1:])
    triangles = np.zeros((int(offsets[-1]), 3), dtype=np.int64)
    for k in unique(val).tolist():
        ids, faces = mesh.faces_of_valence(k)
        if k <= MAX_TEMPLATE_VALENCE:
            templates = polygon_templates(k)
            pts = mesh.vertices[faces]
            if k == 3:
                pick = np.zeros(len(ids), dtype=np.int64)
            elif k == 4 and quads is QuadSplit.SHORTER:
                pick = _quads_shorter(pts)
            else:
                pick = _best_template(pts, templates)
            local = templates[pick]  # (F_k, k-2, 3) corner positions
        else:
            local = np.stack([_ear_clip(mesh.vertices[f]) for f in faces])
        rows = offsets[ids][:, None] + np.arange(k - 2)
        picked = np.take_along_axis(faces, local.reshape(len(ids), -1), axis=1)
        triangles[rows] = picked.reshape(len(ids), k - 2, 3)
    face_of = np.repeat(np.arange(mesh.n_faces, dtype=np.int64), val - 2)
    return Triangulation(triangles, face_of, offsets)


def recover_polygons(triangles: np.ndarray, face_of: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rebuild polygons from their triangles and face ids.

    Within one face, an edge shared by two of its triangles is a cut; the
    other edges form the polygon's boundary, which is chained into a loop
    starting at its smallest vertex index.  This is how the polygon structure
    comes back from an STL or glTF file given the per-triangle face id.

    Parameters
    ----------
    triangles : (T, 3) int
        Vertex indices, consistently oriented within each face.
    face_of : (T,) int
        Face id of each triangle, ``0..F-1``; the triangles need not be
        grouped or sorted.

    Returns
    -------
    face_offsets : (F + 1,) int64
    face_indices : (N,) int64
        Polygons in compressed-row form (see :class:`~ruledmesh.mesh.Mesh`),
        ordered by face id.
    """
    tri = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    fid = np.asarray(face_of, dtype=np.int64).reshape(-1)
    nface = int(fid.max()) + 1 if fid.size else 0
    nvert = int(tri.max()) + 1 if tri.size else 0
    a = tri.reshape(-1)
    b = np.roll(tri, -1, axis=1).reshape(-1)
    f = np.repeat(fid, 3)
    # Directed edge keys within a face; a cut appears in both directions.
    key = (f * nvert + a) * nvert + b
    rkey = (f * nvert + b) * nvert + a
    boundary = ~np.isin(key, rkey)
    f, a, b = f[boundary], a[boundary], b[boundary]
    valence = np.bincount(f, minlength=nface)
    offsets = np.zeros(nface + 1, dtype=np.int64)
    np.cumsum(valence, out=offsets[1:])
    # Successor lookup: sorted (face, start) -> end.
    order = np.lexsort((a, f))
    skey = f[order] * nvert + a[order]
    succ = b[order]
    start = np.full(nface, np.iinfo(np.int64).max)
    np.minimum.at(start, f, a)
    out = np.zeros(int(offsets[-1]), dtype=np.int64)
    faces = np.arange(nface)
    cur = start.copy()
    for step in range(int(valence.max()) if nface else 0):
        live = step < valence
        out[offsets[:-1][live] + step] = cur[live]
        pos = np.searchsorted(skey, faces[live] * nvert + cur[live])
        cur[live] = succ[pos]
    return offsets, out
