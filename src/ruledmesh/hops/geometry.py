"""Rhino geometry in and out of Hops payloads, through rhino3dm.

Curves come in as rhino3dm objects and leave as design-file curve tables, so
the design layer validates them like any other design:

* a line, a polyline, a non-rational NURBS curve of degree 1-5 (including
  poly-curves, through their NURBS form) become ``line``, ``polyline`` and
  ``bspline`` tables with the same control points and knots: the same curve,
  exactly;
* a rational NURBS curve that is a circular arc becomes an ``arc`` table
  (exact);
* any other rational curve, or a degree above 5, is followed by a cubic
  B-spline through ``SAMPLES`` points evaluated on the Rhino curve (a
  warning says so).

Meshes leave as rhino3dm meshes with quads kept (faces of five or more
corners split into triangles without splinters, as in the 3DM export) and
double-precision vertices; lines as Rhino ``Line`` structures.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..mesh import FaceKind, Mesh

__all__ = [
    "SAMPLES",
    "curve_table",
    "decode_curve",
    "decode_line",
    "encode_lines",
    "encode_mesh",
    "face_kinds",
    "rhino3dm",
]

# Points on a rational (non-arc) curve that its cubic B-spline stand-in passes through.
SAMPLES = 257


def rhino3dm():
    """The rhino3dm module, or an error naming the extra that installs it."""
    from ..io import require

    return require("rhino3dm", "hops", "the Hops server")


def _data(item: Any, name: str) -> Any:
    if not isinstance(item, Mapping) or not isinstance(item.get("data"), str):
        raise ParameterError("expected {\"type\": ..., \"data\": \"...\"} items", name)
    try:
        return json.loads(item["data"])
    except json.JSONDecodeError:
        raise ParameterError("the value is not valid JSON", name) from None


def decode_curve(name: str, item: Any):
    """A rhino3dm curve from one Hops value."""
    r3 = rhino3dm()
    data = _data(item, name)
    if isinstance(data, Mapping) and {"From", "To"} <= set(data):  # a Line struct
        p, q = _line_ends(data, name)
        return r3.LineCurve(r3.Point3d(*p), r3.Point3d(*q))
    try:
        obj = r3.CommonObject.Decode(data) if isinstance(data, Mapping) else None
    except Exception:  # noqa: BLE001 (rhino3dm raises KeyError, RuntimeError... for any bad archive)
        obj = None
    if not isinstance(obj, r3.Curve):
        raise ParameterError(f"expected a curve, got {type(obj).__name__ if obj else 'no geometry'}",
                             name)
    return obj


def _point(value: Any, name: str) -> list[float]:
    try:
        xyz = [float(value[k]) for k in ("X", "Y", "Z")]
    except (TypeError, KeyError, ValueError):
        raise ParameterError("expected a point {\"X\", \"Y\", \"Z\"}", name) from None
    if not np.all(np.isfinite(xyz)):
        raise ParameterError("expected finite coordinates", name)
    return xyz


def _line_ends(data: Mapping, name: str) -> tuple[list[float], list[float]]:
    return _point(data.get("From"), name), _point(data.get("To"), name)


def decode_line(name: str, item: Any) -> list[list[float]]:
    """``[[x, y, z], [x, y, z]]`` from one Hops Line (or line curve) value."""
    data = _data(item, name)
    if isinstance(data, Mapping) and {"From", "To"} <= set(data):
        return list(_line_ends(data, name))
    curve = decode_curve(name, item)
    p, q = curve.PointAtStart, curve.PointAtEnd
    return [[p.X, p.Y, p.Z], [q.X, q.Y, q.Z]]


def _xyz(p) -> list[float]:
    return [float(p.X), float(p.Y), float(p.Z)]


def curve_table(curve, name: str) -> tuple[dict[str, Any], str | None]:
    """The design-file table of a rhino3dm curve, and a note if it is approximated.

    Returns
    -------
    table : dict
        A ``[curves.*]`` table (``line``, ``polyline``, ``arc`` or ``bspline``).
    note : str or None
        Why and how the curve was approximated, when it was.
    """
    r3 = rhino3dm()
    if isinstance(curve, r3.LineCurve):
        return {"type": "line", "points": [_xyz(curve.PointAtStart), _xyz(curve.PointAtEnd)]}, None
    if isinstance(curve, r3.PolylineCurve):
        pts = [_xyz(curve.Point(i)) for i in range(curve.PointCount)]
        return {"type": "polyline", "points": pts}, None
    nurbs = curve.ToNurbsCurve()
    if nurbs is None:
        raise ParameterError("the curve has no NURBS form", name)
    if not nurbs.IsRational and 1 <= nurbs.Degree <= 5:
        cps = [_xyz(nurbs.Points[i]) for i in range(len(nurbs.Points))]
        knots = [nurbs.Knots[i] for i in range(len(nurbs.Knots))]
        # openNURBS omits the two end knots that do not influence the curve.
        full = [knots[0], *knots, knots[-1]]
        return {"type": "bspline", "degree": int(nurbs.Degree), "points": cps, "knots": full}, None
    arc = curve.TryGetArc() if nurbs.IsRational else None
    if arc is not None and arc.IsValid:
        plane = arc.Plane
        return {"type": "arc", "center": _xyz(arc.Center), "radius": float(arc.Radius),
                "normal": _xyz(plane.ZAxis), "x_axis": _xyz(plane.XAxis),
                "start_angle": float(arc.StartAngleDegrees),
                "end_angle": float(arc.EndAngleDegrees)}, None
    domain = curve.Domain
    ts = np.linspace(domain.T0, domain.T1, SAMPLES)
    pts = [_xyz(curve.PointAt(float(t))) for t in ts]
    why = "rational" if nurbs.IsRational else f"of degree {nurbs.Degree}"
    return ({"type": "bspline", "interpolate": True, "degree": 3, "points": pts},
            (f"{name}: the curve is {why}; followed by a cubic B-spline through {SAMPLES} of "
             "its points"))


def face_kinds(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Rhino mesh faces of ``mesh`` and the source face of each (see :func:`encode_mesh`)."""
    from ..io.rhino import rhino_faces

    return rhino_faces(mesh)


