"""The helicoid as a translational surface (paper §3.3, Fig. 8).

With the helix ``g(s) = (rho cos s, rho sin s, k s)``,

    g(u) + g(v) = (2 rho cos((u - v)/2) cos((u + v)/2),
                   2 rho cos((u - v)/2) sin((u + v)/2),  2 k (u + v)/2),

a point of the helicoid ``x = r cos th, y = r sin th, z = pitch th / (2 pi)``
with ``th = (u + v)/2``, ``r = 2 rho cos((u - v)/2)`` and
``pitch = 4 pi k``: the helix swept along itself fills the helicoid inside
the cylinder of radius ``2 rho`` (Wunderlich).  The grid ``g(u_i) + g(v_j)``
is a parallelogram mesh with every vertex on the helicoid; the cells kept are
those inside ``0 <= th <= 2 pi turns`` and ``|r| <= radius``.  Different steps
in ``u`` and ``v`` give the variants of the mesh (other helices of the same
family as the two profiles).
"""

from __future__ import annotations

import numpy as np

from .._validation import check_float, check_int
from ..errors import GeometryError
from ..mesh import Mesh
from ..surfaces import ImplicitSurface
from ..tolerances import DEFAULT, ROUNDING
from ._grid import grid_mesh

__all__ = ["helicoid_mesh", "helicoid"]


def helicoid(pitch: float, radius: float | None = None, turns: float | None = None) -> ImplicitSurface:
    """Reference helicoid about the z axis: ``x sin(z/k) - y cos(z/k) = 0``, ``k = pitch / (2 pi)``.

    The area is that of ``|r| <= radius``, ``0 <= th <= 2 pi turns`` when both are given.
    """
    k = pitch / (2 * np.pi)

    def value(p):
        t = p[:, 2] / k
        return p[:, 0] * np.sin(t) - p[:, 1] * np.cos(t)

    def gradient(p):
        t = p[:, 2] / k
        s, c = np.sin(t), np.cos(t)
        return np.stack([s, -c, (p[:, 0] * c + p[:, 1] * s) / k], axis=1)

    area = None
    if radius is not None and turns is not None:
        k2 = k * k
        area = float(2 * np.pi * turns
                     * (radius * np.sqrt(radius ** 2 + k2) + k2 * np.arcsinh(radius / abs(k))))
    return ImplicitSurface("helicoid", value, gradient, area)


def helicoid_mesh(radius: float, pitch: float, turns: float = 1.0, u: int = 48,
                  v: int | None = None) -> Mesh:
    """Parallelogram mesh of the helicoid from a helix translated along itself.

    Parameters
    ----------
    radius : float
        ``|r| <= radius`` (> 0); the helix has radius ``radius / 2``.
    pitch : float
        Rise per full turn of the helicoid (non-zero; negative: left-handed).
    turns : float
        Number of turns (> 0).
    u, v : int
        Steps of the two helix parameters over ``[0, 2 pi turns + pi]``
        (``v`` defaults to ``u``).

    Returns
    -------
    Mesh
        Parallelograms.
    """
    radius = check_float(radius, "radius", lo=0.0, lo_open=True)
    pitch = check_float(pitch, "pitch")
    if abs(pitch) <= DEFAULT.degenerate * radius:
        raise GeometryError(f"pitch must not vanish against the radius (pitch {pitch:g} for "
                            f"radius {radius:g} is a plane)")
    turns = check_float(turns, "turns", lo=0.0, lo_open=True)
    u = check_int(u, "u", lo=2)
    v = u if v is None else check_int(v, "v", lo=2)
    rho = 0.5 * radius
    k = pitch / (4 * np.pi)
    span = 2 * np.pi * turns + np.pi
    su = np.linspace(0.0, span, u + 1)
    sv = np.linspace(-np.pi, span - np.pi, v + 1)
    gu = np.stack([rho * np.cos(su), rho * np.sin(su), k * su], axis=1)
    gv = np.stack([rho * np.cos(sv), rho * np.sin(sv), k * sv], axis=1)
    grid = gu[:, None, :] + gv[None, :, :]
    # Keep cells whose corners all have 0 <= (u - v)/2 <= pi and 0 <= (u + v)/2 <= 2 pi turns.
    d = su[:, None] - sv[None, :]
    s = su[:, None] + sv[None, :]
    eps = ROUNDING * span
    inside = (d >= -eps) & (d <= 2 * np.pi + eps) & (s >= -eps) & (s <= 4 * np.pi * turns + eps)
    cell = inside[:-1, :-1] & inside[1:, :-1] & inside[1:, 1:] & inside[:-1, 1:]
    if not cell.any():
        raise GeometryError(f"u = {u}, v = {v} leave no cell inside the patch: raise u and v")
    return grid_mesh(grid, cell_mask=cell.ravel(), collapse=False,
                     info={"construction": "helicoid (translational)"})
