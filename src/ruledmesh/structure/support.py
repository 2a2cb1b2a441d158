"""Torsion-free support structures: node axes and the offset layer.

:func:`support_structure` gives every vertex of a mesh a *node axis* and
moves it along the axis to the *offset layer* at distance ``D``.  Three ways
to choose the axes, tried in this order by ``method="auto"``:

``circular``
    The mesh is circular (every face has a circumcircle): exact vertex
    offsets through the circles' axes, at the constant distance ``D``
    (:mod:`~ruledmesh.structure.circular`); taken when exact, on the side of
    ``D`` and within ``max_deviation`` degrees of the vertex normals.
``parallel``
    The member of the linear space of parallel meshes closest to
    ``V + D N`` (:mod:`~ruledmesh.structure.parallel`): exact wherever the
    space holds one; taken when its axes stay within ``max_deviation``
    degrees of the vertex normals, all on the side of ``D``.
``normal``
    The vertex normals themselves, at distance ``D``: always near-normal,
    generally *not* torsion-free; the torsion of every edge is reported.

Whatever the method, the result is measured afterwards
(:mod:`~ruledmesh.structure.measures`) and ``exact`` is true only when every
edge plane, every offset face and every offset edge passes the planarity
tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import Any

import numpy as np

from .._validation import check_choice, check_float
from ..analysis.circularity import circularity
from ..analysis.faces import planarity
from ..errors import GeometryError, ParameterError
from ..mesh import Mesh
from ..tolerances import DEFAULT, Tolerances
from ..tolerances import TINY as _TINY
from . import measures as M
from .circular import circular_axes
from .normals import face_edges, vertex_normals
from .parallel import closest_parallel_offset

__all__ = ["AxisMethod", "SupportStructure", "measure_structure", "support_structure"]


class AxisMethod(str, Enum):
    """How the node axes are chosen."""

    AUTO = "auto"
    CIRCULAR = "circular"
    PARALLEL = "parallel"
    NORMAL = "normal"


@dataclass(frozen=True, eq=False)
class SupportStructure:
    """A mesh with node axes and its offset layer.

    Attributes
    ----------
    mesh : Mesh
        The mesh the structure is built on (vertices used by no face dropped).
    offset : (V, 3) float64
        Offset layer: vertex ``i`` moved along its axis.
    normals : (V, 3) float64
        Area-weighted unit vertex normals of ``mesh``.
    method : AxisMethod
        How the axes were chosen (never ``AUTO``).
    distance : float
        The requested offset distance ``D`` (signed: negative is against the
        normals).
    edges : (E, 2) int64
        Face edges, sorted pairs.
    measures : dict
        Per-edge and per-face arrays from :func:`measure_structure`.
    exact : bool
        Torsion-free to rounding: every edge plane, offset face and offset
        edge within ``tol.planarity``.
    candidates : dict
        Summary of every method tried (also the ones not taken) and why.
    """

    mesh: Mesh
    offset: np.ndarray
    normals: np.ndarray
    method: AxisMethod
    distance: float
    edges: np.ndarray
    measures: dict[str, np.ndarray]
    exact: bool
    candidates: dict[str, Any] = field(default_factory=dict)

    @property
    def axes(self) -> np.ndarray:
        """(V, 3) float64: unit node axes, from the mesh towards the offset layer."""
        x = self.offset - self.mesh.vertices
        return x / np.maximum(np.linalg.norm(x, axis=1), _TINY)[:, None]

    @property
    def lengths(self) -> np.ndarray:
        """(V,) float64: distance of each offset vertex from its mesh vertex."""
        return np.linalg.norm(self.offset - self.mesh.vertices, axis=1)

    @property
    def deviation(self) -> np.ndarray:
        """(V,) float64: angle in degrees between each axis and its side's normal."""
        return M.axis_deviation(self.offset - self.mesh.vertices, np.sign(self.distance) * self.normals)

    @property
    def torsion(self) -> np.ndarray:
        """(E,) float64: torsion of every edge in degrees."""
        return self.measures["torsion_deg"]

    def summary(self) -> dict[str, Any]:
        """The figures written to ``structure.json`` (plain JSON types)."""
        return summarise(self)


