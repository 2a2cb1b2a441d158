"""Smooth reference surfaces: the design surface a mesh is measured against.

Two kinds, both answering ``distance(points)`` and ``area()`` (the
:class:`~ruledmesh.registry.Reference` protocol): :class:`ImplicitSurface` for
the catalogue kinds, and :class:`RuledReference` for a parametric ruled patch
(director curves, generators).

:class:`RuledReference` wraps a patch with ``point(u, t)``, ``partials(u, t)``
and ``area()`` and measures how far points are from ``0 <= u, t <= 1``: a
nearest sample on a fine grid seeds a few vectorised Gauss-Newton steps on
``|S(u, t) - p|^2`` with ``(u, t)`` clamped to the patch.

A reference answers ``distance(points)`` and ``area()`` (the
:class:`~ruledmesh.registry.Reference` protocol).  Catalogue references are
*implicit*: ``value(p)`` is zero on the surface and ``gradient(p)`` is its
gradient.  Where an exact distance is known in closed form (sphere, torus,
surface of revolution of a polyline, pipe) it is used; otherwise the distance
is that of a few Newton steps along the gradient onto the zero set, which is
exact for points on the surface and accurate to second order near it (the
regime closeness measures).

A transformed reference is again implicit: ``value(T^-1 q)``, with the
gradient pulled back through the Jacobian, so closeness stays honest after an
affine, projective or inversion transform (see :mod:`ruledmesh.transforms`).
Distances of unbounded implicit surfaces (helicoid, hyperboloid) are to the
whole surface, not only the meshed patch.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .analysis.surface import RuledPatch, RuledReference
from .errors import GeometryError
from .tolerances import ROUNDING
from .tolerances import TINY as _TINY

__all__ = [
    "RuledPatch",
    "RuledReference",
    "ImplicitSurface",
    "newton_distance",
    "parametric_area",
    "sphere",
    "torus",
    "revolution_of_polyline",
    "pipe_of_polyline",
]


def newton_distance(value: Callable, gradient: Callable, points: np.ndarray,
                    iterations: int = 8) -> np.ndarray:
    """Distance from ``points`` to the zero set of ``value`` by Newton steps along the gradient.

    Parameters
    ----------
    value : callable, (n, 3) -> (n,)
    gradient : callable, (n, 3) -> (n, 3)
    points : (n, 3) float64
    iterations : int

    Returns
    -------
    (n,) float64
        ``|p - p*|`` where ``p*`` is where the iteration lands; exactly the
        rounding of ``value`` for points already on the surface.
    """
    p = np.array(points, dtype=np.float64, copy=True)
    for _ in range(iterations):
        f = value(p)
        g = gradient(p)
        gg = np.einsum("ij,ij->i", g, g)
        step = np.where(gg > _TINY, f / np.maximum(gg, _TINY), 0.0)
        p -= step[:, None] * g
    return np.linalg.norm(p - points, axis=1)


@dataclass(frozen=True, eq=False)
class ImplicitSurface:
    """A surface ``value(p) = 0`` with a distance and an optional patch area.

    Parameters
    ----------
    name : str
        What it is (shown in notes).
    value : callable, (n, 3) -> (n,), or None
        Smooth, signed: zero on the surface.  ``None`` for references known
        only by an exact unsigned distance (those survive similarities only).
    gradient : callable, (n, 3) -> (n, 3), or None
    patch_area : float or None
        Area of the design patch the mesh covers, when known.
    exact : callable or None
        Exact distance, (n, 3) -> (n,), when known in closed form.
    """

    name: str
    value: Callable[[np.ndarray], np.ndarray] | None
    gradient: Callable[[np.ndarray], np.ndarray] | None
    patch_area: float | None = None
    exact: Callable[[np.ndarray], np.ndarray] | None = None

    def distance(self, points: np.ndarray) -> np.ndarray:
        """(n,) float64: distance of (n, 3) ``points`` from the surface."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if self.exact is not None:
            return self.exact(points)
        if self.value is None or self.gradient is None:
            raise GeometryError("the implicit surface has neither a distance nor a value and gradient")
        return newton_distance(self.value, self.gradient, points)

    def area(self) -> float | None:
        """Area of the meshed design patch, or ``None`` when not known."""
        return self.patch_area


def parametric_area(partials: Callable, u_range: tuple[float, float],
                    v_range: tuple[float, float], nodes: int = 96) -> float:
    """Area of a parametric patch by tensor Gauss-Legendre quadrature.

    Parameters
    ----------
    partials : callable
        ``partials(u, v) -> (S_u, S_v)``, each (n, 3), for (n,) parameters.
    u_range, v_range : (float, float)
    nodes : int
        Nodes per direction (the integrands here are smooth: 96 nodes give
        rounding-level accuracy for the catalogue patches).
    """
    x, w = np.polynomial.legendre.leggauss(nodes)
    (u0, u1), (v0, v1) = u_range, v_range
    u = 0.5 * (u1 - u0) * (x + 1) + u0
    v = 0.5 * (v1 - v0) * (x + 1) + v0
    uu, vv = np.meshgrid(u, v, indexing="ij")
    su, sv = partials(uu.ravel(), vv.ravel())
    jac = np.linalg.norm(np.cross(su, sv), axis=1).reshape(nodes, nodes)
    return float(0.25 * (u1 - u0) * (v1 - v0) * (w @ jac @ w))


