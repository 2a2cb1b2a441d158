"""How torsion-free a structure is: measured from the mesh and its offset alone.

Every measure here takes the two layers (mesh vertices ``V`` and offset
vertices ``W`` with the same faces), so it applies equally to a structure
just computed and to one read back from ``mesh.obj`` and ``offset.obj``.

* *torsion* of an edge ``i j``: the angle between the plane through the edge
  and the axis at ``i`` and the plane through the edge and the axis at ``j``
  (0 for a torsion-free edge; then a beam along the edge can be a planar slab
  through both axes);
* *edge-plane planarity*: the planarity of the quad ``V_i V_j W_j W_i`` (the
  beam's mid-plane), by the paper's diagonal criterion;
* *edge parallelism*: how far the offset edge leaves the direction of its
  edge, ``|e x (W_j - W_i)| / |e|``, relative to the mesh's bounding-box
  diagonal;
* *face parallelism*: how far the offset face's corners leave the plane
  through its first corner parallel to the face, relative to the diagonal
  (0 for an offset face planar and parallel to its face).

The last two are lengths relative to the model's size, not angles, so that a
sliver edge a thousandth of the model long is judged by the same rounding
as the rest of the model: the angle of a short edge moved far from the origin
carries rounding of the order of the coordinates divided by its length.
"""

from __future__ import annotations

import numpy as np

from ..analysis.faces import face_normals, planarity, quad_planarity
from ..mesh import Mesh
from ..tolerances import DEFAULT, Tolerances
from ..tolerances import TINY as _TINY

__all__ = [
    "axis_deviation",
    "edge_parallelism",
    "edge_plane_planarity",
    "edge_torsion",
    "face_parallelism",
    "offset_planarity",
]


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1), _TINY)[..., None]


def edge_torsion(vertices: np.ndarray, offset: np.ndarray, edges: np.ndarray, *,
                 tol: Tolerances = DEFAULT) -> np.ndarray:
    """Torsion of every edge, in degrees.

    Parameters
    ----------
    vertices, offset : (V, 3) float64
        The two layers; the axis at ``i`` is ``offset[i] - vertices[i]``.
    edges : (E, 2) int64
    tol : Tolerances
        An axis within ``tol.degenerate`` (sine) of its edge's line, or of
        zero length, spans no plane with it: the edge counts as torsion-free
        (the other axis and the edge are always coplanar).

    Returns
    -------
    (E,) float64
        Angle in [0, 90] between the planes (edge, axis i) and (edge, axis j).
    """
    i, j = edges[:, 0], edges[:, 1]
    e = _unit(vertices[j] - vertices[i])
    ai = _unit(offset[i] - vertices[i])
    aj = _unit(offset[j] - vertices[j])
    mi, mj = np.cross(e, ai), np.cross(e, aj)
    # |mi x mj| = |det(e, ai, aj)| for a unit edge vector.
    sin = np.abs(np.einsum("ij,ij->i", e, np.cross(ai, aj)))
    cos = np.abs(np.einsum("ij,ij->i", mi, mj))
    spans = np.minimum(np.linalg.norm(mi, axis=1), np.linalg.norm(mj, axis=1)) > tol.degenerate
    return np.where(spans, np.degrees(np.arctan2(sin, cos)), 0.0)


def edge_plane_planarity(vertices: np.ndarray, offset: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(E,) float64: planarity of the quads ``V_i V_j W_j W_i`` (0 = planar)."""
    i, j = edges[:, 0], edges[:, 1]
    quads = np.stack([vertices[i], vertices[j], offset[j], offset[i]], axis=1)
    return quad_planarity(quads)


def _diagonal(vertices: np.ndarray) -> float:
    return float(np.linalg.norm(np.ptp(vertices, axis=0))) if len(vertices) else 1.0


def edge_parallelism(vertices: np.ndarray, offset: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(E,) float64: offset edges' departure from their edges' directions / diagonal (0 = parallel)."""
    i, j = edges[:, 0], edges[:, 1]
    a = _unit(vertices[j] - vertices[i])
    return np.linalg.norm(np.cross(a, offset[j] - offset[i]), axis=1) / (_diagonal(vertices) or 1.0)


def face_parallelism(mesh: Mesh, offset: np.ndarray) -> np.ndarray:
    """(F,) float64: offset corners' distance from the plane parallel to their face / diagonal."""
    n0, _ = face_normals(mesh)
    face_of = mesh.face_of
    first = offset[mesh.face_indices[np.repeat(mesh.face_offsets[:-1], mesh.valences)]]
    gap = np.abs(np.einsum("ij,ij->i", offset[mesh.face_indices] - first, n0[face_of]))
    out = np.zeros(mesh.n_faces)
    np.maximum.at(out, face_of, gap)
    return out / (_diagonal(mesh.vertices) or 1.0)


def offset_planarity(mesh: Mesh, offset: np.ndarray) -> np.ndarray:
    """(F,) float64: planarity of the offset faces (same measure as the mesh's)."""
    return planarity(mesh.with_vertices(offset))


def axis_deviation(axes: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(V,) float64: angle in degrees between each axis and its vertex normal."""
    a, n = _unit(axes), _unit(normals)
    # atan2 keeps small angles exact (arccos of a cosine near 1 loses half the digits).
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, n), axis=1), np.einsum("ij,ij->i", a, n)))
