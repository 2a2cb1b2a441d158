"""Discrete developables (paper §3.1, Fig. 6): prism, pyramid, torsal polyhedron.

Each is a sequence of planar strips between consecutive straight lines that
meet (pyramid, torsal polyhedron) or are parallel (prism); the lines are the
mesh's members.  These polyhedra *are* the surfaces (no smooth reference).
"""

from __future__ import annotations

import numpy as np

from .._validation import check_points, check_vector
from ..errors import GeometryError, ParameterError
from ..tolerances import DEFAULT, ROUNDING
from ._grid import grid_mesh, polyline_members

__all__ = ["prism", "pyramid", "torsal_polyhedron"]


def _line_members(nu: int, nv: int) -> tuple[np.ndarray, np.ndarray]:
    """Members along the grid columns ``X[:, j]`` (the straight lines)."""
    idx = np.arange(nu * nv).reshape(nu, nv).T
    members = polyline_members(idx)
    return members, np.repeat(np.arange(nv), nu - 1)


def prism(polygon: np.ndarray, direction: np.ndarray, layers: int = 1, *, closed: bool = False):
    """Cylinder analogue: the polygon translated ``layers`` times by ``direction / layers``.

    Parameters
    ----------
    polygon : (n, 3) float64
    direction : (3,) float64
        Total translation (the generators' direction and length).
    layers : int
    closed : bool

    Returns
    -------
    Mesh
        Parallelograms; members along the generators.
    """
    c = check_points(polygon, "polygon", min_count=2)
    d = check_vector(direction, "direction", nonzero=True)
    h = np.linspace(0.0, 1.0, layers + 1)
    grid = c[None] + h[:, None, None] * d
    members, mid = _line_members(layers + 1, len(c))
    return grid_mesh(grid, wrap_v=closed, members=members, member_id=mid,
                     info={"construction": "prism"})


def pyramid(polygon: np.ndarray, apex: np.ndarray, layers: int = 1, *, closed: bool = False,
            to_apex: bool = False):
    """Cone analogue: the polygon scaled towards ``apex`` (similar polygons).

    Parameters
    ----------
    polygon : (n, 3) float64
    apex : (3,) float64
    layers : int
    closed : bool
    to_apex : bool
        Run the last layer into the apex (triangles there); otherwise stop at
        ``1 / (layers + 1)`` of the way.

    Returns
    -------
    Mesh
        Trapezoids; members along the generators.
    """
    c = check_points(polygon, "polygon", min_count=2)
    a = check_vector(apex, "apex")
    stop = 0.0 if to_apex else 1.0 / (layers + 1)
    f = np.linspace(1.0, stop, layers + 1)
    grid = a + f[:, None, None] * (c[None] - a)
    if to_apex:
        grid[-1] = a
    members, mid = _line_members(layers + 1, len(c))
    return grid_mesh(grid, wrap_v=closed, members=members, member_id=mid,
                     info={"construction": "pyramid"})


def torsal_polyhedron(polygon: np.ndarray, lengths=(0.2, 1.0), rows: int = 4):
    """Tangent developable analogue: strips between consecutive edge lines of a space polygon.

    The edge lines ``P_k P_{k+1}`` and ``P_{k+1} P_{k+2}`` meet in ``P_{k+1}``,
    so they span a plane; the mesh takes points at distances ``lengths[0] ..
    lengths[1]`` beyond ``P_{k+1}`` on each edge line, and each quad between
    consecutive edge lines lies in their plane.

    Parameters
    ----------
    polygon : (n, 3) float64, n >= 3
    lengths : (float, float)
        Range of distance from the polygon vertex along each edge line (> 0,
        so that no face degenerates onto the polygon).
    rows : int
        Points per edge line minus one.

    Returns
    -------
    Mesh
    """
    p = check_points(polygon, "polygon", min_count=3)
    l0, l1 = (float(x) for x in lengths)
    if not (0 < l0 < l1):
        raise ParameterError(f"expected 0 < lengths[0] < lengths[1], got {[l0, l1]}", "lengths")
    e = np.diff(p, axis=0)
    n = np.linalg.norm(e, axis=1)
    if np.any(n <= ROUNDING * max(np.abs(p).max(), 1.0)):
        raise GeometryError("polygon has coincident consecutive vertices")
    d = e / n[:, None]
    turn = np.linalg.norm(np.cross(d[:-1], d[1:]), axis=1)
    if np.any(turn < DEFAULT.degenerate):
        raise GeometryError("consecutive edges are parallel: the strip between them is degenerate")
    s = np.linspace(l0, l1, rows + 1)
    # Edge line k starts at P_{k+1} and runs along d_k: X[k, j] = P_{k+1} + s_j d_k.
    grid = p[1:, None, :] + s[None, :, None] * d[:, None, :]
    idx = np.arange(grid.shape[0] * grid.shape[1]).reshape(grid.shape[:2])
    members = polyline_members(idx)
    mid = np.repeat(np.arange(grid.shape[0]), rows)
    return grid_mesh(grid, members=members, member_id=mid, collapse=False,
                     info={"construction": "torsal polyhedron"})
