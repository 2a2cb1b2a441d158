"""The analysis report: one dictionary of figures, as a table or JSON.

Figures (relative ones are divided by the bounding-box diagonal):

* ``planarity``: per-face measure of :func:`.faces.planarity` (max, mean,
  number of faces above the tolerance);
* ``convexity``: number of non-convex faces;
* ``area``, ``edge_length``, ``min_angle``;
* ``closeness`` (with a reference surface): distance of face centroids and
  vertices from the smooth patch, relative to the diagonal;
* ``coverage`` (with a reference surface): mesh area / smooth patch area.
"""

from __future__ import annotations

import inspect
from typing import Any, Mapping

import numpy as np

from ..mesh import Mesh
from ..tolerances import DEFAULT, Tolerances
from . import faces as F

__all__ = ["analyze", "format_table", "format_summary", "METRIC_HOOKS"]

# Extra figures from other modules: name -> fn(mesh) -> dict or None (None: not applicable).
# Modules in _HOOK_MODULES register themselves here when imported.
METRIC_HOOKS: dict[str, Any] = {}
_HOOK_MODULES = ["ruledmesh.analysis.circularity", "ruledmesh.analysis.triangles"]


def _load_hooks() -> None:
    import importlib

    for name in _HOOK_MODULES:
        try:
            importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name != name:
                raise


def _stats(values: np.ndarray) -> dict[str, float]:
    if values.size == 0:
        return {"min": 0.0, "max": 0.0, "mean": 0.0}
    return {"min": float(values.min()), "max": float(values.max()), "mean": float(values.mean())}


def _planarity(plan: np.ndarray, mesh: Mesh, tol: Tolerances) -> dict[str, Any]:
    """Planarity figures; faces exact (to rounding) told apart from those within a tolerance."""
    ptol = max(float(mesh.info.get("planarity_tolerance", tol.planarity)), tol.planarity)
    exact = plan <= tol.planarity
    within = ~exact & (plan <= ptol)
    return {
        **_stats(plan),
        "tolerance": ptol,
        "above_tolerance": int(np.count_nonzero(plan > ptol)),
        "exact": int(np.count_nonzero(exact)),
        "within_tolerance": int(np.count_nonzero(within)),
        "max_exact": float(plan[exact].max()) if exact.any() else 0.0,
        "max_within_tolerance": float(plan[within].max()) if within.any() else 0.0,
    }


def _quality(mesh: Mesh, tol: Tolerances) -> dict[str, Any]:
    """What a fabricator reads first: area in quads, splinters, degenerate faces."""
    shares = F.area_shares(mesh)
    smallest = F.face_min_angles(mesh)
    return {
        "area_share": shares,
        "face_min_angle_deg": {
            "min": float(smallest.min()) if smallest.size else 0.0,
            "p5": float(np.percentile(smallest, 5)) if smallest.size else 0.0,
            "median": float(np.median(smallest)) if smallest.size else 0.0,
        },
        "faces_below_3deg": int(np.count_nonzero(smallest < 3.0)),
        "degenerate_faces": int(np.count_nonzero(F.degenerate_faces(mesh, tol.degenerate))),
    }


