"""Unrolling: every planar panel laid flat in its own plane, exactly.

A planar face needs no development: an orthonormal frame in its plane (origin
at a corner, first axis along its longest edge, second axis ``normal x
first``) gives 2-D coordinates that keep every edge length and corner angle
up to rounding.  The 2-D polygon is seen from the side the face normal (the
Newell normal, which follows the face's vertex order) points to, so it runs
counter-clockwise; print or cut it with that side up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError, ParameterError
from ..mesh import Mesh
from ..tolerances import DEFAULT, Tolerances
from ..tolerances import TINY as _TINY

__all__ = ["Unrolled", "unroll", "corner_structure", "polygon_edges", "interior_angles",
           "min_area_rotation"]


def corner_structure(offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Face of each corner and the positions of its next and previous corners.

    Parameters
    ----------
    offsets : (F + 1,) int64
        Compressed-row face offsets.

    Returns
    -------
    face : (N,) int64
    nxt, prv : (N,) int64
        Positions (into the corner arrays) of the following and preceding corner.
    """
    val = np.diff(offsets)
    n = int(offsets[-1])
    face = np.repeat(np.arange(val.size), val)
    pos = np.arange(n)
    nxt = pos + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    prv = pos - 1
    prv[offsets[:-1]] = offsets[1:] - 1
    return face, nxt, prv


