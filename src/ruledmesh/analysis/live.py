"""Live figures: counts, planarity, convexity and areas in one pass, the full report when asked.

A designer shows these figures after every edit; the full report
(:func:`.report.analyze`: angles, triangle quality, circularity, T-junctions,
closeness to the smooth surface) costs several times the build.  The quads'
diagonal crossing is taken once and read both ways (§2.1: the gap between the
diagonals is the planarity, where they cross decides convexity), the Newell
areas once.  :func:`.report.analyze` takes its planarity, convexity and areas
from :func:`face_measures` too, so the live figures and the full report are the
same numbers.

>>> import ruledmesh
>>> from ruledmesh.analysis.live import LiveAnalysis
>>> live = LiveAnalysis(ruledmesh.build("examples/skew.toml"))
>>> live.figures["planarity"]["max"] < 1e-12, live.figures["non_convex"]
(True, 0)
>>> live.report["planarity"] == live.figures["planarity"]  # computed when first asked
True
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from ..errors import GeometryError
from ..mesh import Mesh
from ..tolerances import DEFAULT, Tolerances
from . import faces as F

__all__ = ["FaceMeasures", "LiveAnalysis", "face_measures", "figure_warnings", "live_figures", "min_max_mean",
           "scaled_back", "unit_copy", "unit_figures"]


@dataclass(frozen=True)
class FaceMeasures:
    """Per-face planarity, convexity and area of a mesh.

    Attributes
    ----------
    planarity : (F,) float64
        :func:`.planar.face_planarity`: in the mesh's unit frame, triangles 0.
    convex : (F,) bool
        :func:`.faces.convexity` in the same frame.
    area : (F,) float64
        Newell areas in the mesh's units (:func:`.faces.face_normals`).
    rounding : (F,) float64
        :func:`.planar.rounding_allowance`: the planarity the rounding of each face's
        stored coordinates alone can give it.
    """

    planarity: np.ndarray
    convex: np.ndarray
    area: np.ndarray
    rounding: np.ndarray


def unit_copy(mesh: Mesh) -> tuple[Mesh, float]:
    """``mesh`` moved to the origin and scaled by a power of two to unit size (:func:`unit_frame`).

    Returns
    -------
    Mesh
        The copy (``mesh`` itself when its coordinates are not all finite).
    float
        The scale: lengths of the copy times it are lengths of ``mesh``.
    """
    from ..normalise import unit_frame

    v = mesh.vertices
    if not v.size or not np.all(np.isfinite(v)):
        return mesh, 1.0
    centre, scale = unit_frame(v)
    return mesh.with_vertices((v - centre) / scale), scale


def face_measures(mesh: Mesh, tol: Tolerances = DEFAULT, rounding: np.ndarray | None = None) -> FaceMeasures:
    """Planarity, convexity and area of every face, the quads' diagonals crossed once.

    Parameters
    ----------
    mesh : Mesh
    tol : Tolerances
        ``tol.convexity`` is the margin of the convexity test.
    rounding : (F,) float64, optional
        :func:`.planar.rounding_allowance` of the mesh where it was stored, when ``mesh`` is
        a copy moved to its unit frame (:func:`unit_copy`); default: that of ``mesh``.

    Returns
    -------
    FaceMeasures
        Planarity bit for bit :func:`.planar.face_planarity`, areas
        :func:`.faces.face_areas`, convexity :func:`.faces.convexity` (both taken
        in the unit frame the planarity is measured in).
    """
    framed, _ = unit_copy(mesh)
    plan = np.zeros(mesh.n_faces)
    convex = np.ones(mesh.n_faces, dtype=bool)
    with np.errstate(all="ignore"):  # non-finite coordinates give NaN, as face_planarity does
        qid, quads = framed.faces_of_valence(4)
        if qid.size:
            corners = framed.vertices[quads]
            s, t, gap = F.quad_diagonal_crossing(corners)
            plan[qid] = F.gap_planarity(corners, gap)
            convex[qid] = F.crossing_inside(s, t, tol.convexity)
        other = np.flatnonzero(framed.valences > 4)
        if other.size:
            plan[other] = F.polygon_planarity(framed, other)
            normals = F.face_normals(framed)[0][other]
            convex[other] = F.polygon_convexity(framed, other, normals, tol.convexity)
    from .planar import rounding_allowance

    return FaceMeasures(plan, convex, F.face_normals(mesh)[1],
                        rounding_allowance(mesh) if rounding is None else rounding)


def unit_figures(work: Mesh, measures: FaceMeasures, tol: Tolerances = DEFAULT) -> dict[str, Any]:
    """The live figures of a mesh already in its unit frame (:func:`unit_copy`), unscaled.

    The keys and values :func:`.report.analyze` reports under the same names:
    ``vertices``, ``faces``, ``members``, ``kinds``, ``finite``, ``diagonal``,
    ``planarity`` (with the tolerance and the exact / within-tolerance counts),
    ``non_convex``, ``area``; and ``quad_area_share``, the report's
    ``quality.area_share.quads``.
    """
    from .planar import planarity_bounds, planarity_tolerance

    plan, area = measures.planarity, measures.area
    ptol = planarity_tolerance(work, tol)
    # Far from the origin the stored coordinates' rounding bends faces beyond 1e-12: exact to
    # that rounding is exact (analysis.planar).
    exact_bound, allowed = planarity_bounds(work, measures.rounding, tol)
    exact = plan <= exact_bound
    within = ~exact & (plan <= allowed)
    total = float(area.sum())
    return {
        "vertices": work.n_vertices,
        "faces": work.n_faces,
        "members": len(work.members),
        "kinds": work.count_kinds(),
        "finite": bool(np.all(np.isfinite(work.vertices))),
        "diagonal": work.diagonal() or 1.0,
        "planarity": {
            **min_max_mean(plan),
            "tolerance": ptol,
            "above_tolerance": int(np.count_nonzero(plan > allowed)),
            "exact_to_rounding": int(np.count_nonzero(exact & (plan > tol.planarity))),
            "exact": int(np.count_nonzero(exact)),
            "within_tolerance": int(np.count_nonzero(within)),
            "max_exact": float(plan[exact].max()) if exact.any() else 0.0,
            "max_within_tolerance": float(plan[within].max()) if within.any() else 0.0,
        },
        "non_convex": int(np.count_nonzero(~measures.convex)),
        "area": {**min_max_mean(area), "total": total},
        "quad_area_share": float(area[work.valences == 4].sum() / (total or 1.0)),
    }


def min_max_mean(values: np.ndarray) -> dict[str, float]:
    """``{"min", "max", "mean"}`` of ``values`` (all 0.0 when there are none)."""
    if values.size == 0:
        return {"min": 0.0, "max": 0.0, "mean": 0.0}
    return {"min": float(values.min()), "max": float(values.max()), "mean": float(values.mean())}


def scaled_back(figures: dict[str, Any], scale: float) -> dict[str, Any]:
    """Figures taken in the unit frame with their absolute lengths and areas in the mesh's units."""
    if scale == 1.0:
        return figures
    figures["diagonal"] *= scale
    figures["area"] = {k: v * scale * scale for k, v in figures["area"].items()}
    if "edge_length" in figures:
        figures["edge_length"] = {k: v * scale for k, v in figures["edge_length"].items()}
    return figures


