"""A construction's guarantee, checked against the mesh's own figures.

Constructions state what their quads are by design (``extras["guarantee"]``,
e.g. ``"isosceles trapezoids, circular"``).  A transform, an edit in another
program or a wrong ``--design`` can break that promise, so
``ruledmesh analyze`` never repeats a claim without measuring it: each
property the text names is measured on the construction's quads
(:attr:`~ruledmesh.mesh.FaceKind.QUAD` faces; border faces and fill triangles
promise nothing) and reported as met, not met (with the figure and its
tolerance) or not checked (a property without a measure here, e.g.
``"diagonals are generators of both reguli"``).

Measures (all scale-free, 0 for an exact face):

* ``parallelograms``: :func:`.circularity.quad_parallelogram`;
* ``trapezoids``: sine of the angle between the more nearly parallel pair of
  opposite edges;
* ``isosceles trapezoids``: that sine, or the relative length difference of
  the two other edges (the legs), whichever is larger;
* ``circular``: :func:`.circularity.quad_circularity`;
* ``planar``: :func:`.faces.planarity` over all faces.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from ..mesh import FaceKind, Mesh
from ..tolerances import DEFAULT, Tolerances
from ..tolerances import TINY as _TINY
from .circularity import quad_circularity, quad_parallelogram
from .planar import planarity_bounds, rounding_allowance

__all__ = ["check_guarantee", "format_guarantee", "quad_trapezoid"]


def quad_trapezoid(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """How far quads are from trapezoids and from isosceles trapezoids.

    Parameters
    ----------
    corners : (F, 4, 3) float64

    Returns
    -------
    trapezoid : (F,) float64
        Sine of the angle between the more nearly parallel pair of opposite edges.
    isosceles : (F,) float64
        The larger of that sine and the relative length difference of the legs
        (the other two edges).

    Examples
    --------
    >>> import numpy as np
    >>> trap = np.array([[[0, 0, 0], [4, 0, 0], [3, 1, 0], [1, 1, 0]]], float)
    >>> t, i = quad_trapezoid(trap)
    >>> bool(t[0] < 1e-15 and i[0] < 1e-15)
    True
    >>> bent = np.array([[[0, 0, 0], [4, 0, 0], [3, 1, 0], [0, 1, 0]]], float)
    >>> bool(quad_trapezoid(bent)[1][0] > 0.1)
    True
    """
    corners = np.asarray(corners, dtype=np.float64)
    e = np.roll(corners, -1, axis=1) - corners                 # (F, 4, 3): edge k = p[k+1] - p[k]
    length = np.linalg.norm(e, axis=2)                          # (F, 4)

    def sine(a: int, b: int) -> np.ndarray:
        cross = np.linalg.norm(np.cross(e[:, a], e[:, b]), axis=1)
        return cross / np.maximum(length[:, a] * length[:, b], _TINY)

    def legs(a: int, b: int) -> np.ndarray:
        return np.abs(length[:, a] - length[:, b]) / np.maximum(0.5 * (length[:, a] + length[:, b]),
                                                               _TINY)

    s02, s13 = sine(0, 2), sine(1, 3)
    first = s02 <= s13                                          # edges 0, 2 are the parallel pair
    trapezoid = np.where(first, s02, s13)
    isosceles = np.maximum(trapezoid, np.where(first, legs(1, 3), legs(0, 2)))
    return trapezoid, isosceles


def _properties(text: str) -> list[str]:
    """The properties a guarantee text names, in order, e.g. ``["isosceles", "circular"]``."""
    out = []
    for clause in re.split(r"[;,]", re.sub(r"\([^)]*\)", "", text)):
        clause = clause.strip().lower()
        if not clause:
            continue
        if "isosceles" in clause:
            out.append("isosceles trapezoids")
        elif "parallelogram" in clause:
            out.append("parallelograms")
        elif "trapezoid" in clause:
            out.append("trapezoids")
        elif "circular" in clause:
            out.append("circular")
        elif "planar" in clause:
            out.append("planar")
        else:
            out.append(clause)
    return out


def _measure(prop: str, mesh: Mesh, quads: np.ndarray, tol: Tolerances):
    """(figure name, worst value, tolerance) of one property, or None if not measurable."""
    if prop == "planar":
        from .planar import face_planarity, planarity_tolerance

        return "planarity", face_planarity(mesh), planarity_tolerance(mesh, tol)
    if prop not in ("parallelograms", "trapezoids", "isosceles trapezoids", "circular"):
        return None
    if prop == "circular":
        return "circularity", quad_circularity(quads), tol.circularity
    if prop == "parallelograms":
        return "parallelogram", quad_parallelogram(quads), tol.planarity
    trapezoid, isosceles = quad_trapezoid(quads)
    if prop == "trapezoids":
        return "trapezoid", trapezoid, tol.planarity
    return "isosceles trapezoid", isosceles, tol.planarity


def check_guarantee(text: str, mesh: Mesh, tol: Tolerances = DEFAULT) -> dict[str, Any]:
    """Measure each property a guarantee names.

    Parameters
    ----------
    text : str
        The construction's guarantee, e.g. ``"isosceles trapezoids, circular"``.
    mesh : Mesh
    tol : Tolerances
        ``planarity`` bounds the edge-direction measures (exact up to rounding,
        like planarity); ``circularity`` bounds circularity.

    Returns
    -------
    dict
        ``{"claim": text, "met": bool, "properties": [{"property", "status",
        "figure", "max", "tolerance", "faces_above"}, ...]}`` where status is
        ``"met"``, ``"not met"`` or ``"not checked"``; ``met`` is False when
        any measured property is not met.
    """
    ids = np.flatnonzero((mesh.face_kind == FaceKind.QUAD) & (mesh.valences == 4))
    corners = mesh.vertices[mesh.face_indices[mesh.face_offsets[ids][:, None] + np.arange(4)]]
    rows: list[dict[str, Any]] = []
    for prop in _properties(text):
        measured = _measure(prop, mesh, corners, tol) if ids.size or prop == "planar" else None
        if measured is None:
            rows.append({"property": prop, "status": "not checked"})
            continue
        figure, values, bound = measured
        worst = float(values.max()) if values.size else 0.0
        # Planar as analyze and fabricate say: within what the stored coordinates' rounding
        # explains too (far from the origin, analysis.planar).
        allowed = planarity_bounds(mesh, rounding_allowance(mesh), tol)[1] if prop == "planar" else bound
        above = int(np.count_nonzero(~(values <= allowed)))      # NaN (non-finite corners) too
        rows.append({"property": prop, "status": "not met" if above else "met",
                     "figure": figure, "max": worst, "tolerance": bound, "faces_above": above})
    return {"claim": text, "met": all(r["status"] != "not met" for r in rows), "properties": rows}


def format_guarantee(check: dict[str, Any]) -> str:
    """One line: each property with its evidence, e.g. ``circular — not met: circularity 0.31 > 1e-10``."""
    parts = []
    for row in check["properties"]:
        if row["status"] == "met":
            parts.append(f"{row['property']} (met: {row['figure']} {row['max']:.2g} <= "
                         f"{row['tolerance']:g})")
        elif row["status"] == "not met":
            parts.append(f"{row['property']} \u2014 not met: {row['figure']} {row['max']:.3g} > "
                         f"{row['tolerance']:g} on {row['faces_above']} quads")
        else:
            parts.append(f"{row['property']} (not checked)")
    return "; ".join(parts)