def polygon_edges(points: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """(N,) float64: length of the edge leaving every corner (corner i to i + 1).

    Parameters
    ----------
    points : (N, d) float64
        Corners of all faces, in compressed-row order.
    offsets : (F + 1,) int64
    """
    _, nxt, _ = corner_structure(offsets)
    return np.linalg.norm(points[nxt] - points, axis=1)


def interior_angles(points2d: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """(N,) float64: interior angle in radians at every corner of counter-clockwise polygons.

    Unlike the unsigned angle between the two edges, this tells a reflex
    corner (greater than pi) from a convex one, so it identifies a polygon
    up to congruence together with the edge lengths.

    Parameters
    ----------
    points2d : (N, 2) float64
    offsets : (F + 1,) int64
    """
    _, nxt, prv = corner_structure(offsets)
    d_in = points2d - points2d[prv]
    d_out = points2d[nxt] - points2d
    turn = np.arctan2(d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0],
                      np.einsum("ij,ij->i", d_in, d_out))
    return np.pi - turn


@dataclass(frozen=True, eq=False)
class Unrolled:
    """Faces of a mesh laid flat, each in its own plane.

    Attributes
    ----------
    points : (N, 2) float64
        2-D corners of all faces, in the mesh's ``face_indices`` order.
    face_offsets : (F + 1,) int64
        The mesh's face offsets (face ``f`` is ``points[face_offsets[f]:face_offsets[f + 1]]``).
    origin : (F, 3) float64
        The 3-D point mapped to (0, 0) for each face.
    axes : (F, 2, 3) float64
        The 3-D unit vectors of the 2-D axes: ``p3 = origin + x * axes[:, 0] + y * axes[:, 1]``.
    out_of_plane : (F,) float64
        Largest distance of a corner from the face's plane, divided by the face's
        longest edge (0 up to rounding for the planar faces ruledmesh builds).
    """

    points: np.ndarray
    face_offsets: np.ndarray
    origin: np.ndarray
    axes: np.ndarray
    out_of_plane: np.ndarray

    @property
    def n_faces(self) -> int:
        """Number of faces."""
        return int(self.face_offsets.size - 1)

    def polygon(self, f: int) -> np.ndarray:
        """(k, 2) float64: the 2-D corners of face ``f``."""
        return self.points[self.face_offsets[f]:self.face_offsets[f + 1]]

    def to_3d(self, points2d: np.ndarray) -> np.ndarray:
        """(N, 3) float64: map corners (in ``points`` layout) back into space."""
        face, _, _ = corner_structure(self.face_offsets)
        return (self.origin[face] + points2d[:, :1] * self.axes[face, 0]
                + points2d[:, 1:] * self.axes[face, 1])


def unroll(mesh: Mesh, *, require_planar: bool = True, tol: Tolerances = DEFAULT) -> Unrolled:
    """Lay every face of ``mesh`` flat in its own plane.

    Parameters
    ----------
    mesh : Mesh
    require_planar : bool
        Refuse faces whose corners leave their plane by more than
        ``tol.planarity`` times their longest edge: a bent panel cannot be cut
        flat, and projecting it would silently change its edge lengths.
    tol : Tolerances

    Returns
    -------
    Unrolled

    Raises
    ------
    GeometryError
        For degenerate faces (no area) and, with ``require_planar``, bent ones.
    """
    if not isinstance(mesh, Mesh):
        raise ParameterError(f"expected a Mesh, got {type(mesh).__name__}", "mesh")
    v = mesh.vertices
    off = mesh.face_offsets
    face, nxt, _ = corner_structure(off)
    p = v[mesh.face_indices]
    edge = p[nxt] - p
    length = np.linalg.norm(edge, axis=1)
    if mesh.n_faces == 0:
        z = np.zeros((0, 3))
        return Unrolled(np.zeros((0, 2)), off, z, np.zeros((0, 2, 3)), np.zeros(0))
    # The longest edge is the best-conditioned first axis of the face's frame.
    order = np.lexsort((-length, face))
    first = order[off[:-1]]
    longest = length[first]
    # Newell's vector area: the normal of the plane, oriented by the vertex order.
    cr = np.cross(p - p[first][face], p[nxt] - p[first][face])
    area_vec = 0.5 * np.add.reduceat(cr, off[:-1], axis=0)
    area = np.linalg.norm(area_vec, axis=1)
    bad = np.flatnonzero(area <= tol.degenerate * np.maximum(longest, _TINY) ** 2)
    if bad.size:
        raise GeometryError(f"{bad.size} faces have no area and cannot be unrolled "
                            f"(first: face {int(bad[0])})")
    normal = area_vec / area[:, None]
    e1 = edge[first] / longest[:, None]
    # Make e1 exactly orthogonal to the normal (rounding), then complete the frame.
    e1 = e1 - np.einsum("ij,ij->i", e1, normal)[:, None] * normal
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(normal, e1)
    origin = p[first]
    rel = p - origin[face]
    pts = np.stack([np.einsum("ij,ij->i", rel, e1[face]), np.einsum("ij,ij->i", rel, e2[face])],
                   axis=1)
    dist = np.abs(np.einsum("ij,ij->i", rel, normal[face]))
    out = np.maximum.reduceat(dist, off[:-1]) / longest
    if require_planar:
        # The rule the analysis reports by (ruledmesh.analysis.planar): what build
        # calls planar, fabricate cuts; triangles are planar by definition.
        from ..analysis.planar import bent_faces, planarity_tolerance

        is_bent, plan = bent_faces(mesh, tol)
        bent = np.flatnonzero(is_bent)
        if bent.size:
            worst = int(bent[np.argmax(np.nan_to_num(plan[bent], nan=np.inf))])
            raise GeometryError(
                f"{bent.size} faces are not planar to {planarity_tolerance(mesh, tol):g} "
                f"(worst: face {worst}, planarity {float(plan[worst]):.3g}, as "
                "`ruledmesh analyze` measures it); a bent panel cannot be cut flat")
    return Unrolled(pts, off, origin, np.stack([e1, e2], axis=1), out)


def min_area_rotation(points2d: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """(F,) float64: rotation (radians) giving each polygon its smallest bounding box.

    The minimum-area rectangle of a convex polygon has a side along one of its
    edges; trying every edge direction of every face at once keeps this
    vectorised (and is a good, if not always optimal, choice for non-convex
    faces too).  The box is then laid on its long side.
    """
    val = np.diff(offsets)
    nf = val.size
    if nf == 0:
        return np.zeros(0)
    k = int(val.max())
    cols = np.arange(k)
    mask = cols[None, :] < val[:, None]
    idx = np.where(mask, offsets[:-1, None] + cols, offsets[:-1, None])
    pts = points2d[idx]                                     # (F, K, 2), padded by corner 0
    nxt_idx = np.where(cols[None, :] + 1 < val[:, None], idx + 1, offsets[:-1, None])
    d = points2d[nxt_idx] - pts
    theta = np.arctan2(d[..., 1], d[..., 0])                # (F, K) candidate edge directions
    c, s = np.cos(theta), np.sin(theta)
    # Rotate every face by -theta_j for every candidate j: (F, K cand, K pts).
    x = c[:, :, None] * pts[:, None, :, 0] + s[:, :, None] * pts[:, None, :, 1]
    y = -s[:, :, None] * pts[:, None, :, 0] + c[:, :, None] * pts[:, None, :, 1]
    w = x.max(axis=2) - x.min(axis=2)
    h = y.max(axis=2) - y.min(axis=2)
    area = np.where(mask & (np.hypot(d[..., 0], d[..., 1]) > 0), w * h, np.inf)
    # Lay the box on its long side so shelves stay low.
    turn = h > w
    best = np.argmin(area, axis=1)
    rows = np.arange(nf)
    angle = -theta[rows, best] + np.where(turn[rows, best], np.pi / 2, 0.0)
    return angle
