"""The analysis report: one dictionary of figures, as a table or JSON.

Figures (relative ones are divided by the bounding-box diagonal):

* ``planarity``: per-face measure of :func:`.faces.planarity` (max, mean,
  number of faces above the tolerance);
* ``convexity``: number of non-convex faces;
* ``area``, ``edge_length``, ``min_angle``;
* ``closeness`` (with a reference surface): distance of face centroids and
  vertices from the smooth patch, relative to the diagonal;
* ``coverage`` (with a reference surface): mesh area / smooth patch area;
* ``guarantee_check`` (when a construction states a ``guarantee``): each
  promised property measured (:mod:`.guarantees`); a promise the figures do
  not confirm becomes a warning;
* ``t_junctions``: vertices inside an edge of a neighbouring face (:mod:`.conformity`),
  with a warning;
* ``matches_design`` (with a reference surface): False, with a warning, when
  closeness or coverage is far off (the mesh is not one of that design).

A mesh without faces is refused (:class:`~ruledmesh.errors.GeometryError`):
there is nothing to measure, and a table of zeros would read as a result.
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from typing import Any

import numpy as np

from .._arrays import median, percentile, unique
from ..errors import GeometryError
from ..mesh import FaceKind, Mesh
from ..progress import Progress, stages
from ..tolerances import CLOSENESS_SEARCH, DEFAULT, Tolerances
from . import faces as F
from .live import face_measures, figure_warnings, min_max_mean, scaled_back, unit_copy, unit_figures
from .planar import rounding_allowance

__all__ = ["KIND_NOUNS", "METRIC_HOOKS", "MISMATCH", "analyze", "format_summary", "format_table",
           "kind_counts", "require_faces", "strict_json"]

# The words every report, the command line and the docs use for face counts.
KIND_NOUNS = {
    FaceKind.QUAD: ("quad", "quads"),
    FaceKind.BORDER: ("border face", "border faces"),
    FaceKind.FILL: ("fill triangle", "fill triangles"),
    FaceKind.SPLIT: ("split quad", "split quads"),
    FaceKind.TRIANGLE: ("triangle", "triangles"),
    FaceKind.POLYGON: ("polygon", "polygons"),
    FaceKind.STRIP: ("strip quad", "strip quads"),
}

# A mesh "matches" a design unless its vertices are farther than this from the design
# surface (relative to the diagonal) or its area is outside this ratio of the patch's.
# Deliberately loose, "far off" only: meshes of the bundled designs reach 0.04 (hybrid
# meshes near torsal lines) and coverage 0.73 (compounds covering part of the patch); a
# skew mesh measured against the torus design gives 0.62 and 0.43.
MISMATCH: dict[str, Any] = {"closeness": 0.1, "coverage": (0.5, 2.0)}
# A mesh of the design (close to it) that covers less than this share of the designed
# patch's area gets a warning saying how much; the bundled designs cover 0.93 (the
# hybrid mesh of crossing lines) and more.
COVERAGE_WARN = 0.9

# Extra figures from other modules: name -> fn(mesh) -> dict or None (None: not applicable).
# Modules in _HOOK_MODULES register themselves here when imported.
METRIC_HOOKS: dict[str, Any] = {}
_HOOK_MODULES = ["ruledmesh.analysis.triangles"]


def _load_hooks() -> None:
    import importlib

    # circularity is a measure the transforms use too: it does not import the report
    from .circularity import circularity_report, parallelogram_report

    METRIC_HOOKS.setdefault("circularity", circularity_report)
    METRIC_HOOKS.setdefault("parallelogram", parallelogram_report)
    for name in _HOOK_MODULES:
        try:
            importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name != name:
                raise


def kind_counts(counts: Mapping[str, int]) -> str:
    """Face counts by kind in words: ``"633 quads, 9 border faces, 306 fill triangles"``.

    Parameters
    ----------
    counts : mapping of kind label to count
        As from :meth:`Mesh.count_kinds`.
    """
    words = []
    for label, n in counts.items():
        one, many = KIND_NOUNS[FaceKind.from_label(label)]
        words.append(f"{n} {one if n == 1 else many}")
    return ", ".join(words) or "no faces"


def _quality(mesh: Mesh, tol: Tolerances) -> dict[str, Any]:
    """What a fabricator reads first: area in quads, splinters, degenerate faces."""
    shares = F.area_shares(mesh)
    smallest = F.face_min_angles(mesh)
    return {
        "area_share": shares,
        "face_min_angle_deg": {
            "min": float(smallest.min()) if smallest.size else 0.0,
            "p5": percentile(smallest, 5) if smallest.size else 0.0,
            "median": median(smallest) if smallest.size else 0.0,
        },
        "faces_below_3deg": int(np.count_nonzero(smallest < F.SPLINTER_DEG)),
        "degenerate_faces": int(np.count_nonzero(F.degenerate_faces(mesh, tol.degenerate))),
    }


def analyze(mesh: Mesh, reference=None, extras: Mapping[str, Any] | None = None,
            tol: Tolerances = DEFAULT, compare: bool = False,
            progress: Progress | None = None) -> dict[str, Any]:
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
    progress : Progress, optional
        Told the figures as they are computed (see :mod:`ruledmesh.progress`).

    Returns
    -------
    dict
        JSON-serialisable figures (see the module docstring).

    Raises
    ------
    GeometryError
        If the mesh has no faces.
    """
    require_faces(mesh)
    _load_hooks()
    # The figures are taken on a copy in a unit frame (a power-of-two scale: exact),
    # so they do not depend on the scale of the mesh, and products of lengths never
    # overflow; absolute figures are scaled back.  Whatever still overflows (areas
    # of a mesh near 1e308) becomes null in the report, not a numpy warning.
    work, scale = unit_copy(mesh)
    names = ["faces"] + ["closeness"] * (reference is not None) + list(METRIC_HOOKS)
    with stages(progress, "analyse", names) as task, np.errstate(all="ignore"):
        report = scaled_back(_figures(work, tol, rounding_allowance(mesh)), scale)
        task.advance(note=names[1] if len(names) > 1 else None)
        if reference is not None:
            report.update(_closeness(mesh, reference, report["area"]["total"]))
            task.advance(note=names[2] if len(names) > 2 else None)
        for k, (name, hook) in enumerate(METRIC_HOOKS.items()):
            # Hooks that compare with the smooth surface take it as ``reference``,
            # only when a comparison was asked for (it tessellates the surface anew).
            takes_ref = compare and "reference" in inspect.signature(hook).parameters
            value = hook(mesh, reference=reference) if takes_ref else hook(work)
            if value is not None:
                report[name] = value
            task.advance(note=(list(METRIC_HOOKS) + [None])[k + 1])
    if extras:
        report.update(dict(extras))
    report["warnings"] = _warnings(work, report, tol)
    return strict_json(report)


