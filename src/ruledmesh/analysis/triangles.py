"""Triangle quality of the export triangulation, and the splinter comparison.

The paper (§6) blames the rough look of ruled surfaces in renderings and
prints on the standard tessellation: *splinters*, triangles with one or two
very small angles.  This module measures a triangulation (smallest angles,
aspect ratios) and compares ruledmesh's triangulated PQ mesh with two
standard tessellations of the same smooth surface: the parameter-grid
triangulation (a uniform ``(u, t)`` grid, every cell cut along the same
diagonal, as most tools do) and, when ``cadquery-ocp`` is installed, OCCT's
``BRepMesh_IncrementalMesh`` of a B-spline surface through the same patch.

The aspect ratio is the radius ratio ``R / (2 r)`` (circumradius over twice
the inradius): 1 for an equilateral triangle, growing without bound for a
splinter.  A triangle is counted as a splinter when its smallest angle is
below :data:`SPLINTER_ANGLE` degrees.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import Any

import numpy as np

from .._arrays import median, percentile
from ..errors import ParameterError
from ..mesh import Mesh
from ..tolerances import OCCT_FACE, TINY
from ..triangulate import triangle_angles, triangulate
from .report import METRIC_HOOKS

__all__ = [
    "SPLINTER_ANGLE",
    "ASPECT_BINS",
    "aspect_ratios",
    "triangle_quality",
    "mesh_triangle_quality",
    "parameter_grid",
    "occt_tessellation",
    "compare_tessellations",
]

SPLINTER_ANGLE = 10.0
"""Degrees: a triangle whose smallest angle is below this is a splinter."""

ASPECT_BINS = (1.0, 1.5, 2.0, 3.0, 5.0, 10.0, np.inf)
"""Bin edges of the aspect-ratio distribution in the report."""


def aspect_ratios(points: np.ndarray) -> np.ndarray:
    """Radius ratio ``R / (2 r)`` of triangles (1 when equilateral).

    Parameters
    ----------
    points : (T, 3, 3) float64

    Returns
    -------
    (T,) float64
        ``inf`` for a degenerate triangle.

    Examples
    --------
    >>> import numpy as np
    >>> eq = np.array([[[0, 0, 0], [1, 0, 0], [0.5, 3 ** 0.5 / 2, 0]]])
    >>> round(float(aspect_ratios(eq)[0]), 12)
    1.0
    """
    p = np.asarray(points, dtype=np.float64)
    a = np.linalg.norm(p[:, 1] - p[:, 2], axis=1)
    b = np.linalg.norm(p[:, 2] - p[:, 0], axis=1)
    c = np.linalg.norm(p[:, 0] - p[:, 1], axis=1)
    # R / (2 r) = a b c / (8 (s - a)(s - b)(s - c)), s the half perimeter.
    s = 0.5 * (a + b + c)
    den = 8.0 * (s - a) * (s - b) * (s - c)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(den > 0, a * b * c / np.where(den > 0, den, 1.0), np.inf)
    return np.maximum(ratio, 1.0)


def triangle_quality(vertices: np.ndarray, triangles: np.ndarray) -> dict[str, Any]:
    """Smallest angles and aspect ratios of a triangulation.

    Parameters
    ----------
    vertices : (V, 3) float64
    triangles : (T, 3) int

    Returns
    -------
    dict
        ``triangles``; ``min_angle_deg`` (the smallest angle anywhere);
        ``min_angle_percentiles`` (1, 5, 50 % of the per-triangle smallest
        angle); ``splinters`` (triangles whose smallest angle is below
        :data:`SPLINTER_ANGLE`); ``aspect_ratio`` (median, 95 %, max over the
        non-degenerate triangles), ``degenerate_triangles`` (zero area) and
        ``aspect_histogram`` (counts per :data:`ASPECT_BINS` interval).
    """
    pts = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles, dtype=np.int64)]
    if len(pts) == 0:
        return {"triangles": 0}
    mins = triangle_angles(pts).min(axis=1)
    ar = aspect_ratios(pts)
    counts, _ = np.histogram(np.minimum(ar, 1e300), bins=np.array(ASPECT_BINS[:-1] + (1e301,)))
    labels = [f"{lo:g}-{hi:g}" for lo, hi in itertools.pairwise(ASPECT_BINS)]
    return {
        "triangles": len(pts),
        "min_angle_deg": float(mins.min()),
        "min_angle_percentiles": {f"p{q}": percentile(mins, q) for q in (1, 5, 50)},
        "splinters": int(np.count_nonzero(mins < SPLINTER_ANGLE)),
        # Degenerate triangles (infinite ratio) are counted, not averaged: statistics of
        # infinities are NaN, and JSON has no infinity.
        "aspect_ratio": ({"median": median(fin), "p95": percentile(fin, 95),
                          "max": float(fin.max())} if (fin := ar[np.isfinite(ar)]).size
                         else {"median": 0.0, "p95": 0.0, "max": 0.0}),
        "degenerate_triangles": int(np.count_nonzero(~np.isfinite(ar))),
        "aspect_histogram": dict(zip(labels, counts.tolist())),
    }


def mesh_triangle_quality(mesh: Mesh, quads: str = "shorter") -> dict[str, Any] | None:
    """:func:`triangle_quality` of ``mesh`` as STL/glTF export triangulates it.

    Returns None for a mesh without faces.
    """
    if mesh.n_faces == 0:
        return None
    tri = triangulate(mesh, quads)
    out = triangle_quality(mesh.vertices, tri.triangles)
    out["split"] = f"quads along the {quads} diagonal; polygons by largest smallest angle"
    return out


def parameter_grid(point: Callable[[np.ndarray, np.ndarray], np.ndarray], nu: int, nt: int,
                   diagonal: str = "fixed") -> tuple[np.ndarray, np.ndarray]:
    """The parameter-grid triangulation of a surface patch ``point(u, t)``, ``0 <= u, t <= 1``.

    Parameters
    ----------
    point : callable
        ``point(u, t) -> (n, 3)`` for arrays ``u, t`` of shape (n,).
    nu, nt : int
        Cells along ``u`` and ``t``.
    diagonal : {"fixed", "shorter"}
        ``"fixed"``: every cell cut from (i, j) to (i + 1, j + 1), the
        standard tessellation; ``"shorter"``: each cell along its shorter
        diagonal (a kinder baseline).

    Returns
    -------
    vertices : ((nu + 1) (nt + 1), 3) float64
    triangles : (2 nu nt, 3) int64
    """
    u, t = np.meshgrid(np.linspace(0, 1, nu + 1), np.linspace(0, 1, nt + 1), indexing="ij")
    verts = np.asarray(point(u.reshape(-1), t.reshape(-1)), dtype=np.float64).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nt), indexing="ij")
    v00 = (i * (nt + 1) + j).reshape(-1)
    v10, v01, v11 = v00 + nt + 1, v00 + 1, v00 + nt + 2
    main = np.concatenate([np.stack([v00, v10, v11], 1), np.stack([v00, v11, v01], 1)])
    if diagonal == "fixed":
        return verts, main
    other = np.concatenate([np.stack([v00, v10, v01], 1), np.stack([v10, v11, v01], 1)])
    d_main = np.linalg.norm(verts[v11] - verts[v00], axis=1)
    d_other = np.linalg.norm(verts[v01] - verts[v10], axis=1)
    use_main = np.tile(d_main <= d_other, 2)
    return verts, np.where(use_main[:, None], main, other)


def _grid_counts(point, n_triangles: int) -> tuple[int, int]:
    """Cell counts along u and t giving about ``n_triangles`` triangles with
    cells about as long as wide (in the mean)."""
    s = np.linspace(0, 1, 17)
    uu, tt = np.meshgrid(s, s, indexing="ij")
    p = np.asarray(point(uu.reshape(-1), tt.reshape(-1))).reshape(17, 17, 3)
    len_u = np.linalg.norm(np.diff(p, axis=0), axis=2).sum(axis=0).mean()
    len_t = np.linalg.norm(np.diff(p, axis=1), axis=2).sum(axis=1).mean()
    cells = max(n_triangles / 2.0, 1.0)
    nu = max(int(round(np.sqrt(cells * len_u / max(len_t, TINY)))), 1)  # noqa: RUF046 - numpy scalar
    nt = max(round(cells / nu), 1)
    return nu, nt


def occt_tessellation(point: Callable[[np.ndarray, np.ndarray], np.ndarray],
                      deflection: float, samples: int = 33) -> tuple[np.ndarray, np.ndarray] | None:
    """OCCT's BRepMesh tessellation of a B-spline surface through the patch.

    The patch ``point(u, t)`` is sampled on a ``samples x samples`` grid,
    approximated by a B-spline surface (``GeomAPI_PointsToBSplineSurface``),
    and meshed by ``BRepMesh_IncrementalMesh`` with the given linear
    deflection (and OCCT's default angular deflection, 0.5 rad).

    Returns
    -------
    (vertices, triangles) or None
        None when ``cadquery-ocp`` is not installed.
    """
    try:
        from OCP.BRep import BRep_Tool
        from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
        from OCP.BRepMesh import BRepMesh_IncrementalMesh
        from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface
        from OCP.gp import gp_Pnt
        from OCP.TopLoc import TopLoc_Location
    except ImportError:
        return None
    try:  # OCP 7.x names the array TColgp_Array2OfPnt, OCP 8 moved it.
        from OCP.TColgp import TColgp_Array2OfPnt as Array2
    except ImportError:
        try:
            from OCP.OCP.collections import Array2_gp_Pnt as Array2
        except ImportError:
            return None
    s = np.linspace(0, 1, samples)
    uu, tt = np.meshgrid(s, s, indexing="ij")
    pts = np.asarray(point(uu.reshape(-1), tt.reshape(-1))).reshape(samples, samples, 3)
    grid = Array2(1, samples, 1, samples)
    for i in range(samples):
        for j in range(samples):
            grid.SetValue(i + 1, j + 1, gp_Pnt(*map(float, pts[i, j])))
    surface = GeomAPI_PointsToBSplineSurface(grid).Surface()
    face = BRepBuilderAPI_MakeFace(surface, OCCT_FACE).Face()
    BRepMesh_IncrementalMesh(face, float(deflection), False, 0.5, True)
    tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
    if tri is None:
        return None
    verts = np.array([[tri.Node(k).X(), tri.Node(k).Y(), tri.Node(k).Z()]
                      for k in range(1, tri.NbNodes() + 1)])
    tris = np.array([tri.Triangle(k).Get() for k in range(1, tri.NbTriangles() + 1)],
                    dtype=np.int64) - 1
    return verts, tris


def compare_tessellations(mesh: Mesh, point: Callable[[np.ndarray, np.ndarray], np.ndarray],
                          occt: bool = True) -> list[dict[str, Any]]:
    """Triangle quality of ``mesh`` (as exported) next to standard tessellations.

    Parameters
    ----------
    mesh : Mesh
        A mesh of the surface patch.
    point : callable
        The smooth patch, ``point(u, t) -> (n, 3)`` on ``0 <= u, t <= 1``.
    occt : bool
        Include OCCT's BRepMesh when ``cadquery-ocp`` is installed.

    Returns
    -------
    list of dict
        One row per tessellation (``"tessellation"`` names it, the rest is
        :func:`triangle_quality`); the grids have about as many triangles as
        the exported mesh, with cells as long as wide on average.
    """
    ours = mesh_triangle_quality(mesh)
    if ours is None:
        raise ParameterError("a mesh without faces has no triangles to compare", "mesh")
    rows = [{"tessellation": "ruledmesh (PQ faces split)", **ours}]
    nu, nt = _grid_counts(point, ours["triangles"])
    for diag, label in (("fixed", "parameter grid"), ("shorter", "parameter grid, shorter diagonal")):
        v, t = parameter_grid(point, nu, nt, diag)
        rows.append({"tessellation": f"{label} {nu}x{nt}", **triangle_quality(v, t)})
    if occt:
        edges = mesh.edges()
        mean_edge = float(np.linalg.norm(mesh.vertices[edges[:, 1]] - mesh.vertices[edges[:, 0]],
                                         axis=1).mean())
        # A deflection giving a comparable triangle count: the sagitta of a
        # chord of the mean edge length on a curvature radius ~ the patch size.
        res = occt_tessellation(point, deflection=mean_edge ** 2 / (8 * max(mesh.diagonal(), TINY)))
        if res is not None:
            rows.append({"tessellation": "OCCT BRepMesh", **triangle_quality(*res)})
    return rows


def _hook(mesh: Mesh, reference: Any = None) -> dict[str, Any] | None:
    """Report hook: the export triangulation's quality, and the comparison
    when the smooth reference surface (with ``surface.point``) is known."""
    quality = mesh_triangle_quality(mesh)
    if quality is None:
        return None
    surface = getattr(reference, "surface", None)
    if surface is not None and hasattr(surface, "point"):
        quality["comparison"] = compare_tessellations(mesh, surface.point)
    return quality


METRIC_HOOKS["triangles"] = _hook
