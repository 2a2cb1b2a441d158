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
* *edge parallelism*: the sine of the angle between an edge and its offset;
* *face parallelism*: the sine of the angle between a face's normal and its
  offset's normal.
"""

from __future__ import annotations

import numpy as np

from ..analysis.faces import face_normals, planarity, quad_planarity
from ..mesh import Mesh

__all__ = [
    "axis_deviation",
    "edge_parallelism",
    "edge_plane_planarity",
    "edge_torsion",
    "face_parallelism",
    "offset_planarity",
]

_TINY = 1e-300


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1), _TINY)[..., None]


def edge_torsion(vertices: np.ndarray, offset: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Torsion of every edge, in degrees.

    Parameters
    ----------
    vertices, offset : (V, 3) float64
        The two layers; the axis at ``i`` is ``offset[i] - vertices[i]``.
    edges : (E, 2) int64

    Returns
    -------
    (E,) float64
        Angle in [0, 90] between the planes (edge, axis i) and (edge, axis j);
        0 where an axis is along the edge or zero (no plane to compare).
    """
    i, j = edges[:, 0], edges[:, 1]
    e = _unit(vertices[j] - vertices[i])
    ai = _unit(offset[i] - vertices[i])
    aj = _unit(offset[j] - vertices[j])
    mi, mj = np.cross(e, ai), np.cross(e, aj)
    # |mi x mj| = |det(e, ai, aj)| for a unit edge vector.
    sin = np.abs(np.einsum("ij,ij->i", e, np.cross(ai, aj)))
    cos = np.abs(np.einsum("ij,ij->i", mi, mj))
    return np.degrees(np.arctan2(sin, cos))


def edge_plane_planarity(vertices: np.ndarray, offset: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(E,) float64: planarity of the quads ``V_i V_j W_j W_i`` (0 = planar)."""
    i, j = edges[:, 0], edges[:, 1]
    quads = np.stack([vertices[i], vertices[j], offset[j], offset[i]], axis=1)
    return quad_planarity(quads)


def edge_parallelism(vertices: np.ndarray, offset: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(E,) float64: sine of the angle between each edge and its offset (0 = parallel)."""
    i, j = edges[:, 0], edges[:, 1]
    a = _unit(vertices[j] - vertices[i])
    b = _unit(offset[j] - offset[i])
    return np.linalg.norm(np.cross(a, b), axis=1)


def face_parallelism(mesh: Mesh, offset: np.ndarray) -> np.ndarray:
    """(F,) float64: sine of the angle between each face and its offset face."""
    n0, _ = face_normals(mesh)
    n1, _ = face_normals(mesh.with_vertices(offset))
    return np.linalg.norm(np.cross(n0, n1), axis=1)


def offset_planarity(mesh: Mesh, offset: np.ndarray) -> np.ndarray:
    """(F,) float64: planarity of the offset faces (same measure as the mesh's)."""
    return planarity(mesh.with_vertices(offset))


def axis_deviation(axes: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(V,) float64: angle in degrees between each axis and its vertex normal."""
    a, n = _unit(axes), _unit(normals)
    # atan2 keeps small angles exact (arccos of a cosine near 1 loses half the digits).
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, n), axis=1), np.einsum("ij,ij->i", a, n)))