def measure_structure(mesh: Mesh, offset: np.ndarray, edges: np.ndarray | None = None, *,
                      tol: Tolerances = DEFAULT) -> dict[str, np.ndarray]:
    """Every exactness measure of a mesh and its offset layer.

    Parameters
    ----------
    mesh : Mesh
    offset : (V, 3) float64
    edges : (E, 2) int64, optional
        Face edges (computed when omitted).
    tol : Tolerances
        ``degenerate`` decides when an axis runs along its edge (see
        :func:`~ruledmesh.structure.measures.edge_torsion`).

    Returns
    -------
    dict
        ``torsion_deg``, ``edge_planarity``, ``edge_parallelism`` (E,);
        ``offset_planarity``, ``face_parallelism``, ``mesh_planarity`` (F,).
    """
    edges = face_edges(mesh)[0] if edges is None else edges
    v = mesh.vertices
    return {
        "torsion_deg": M.edge_torsion(v, offset, edges, tol=tol),
        "edge_planarity": M.edge_plane_planarity(v, offset, edges),
        "edge_parallelism": M.edge_parallelism(v, offset, edges),
        "offset_planarity": M.offset_planarity(mesh, offset),
        "face_parallelism": M.face_parallelism(mesh, offset),
        "mesh_planarity": planarity(mesh),
    }


def _is_exact(measures: dict[str, np.ndarray], tol: Tolerances) -> bool:
    keys = ("edge_planarity", "edge_parallelism", "offset_planarity", "face_parallelism")
    return all(float(np.max(measures[k], initial=0.0)) <= tol.planarity for k in keys)


def _candidate(mesh, offset, normals, edges, distance, tol) -> dict[str, Any]:
    measures = measure_structure(mesh, offset, edges, tol=tol)
    x = offset - mesh.vertices
    along = np.einsum("ij,ij->i", x, normals) * np.sign(distance)
    dev = M.axis_deviation(x, np.sign(distance) * normals)
    return {"offset": offset, "measures": measures, "exact": _is_exact(measures, tol),
            "deviation_max_deg": float(dev.max(initial=0.0)),
            "same_side": bool(np.all(along > 0.0)),
            "torsion_max_deg": float(measures["torsion_deg"].max(initial=0.0))}


def _circular_candidate(mesh: Mesh, edges: np.ndarray, normals: np.ndarray, distance: float,
                        tol: Tolerances) -> dict[str, Any]:
    """The circular offset at ``distance``, measured."""
    v = mesh.vertices
    axes = circular_axes(v, edges, normals)
    cand = _candidate(mesh, v + distance * axes, normals, edges, distance, tol)
    # One projection onto the parallel space removes the rounding the
    # reflections accumulated along the spanning tree; it is kept only as a
    # correction of rounding size (faces with an odd number of sides can make
    # the reflected field inconsistent, and then no polish helps).
    polished = closest_parallel_offset(v, edges, axes, distance).offset
    if np.max(np.abs(polished - distance * axes)) <= tol.degenerate * abs(distance):
        polished_cand = _candidate(mesh, v + polished, normals, edges, distance, tol)
        if polished_cand["exact"]:
            return polished_cand
    return cand


def _acceptable(cand: dict[str, Any], max_deviation: float) -> bool:
    return bool(cand["exact"] and cand["same_side"] and cand["deviation_max_deg"] <= max_deviation)


def _why_not(cand: dict[str, Any], max_deviation: float) -> str:
    if not cand["exact"]:
        return "not exact"
    if not cand["same_side"]:
        return "some axes point to the other side of the mesh"
    return (f"axes deviate up to {cand['deviation_max_deg']:.3g} deg from the normals "
            f"(limit {max_deviation:g})")


