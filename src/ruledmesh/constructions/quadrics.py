"""Quadrics by similar parallel sections (paper §2.2): ellipsoid, two-sheet
hyperboloid, elliptic paraboloid.

Parallel plane sections of a quadric are similar conics; taking corresponding
points at equal parameter makes consecutive section polygons have pairwise
parallel edges, so every quad is a trapezoid (planar) and every vertex lies on
the quadric.  Sections are the planes ``z = const``; other directions follow
with a ``[[transform]]``.  With ``a == b`` the surfaces are rotational and the
meshes circular.  Poles become triangles.
"""

from __future__ import annotations

import numpy as np

from .._validation import check_float, check_int
from ..surfaces import ImplicitSurface, parametric_area
from ._grid import grid_mesh

__all__ = ["ellipsoid_mesh", "two_sheet_hyperboloid_mesh", "elliptic_paraboloid_mesh",
           "ellipsoid", "two_sheet_hyperboloid", "elliptic_paraboloid"]


def _sections(scale: np.ndarray, height: np.ndarray, a: float, b: float, u: int):
    """Grid of similar ellipses ``(a s cos phi, b s sin phi, h)``: (u, len(s), 3)."""
    phi = 2 * np.pi * np.arange(u) / u
    x = a * np.cos(phi)[:, None] * scale[None, :]
    y = b * np.sin(phi)[:, None] * scale[None, :]
    z = np.broadcast_to(height[None, :], x.shape)
    return np.stack([x, y, z], axis=-1)


def _positive(value, name):
    return check_float(value, name, lo=0.0, lo_open=True)


def ellipsoid(a: float, b: float, c: float) -> ImplicitSurface:
    """Reference ``x^2/a^2 + y^2/b^2 + z^2/c^2 = 1`` with its area."""
    w = np.array([1 / a ** 2, 1 / b ** 2, 1 / c ** 2])

    def partials(t, p):
        st, ct, sp, cp = np.sin(t), np.cos(t), np.sin(p), np.cos(p)
        return (np.stack([a * ct * cp, b * ct * sp, -c * st], axis=1),
                np.stack([-a * st * sp, b * st * cp, 0 * t], axis=1))

    return ImplicitSurface("ellipsoid", lambda p: 0.5 * ((p * p) @ w - 1.0), lambda p: p * w,
                           parametric_area(partials, (0, np.pi), (0, 2 * np.pi)))


def ellipsoid_mesh(a: float, b: float, c: float, u: int, v: int):
    """Ellipsoid ``x^2/a^2 + y^2/b^2 + z^2/c^2 = 1`` by sections ``z = c cos(theta_j)``.

    Parameters
    ----------
    a, b, c : float
        Semi-axes (> 0).
    u : int
        Points per section (>= 3).
    v : int
        Steps from pole to pole (>= 2), uniform in ``theta``.

    Returns
    -------
    Mesh
        Trapezoids, triangles at the poles; normals point outwards.
    """
    a, b, c = (_positive(x, n) for x, n in ((a, "a"), (b, "b"), (c, "c")))
    u, v = check_int(u, "u", lo=3), check_int(v, "v", lo=2)
    # South to north, so that the faces' normals point outwards.
    t = np.pi * np.arange(v, -1, -1) / v
    s, h = np.sin(t), c * np.cos(t)
    s[[0, -1]] = 0.0  # exact poles (sin(pi) is not 0 in floating point)
    h[[0, -1]] = [-c, c]
    return grid_mesh(_sections(s, h, a, b, u), wrap_u=True, info={"construction": "ellipsoid"})


def two_sheet_hyperboloid(a: float, b: float, c: float, height: float) -> ImplicitSurface:
    """Reference ``z^2/c^2 - x^2/a^2 - y^2/b^2 = 1`` (upper sheet, ``z <= height``)."""
    w = np.array([-1 / a ** 2, -1 / b ** 2, 1 / c ** 2])
    T = np.arccosh(height / c)

    def partials(t, p):
        sh, ch, sp, cp = np.sinh(t), np.cosh(t), np.sin(p), np.cos(p)
        return (np.stack([a * ch * cp, b * ch * sp, c * sh], axis=1),
                np.stack([-a * sh * sp, b * sh * cp, 0 * t], axis=1))

    return ImplicitSurface("two-sheet hyperboloid", lambda p: 0.5 * ((p * p) @ w - 1.0),
                           lambda p: p * w, parametric_area(partials, (0, T), (0, 2 * np.pi)))


def two_sheet_hyperboloid_mesh(a: float, b: float, c: float, height: float, u: int, v: int):
    """Upper sheet of ``z^2/c^2 - x^2/a^2 - y^2/b^2 = 1`` up to ``z = height``.

    Sections ``z = c cosh(t_j)``, ``t`` uniform on ``[0, arccosh(height / c)]``.
    """
    a, b, c = (_positive(x, n) for x, n in ((a, "a"), (b, "b"), (c, "c")))
    height = check_float(height, "height", lo=c, lo_open=True)
    u, v = check_int(u, "u", lo=3), check_int(v, "v", lo=1)
    t = np.arccosh(height / c) * np.arange(v + 1) / v
    return grid_mesh(_sections(np.sinh(t), c * np.cosh(t), a, b, u), wrap_u=True,
                     info={"construction": "two-sheet hyperboloid"})


def elliptic_paraboloid(a: float, b: float, height: float) -> ImplicitSurface:
    """Reference ``z = x^2/a^2 + y^2/b^2`` (``z <= height``)."""

    def partials(r, p):
        sp, cp = np.sin(p), np.cos(p)
        return (np.stack([a * cp, b * sp, 2 * r], axis=1),
                np.stack([-a * r * sp, b * r * cp, 0 * r], axis=1))

    return ImplicitSurface(
        "elliptic paraboloid",
        lambda p: p[:, 0] ** 2 / a ** 2 + p[:, 1] ** 2 / b ** 2 - p[:, 2],
        lambda p: np.stack([2 * p[:, 0] / a ** 2, 2 * p[:, 1] / b ** 2, -np.ones(len(p))], axis=1),
        parametric_area(partials, (0, np.sqrt(height)), (0, 2 * np.pi)))


def elliptic_paraboloid_mesh(a: float, b: float, height: float, u: int, v: int):
    """``z = x^2/a^2 + y^2/b^2`` for ``0 <= z <= height``: sections ``z = rho_j^2``, rho uniform."""
    a, b = _positive(a, "a"), _positive(b, "b")
    height = _positive(height, "height")
    u, v = check_int(u, "u", lo=3), check_int(v, "v", lo=1)
    rho = np.sqrt(height) * np.arange(v + 1) / v
    return grid_mesh(_sections(rho, rho * rho, a, b, u), wrap_u=True,
                     info={"construction": "elliptic paraboloid"})


def quadric_guarantee(a: float, b: float) -> str:
    """What every face of a quadric mesh with semi-axes ``a``, ``b`` is (for the report)."""
    return ("isosceles trapezoids, circular (rotational)" if a == b
            else "trapezoids (similar sections)")
