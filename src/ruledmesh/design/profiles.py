"""Profiles in design files: a list of points or a ``{type = ...}`` table.

See :mod:`ruledmesh.constructions.profiles` for the forms; this module reads
them, each value once, and hands the numbers to the profile constructors.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .._validation import check_points, describe
from ..constructions.profiles import (
    AXES,
    Plane,
    Profile,
    arc_profile,
    helix_profile,
    parabola_profile,
    polyline,
)
from ..errors import DesignError
from .fields import Fields

__all__ = ["profile_from_spec"]


def _plane(f: Fields, default: str) -> tuple[np.ndarray, np.ndarray]:
    plane = f.choice("plane", Plane, default)
    return AXES[plane.value[0]], AXES[plane.value[1]]


def profile_from_spec(spec: Any, path: str, *, dim: int = 3, min_points: int = 2) -> Profile:
    """Read a profile: a list of points or a ``{type = ...}`` table.

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
        r = f.number("radius", Fields.REQUIRED, lo=0.0, lo_open=True)
        a0 = np.radians(f.number("start", 0.0))
        a1 = np.radians(f.number("end", 90.0))
        if a0 == a1:
            raise DesignError("expected end different from start", f"{path}.end")
        return arc_profile(c, r, a0, a1, *_plane(f, "xy"))
    if kind == "parabola":
        f = Fields(spec, path, ["type", "vertex", "k", "range", "plane"])
        v0 = f.vector("vertex", [0.0, 0.0, 0.0])
        k = f.number("k", Fields.REQUIRED)
        s0, s1 = f.floats("range", [-1.0, 1.0], count=2)
        if s0 == s1:
            raise DesignError("expected two different numbers", f"{path}.range")
        return parabola_profile(v0, k, s0, s1, *_plane(f, "xz"))
    if kind == "helix":
        f = Fields(spec, path, ["type", "center", "radius", "pitch", "turns", "start"])
        c = f.vector("center", [0.0, 0.0, 0.0])
        r = f.number("radius", Fields.REQUIRED, lo=0.0, lo_open=True)
        pitch = f.number("pitch", Fields.REQUIRED)
        turns = f.number("turns", 1.0, lo=0.0, lo_open=True)
        return helix_profile(c, r, pitch, turns, np.radians(f.number("start", 0.0)))
    raise DesignError(f'expected type "polyline" | "arc" | "parabola" | "helix", got '
                      f'{describe(kind)}', f"{path}.type")


def _points(value: Any, path: str, dim: int, min_points: int) -> np.ndarray:
    pts = check_points(value, path, dim=dim, min_count=min_points, err=DesignError)
    if dim == 2:
        pts = np.concatenate([pts, np.zeros((len(pts), 1))], axis=1)
    return pts
