"""Profile curves for the catalogue: polylines and a few analytic curves.

A profile is the curve of a translational surface, the meridian of a rotational
surface or the spine of a pipe, on ``0 <= s <= 1``.  In a design file
(read by :func:`ruledmesh.design.profiles.profile_from_spec`) it is either a
list of points (a polyline, used as it is) or a table with a ``type``:

* ``{type = "polyline", points = [[x, y, z], ...]}``
* ``{type = "arc", center = [..], radius = r, start = deg, end = deg, plane = "xy"}``
* ``{type = "parabola", vertex = [..], k = k, range = [s0, s1], plane = "xz"}``:
  ``vertex + s e1 + k s^2 e2``
* ``{type = "helix", center = [..], radius = r, pitch = p, turns = t, start = deg}``
  about the axis through ``center`` parallel to z

``plane`` is one of ``"xy"``, ``"xz"``, ``"yz"`` (first letter: e1, second: e2).
Analytic profiles are sampled uniformly in their parameter with the count the
``[mesh]`` table gives for that direction.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import Enum

import numpy as np

__all__ = ["Profile", "polyline", "arc_profile", "parabola_profile", "helix_profile", "AXES", "Plane"]

AXES = {"x": np.array([1.0, 0, 0]), "y": np.array([0, 1.0, 0]), "z": np.array([0, 0, 1.0])}


class Plane(str, Enum):
    XY = "xy"
    XZ = "xz"
    YZ = "yz"
    YX = "yx"
    ZX = "zx"
    ZY = "zy"


@dataclass(frozen=True, eq=False)
class Profile:
    """A curve on ``0 <= s <= 1``, or a fixed polyline.

    Attributes
    ----------
    point : callable, (n,) -> (n, 3)
    derivative : callable, (n,) -> (n, 3), or None for a polyline
    vertices : (m, 3) float64 or None
        The polyline's points (then ``point`` interpolates linearly).
    """

    point: Callable[[np.ndarray], np.ndarray]
    derivative: Callable[[np.ndarray], np.ndarray] | None = None
    vertices: np.ndarray | None = None

    @property
    def analytic(self) -> bool:
        return self.vertices is None

    def sample(self, segments: int) -> np.ndarray:
        """(m, 3) points: the polyline's own, or ``segments + 1`` uniform samples."""
        if self.vertices is not None:
            return self.vertices
        return self.point(np.linspace(0.0, 1.0, segments + 1))


def polyline(points: np.ndarray) -> Profile:
    """A polyline as a profile (linear interpolation by vertex index)."""
    pts = np.asarray(points, dtype=np.float64)

    def point(s):
        x = np.clip(np.asarray(s) * (len(pts) - 1), 0, len(pts) - 1)
        k = np.minimum(np.floor(x).astype(int), len(pts) - 2)
        f = (x - k)[:, None]
        return (1 - f) * pts[k] + f * pts[k + 1]

    return Profile(point, None, pts)


def arc_profile(center: np.ndarray, radius: float, start: float, end: float,
                e1: np.ndarray, e2: np.ndarray) -> Profile:
    """``center + radius (cos a e1 + sin a e2)`` for ``a`` from ``start`` to ``end`` (radians)."""
    c = np.asarray(center, dtype=np.float64)

    def point(s):
        a = start + (end - start) * np.asarray(s, dtype=np.float64)
        return c + radius * (np.cos(a)[:, None] * e1 + np.sin(a)[:, None] * e2)

    def derivative(s):
        a = start + (end - start) * np.asarray(s, dtype=np.float64)
        return (end - start) * radius * (-np.sin(a)[:, None] * e1 + np.cos(a)[:, None] * e2)

    return Profile(point, derivative)


def parabola_profile(vertex: np.ndarray, k: float, s0: float, s1: float,
                     e1: np.ndarray, e2: np.ndarray) -> Profile:
    """``vertex + x e1 + k x^2 e2`` for ``x`` from ``s0`` to ``s1``."""
    v0 = np.asarray(vertex, dtype=np.float64)

    def point(s):
        x = s0 + (s1 - s0) * np.asarray(s, dtype=np.float64)
        return v0 + x[:, None] * e1 + (k * x * x)[:, None] * e2

    def derivative(s):
        x = s0 + (s1 - s0) * np.asarray(s, dtype=np.float64)
        return (s1 - s0) * (e1 + (2 * k * x)[:, None] * e2)

    return Profile(point, derivative)


def helix_profile(center: np.ndarray, radius: float, pitch: float, turns: float,
                  start: float) -> Profile:
    """A helix about the z-parallel axis through ``center``, from angle ``start`` (radians)."""
    c = np.asarray(center, dtype=np.float64)
    span = 2 * np.pi * turns
    k = pitch / (2 * np.pi)

    def point(s):
        a = span * np.asarray(s, dtype=np.float64)
        return c + np.stack([radius * np.cos(a + start), radius * np.sin(a + start), k * a], axis=1)

    def derivative(s):
        a = span * np.asarray(s, dtype=np.float64)
        return span * np.stack([-radius * np.sin(a + start), radius * np.cos(a + start),
                                np.full_like(a, k)], axis=1)

    return Profile(point, derivative)
