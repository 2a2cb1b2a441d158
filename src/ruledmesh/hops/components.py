"""The Hops components ruledmesh serves: each one turns its inputs into a design.

Every component builds a design table from its inputs and hands it to
:func:`ruledmesh.build_full`, so Grasshopper gets the same validation,
the same grid budget and the same mesh as a design file; an error names the
Hops input it comes from.  All components share the outputs of
:data:`OUTPUTS`.
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import ParameterError, RuledMeshError
from ..tolerances import DEFAULT
from .geometry import (
    curve_table,
    decode_curve,
    decode_line,
    encode_lines,
    encode_mesh,
    kind_labels,
)
from .protocol import Component, Param, value_item

__all__ = ["COMPONENTS", "OUTPUTS", "solve_design"]

OUTPUTS = (
    Param("Mesh", "Mesh", "the mesh: planar quads kept as quads, border faces and fill triangles"),
    Param("Generators", "Line", "the generators (rulings) of the surface", many=True),
    Param("Kinds", "Text", "kind of each mesh face: quad, border, fill, split, triangle, polygon",
          many=True),
    Param("Planarity", "Number", "largest face planarity (relative to the face size)", "P"),
    Param("Quad share", "Number", "share of the mesh area in planar quads (0..1)", "Q"),
    Param("Report", "Text", "the full analysis report as JSON (ruledmesh analyze --json)", "R"),
)
_DECODERS = {"Curve": decode_curve, "Line": decode_line}

# Design paths -> the Hops input they come from, for error messages.
_FIELDS = {
    "curves.A": "Curve A", "curves.B": "Curve B", "rulings.count": "Count",
    "rulings.distribution": "Distribution", "rulings.lines": "Lines", "mesh.rows": "Rows",
    "mesh.primary": "Primary", "mesh.option": "Option", "mesh.midpoints": "Midpoints",
    "mesh.divisions": "Divisions", "mesh.flip": "Flip", "mesh.u": "U", "mesh.v": "V",
}


def _input_name(detail: str, path: str | None) -> ParameterError:
    """The error of design field ``path``, named by the Hops input it came from."""
    if not path:
        return ParameterError(detail)
    for prefix, name in _FIELDS.items():
        if path == prefix or path.startswith(prefix + "."):
            return ParameterError(detail, name)
    if path.startswith("surface."):
        return ParameterError(detail, path.split(".", 1)[1])
    return ParameterError(detail, path)


def _quad_share(mesh) -> float:
    """Share of the area in faces with four corners (whatever their kind)."""
    from ..analysis.faces import area_shares

    return area_shares(mesh)["quads"] if mesh.n_faces else 0.0


def solve_design(design: Mapping[str, Any], notes: list[str], tolerance: float | None = None
                 ) -> tuple[dict[str, list[dict[str, str]]], list[str]]:
    """Build ``design`` and encode the shared outputs.

    Parameters
    ----------
    design : mapping
        Design tables, as a design file holds them (no file references).
    notes : list of str
        Warnings gathered while reading the inputs.
    tolerance : float, optional
        Planarity tolerance of the report (default: the library's).
    """
    from .. import api
    from ..analysis.report import analyze
    from ..tolerances import DEFAULT

    tol = DEFAULT if tolerance is None else replace(DEFAULT, planarity=tolerance)
    try:
        built = api.build_full(dict(design))
    except RuledMeshError as exc:
        if not hasattr(exc, "detail"):  # geometry errors name no field
            raise
        raise _input_name(exc.detail, getattr(exc, "field", None)) from None
    mesh = built.mesh
    report = analyze(mesh, reference=built.reference, extras=built.extras, tol=tol)
    encoded, face_of = encode_mesh(mesh)
    if built.rulings is not None:
        a, b = built.rulings.a, built.rulings.b
    else:
        a, b = mesh.vertices[mesh.members[:, 0]], mesh.vertices[mesh.members[:, 1]]
    outputs = {
        "Mesh": [value_item("Mesh", encoded)],
        "Generators": [value_item("Line", line) for line in encode_lines(a, b)],
        "Kinds": [value_item("Text", k) for k in kind_labels(mesh, face_of)],
        "Planarity": [value_item("Number", float(report["planarity"]["max"]))],
        "Quad share": [value_item("Number", _quad_share(mesh))],
        "Report": [value_item("Text", json.dumps(report))],
    }
    return outputs, [*notes, *report["warnings"]]


def _primary(value: str) -> int | str:
    text = value.strip()
    if text == "middle":
        return text
    try:
        return int(text)
    except ValueError:
        raise ParameterError(f'expected "middle" or a generator index, got {value[:40]!r}',
                             "Primary") from None


def _tolerance(value: float) -> float:
    if not (np.isfinite(value) and value > 0):
        raise ParameterError(f"expected a positive number, got {value:g}", "Tolerance")
    return value


_ROWS = Param("Rows", "Integer", "divisions of the primary generator", "R", default=40)
_PRIMARY = Param("Primary", "Text", '"middle" or the index of the primary generator', "P",
                 default="middle")
_OPTION = Param("Option", "Integer", "0 or 1: the two checkerboards of the PQ mesh", "O", default=0)
_TOLERANCE = Param("Tolerance", "Number", "planarity tolerance of the report (relative)", "T",
                   default=DEFAULT.planarity)


def _pq_mesh_table(inputs: Mapping[str, Any]) -> dict[str, Any]:
    table = {"method": "pq", "rows": inputs["Rows"], "primary": _primary(inputs["Primary"]),
             "option": inputs["Option"]}
    if table["primary"] == "middle" and table["option"] == 0:
        # Both at their defaults: as a design file that leaves them out, the build may take
        # the other checkerboard or primary where its mesh misses a goal (and says so).
        del table["primary"], table["option"]
    return table


def _ruled_pq(inputs: dict[str, Any]):
    notes: list[str] = []
    curves = {}
    for key, name in (("A", "Curve A"), ("B", "Curve B")):
        table, note = curve_table(inputs[name], name)
        curves[key] = table
        if note:
            notes.append(note)
    distribution = inputs["Distribution"]
    if distribution not in ("arc-length", "parameter"):
        raise ParameterError(f'expected "arc-length" or "parameter", got {distribution[:40]!r} '
                             "(director-plane and linear-directrix: use the design component)",
                             "Distribution")
    design = {"curves": curves,
              "rulings": {"between": ["A", "B"], "count": inputs["Count"],
                          "distribution": distribution},
              "mesh": _pq_mesh_table(inputs)}
    return solve_design(design, notes, _tolerance(inputs["Tolerance"]))


def _ruled_lines(inputs: dict[str, Any]):
    design = {"rulings": {"lines": inputs["Lines"]}, "mesh": _pq_mesh_table(inputs)}
    return solve_design(design, [], _tolerance(inputs["Tolerance"]))


def _hybrid_lines(inputs: dict[str, Any]):
    design = {"rulings": {"lines": inputs["Lines"]},
              "mesh": {"method": "hybrid", "midpoints": inputs["Midpoints"],
                       "divisions": inputs["Divisions"], "flip": inputs["Flip"]}}
    return solve_design(design, [])


def _refuse_files(value: Any, path: str = "") -> None:
    """A design sent over the network must not make the server read its own files."""
    if isinstance(value, Mapping):
        for key, item in value.items():
            where = f"{path}.{key}" if path else str(key)
            if key == "file":
                raise ParameterError(f"{where}: designs sent to the Hops server cannot read "
                                     "files; give the lines in the design (rulings.lines)",
                                     "Design")
            _refuse_files(item, where)
    elif isinstance(value, list):
        for k, item in enumerate(value):
            _refuse_files(item, f"{path}[{k}]")


def _check_surface_budget(design: Mapping[str, Any]) -> None:
    """Refuse catalogue grids beyond the build budget of design files (``u x v`` points)."""
    from ..design import MAX_BUILD_BYTES
    from ..rulings import BUILD_BYTES_PER_GRID_POINT

    mesh = design.get("mesh")
    if "surface" not in design or not isinstance(mesh, Mapping):
        return
    sizes = [v for k, v in mesh.items() if k in ("u", "v") and isinstance(v, int)
             and not isinstance(v, bool)]
    points = int(np.prod([max(s, 1) + 1 for s in sizes], dtype=float)) if sizes else 0
    if points * BUILD_BYTES_PER_GRID_POINT > MAX_BUILD_BYTES:
        raise ParameterError(f"a grid of {points} points is beyond the build budget "
                             f"({MAX_BUILD_BYTES / 2**30:.0f} GiB); reduce u and v", "mesh.u")


def _design(inputs: dict[str, Any]):
    text = inputs["Design"]
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"invalid TOML: {exc}", "Design") from None
    _refuse_files(data)
    _check_surface_budget(data)
    return solve_design(data, [], _tolerance(inputs["Tolerance"]))


def _surface(kind: str, names: tuple[str, ...], mesh_names: tuple[str, ...],
             fixed: Mapping[str, Any] | None = None
             ) -> Callable[[dict[str, Any]], Any]:
    def solve(inputs: dict[str, Any]):
        surface = {"kind": kind, **(fixed or {}), **{n: inputs[n] for n in names}}
        design = {"surface": surface, "mesh": {n.lower(): inputs[n] for n in mesh_names}}
        _check_surface_budget(design)
        return solve_design(design, [])
    return solve


def _num(name: str, text: str, default: float) -> Param:
    return Param(name, "Number", text, default=default)


def _int(name: str, text: str, default: int) -> Param:
    return Param(name, "Integer", text, default=default)


_LINES = Param("Lines", "Line", "the generators: any set of at least 3 straight lines", "L",
               many=True)

COMPONENTS: dict[str, Component] = {c.name: c for c in [
    Component(
        "ruled_pq", "PQ mesh of the ruled surface between two director curves (Lordick §4.3): "
        "generators at equal arc length or parameter, planar quads with generator diagonals.",
        (Param("Curve A", "Curve", "first director curve (t = 0)", "A"),
         Param("Curve B", "Curve", "second director curve (t = 1)", "B"),
         _int("Count", "number of generators (>= 3)", 41), _ROWS,
         Param("Distribution", "Text", '"arc-length" or "parameter"', "D", default="arc-length"),
         _PRIMARY, _OPTION, _TOLERANCE),
        OUTPUTS, _ruled_pq, decode=_DECODERS),
    Component(
        "ruled_lines", "PQ mesh (§4.3) of a ruled surface given by its generators as lines.",
        (_LINES, _ROWS, _PRIMARY, _OPTION, _TOLERANCE), OUTPUTS, _ruled_lines, decode=_DECODERS),
    Component(
        "hybrid_lines", "Hybrid mesh (§4.1) of any set of lines: planar quads inside the strips, "
        "triangles along the generators.",
        (_LINES, _int("Midpoints", "generators inserted per strip", 1),
         _int("Divisions", "divisions of each generator", 8),
         Param("Flip", "Boolean", "the other diagonal across the generators", default=False)),
        OUTPUTS, _hybrid_lines, decode=_DECODERS),
    Component(
        "design", "Any ruledmesh design given as TOML text (see the design-file reference).",
        (Param("Design", "Text", "the design file's text", "D"), _TOLERANCE),
        OUTPUTS, _design, subcategory="Designs"),
    Component(
        "hyperboloid", "One-sheet hyperboloid x²/a² + y²/a² - z²/c² = 1, |z| <= height, by its "
        "generators (§3.2, Fig. 7c): a circular mesh with the generators as diagonals.",
        (_num("a", "waist radius", 1.0), _num("c", "axis scale", 1.5),
         _num("height", "half height", 2.0), _int("U", "generators per regulus", 32)),
        OUTPUTS, _surface("hyperboloid", ("a", "c", "height"), ("U",), {"style": "generators"}),
        subcategory="Catalogue"),
    Component(
        "hyperbolic_paraboloid", "Hyperbolic paraboloid z = x²/a² - y²/b² by its generators "
        "(§3.2, Fig. 7c): parallelograms with generator diagonals.",
        (_num("a", "x scale", 1.0), _num("angle", "angle of the reguli in plan, degrees", 70.0),
         _num("size", "half width of the patch", 2.0), _int("U", "generators, first regulus", 12),
         _int("V", "generators, second regulus", 12)),
        OUTPUTS, _surface("hyperbolic-paraboloid", ("a", "angle", "size"), ("U", "V"),
                          {"style": "generators"}),
        subcategory="Catalogue"),
    Component(
        "helicoid", "Helicoid as a translational surface of a helix (§3.3, Fig. 8): "
        "parallelograms on the helicoid.",
        (_num("radius", "outer radius", 2.0), _num("pitch", "rise per turn", 3.0),
         _num("turns", "number of turns", 1.0), _int("U", "steps of the first helix", 48),
         _int("V", "steps of the second helix", 48)),
        OUTPUTS, _surface("helicoid", ("radius", "pitch", "turns"), ("U", "V")),
        subcategory="Catalogue"),
]}
