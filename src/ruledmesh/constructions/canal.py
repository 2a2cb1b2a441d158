"""Canal surfaces, the torus and Dupin cyclides (paper §2.2, Figs. 4c, 5b, 5c).

Canal surface: the envelope of spheres ``(s_k, rho_k)``.  Its discrete
analogue here takes the circles ``C_k = S_k ∩ S_{k+1}``; consecutive circles
``C_k`` and ``C_{k+1}`` both lie on the sphere ``S_{k+1}``.  Points correspond
by central projection from the apex of a cone through both circles (on the
symmetry plane spanned by their axes, which meet in ``s_{k+1}``): corresponding
lines meet in the apex, so each quad is planar, and its four vertices are on a
sphere, so it is circular.  Vertices lie on the spheres, not on one smooth
surface: the build reports how far they are from them instead of closeness.

Torus: the rotational mesh of a circle (circular).  Dupin cyclide: the
inversion of a torus mesh in a sphere, circular again (§2.3).
"""

from __future__ import annotations

import numpy as np

from .._validation import check_float, check_int, check_points
from ..errors import GeometryError, ParameterError
from ..tolerances import DEFAULT, ROUNDING, TINY
from ._grid import grid_mesh
from .frames import perpendicular

__all__ = ["canal_mesh", "sphere_circles", "torus_mesh", "dupin_cyclide"]


def sphere_circles(centers: np.ndarray, radii: np.ndarray):
    """Circles where consecutive spheres meet.

    Parameters
    ----------
    centers : (K + 1, 3) float64
    radii : (K + 1,) float64

    Returns
    -------
    c : (K, 3) float64
        Circle centres.
    n : (K, 3) float64
        Unit normals (along ``s_{k+1} - s_k``).
    r : (K,) float64
        Radii.

    Raises
    ------
    GeometryError
        When two consecutive spheres do not meet in a circle.
    """
    chord = np.diff(centers, axis=0)
    d = np.linalg.norm(chord, axis=1)
    r0, r1 = radii[:-1], radii[1:]
    bad = np.flatnonzero(~((np.abs(r0 - r1) < d) & (d < r0 + r1)))
    if bad.size:
        k = int(bad[0])
        raise GeometryError(f"spheres {k} and {k + 1} do not meet in a circle (centre distance "
                            f"{d[k]:g}, radii {r0[k]:g} and {r1[k]:g}): sample the spine more "
                            f"densely or vary the radius more slowly")
    x = (d * d + r0 * r0 - r1 * r1) / (2 * d)
    n = chord / d[:, None]
    return centers[:-1] + x[:, None] * n, n, np.sqrt(r0 * r0 - x * x)


def canal_mesh(centers: np.ndarray, radii, segments: int):
    """Circular mesh of a canal surface from a chain of spheres.

    Parameters
    ----------
    centers : (K + 1, 3) float64, K >= 2
        Sphere centres (spine points).
    radii : (K + 1,) float64 or float
        Sphere radii.
    segments : int
        Points per circle.

    Returns
    -------
    Mesh
        ``K - 1`` rings of circular quads between the ``K`` circles.
    """
    s = check_points(centers, "centers", min_count=3)
    rho = np.broadcast_to(np.asarray(radii, dtype=np.float64), (len(s),)).copy()
    if np.any(~np.isfinite(rho)) or np.any(rho <= 0):
        raise ParameterError("expected positive radii", "radii")
    segments = check_int(segments, "segments", lo=3)
    c, n, r = sphere_circles(s, rho)
    e = perpendicular(n[0])
    a = 2 * np.pi * np.arange(segments) / segments
    rows = [c[0] + r[0] * (np.cos(a)[:, None] * e + np.sin(a)[:, None] * np.cross(n[0], e))]
    for k in range(len(c) - 1):  # one projection per circle, vectorised over its points
        o = s[k + 1]
        # Unit vectors in the symmetry plane, perpendicular to each circle's axis,
        # oriented alike; a straight piece of spine keeps the previous one.
        ek = n[k + 1] - (n[k + 1] @ n[k]) * n[k]
        if np.linalg.norm(ek) <= ROUNDING:
            ek = e - (e @ n[k]) * n[k]
        ek /= np.linalg.norm(ek)
        e1 = ek - (ek @ n[k + 1]) * n[k + 1]
        if np.linalg.norm(e1) <= DEFAULT.degenerate:
            raise GeometryError(f"circles {k} and {k + 1} lie in perpendicular planes (the spine "
                                f"turns by 90 degrees or more at point {k + 1}): sample the spine "
                                "more densely there")
        e1 /= np.linalg.norm(e1)
        ends = np.array([c[k] + r[k] * ek, c[k] - r[k] * ek,
                         c[k + 1] + r[k + 1] * e1, c[k + 1] - r[k + 1] * e1]) - o
        # Homogeneous 2-D coordinates in the plane (o; n_k, e_k): apex = a_k a_{k+1} ∩ b_k b_{k+1}.
        h = np.stack([ends @ n[k], ends @ ek, np.ones(4)], axis=1)
        apex = np.cross(np.cross(h[0], h[2]), np.cross(h[1], h[3]))
        size = np.linalg.norm(apex)
        if not np.isfinite(size) or size <= TINY or np.abs(h).max() * ROUNDING > size:
            # The lines through corresponding points coincide: the two circles coincide
            # or the spine has no length between them.
            raise GeometryError(f"circles {k} and {k + 1} coincide (the spine doubles back or has "
                                f"no length at point {k + 1})")
        apex /= size
        x = rows[-1] - o
        w = apex[2] * x - (apex[0] * n[k] + apex[1] * ek)
        t = -2.0 * np.einsum("ij,ij->i", w, x) / np.einsum("ij,ij->i", w, w)
        rows.append(rows[-1] + t[:, None] * w)
        e = ek
    return grid_mesh(np.stack(rows), wrap_v=True, collapse=False,
                     info={"construction": "canal"})


def torus_mesh(R: float, r: float, u: int, v: int):
    """Circular mesh of the torus ``(sqrt(x^2 + y^2) - R)^2 + z^2 = r^2`` (axis z).

    Parameters
    ----------
    R, r : float
        ``R > r > 0``.
    u, v : int
        Steps around the axis and around the tube (>= 3).

    Returns
    -------
    Mesh
        Closed, ``u * v`` isosceles trapezoids; vertex ``(i, j)`` at angles
        ``2 pi i / u`` about the axis and ``2 pi j / v`` about the tube.
    """
    R = check_float(R, "R", lo=0.0, lo_open=True)
    r = check_float(r, "r", lo=0.0, lo_open=True)
    if r >= R:
        raise ParameterError(f"expected r < R (a ring torus), got r = {r:g}, R = {R:g}", "r")
    u = check_int(u, "u", lo=3)
    v = check_int(v, "v", lo=3)
    a = 2 * np.pi * np.arange(u) / u
    b = 2 * np.pi * np.arange(v) / v
    rad = R + r * np.cos(b)
    grid = np.stack([np.cos(a)[:, None] * rad, np.sin(a)[:, None] * rad,
                     np.broadcast_to(r * np.sin(b), (u, v))], axis=-1)
    return grid_mesh(grid, wrap_u=True, wrap_v=True, collapse=False,
                     info={"construction": "torus"})


def dupin_cyclide(R: float, r: float, u: int, v: int, center, radius: float):
    """Dupin cyclide mesh: the torus mesh inverted in the sphere ``(center, radius)``.

    Returns
    -------
    Mesh
        Circular quads (inversion keeps circles circles).
    """
    from ..transforms import inversion

    return inversion(torus_mesh(R, r, u, v), center, radius)
