"""Profile curves for the catalogue: polylines and a few analytic curves.

A profile (of a translational surface, the meridian of a rotational surface,
the spine of a pipe) is written in a design file either as a list of points
(a polyline, used as it is) or as a table with a ``type``:

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

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from enum import Enum
from typing import Any

import numpy as np

from .._validation import describe
from ..errors import DesignError
from ._spec import Fields

__all__ = ["Profile", "profile_from_spec", "polyline"]

_AXES = {"x": np.array([1.0, 0, 0]), "y": np.array([0, 1.0, 0]), "z": np.array([0, 0, 1.0])}


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


def _plane(f: Fields, default: str) -> tuple[np.ndarray, np.ndarray]:
    plane = f.choice("plane", Plane, default)
    return _AXES[plane.value[0]], _AXES[plane.value[1]]


def profile_from_spec(spec: Any, path: str, *, dim: int = 3, min_points: int = 2) -> Profile:
    """Read a profile: a list of points or a ``{type = ...}`` table (see module doc).

    ``dim = 2`` reads polylines of 2-D points (a meridian as (r, z)), returned
    as (m, 3) points with a zero third coordinate.
    """
    if not isinstance(spec, Mapping):
        return polyline(_points(spec, path, dim, min_points))
    kind = spec.get("type", "polyline")
    if kind == "polyline":
        f = Fields(spec, path, ["type", "points"])
        return polyline(_points(f.raw("points", Fields.REQUIRED), f"{path}.points", dim,
                                min_points))
    if kind == "arc":
        f = Fields(spec, path, ["type", "center", "radius", "start", "end", "plane"])
        c = f.vector("center", [0.0, 0.0, 0.0])
        r = f.float("radius", Fields.REQUIRED, lo=0.0, lo_open=True)
        a0 = np.radians(f.float("start", 0.0))
        a1 = np.radians(f.float("end", 90.0))
        if a0 == a1:
            raise DesignError("expected end different from start", f"{path}.end")
        e1, e2 = _plane(f, "xy")

        def point(s):
            a = a0 + (a1 - a0) * np.asarray(s, dtype=np.float64)
            return c + r * (np.cos(a)[:, None] * e1 + np.sin(a)[:, None] * e2)

        def derivative(s):
            a = a0 + (a1 - a0) * np.asarray(s, dtype=np.float64)
            return (a1 - a0) * r * (-np.sin(a)[:, None] * e1 + np.cos(a)[:, None] * e2)

        return Profile(point, derivative)
    if kind == "parabola":
        f = Fields(spec, path, ["type", "vertex", "k", "range", "plane"])
        v0 = f.vector("vertex", [0.0, 0.0, 0.0])
        k = f.float("k", Fields.REQUIRED)
        s0, s1 = f.floats("range", [-1.0, 1.0], count=2)
        if s0 == s1:
            raise DesignError("expected two different numbers", f"{path}.range")
        e1, e2 = _plane(f, "xz")

        def point(s):
            x = s0 + (s1 - s0) * np.asarray(s, dtype=np.float64)
            return v0 + x[:, None] * e1 + (k * x * x)[:, None] * e2

        def derivative(s):
            x = s0 + (s1 - s0) * np.asarray(s, dtype=np.float64)
            return (s1 - s0) * (e1 + (2 * k * x)[:, None] * e2)

        return Profile(point, derivative)
    if kind == "helix":
        f = Fields(spec, path, ["type", "center", "radius", "pitch", "turns", "start"])
        c = f.vector("center", [0.0, 0.0, 0.0])
        r = f.float("radius", Fields.REQUIRED, lo=0.0, lo_open=True)
        pitch = f.float("pitch", Fields.REQUIRED)
        turns = f.float("turns", 1.0, lo=0.0, lo_open=True)
        a0 = np.radians(f.float("start", 0.0))
        span = 2 * np.pi * turns
        k = pitch / (2 * np.pi)

        def point(s):
            a = span * np.asarray(s, dtype=np.float64)
            return c + np.stack([r * np.cos(a + a0), r * np.sin(a + a0), k * a], axis=1)

        def derivative(s):
            a = span * np.asarray(s, dtype=np.float64)
            return span * np.stack([-r * np.sin(a + a0), r * np.cos(a + a0),
                                    np.full_like(a, k)], axis=1)

        return Profile(point, derivative)
    raise DesignError(f'expected type "polyline" | "arc" | "parabola" | "helix", got '
                      f'{describe(kind)}', f"{path}.type")


def _points(value: Any, path: str, dim: int, min_points: int) -> np.ndarray:
    from .._validation import check_points

    pts = check_points(value, path, dim=dim, min_count=min_points, err=DesignError)
    if dim == 2:
        pts = np.concatenate([pts, np.zeros((len(pts), 1))], axis=1)
    return pts