def figure_warnings(figures: Mapping[str, Any]) -> tuple[str | None, str | None, str | None]:
    """The warnings the live figures give: non-finite coordinates, non-convex faces, bent faces.

    Returns
    -------
    tuple of str or None
        Each warning's text, or None where the figures give no cause (the full
        report words them the same).
    """
    pl = figures["planarity"]
    return ("mesh has NaN or infinite coordinates" if not figures["finite"] else None,
            f"{figures['non_convex']} faces are not convex" if figures["non_convex"] else None,
            f"{pl['above_tolerance']} faces are not planar to {pl['tolerance']:g}"
            if pl["above_tolerance"] else None)


def live_figures(mesh: Mesh, tol: Tolerances = DEFAULT) -> dict[str, Any]:
    """Counts, planarity, convexity and areas of ``mesh``: the report's figures of those names.

    Parameters
    ----------
    mesh : Mesh
    tol : Tolerances

    Returns
    -------
    dict
        JSON-serialisable (see :func:`unit_figures` for the keys); the values
        are those :func:`.report.analyze` gives ``mesh``.  ``warnings`` holds the
        mesh's own (from its build) and those of :func:`figure_warnings`.

    Raises
    ------
    GeometryError
        If the mesh has no faces, as :func:`.report.analyze`.
    """
    from .planar import rounding_allowance
    from .report import strict_json

    work, scale = _checked_unit_copy(mesh)
    with np.errstate(all="ignore"):
        figures = scaled_back(unit_figures(work, face_measures(work, tol, rounding_allowance(mesh)), tol),
                              scale)
    said = [w for w in figure_warnings(figures) if w]
    figures["warnings"] = [str(w) for w in mesh.info.get("warnings", [])] + said
    return strict_json(figures)


def _checked_unit_copy(mesh: Mesh) -> tuple[Mesh, float]:
    if mesh.n_faces == 0:
        raise GeometryError(f"the mesh has no faces ({mesh.n_vertices} vertices); "
                            "nothing to analyse")
    return unit_copy(mesh)


@dataclass(frozen=True, eq=False)
class LiveAnalysis:
    """A mesh's live figures at once, its full report when first asked.

    Parameters
    ----------
    mesh : Mesh
    reference : Reference, optional
        The smooth design surface, for the full report's closeness and coverage.
    extras : mapping, optional
        Construction figures for the full report.
    tol : Tolerances
    """

    mesh: Mesh
    reference: Any = None
    extras: Mapping[str, Any] | None = None
    tol: Tolerances = DEFAULT

    @cached_property
    def figures(self) -> dict[str, Any]:
        """:func:`live_figures` of the mesh."""
        return live_figures(self.mesh, self.tol)

    @cached_property
    def report(self) -> dict[str, Any]:
        """The full :func:`.report.analyze` report (computed on first access, then kept)."""
        from .report import analyze

        return analyze(self.mesh, reference=self.reference, extras=self.extras, tol=self.tol)
