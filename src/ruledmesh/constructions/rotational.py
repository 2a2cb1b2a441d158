"""Rotational surfaces (paper §2.2): a meridian polygon turned about an axis.

Each quad joins two consecutive meridian points in two consecutive turned
positions; it is symmetric about the bisecting meridian plane, an isosceles
trapezoid, hence circular (and so planar).  Meridian points on the axis
become poles where the quads turn into triangles.
"""

from __future__ import annotations

import numpy as np

from .._validation import check_float, check_int, check_points, check_vector
from ..tolerances import COLLINEAR, TINY
from ._grid import grid_mesh
from .frames import axis_frame

__all__ = ["rotational_mesh", "meridian_coordinates"]


def meridian_coordinates(points: np.ndarray, origin: np.ndarray, axis: np.ndarray):
    """Cylindrical coordinates of points about an axis.

    Parameters
    ----------
    points : (m, 3) float64
    origin : (3,) float64
    axis : (3,) float64, unit

    Returns
    -------
    rho, h, phi : (m,) float64
        Distance from the axis (snapped to 0 on the axis), height along it,
        angle from the frame's first axis.
    """
    e1, e2, a = axis_frame(axis)
    rel = points - origin
    h = rel @ a
    x, y = rel @ e1, rel @ e2
    rho = np.hypot(x, y)
    scale = max(float(np.abs(rel).max()), TINY)
    on_axis = rho <= COLLINEAR * scale
    rho = np.where(on_axis, 0.0, rho)
    return rho, h, np.where(on_axis, 0.0, np.arctan2(y, x))


def rotational_mesh(meridian: np.ndarray, steps: int, *, origin=(0.0, 0.0, 0.0),
                    axis=(0.0, 0.0, 1.0), angle: float = 360.0):
    """The circular mesh of a meridian polygon turned about an axis.

    Parameters
    ----------
    meridian : (m, 3) float64
        Meridian polygon.  Only each point's distance from the axis and
        height along it matter: the polygon is laid into the half-plane
        through the axis and its first point off the axis (a skew polygon
        would not give planar quads, since each quad's symmetry plane is the
        bisecting meridian plane of *both* its meridian points).
    steps : int
        Number of rotation steps.
    origin, axis : (3,) float64
        The axis (``axis`` non-zero).
    angle : float
        Sweep in degrees; 360 closes the surface.

    Returns
    -------
    Mesh
        Isosceles trapezoids (circular), triangles at poles.
    """
    merid = check_points(meridian, "meridian", min_count=2)
    steps = check_int(steps, "steps", lo=1)
    o = check_vector(origin, "origin")
    a = check_vector(axis, "axis", nonzero=True)
    angle = check_float(angle, "angle", lo=0.0, lo_open=True, hi=360.0)
    full = angle == 360.0
    if full and steps < 3:
        steps = check_int(steps, "steps", lo=3)
    e1, e2, a = axis_frame(a)
    rho, h, phi = meridian_coordinates(merid, o, a)
    phi0 = phi[np.argmax(rho > 0)]
    t = np.radians(angle) * np.arange(steps if full else steps + 1) / steps + phi0
    ang = np.broadcast_to(t[:, None], (len(t), len(rho)))
    grid = (o + h[None, :, None] * a
            + rho[None, :, None] * (np.cos(ang)[..., None] * e1 + np.sin(ang)[..., None] * e2))
    return grid_mesh(grid, wrap_u=full, info={"construction": "rotational"})