def require_faces(mesh: Mesh) -> None:
    """Raise GeometryError if ``mesh`` has no faces (nothing to analyse or to write)."""
    if mesh.n_faces == 0:
        raise GeometryError(f"the mesh has no faces ({mesh.n_vertices} vertices); "
                            "nothing to analyse")


def strict_json(report: dict[str, Any]) -> dict[str, Any]:
    """``report`` with every NaN or infinite number replaced by ``None`` (JSON ``null``).

    The dotted paths of the replaced figures are listed in ``report["non_finite"]``
    and named in a warning, so the report stays strict JSON (RFC 8259 has no NaN)
    and says what it could not measure.
    """
    bad: list[str] = []

    def clean(value: Any, path: str) -> Any:
        if isinstance(value, (float, np.floating)):
            if not np.isfinite(value):
                bad.append(path)
                return None
            return float(value)
        if isinstance(value, Mapping):
            return {k: clean(v, f"{path}.{k}" if path else str(k)) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [clean(v, f"{path}[{i}]") for i, v in enumerate(value)]
        return value

    out = clean(report, "")
    if bad:
        shown = ", ".join(bad[:6]) + (f" and {len(bad) - 6} more" if len(bad) > 6 else "")
        out["non_finite"] = bad
        out.setdefault("warnings", []).append(
            f"{len(bad)} figures are beyond float64 (overflow or 0/0) and are null: {shown}")
    return out


def _figures(mesh: Mesh, tol: Tolerances, rounding: np.ndarray) -> dict[str, Any]:
    """The figures every mesh has: counts, planarity, convexity, sizes, angles (``mesh`` in its
    unit frame; ``rounding``: the planarity its stored coordinates' rounding allows each face)."""
    live = unit_figures(mesh, face_measures(mesh, tol, rounding), tol)
    angles = F.corner_angles(mesh)
    edges = mesh.edges()
    lengths = np.linalg.norm(mesh.vertices[edges[:, 1]] - mesh.vertices[edges[:, 0]], axis=1)
    report: dict[str, Any] = {k: live[k] for k in ("vertices", "faces", "members", "kinds")}
    report["valences"] = {str(int(k)): int(c) for k, c in zip(*np.unique(mesh.valences, return_counts=True))}
    report.update({k: live[k] for k in ("finite", "diagonal", "planarity", "non_convex", "area")})
    report.update({
        "edge_length": min_max_mean(lengths),
        "min_angle_deg": float(angles.min()) if angles.size else 0.0,
        "quality": _quality(mesh, tol),
        "euler_characteristic": mesh.euler_characteristic(len(edges)),
        "t_junctions": _t_junctions(mesh),
    })
    return report


def _t_junctions(mesh: Mesh) -> dict[str, Any]:
    """T-junctions (:mod:`.conformity`): how many, and the first few ``[vertex, a, b]``."""
    from .conformity import t_junctions

    found = t_junctions(mesh)
    return {"count": len(found), "first": found[:5].tolist()}


def _closeness(mesh: Mesh, reference, mesh_area: float) -> dict[str, Any]:
    """Closeness to the smooth patch and coverage of it (relative to the diagonal)."""
    diag = mesh.diagonal() or 1.0
    used = unique(mesh.face_indices)
    known = getattr(reference, "vertex_parameters", lambda _: None)(mesh)
    if known is None:
        dc = reference.distance(F.face_centroids(mesh)) / diag
        dv = reference.distance(mesh.vertices[used]) / diag
    else:
        # Where the mesher says on which generator and where each vertex lies, the
        # descent starts there (a face's at the mean of its corners'); only what ends
        # farther than CLOSENESS_SEARCH is searched for from samples too.
        u, t = known
        corner = mesh.face_indices
        mean = [np.add.reduceat(x[corner], mesh.face_offsets[:-1]) / mesh.valences for x in (u, t)]
        beyond = CLOSENESS_SEARCH * diag
        dc = reference.distance(F.face_centroids(mesh), near=(mean[0], mean[1]), beyond=beyond) / diag
        dv = reference.distance(mesh.vertices[used], near=(u[used], t[used]), beyond=beyond) / diag
    out: dict[str, Any] = {"closeness": {
        "vertices_max": float(dv.max()) if dv.size else 0.0,
        "centroids_max": float(dc.max()) if dc.size else 0.0,
        "centroids_mean": float(dc.mean()) if dc.size else 0.0,
        "relative_to": "bounding-box diagonal",
    }}
    patch = reference.area()
    if patch:
        out["coverage"] = {"mesh_area": mesh_area, "patch_area": float(patch),
                           "ratio": float(mesh_area / patch)}
    return out


def _design_mismatch(report: Mapping[str, Any]) -> list[str]:
    """Why the mesh is not one of the design it is measured against (empty: it is)."""
    why = []
    close = report["closeness"]["vertices_max"]
    if not close <= MISMATCH["closeness"]:
        why.append(f"closeness {close:.3g} > {MISMATCH['closeness']:g}")
    lo, hi = MISMATCH["coverage"]
    if "coverage" in report and not lo <= report["coverage"]["ratio"] <= hi:
        why.append(f"coverage {report['coverage']['ratio']:.3g} outside {lo:g}..{hi:g}")
    return why


def _low_coverage(report: Mapping[str, Any], explained: bool) -> str | None:
    """A warning when the mesh covers less than :data:`COVERAGE_WARN` of the designed patch."""
    cov = report.get("coverage")
    if not cov or cov["ratio"] is None or cov["ratio"] >= COVERAGE_WARN:
        return None
    why = ("the warnings above say which parts were left out" if explained else
           "parts of the designed patch have no faces (a notched or untrimmed border, rows "
           "that end short of the generators' ends, or faces dropped as degenerate)")
    return (f"the mesh covers {cov['ratio']:.1%} of the designed patch (mesh area "
            f"{cov['mesh_area']:.4g}, patch {cov['patch_area']:.4g}): {why}")


def _t_junction_warning(mesh: Mesh, tj: dict[str, Any]) -> str:
    """The warning of the T-junctions ``tj`` (:func:`_t_junctions`), naming the first.

    Where the edge runs along a generator (two of the three points on one generator) and
    the three points are not all on that one, the generators they lie on coincide there:
    the seam of a closed surface given by lines (the last line its first), whose two sides
    carry different divisions, rather than a face that fails to meet its neighbour.
    """
    v, a, b = tj["first"][0]
    said = (f"{tj['count']} T-junction{'s' if tj['count'] != 1 else ''}: vertex {v} lies inside the "
            f"edge {a}-{b} of another face")
    gap = "welding or smoothing in another program would open a gap there"
    data = mesh.vertex_data
    if "generator" in data and "t" in data:
        g, t = np.asarray(data["generator"])[[v, a, b]], np.asarray(data["t"])[[v, a, b]]
        along = any(g[i] == g[j] and t[i] != t[j] for i, j in ((0, 1), (0, 2), (1, 2)))
        on = sorted(set(g.tolist()))
        if along and on[0] >= 0 and len(on) > 1:
            return (f"{said}: generators {' and '.join(str(k) for k in on)} "
                    "coincide there (the seam of a closed surface) and each side is divided its own "
                    f"way; {gap}")
    return f"{said} (conforming by connectivity, not geometrically: {gap})"


def _warnings(mesh: Mesh, report: dict[str, Any], tol: Tolerances) -> list[str]:
    """Warnings from the figures; adds ``guarantee_check`` and ``matches_design``."""
    from .guarantees import check_guarantee, format_guarantee

    warnings = list(mesh.info.get("warnings", []))
    nonfinite, non_convex, bent = figure_warnings(report)
    warnings += [w for w in (nonfinite, non_convex) if w]
    share = report["quality"]["area_share"]
    said = any("of the area is not in quads" in w for w in warnings)
    if mesh.n_faces and 1.0 - share["quads"] > 0.3 and not said:
        warnings.append(f"{1.0 - share['quads']:.0%} of the area is not in quads "
                        f"(by kind: {_shares(share['by_kind'])})")
    if report["t_junctions"]["count"]:
        warnings.append(_t_junction_warning(mesh, report["t_junctions"]))
    if report["quality"]["degenerate_faces"]:
        warnings.append(f"{report['quality']['degenerate_faces']} faces have no area")
    if bent:
        warnings.append(bent)
    if "closeness" in report:
        why = _design_mismatch(report)
        report["matches_design"] = not why
        if why:
            warnings.append("the mesh does not match the design: " + ", ".join(why)
                            + " (is --design the file this mesh was built from?)")
        low = _low_coverage(report, bool(mesh.info.get("warnings")))
        if low and report["closeness"]["vertices_max"] <= MISMATCH["closeness"]:
            warnings.append(low)
    if isinstance(report.get("guarantee"), str):
        check = check_guarantee(report["guarantee"], mesh, tol)
        report["guarantee_check"] = check
        if not check["met"]:
            unmet = {**check, "properties": [r for r in check["properties"]
                                             if r["status"] == "not met"]}
            warnings.append(f"guarantee: {format_guarantee(unmet)}")
    return warnings


def _shares(by_kind: Mapping[str, float]) -> str:
    return ", ".join(f"{k} {v:.0%}" for k, v in sorted(by_kind.items(), key=lambda kv: -kv[1]))


def format_summary(report: Mapping[str, Any]) -> str:
    """One line: faces by kind and the worst planarity."""
    text = (f"{report['faces']} faces ({kind_counts(report['kinds'])}), {report['vertices']} vertices, "
            f"max planarity {report['planarity']['max']:.2e}")
    pl = report["planarity"]
    if pl.get("within_tolerance"):
        text += (f" ({pl['exact']} faces exact, {pl['within_tolerance']} within "
                 f"{pl['tolerance']:g})")
    if pl.get("exact_to_rounding"):
        # Far from the origin: the coordinates themselves cannot hold 1e-12 (analysis.planar).
        text += (f" ({pl['exact_to_rounding']} faces planar to the rounding of their "
                 "coordinates, which lie far from the origin)")
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
    from .guarantees import format_guarantee

    shown = {"kinds": kind_counts,
             "guarantee": lambda g: format_guarantee(report["guarantee_check"])
             if "guarantee_check" in report else str(g)}
    # "triangles" are the export triangulation's, not faces: the row says so.
    names = {"triangles": "triangulation"}
    rows = [(names.get(k, k), shown.get(k, _fmt)(v)) for k, v in report.items()
            if k not in ("warnings", "guarantee_check")]
    width = max(len(k) for k, _ in rows)
    lines = [f"{k.ljust(width)}  {v}" for k, v in rows]
    for w in report.get("warnings", []):
        lines.append(f"{'warning'.ljust(width)}  {w}")
    return "\n".join(lines) + "\n"