# ----------------------------------------------------------------- closed forms
def sphere(center, radius: float) -> ImplicitSurface:
    """The sphere ``|p - center| = radius``."""
    c = np.asarray(center, dtype=np.float64)
    return ImplicitSurface(
        "sphere",
        lambda p: (np.einsum("ij,ij->i", p - c, p - c) - radius ** 2) / (2 * radius),
        lambda p: (p - c) / radius,
        4 * np.pi * radius ** 2,
        lambda p: np.abs(np.linalg.norm(p - c, axis=1) - radius),
    )


def torus(R: float, r: float) -> ImplicitSurface:
    """The torus about the z axis: ``(sqrt(x^2 + y^2) - R)^2 + z^2 = r^2``."""

    def tube(p):
        rho = np.hypot(p[:, 0], p[:, 1])
        return rho, np.hypot(rho - R, p[:, 2])

    def value(p):
        return tube(p)[1] - r

    def gradient(p):
        rho, d = tube(p)
        d = np.maximum(d, _TINY)
        rho_safe = np.maximum(rho, _TINY)
        radial = (rho - R) / d
        return np.stack([radial * p[:, 0] / rho_safe, radial * p[:, 1] / rho_safe, p[:, 2] / d],
                        axis=1)

    return ImplicitSurface("torus", value, gradient, 4 * np.pi ** 2 * R * r,
                           lambda p: np.abs(value(p)))


# Point-segment pairs per block of :func:`_segment_distance`: its (points, segments)
# temporaries then stay in the cache (a design's meridian has thousands of segments).
_SEGMENT_PAIRS = 16_384


def _segment_distance(q: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """(n,) distance of (n, k) points from an (m, k) polyline, in any dimension k.

    Coordinate by coordinate on (points, segments) blocks: numpy's loops over an
    innermost axis of k = 2 or 3 numbers cost ten times the arithmetic.  The sums
    over coordinates run in the order ``einsum`` takes them, so the distances are
    those of the (points, segments, k) formula, bit for bit.
    """
    a, b = poly[:-1], poly[1:]
    d = b - a
    dd = np.maximum(np.einsum("ij,ij->i", d, d), _TINY)
    a_rows, d_rows = np.ascontiguousarray(a.T), np.ascontiguousarray(d.T)
    out = np.empty(len(q))
    step = max(1, _SEGMENT_PAIRS // max(len(a), 1))
    for lo in range(0, len(q), step):
        cols = [q[lo:lo + step, j, None] for j in range(q.shape[1])]
        dot = sum((c - a_j) * d_j for c, a_j, d_j in zip(cols, a_rows, d_rows))
        t = np.clip(dot / dd, 0.0, 1.0)
        square = sum((off := c - (a_j + t * d_j)) * off for c, a_j, d_j in zip(cols, a_rows, d_rows))
        out[lo:lo + step] = np.sqrt(np.min(square, axis=1))
    return out


def revolution_of_polyline(meridian_rz: np.ndarray, origin: np.ndarray, axis: np.ndarray,
                           angle: float, x_dir: np.ndarray) -> ImplicitSurface:
    """The surface a polyline sweeps when turned by ``angle`` about an axis.

    Parameters
    ----------
    meridian_rz : (m, 2) float64
        Meridian as (distance from the axis, height along the axis).
    origin, axis : (3,) float64
        A point of the axis and its unit direction.
    angle : float
        Sweep in radians (``2 pi``: the full surface).
    x_dir : (3,) float64
        Unit vector perpendicular to the axis where the sweep starts.

    Notes
    -----
    The distance is exact: inside the sweep it is the planar distance of
    ``(rho, h)`` from the meridian polyline; outside, the distance from the
    nearer of the two end meridians.
    """
    y_dir = np.cross(axis, x_dir)
    full = angle >= 2 * np.pi - ROUNDING

    def local(p):
        rel = p - origin
        h = rel @ axis
        radial = rel - h[:, None] * axis
        return h, radial

    def exact(p):
        h, radial = local(p)
        rho = np.linalg.norm(radial, axis=1)
        d = _segment_distance(np.stack([rho, h], axis=1), meridian_rz)
        if full:
            return d
        phi = np.mod(np.arctan2(radial @ y_dir, radial @ x_dir), 2 * np.pi)
        outside = phi > angle
        if np.any(outside):
            ends = []
            for a in (0.0, angle):
                direction = np.cos(a) * x_dir + np.sin(a) * y_dir
                curve = origin + meridian_rz[:, :1] * direction + meridian_rz[:, 1:] * axis
                ends.append(_segment_distance(p[outside], curve))
            d = d.copy()
            d[outside] = np.minimum(*ends)
        return d

    # Pappus: each meridian segment sweeps (length) x (angle) x (mean radius).
    seg = np.diff(meridian_rz, axis=0)
    area = float(np.sum(np.linalg.norm(seg, axis=1) * angle
                        * 0.5 * (meridian_rz[:-1, 0] + meridian_rz[1:, 0])))
    return ImplicitSurface("surface of revolution", None, None, area, exact)


def pipe_of_polyline(spine: np.ndarray, radius: float) -> ImplicitSurface:
    """Points at distance ``radius`` from a polyline (a pipe with round joints)."""

    def exact(p):
        return np.abs(_segment_distance(p, spine) - radius)

    length = float(np.linalg.norm(np.diff(spine, axis=0), axis=1).sum())
    return ImplicitSurface("pipe", None, None, 2 * np.pi * radius * length, exact)