def _prepare(mesh: Mesh, distance: float) -> tuple[Mesh, np.ndarray, np.ndarray]:
    if not isinstance(mesh, Mesh):
        raise ParameterError(f"expected a Mesh, got {type(mesh).__name__}", "mesh")
    if mesh.n_faces == 0:
        raise ParameterError("the mesh has no faces", "mesh")
    if not np.all(np.isfinite(mesh.vertices)):
        raise ParameterError("the mesh has NaN or infinite coordinates", "mesh")
    used = np.zeros(mesh.n_vertices, dtype=bool)
    used[mesh.face_indices] = True
    if not used.all():
        # A vertex on no face has no normal and no axis; members through it go too.
        keep = used[mesh.members].all(axis=1)
        mesh = Mesh(mesh.vertices, mesh.face_offsets, mesh.face_indices, mesh.face_kind,
                    mesh.members[keep], mesh.member_id[keep], mesh.vertex_data, mesh.info).compact()
    edges = face_edges(mesh)[0]
    length = np.linalg.norm(mesh.vertices[edges[:, 1]] - mesh.vertices[edges[:, 0]], axis=1)
    scale = mesh.diagonal() or 1.0
    if np.any(length <= tol_degenerate(scale)):
        raise GeometryError(f"the mesh has {int(np.count_nonzero(length <= tol_degenerate(scale)))} "
                            "edges of zero length; merge its vertices first")
    normals = vertex_normals(mesh)
    if np.any(np.linalg.norm(normals, axis=1) < 0.5):
        raise GeometryError("some vertices have no normal (their faces cancel or are degenerate)")
    return mesh, edges, normals


def tol_degenerate(scale: float, tol: Tolerances = DEFAULT) -> float:
    """Length below which an edge counts as zero, for a mesh of diagonal ``scale``."""
    return tol.degenerate * scale


def support_structure(mesh: Mesh, distance: float, *, method: AxisMethod | str = "auto",
                      max_deviation: float = 15.0, tol: Tolerances = DEFAULT) -> SupportStructure:
    """Node axes and the offset layer of ``mesh`` at distance ``distance``.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh (quads, triangles, pentagons, mixed), consistently
        oriented.
    distance : float
        Offset distance ``D`` along the normals (negative: the other side).
    method : {"auto", "circular", "parallel", "normal"}
        See the module notes.  ``"circular"`` raises when the mesh is not
        circular; ``"parallel"`` takes the closest parallel mesh whatever its
        deviation from the normals.
    max_deviation : float
        ``"auto"`` accepts the circular or the parallel axes when none
        deviates more than this from its normal, in degrees.
    tol : Tolerances
        ``planarity`` decides exactness, ``circularity`` whether the mesh is
        circular.

    Returns
    -------
    SupportStructure

    Examples
    --------
    >>> from ruledmesh.constructions import hyperboloid_mesh
    >>> s = support_structure(hyperboloid_mesh(1.0, 1.5, 2.0, 16, 8), 0.1)
    >>> s.method.value, s.exact, round(float(s.lengths.max()), 12)
    ('circular', True, 0.1)
    """
    distance = check_float(distance, "distance")
    if distance == 0.0:
        raise ParameterError("expected a non-zero offset distance, got 0", "distance")
    method = check_choice(method, AxisMethod, "method")
    max_deviation = check_float(max_deviation, "max_deviation", lo=0.0, hi=180.0)
    mesh, edges, normals = _prepare(mesh, distance)
    v = mesh.vertices
    tried: dict[str, Any] = {}

    def finish(name: AxisMethod, cand: dict[str, Any]) -> SupportStructure:
        public = {k: {kk: vv for kk, vv in c.items() if kk not in ("offset", "measures")}
                  for k, c in tried.items()}
        return SupportStructure(mesh, cand["offset"], normals, name, distance, edges,
                                cand["measures"], cand["exact"], public)

    if method in (AxisMethod.AUTO, AxisMethod.CIRCULAR):
        circ = float(circularity(mesh).max(initial=0.0))
        if circ <= tol.circularity:
            cand = _circular_candidate(mesh, edges, normals, distance, tol)
            accept = _acceptable(cand, max_deviation)
            tried["circular"] = {**cand, "circularity_max": circ}
            if not accept:
                tried["circular"]["rejected"] = _why_not(cand, max_deviation)
            if accept or method is AxisMethod.CIRCULAR:
                return finish(AxisMethod.CIRCULAR, cand)
        elif method is AxisMethod.CIRCULAR:
            raise GeometryError(f"the mesh is not circular (largest circularity {circ:.3g}, "
                                f"tolerance {tol.circularity:g}); use method auto or parallel")
        else:
            tried["circular"] = {"skipped": f"not circular (largest circularity {circ:.3g})"}
    if method in (AxisMethod.AUTO, AxisMethod.PARALLEL):
        fit = closest_parallel_offset(v, edges, normals, distance)
        cand = _candidate(mesh, v + fit.offset, normals, edges, distance, tol)
        accept = _acceptable(cand, max_deviation)
        if not accept:
            cand = {**cand, "rejected": _why_not(cand, max_deviation)}
        tried["parallel"] = cand
        if accept or method is AxisMethod.PARALLEL:
            return finish(AxisMethod.PARALLEL, cand)
    cand = _candidate(mesh, v + distance * normals, normals, edges, distance, tol)
    tried["normal"] = cand
    return finish(AxisMethod.NORMAL, cand)