def encode_mesh(mesh: Mesh) -> tuple[dict[str, Any], np.ndarray]:
    """The rhino3dm encoding of ``mesh`` (quads kept) and the source face per Rhino face.

    Returns
    -------
    encoded : dict
        ``rhino3dm.Mesh.Encode()``: what a Hops Mesh output carries.
    face_of : (G,) int64
        The ``mesh`` face of each Rhino mesh face.
    """
    r3 = rhino3dm()
    faces, face_of = face_kinds(mesh)
    used, local = np.unique(faces, return_inverse=True)
    rmesh = r3.Mesh()
    # rhino3dm has no bulk setter: one call per vertex and face, as in the 3DM export.
    for x, y, z in mesh.vertices[used].tolist():
        rmesh.Vertices.AddPoint3d(x, y, z)  # double precision (Add() is float32)
    for a, b, c, d in local.reshape(-1, 4).tolist():
        if c == d:
            rmesh.Faces.AddFace(a, b, c)
        else:
            rmesh.Faces.AddFace(a, b, c, d)
    rmesh.Normals.ComputeNormals()
    rmesh.SetUserString("ruledmesh.face_of", ",".join(map(str, face_of.tolist())))
    return rmesh.Encode(), face_of


def encode_lines(a: np.ndarray, b: np.ndarray) -> list[dict[str, Any]]:
    """Rhino ``Line`` structures from end points ``a``, ``b`` (``(m, 3)`` each)."""
    names = ("X", "Y", "Z")
    return [{"From": dict(zip(names, p)), "To": dict(zip(names, q))}
            for p, q in zip(np.asarray(a, float).tolist(), np.asarray(b, float).tolist())]


def kind_labels(mesh: Mesh, face_of: np.ndarray) -> list[str]:
    """The :class:`FaceKind` label of each Rhino mesh face."""
    labels = np.array([k.label for k in FaceKind])
    return labels[mesh.face_kind[face_of]].tolist()
