"""Which faces are planar: the one rule that build, analyze, fabricate and the exports share.

The measure is :func:`ruledmesh.analysis.faces.planarity` (the paper's for quads:
the distance between the diagonal lines over the mean diagonal; the best-fit plane
for larger polygons; 0 for triangles, which are planar by definition).  It is taken
on a copy of the mesh moved to the origin and scaled by a power of two, so it does
not depend on where the mesh lies or how large it is, and a face is *bent* when it
exceeds :func:`planarity_tolerance` and what the rounding of its stored coordinates can
explain (:func:`rounding_allowance`: far from the origin a float64 coordinate cannot hold a
panel's corners to 1e-12 of its size).  Because every tool asks this module, the
report of ``ruledmesh build`` and the refusal of ``ruledmesh fabricate`` cannot
disagree about a face.
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh
from ..tolerances import COORDINATE_ROUNDING, DEFAULT, TINY, Tolerances

__all__ = ["bent_faces", "face_planarity", "planarity_bounds", "planarity_tolerance", "rounding_allowance"]


def face_planarity(mesh: Mesh) -> np.ndarray:
    """(F,) float64: the planarity of every face, measured in the mesh's unit frame.

    Triangles are 0.  Non-finite coordinates give NaN for their faces.
    """
    from ..normalise import unit_frame
    from .faces import planarity

    v = mesh.vertices
    if v.size and np.all(np.isfinite(v)):
        centre, scale = unit_frame(v)
        mesh = mesh.with_vertices((v - centre) / scale)
    with np.errstate(all="ignore"):
        return planarity(mesh)


def planarity_tolerance(mesh: Mesh, tol: Tolerances = DEFAULT) -> float:
    """The planarity a face of ``mesh`` may have: ``tol.planarity``, or the mesh's own.

    A mesh built with ``[mesh] planarity_tolerance`` (nearly developable strips)
    records it in ``info["planarity_tolerance"]``; it is never below ``tol.planarity``.
    """
    return max(float(mesh.info.get("planarity_tolerance", tol.planarity)), tol.planarity)


def rounding_allowance(mesh: Mesh) -> np.ndarray:
    """(F,) float64: the planarity the rounding of each face's stored coordinates alone can give it.

    :data:`~ruledmesh.tolerances.COORDINATE_ROUNDING` times the largest absolute
    coordinate of the mesh over the face's longest edge.  Near the origin it is far below
    the tolerance; a design placed in building coordinates 5e6 m out has its 1 m panels'
    corners stored to 9e-10 m, and their planarity measures up to about 1e-9 however
    exactly they were built.  0 where a coordinate is not finite.
    """
    v = mesh.vertices
    if not mesh.n_faces or not np.all(np.isfinite(v)):
        return np.zeros(mesh.n_faces)
    idx = mesh.face_indices
    edge = np.linalg.norm(v[idx[mesh.next_corners()]] - v[idx], axis=1)
    longest = np.maximum.reduceat(edge, mesh.face_offsets[:-1])
    return COORDINATE_ROUNDING * float(np.abs(v).max()) / np.maximum(longest, TINY)


def planarity_bounds(mesh: Mesh, rounding: np.ndarray,
                     tol: Tolerances = DEFAULT) -> tuple[np.ndarray, np.ndarray]:
    """(F,) float64 each: the planarity up to which each face of ``mesh`` is exact, and up to
    which it is planar (within :func:`planarity_tolerance`); both at least ``rounding``
    (:func:`rounding_allowance` of the mesh as stored: ``mesh`` may be its unit-frame copy).
    """
    return np.maximum(tol.planarity, rounding), np.maximum(planarity_tolerance(mesh, tol), rounding)


def bent_faces(mesh: Mesh, tol: Tolerances = DEFAULT) -> tuple[np.ndarray, np.ndarray]:
    """Faces that are not planar within :func:`planarity_tolerance`, nor within what the
    rounding of their coordinates can explain (:func:`rounding_allowance`).

    Returns
    -------
    bent : (F,) bool
    planarity : (F,) float64
        The measure of every face (:func:`face_planarity`).
    """
    plan = face_planarity(mesh)
    return ~(plan <= planarity_bounds(mesh, rounding_allowance(mesh), tol)[1]), plan