def _reversed_edges(s: SupportStructure) -> int:
    """Offset edges pointing against their edges: the offset layer folds over there."""
    i, j = s.edges[:, 0], s.edges[:, 1]
    v, w = s.mesh.vertices, s.offset
    return int(np.count_nonzero(np.einsum("ij,ij->i", v[j] - v[i], w[j] - w[i]) <= 0.0))


def _stats(values: np.ndarray) -> dict[str, float]:
    if values.size == 0:
        return {"min": 0.0, "median": 0.0, "max": 0.0}
    return {"min": float(values.min()), "median": float(np.median(values)),
            "max": float(values.max())}


def summarise(s: SupportStructure) -> dict[str, Any]:
    """Plain-JSON figures of a structure (see :meth:`SupportStructure.summary`)."""
    m = s.measures
    dev = s.deviation
    lengths = s.lengths
    torsion = m["torsion_deg"]
    twisted = int(np.count_nonzero(m["edge_planarity"] > DEFAULT.planarity))
    return {
        "exact": bool(s.exact),
        "method": s.method.value,
        "offset": s.distance,
        "torsion_max_deg": float(torsion.max(initial=0.0)),
        "torsion_median_deg": float(np.median(torsion)) if torsion.size else 0.0,
        "twisted_edges": twisted,
        "reversed_edges": _reversed_edges(s),
        "edges": len(s.edges),
        "axis_deviation_deg": {"median": float(np.median(dev)), "max": float(dev.max())},
        "offset_distance": {**_stats(lengths), "ratio_to_offset": {
            "min": float(lengths.min() / abs(s.distance)), "max": float(lengths.max() / abs(s.distance))}},
        "edge_plane_planarity_max": float(m["edge_planarity"].max(initial=0.0)),
        "offset_planarity_max": float(m["offset_planarity"].max(initial=0.0)),
        "mesh_planarity_max": float(m["mesh_planarity"].max(initial=0.0)),
        "edge_parallelism_max": float(m["edge_parallelism"].max(initial=0.0)),
        "face_parallelism_max": float(m["face_parallelism"].max(initial=0.0)),
        "candidates": _jsonable(s.candidates),
    }


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (np.floating, float)):
        return float(obj)
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    return obj
