"""The ``[curves.<name>]`` tables of a design file: one reader per curve type.

Types and keys:

* ``line``: ``points`` (2 points);
* ``polyline``: ``points`` (>= 2);
* ``arc``: ``points`` (start, through, end) or ``center``, ``radius``, ``normal``,
  ``start_angle``, ``end_angle`` (degrees) and optional ``x_axis`` (direction of angle 0);
* ``bspline``: ``points`` (control points), ``degree`` (1..5, default 3), optional
  ``knots``; or ``interpolate = true`` to pass through ``points``;
* ``helix``: ``center``, ``axis``, ``radius``, ``pitch``, ``turns``, optional
  ``start_angle`` (degrees, default 0).

Every value is checked here once; what the curve constructors of
:mod:`ruledmesh.curves` still refuse comes back as a ``DesignError`` on the key it came from.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from .._validation import (
    check_bool,
    check_choice,
    check_float,
    check_int,
    check_keys,
    check_points,
    check_vector,
    describe,
)
from ..curves import Arc, BSpline, Curve, CurveType, Helix, Line, Polyline
from ..errors import DesignError, ParameterError

__all__ = ["curve_from_spec"]

_KEYS = {
    CurveType.LINE: ("type", "points"),
    CurveType.POLYLINE: ("type", "points"),
    CurveType.ARC: ("type", "points", "center", "radius", "normal", "start_angle", "end_angle",
                    "x_axis"),
    CurveType.BSPLINE: ("type", "points", "degree", "knots", "interpolate"),
    CurveType.HELIX: ("type", "center", "axis", "radius", "pitch", "turns", "start_angle"),
}

# constructor parameter -> design key, for naming the key a ParameterError came from
_RENAME = {
    CurveType.LINE: {"p0": "points", "p1": "points"},
    CurveType.ARC: {"start": "points", "mid": "points", "end": "points"},
    CurveType.BSPLINE: {"control_points": "points"},
}

_ARC_CENTER_KEYS = ("center", "radius", "normal", "start_angle", "end_angle", "x_axis")


def _require(spec: Mapping, key: str, path: str, what: str) -> Any:
    if key not in spec:
        raise DesignError(f"missing; expected {what}", f"{path}.{key}")
    return spec[key]


class _Table:
    """One ``[curves.<name>]`` table: typed values whose errors name ``path.key``."""

    def __init__(self, spec: Mapping, path: str):
        self.spec, self.path = spec, path

    def field(self, key: str) -> str:
        return f"{self.path}.{key}"

    def points(self, key: str, **kw: Any) -> np.ndarray:
        return check_points(_require(self.spec, key, self.path, "a list of points [x, y, z]"),
                            self.field(key), err=DesignError, **kw)

    def vector(self, key: str, nonzero: bool = False) -> np.ndarray:
        return check_vector(_require(self.spec, key, self.path, "[x, y, z]"), self.field(key),
                            nonzero=nonzero, err=DesignError)

    def number(self, key: str, default: Any = None, **kw: Any) -> float:
        value = (self.spec.get(key, default) if default is not None
                 else _require(self.spec, key, self.path, "a number"))
        return check_float(value, self.field(key), err=DesignError, **kw)


def _line(t: _Table) -> Curve:
    p = t.points("points")
    if len(p) != 2:
        raise DesignError(f"expected 2 points, got {len(p)}", t.field("points"))
    return Line(p[0], p[1])


def _polyline(t: _Table) -> Curve:
    return Polyline(t.points("points", min_count=2))


def _arc(t: _Table) -> Curve:
    center_keys = [k for k in _ARC_CENTER_KEYS if k in t.spec]
    if "points" in t.spec:
        if center_keys:
            raise DesignError("give either points (start, through, end) or center/radius/normal/"
                              "angles, not both", t.field(center_keys[0]))
        p = t.points("points")
        if len(p) != 3:
            raise DesignError(f"expected 3 points (start, through, end), got {len(p)}",
                              t.field("points"))
        return Arc.through(p[0], p[1], p[2])
    if not center_keys:
        raise DesignError("missing; expected points (start, through, end) or center, radius, "
                          "normal, start_angle, end_angle", t.field("points"))
    x_axis = t.vector("x_axis", nonzero=True) if "x_axis" in t.spec else None
    return Arc.from_center(t.vector("center"), t.number("radius", lo=0.0, lo_open=True),
                           t.vector("normal", nonzero=True), t.number("start_angle"),
                           t.number("end_angle"), x_axis)


def _bspline(t: _Table) -> Curve:
    degree = check_int(t.spec.get("degree", 3), t.field("degree"), lo=1, hi=5, err=DesignError)
    interp = check_bool(t.spec.get("interpolate", False), t.field("interpolate"), err=DesignError)
    p = t.points("points")
    if len(p) < degree + 1:
        raise DesignError(f"a degree-{degree} B-spline needs at least {degree + 1} points, "
                          f"got {len(p)}", t.field("points"))
    if interp:
        if "knots" in t.spec:
            raise DesignError("knots cannot be given with interpolate = true", t.field("knots"))
        return BSpline.interpolate(p, degree)
    knots = t.spec.get("knots")
    if isinstance(knots, (str, Mapping)):
        raise DesignError(f"expected a list of numbers, got {describe(knots)}", t.field("knots"))
    return BSpline(p, degree, knots)


def _helix(t: _Table) -> Curve:
    return Helix(t.vector("center"), t.vector("axis", nonzero=True),
                 t.number("radius", lo=0.0, lo_open=True), t.number("pitch"),
                 t.number("turns", lo=0.0, lo_open=True), t.number("start_angle", default=0.0))


_READERS: dict[CurveType, Callable[[_Table], Curve]] = {
    CurveType.LINE: _line, CurveType.POLYLINE: _polyline, CurveType.ARC: _arc,
    CurveType.BSPLINE: _bspline, CurveType.HELIX: _helix,
}


def curve_from_spec(spec: Mapping, path: str) -> Curve:
    """Build a curve from a design file's ``[curves.<name>]`` table (types: see the module).

    Parameters
    ----------
    spec : Mapping
        E.g. ``{"type": "bspline", "degree": 3, "points": [[0, 0, 0], ...]}``.
    path : str
        The table's dotted path, e.g. ``"curves.c1"``, prefixed to errors.

    Returns
    -------
    Curve

    Raises
    ------
    DesignError
        With the full dotted field path, e.g.
        ``curves.c1.degree: expected an integer >= 1 and <= 5, got 7``.

    Examples
    --------
    >>> c = curve_from_spec({"type": "line", "points": [[0, 0, 0], [3, 4, 0]]}, "curves.c1")
    >>> c.length()
    5.0
    >>> curve_from_spec(c.to_spec(), "curves.c1") == c
    True
    """
    if not isinstance(spec, Mapping):
        raise DesignError(f"expected a table, got {describe(spec)}", path)
    kind = check_choice(_require(spec, "type", path, "one of " + " | ".join(
        f'"{t.value}"' for t in CurveType)), CurveType, f"{path}.type", err=DesignError)
    check_keys(spec, _KEYS[kind], path, err=DesignError)
    try:
        return _READERS[kind](_Table(spec, path))
    except ParameterError as exc:
        key = _RENAME.get(kind, {}).get(exc.field or "", exc.field or "")
        raise DesignError(exc.detail, f"{path}.{key}" if key else path) from None
