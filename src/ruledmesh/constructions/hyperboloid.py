"""One-sheet hyperboloid ``(x^2/a^2 + y^2/b^2) - z^2/c^2 = 1`` (paper §3.2, Fig. 7b, c).

``style = "circular"``: meridians x parallels, uniform in ``z``; for ``a == b``
a rotational surface, so the quads are isosceles trapezoids, circular.

``style = "generators"``: the checkerboard of the two reguli.  The generators
of one regulus through the points at angles ``phi_i = 2 pi i / u`` of the
waist ellipse are reflected in a meridian plane to give the other regulus;
generator ``i`` of the first and ``j`` of the second cross at angle
``(phi_i + phi_j) / 2`` and height ``z = c tan((phi_j - phi_i) / 2)``.  Taking
every other crossing as a vertex leaves exactly the grid of meridians
``m 2 pi / u`` and parallels ``z_p = c tan(p 2 pi / u)``: each face has the two
generators as diagonals (they cross, so it is planar) and, for ``a == b``, is
an isosceles trapezoid (circular).  The generators are the mesh's members.
"""

from __future__ import annotations

from enum import Enum

import numpy as np

from .._validation import check_choice, check_float, check_int
from ..errors import GeometryError
from ..surfaces import ImplicitSurface, parametric_area
from ..tolerances import ROUNDING
from ._grid import grid_mesh

__all__ = ["HyperboloidStyle", "hyperboloid_mesh", "one_sheet_hyperboloid"]


class HyperboloidStyle(str, Enum):
    """How the one-sheet hyperboloid is meshed."""

    CIRCULAR = "circular"
    GENERATORS = "generators"


def one_sheet_hyperboloid(a: float, b: float, c: float, z0: float, z1: float) -> ImplicitSurface:
    """Reference ``x^2/a^2 + y^2/b^2 - z^2/c^2 = 1`` with the area of ``z0 <= z <= z1``."""
    w = np.array([1 / a ** 2, 1 / b ** 2, -1 / c ** 2])

    def partials(p, z):
        rho = np.sqrt(1 + z * z / c ** 2)
        dr = z / (c ** 2 * rho)
        sp, cp = np.sin(p), np.cos(p)
        return (np.stack([-a * rho * sp, b * rho * cp, 0 * z], axis=1),
                np.stack([a * dr * cp, b * dr * sp, np.ones_like(z)], axis=1))

    return ImplicitSurface("one-sheet hyperboloid", lambda p: 0.5 * ((p * p) @ w - 1.0),
                           lambda p: p * w, parametric_area(partials, (0, 2 * np.pi), (z0, z1)))


def hyperboloid_mesh(a: float, c: float, height: float, u: int, v: int | None = None, *,
                     b: float | None = None, style: HyperboloidStyle | str = "circular"):
    """Mesh of the one-sheet hyperboloid for ``|z| <= height``.

    Parameters
    ----------
    a, c : float
        ``(x^2 + y^2)/a^2 - z^2/c^2 = 1`` (> 0).
    height : float
        Half height of the patch (> 0).
    u : int
        Steps around the axis (>= 3); with ``style="generators"`` the number
        of generators of each regulus (>= 4).
    v : int, optional
        Steps in ``z`` (style ``"circular"`` only; the generator grid fixes
        its parallels itself).
    b : float, optional
        Second semi-axis of the waist ellipse (default ``a``).
    style : {"circular", "generators"}

    Returns
    -------
    Mesh
    """
    a = check_float(a, "a", lo=0.0, lo_open=True)
    c = check_float(c, "c", lo=0.0, lo_open=True)
    b = a if b is None else check_float(b, "b", lo=0.0, lo_open=True)
    height = check_float(height, "height", lo=0.0, lo_open=True)
    style = check_choice(style, HyperboloidStyle, "style")
    u = check_int(u, "u", lo=3 if style is HyperboloidStyle.CIRCULAR else 4)
    phi = 2 * np.pi * np.arange(u) / u
    if style is HyperboloidStyle.CIRCULAR:
        v = check_int(16 if v is None else v, "v", lo=1)
        z = height * np.linspace(-1.0, 1.0, v + 1)
        rho = np.sqrt(1 + (z / c) ** 2)
        members = mid = None
    else:
        step = 2 * np.pi / u
        pmax = np.floor(np.arctan(height / c) / step * (1 + ROUNDING))
        if pmax < 1:
            raise GeometryError(f"height {height:g} is below the first crossing of the generators "
                                f"(z = {c * np.tan(step):g} for u = {u}): raise height or u")
        p = np.arange(-pmax, pmax + 1)
        ang = p * step
        z = c * np.tan(ang)
        rho = 1.0 / np.cos(ang)
        # Cell diagonals: (m, p)-(m+1, p+1) on the first regulus, (m+1, p)-(m, p+1) on the second.
        nv = len(p)
        gm, gq = np.meshgrid(np.arange(u), np.arange(nv - 1), indexing="ij")
        m, q = gm.ravel(), gq.ravel()
        m1 = (m + 1) % u
        members = np.concatenate([np.stack([m * nv + q, m1 * nv + q + 1], axis=1),
                                  np.stack([m1 * nv + q, m * nv + q + 1], axis=1)])
        pp = p[q].astype(np.int64)
        mid = np.concatenate([(m - pp) % u, u + (m + pp + 1) % u])
    grid = np.stack([a * np.cos(phi)[:, None] * rho, b * np.sin(phi)[:, None] * rho,
                     np.broadcast_to(z, (u, len(z)))], axis=-1)
    return grid_mesh(grid, wrap_u=True, members=members, member_id=mid, collapse=False,
                     info={"construction": f"hyperboloid ({style.value})"})