def analyze(mesh: Mesh, reference=None, extras: Mapping[str, Any] | None = None,
            tol: Tolerances = DEFAULT, compare: bool = False) -> dict[str, Any]:
    """Measure ``mesh``.

    Parameters
    ----------
    mesh : Mesh
    reference : Reference, optional
        The smooth design surface (``distance(points)``, ``area()``).
    extras : mapping, optional
        Construction-specific figures to include as they are.
    tol : Tolerances
    compare : bool
        Also let hooks that compare with the smooth surface run (e.g. the
        triangulation against the parameter-grid and OCCT tessellations of
        the same surface); slow, so off by default.

    Returns
    -------
    dict
        JSON-serialisable figures (see the module docstring).
    """
    diag = mesh.diagonal() or 1.0
    plan = F.planarity(mesh)
    convex = F.convexity(mesh, tol.convexity)
    normals, areas = F.face_normals(mesh)
    angles = F.corner_angles(mesh)
    edges = mesh.edges()
    lengths = np.linalg.norm(mesh.vertices[edges[:, 1]] - mesh.vertices[edges[:, 0]], axis=1)
    finite = bool(np.all(np.isfinite(mesh.vertices)))
    report: dict[str, Any] = {
        "vertices": mesh.n_vertices,
        "faces": mesh.n_faces,
        "members": int(len(mesh.members)),
        "kinds": mesh.count_kinds(),
        "valences": {str(int(k)): int(c) for k, c in zip(*np.unique(mesh.valences, return_counts=True))},
        "finite": finite,
        "diagonal": diag,
        "planarity": _planarity(plan, mesh, tol),
        "non_convex": int(np.count_nonzero(~convex)),
        "area": {**_stats(areas), "total": float(areas.sum())},
        "edge_length": _stats(lengths),
        "min_angle_deg": float(angles.min()) if angles.size else 0.0,
        "quality": _quality(mesh, tol),
        "euler_characteristic": mesh.euler_characteristic(len(edges)),
    }
    if reference is not None:
        cent = F.face_centroids(mesh)
        dc = reference.distance(cent) / diag
        dv = reference.distance(mesh.vertices[np.unique(mesh.face_indices)]) / diag
        report["closeness"] = {
            "vertices_max": float(dv.max()) if dv.size else 0.0,
            "centroids_max": float(dc.max()) if dc.size else 0.0,
            "centroids_mean": float(dc.mean()) if dc.size else 0.0,
            "relative_to": "bounding-box diagonal",
        }
        patch = reference.area()
        if patch:
            report["coverage"] = {
                "mesh_area": float(areas.sum()),
                "patch_area": float(patch),
                "ratio": float(areas.sum() / patch),
            }
    _load_hooks()
    for name, hook in METRIC_HOOKS.items():
        # Hooks that compare with the smooth surface take it as ``reference``,
        # only when a comparison was asked for (it tessellates the surface anew).
        takes_ref = compare and "reference" in inspect.signature(hook).parameters
        value = hook(mesh, reference=reference) if takes_ref else hook(mesh)
        if value is not None:
            report[name] = value
    if extras:
        report.update(dict(extras))
    warnings = list(mesh.info.get("warnings", []))
    if not finite:
        warnings.append("mesh has NaN or infinite coordinates")
    if report["non_convex"]:
        warnings.append(f"{report['non_convex']} faces are not convex")
    share = report["quality"]["area_share"]
    said = any("of the area is not in quads" in w for w in warnings)
    if mesh.n_faces and 1.0 - share["quads"] > 0.3 and not said:
        warnings.append(f"{1.0 - share['quads']:.0%} of the area is not in quads "
                        f"(by kind: {_shares(share['by_kind'])})")
    if report["quality"]["degenerate_faces"]:
        warnings.append(f"{report['quality']['degenerate_faces']} faces have no area")
    if report["planarity"]["above_tolerance"]:
        warnings.append(f"{report['planarity']['above_tolerance']} faces are not planar to "
                        f"{report['planarity']['tolerance']:g}")
    report["warnings"] = warnings
    return report


def _shares(by_kind: Mapping[str, float]) -> str:
    return ", ".join(f"{k} {v:.0%}" for k, v in sorted(by_kind.items(), key=lambda kv: -kv[1]))


def format_summary(report: Mapping[str, Any]) -> str:
    """One line: faces by kind and the worst planarity."""
    kinds = ", ".join(f"{c} {k}" for k, c in report["kinds"].items())
    text = (f"{report['faces']} faces ({kinds}), {report['vertices']} vertices, "
            f"max planarity {report['planarity']['max']:.2e}")
    pl = report["planarity"]
    if pl.get("within_tolerance"):
        text += (f" ({pl['exact']} faces exact, {pl['within_tolerance']} within "
                 f"{pl['tolerance']:g})")
    q = report.get("quality")
    if q:
        text += (f", {q['area_share']['quads']:.0%} of the area in quads, smallest angle "
                 f"{q['face_min_angle_deg']['min']:.2f} deg")
    if "coverage" in report:
        text += f", coverage {report['coverage']['ratio']:.4f}"
    return text


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, Mapping):
        return ", ".join(f"{k} {_fmt(v)}" for k, v in value.items())
    if isinstance(value, (list, tuple)):
        return "; ".join(_fmt(v) for v in value) or "-"
    return str(value)


def format_table(report: Mapping[str, Any]) -> str:
    """The report as an aligned two-column text table."""
    rows = [(k, _fmt(v)) for k, v in report.items() if k != "warnings"]
    width = max(len(k) for k, _ in rows)
    lines = [f"{k.ljust(width)}  {v}" for k, v in rows]
    for w in report.get("warnings", []):
        lines.append(f"{'warning'.ljust(width)}  {w}")
    return "\n".join(lines) + "\n"
