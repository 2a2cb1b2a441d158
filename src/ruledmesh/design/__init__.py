"""Design files: TOML in, a built mesh out.

A design is either a ruled surface given by director curves or lines
(``[curves.*]``, ``[rulings]``, ``[mesh]``) or a catalogue surface
(``[surface]`` with a ``kind``, and ``[mesh]``), optionally followed by
``[[transform]]`` tables applied in order.  Every error names the file, the
dotted field path and what was expected (see ``docs/design-reference.md``).
"""

from __future__ import annotations

import math
import os
import sys
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from .. import budget as _budget
from .._arrays import unique
from .._validation import check_keys, describe, near_miss
from ..errors import DesignError, GeometryError, RuledMeshError
from ..progress import SILENT, Progress, Task, stages
from ..registry import MESH_METHODS, SURFACE_KINDS, TRANSFORMS, BuildContext, Built, load_plugins
from ..tolerances import DEFAULT, INTERIOR, ULPS

__all__ = ["Design", "load_design", "parse_design", "design_from_tables", "build_design", "build_file"]

TOP_LEVEL = ("curves", "rulings", "mesh", "surface", "transform", "name", "description", "units")


@dataclass(frozen=True)
class Design:
    """A parsed design file.

    Attributes
    ----------
    data : mapping
        The TOML tables.
    source : str
        File name (for messages).
    base_dir : Path
        Folder that relative paths resolve against.
    """

    data: Mapping[str, Any]
    source: str = "<design>"
    base_dir: Path = Path(".")

    @property
    def context(self) -> BuildContext:
        """The :class:`BuildContext` handed to builders."""
        return BuildContext(self.source, self.base_dir, self.data)


def parse_design(text: str, source: str = "<design>", base_dir: str | os.PathLike = ".") -> Design:
    """Parse design TOML text.

    Raises
    ------
    DesignError
        For TOML syntax errors (with line and column) and unknown top-level tables.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DesignError(f"invalid TOML: {exc}", None, source) from None
    except RecursionError:
        raise DesignError(f"invalid design: tables or arrays nested deeper than the TOML "
                          f"reader can follow (a design needs at most {MAX_NESTING} levels)",
                          None, source) from None
    return design_from_tables(data, source, base_dir)


def design_from_tables(data: Mapping[str, Any], source: str = "<dict>",
                       base_dir: str | os.PathLike = ".") -> Design:
    """A :class:`Design` from tables already parsed (a dict shaped like the TOML file).

    Raises
    ------
    DesignError
        For unknown top-level tables, nesting deeper than :data:`MAX_NESTING`
        and numbers no design needs, naming ``source``.
    """
    _check_tree(data, source)
    try:
        check_keys(data, TOP_LEVEL, "", err=DesignError)
    except DesignError as exc:
        raise exc.with_source(source) from None
    return Design(data, source, Path(base_dir))


# Deepest nesting of tables and arrays a design may have: the deepest real one
# (transform tables holding a matrix) has 4; deeper data only makes every walker
# over it recurse.
MAX_NESTING = 32
_SMALLEST_NORMAL = sys.float_info.min


def _check_tree(data: Any, source: str) -> None:
    """Refuse nesting deeper than :data:`MAX_NESTING` and numbers beyond the coordinate range.

    No field of a design needs a number larger than
    :data:`ruledmesh.normalise.MAX_COORDINATE` (coordinates, lengths, angles in
    degrees, counts), nor a non-zero scalar of a surface or curve below
    :data:`~ruledmesh.normalise.MIN_EXTENT`, nor a subnormal number anywhere;
    such a number only overflows or divides by zero somewhere inside a build
    (a semi-axis of 5e-324).
    NaN and infinity are left to the fields' own checks, which say "finite".
    """
    stack: list[tuple[Any, str, int]] = [(data, "", 0)]
    while stack:
        value, path, depth = stack.pop()
        if depth > MAX_NESTING:
            raise DesignError(f"nested more than {MAX_NESTING} levels deep; a design needs a "
                              "few", path or None, source)
        if isinstance(value, Mapping):
            stack.extend((v, f"{path}.{k}" if path else str(k), depth + 1) for k, v in value.items())
        elif isinstance(value, list):
            stack.extend((v, f"{path}[{i}]", depth + 1) for i, v in enumerate(value))
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            _check_number(value, path, source)


def _check_number(value: float, path: str, source: str) -> None:
    """Refuse a number no design field needs (see :func:`_check_tree`)."""
    from ..normalise import MAX_COORDINATE, MIN_EXTENT

    size = abs(value)
    if math.isinf(size) or math.isnan(size):
        return  # the field's own check says "finite"
    shown = (f"{value:.3g}" if isinstance(value, float)
             else f"an integer of {len(str(abs(value)))} digits")
    if size > MAX_COORDINATE:
        raise DesignError(f"expected a number within +-{MAX_COORDINATE:g}, got {shown}",
                          path or None, source)
    # A scalar of a surface or curve (a radius, a semi-axis, a pitch, an angle) sets a size
    # or a sweep: a tiny one divides by zero inside the construction.  Points in arrays
    # may hold tiny coordinates (rounding noise next to the others).
    scalar = path.split(".")[0] in ("surface", "curves") and not path.endswith("]")
    if 0 < size < (MIN_EXTENT if scalar else _SMALLEST_NORMAL):
        raise DesignError(f"expected 0 or a number of magnitude at least "
                          f"{MIN_EXTENT if scalar else _SMALLEST_NORMAL:.3g}, got {shown}",
                          path or None, source)


def load_design(path: str | os.PathLike) -> Design:
    """Read and parse the design file at ``path``.

    A relative ``examples/NAME.toml`` that does not exist here is the bundled
    example of that name (:func:`ruledmesh.bundled.resolve`).
    """
    from .._files import MAX_DESIGN_BYTES, FileRefused, read_capped
    from ..bundled import resolve

    path = resolve(path)
    try:
        text = read_capped(path, MAX_DESIGN_BYTES, "a design file").decode("utf-8")
    except FileNotFoundError:
        raise DesignError("file not found", None, str(path)) from None
    except FileRefused as exc:
        raise DesignError(str(exc.strerror), None, str(path)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DesignError(f"cannot read: {exc}", None, str(path)) from None
    return parse_design(text, path.name, path.parent)


def _table(data: Mapping, key: str, required: bool = False) -> Mapping:
    value = data.get(key, {})
    if key in data and not isinstance(value, Mapping):
        raise DesignError(f"expected a table, got {describe(value)}", key)
    if required and key not in data:
        raise DesignError("missing table", key)
    return value


def _build(design: Design, progress: Progress) -> Built:
    data = design.data
    from ..units import unit_of

    units = unit_of(data.get("units"), "units", err=DesignError)
    load_plugins()
    mesh_table = _table(data, "mesh")
    transforms = data.get("transform", [])
    if not isinstance(transforms, list):
        raise DesignError("expected [[transform]] tables (an array of tables)", "transform")
    names = ([] if "surface" in data else ["generators"]) + ["mesh"] + ["transforms"] * bool(transforms)
    with stages(progress, "build", names) as task:
        built = _build_surface(design, mesh_table, task)
        hint = ("; trim = true closes torsal strips with triangles"
                if mesh_table.get("trim") is False else "")
        _in_range(built.mesh, "the mesh", hint)
        task.advance(note="transforms" if transforms else None)
        built = _apply_transforms(built, transforms)
        if transforms:
            _in_range(built.mesh, "the transformed mesh")
            task.advance()
    return replace(built, mesh=built.mesh.with_info(units=units.value))


def _build_surface(design: Design, mesh_table: Mapping, task: Task) -> Built:
    """The mesh of the [surface] or [rulings] tables, before any transform."""
    data = design.data
    ctx = replace(design.context, task=task)
    if "surface" in data:
        if "rulings" in data:
            raise DesignError("give either [surface] or [rulings], not both", "rulings")
        surface = _table(data, "surface")
        kind = surface.get("kind")
        if not isinstance(kind, str) or kind not in SURFACE_KINDS:
            raise _unknown("surface.kind", kind, SURFACE_KINDS)
        built = SURFACE_KINDS[kind](surface, mesh_table, ctx)
    else:
        if "rulings" not in data:
            raise DesignError("expected a [rulings] table (with [curves.*]) or a [surface] table", "rulings")
        from .curves import curve_from_spec
        from .rulings import rulings_from_spec

        curves_table = _table(data, "curves")
        curves = {}
        for name, spec in curves_table.items():
            if not isinstance(spec, Mapping):
                raise DesignError(f"expected a table, got {describe(spec)}", f"curves.{name}")
            curves[name] = curve_from_spec(spec, f"curves.{name}")
        rulings_table = _table(data, "rulings")
        rulings = rulings_from_spec(rulings_table, curves, path="rulings", base_dir=design.base_dir)
        rulings = _with_creases(rulings, rulings_table, curves)
        task.advance(note="mesh")
        method = mesh_table.get("method", "pq")
        if not isinstance(method, str) or method not in MESH_METHODS:
            raise _unknown("mesh.method", method, MESH_METHODS)
        _check_budget(len(rulings), mesh_table, method)
        built = MESH_METHODS[method](rulings, mesh_table, ctx)
        said = list(rulings.info.get("warnings", []))
        if said:
            # What the generators' construction had to say comes first (a part of c1 left out).
            mesh = built.mesh
            built = replace(built, mesh=mesh.with_info(warnings=said + list(mesh.info.get("warnings", []))))
    return built


# Faces whose areas are measured first when a build is checked for faces with area.
_AREA_SAMPLE = 64


def _in_range(mesh: Any, what: str, hint: str = "") -> None:
    """Refuse a mesh that is empty, all degenerate, or beyond the coordinate range.

    A build never ends with a mesh that has nothing to fabricate: no faces, or
    only faces without area (the design's features below float64 resolution at
    its size), or coordinates outside what the analysis and the file formats
    hold faithfully (:func:`ruledmesh.normalise.check_range`).  The message
    passes on what the mesher said about the parts it could not mesh.
    """
    from ..analysis.faces import degenerate_faces, face_normals
    from ..normalise import check_range, unit_frame

    v = np.asarray(mesh.vertices, dtype=np.float64)
    said = "; ".join(str(w) for w in mesh.info.get("warnings", [])[:2])
    said = f" ({said})" if said else ""
    if mesh.n_faces == 0:
        raise GeometryError(f"{what} has no faces: nothing of the design could be meshed"
                            f"{said}{hint}")
    if not np.all(np.isfinite(v)):
        raise GeometryError(f"{what} has NaN or infinite coordinates; check the numbers of "
                            "the design (an angle, a scale, a far axis point)")
    check_range(v, what)
    extent = float(np.linalg.norm(np.ptp(v, axis=0)))
    # Cheap first: one face of real area (relative to the whole) settles it; a sample of
    # the faces almost always holds one (the areas are the same numbers face_normals
    # gives on the whole mesh), and only a mesh without one measures every face.
    sample = np.zeros(mesh.n_faces, dtype=bool)
    sample[:: max(mesh.n_faces // _AREA_SAMPLE, 1)] = True
    for faces in (sample, None):
        _, area = face_normals(mesh if faces is None else mesh.select_faces(faces))
        if area.max() > INTERIOR * extent * extent:
            return
    centre, scale = unit_frame(v)
    if np.all(degenerate_faces(mesh.with_vertices((v - centre) / scale))):
        raise GeometryError(f"every one of the {mesh.n_faces} faces of {what} has no area: the "
                            f"design's features are below float64 resolution at its size "
                            f"({extent:.3g} across); bring its parts to comparable sizes{said}")


def _apply_transforms(built: Built, transforms: list) -> Built:
    for k, table in enumerate(transforms):
        path = f"transform[{k}]"
        if not isinstance(table, Mapping):
            raise DesignError(f"expected a table, got {describe(table)}", path)
        kind = table.get("type")
        if not isinstance(kind, str) or kind not in TRANSFORMS:
            raise _unknown(f"{path}.type", kind, TRANSFORMS)
        built = TRANSFORMS[kind](built, table, path)
    return built


# Refuse builds whose estimated peak memory exceeds this, before allocating anything.
MAX_BUILD_BYTES = _budget.MAX_BUILD_BYTES


def _count(table: Mapping, key: str, default: int) -> int | None:
    """``table[key]`` when it is a usable count, else ``None`` (the mesher reports it)."""
    value = table.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        return None
    return value


def _check_budget(generators: int, mesh_table: Mapping, method: str) -> None:
    """Refuse a grid too large to build, from every count that multiplies it.

    §4.3: ``generators x (rows + 1) x (1 + 2 extend)``; hybrid:
    ``(generators - 1)(midpoints + 1) + 1`` columns ``x (divisions + 1)``.
    """
    if method == "pq":
        rows = _count(mesh_table, "rows", 20)
        extend = mesh_table.get("extend", "auto")
        if rows is None or rows < 1:
            return
        factor = 1.0
        what = f"{generators} generators x {rows + 1} rows"
        if isinstance(extend, (int, float)) and not isinstance(extend, bool) and 0 < extend <= 1e3:
            factor = 1.0 + 2.0 * float(extend)
            what += f" x (1 + 2 x extend {extend:g})"
        _budget.check_budget(generators * (rows + 1) * factor, _budget.PQ_BYTES_PER_GRID_POINT,
                             what, "reduce the rows, the extension or the generator count",
                             "mesh.rows", DesignError)
    elif method == "hybrid":
        mid, div = _count(mesh_table, "midpoints", 1), _count(mesh_table, "divisions", 8)
        if mid is None or div is None:
            return
        columns = (generators - 1) * (mid + 1) + 1
        _budget.check_budget(columns * (div + 1), _budget.HYBRID_BYTES_PER_NODE,
                             f"{columns} columns ({generators} generators, {mid} midpoints) x "
                             f"{div + 1} rows", "reduce the divisions, the midpoints or the "
                             "generator count", "mesh.divisions", DesignError)


def curve_kinks(curve) -> np.ndarray:
    """Parameters ``u`` in (0, 1) where a curve has a corner (is only C0).

    Polyline corners, and knots of a B-spline repeated ``degree`` times (every
    interior knot of a degree-1 spline).
    """
    from ..curves import BSpline, Polyline

    if isinstance(curve, Polyline):
        return np.asarray(curve.breaks()[1:-1], dtype=float)
    if isinstance(curve, BSpline):
        k = np.asarray(curve.knots if curve.knots is not None else [], dtype=float)
        p = curve.degree
        if k.size == 0:
            return np.zeros(0)
        lo, hi = k[p], k[-p - 1]
        inner = k[(k > lo) & (k < hi)]
        vals, counts = np.unique(inner, return_counts=True)
        return (vals[counts >= p] - lo) / (hi - lo)
    return np.zeros(0)


def _with_creases(rulings, table: Mapping, curves: Mapping) -> Any:
    """Put a generator through every kink of a director curve.

    A kink (a polyline corner, a C0 knot) makes a crease along the generator
    through it.  A generator exactly there keeps every strip on one side of the
    crease, so the §4.3 rows cross it like any other generator instead of a
    strip straddling the bend.  The user's generators stay; the added ones are
    counted in ``info["inserted"]``.  Where the correspondence cannot be
    inverted (no smooth surface), the strips holding a kink are recorded in
    ``info["creases"]`` and the mesher closes them with triangles.
    """
    names = table.get("between")
    if "conoid" in table and isinstance(table["conoid"], Mapping):
        names = [table["conoid"].get("curve")]
    if not isinstance(names, list):
        return rulings
    new_u: list[float] = []
    pairs: set[int] = set()
    surface = getattr(rulings, "surface", None)
    for key, name, rail in zip(("c1_params", "c2_params"), names,
                               (getattr(surface, "rail_a", None), getattr(surface, "rail_b", None))):
        params = rulings.info.get(key)
        curve = curves.get(name)
        if params is None or curve is None:
            continue
        kinks = curve_kinks(curve)
        params = np.asarray(params, dtype=float)
        if kinks.size == 0 or params.size < 2:
            continue
        # Works for parameters increasing or decreasing along the generators.
        order = np.argsort(params)
        pos = np.searchsorted(params[order], kinks)
        ok = (pos > 0) & (pos < params.size)
        for kink, lo_i, hi_i in zip(kinks[ok], order[pos[ok] - 1], order[pos[ok]]):
            if abs(int(lo_i) - int(hi_i)) != 1:
                continue
            lo_i, hi_i = min(int(lo_i), int(hi_i)), max(int(lo_i), int(hi_i))
            u = _kink_parameter(rail, rulings.u[lo_i], rulings.u[hi_i], kink)
            if u is None:
                pairs.add(lo_i)
            else:
                new_u.append(u)
    if new_u and surface is not None:
        u_all = unique(np.concatenate([rulings.u, new_u]))
        keep = np.r_[True, np.diff(u_all) > DEFAULT.degenerate]
        u_all = u_all[keep]
        inserted = len(u_all) - len(rulings.u)
        info = {**rulings.info, "inserted": inserted,
                "crease_generators": [int(np.argmin(np.abs(u_all - u))) for u in new_u]}
        info.pop("c1_params", None)
        info.pop("c2_params", None)
        rulings = replace(rulings, a=surface.a(u_all), b=surface.b(u_all), u=u_all, info=info)
    if not pairs:
        return rulings
    return replace(rulings, info={**rulings.info, "creases": sorted(pairs)})


def _kink_parameter(rail: Any, u0: float, u1: float, kink: float) -> float | None:
    """The surface parameter in (u0, u1) where a rail reaches the curve parameter ``kink``."""
    sigma = getattr(rail, "sigma", None)
    if sigma is None:
        return None
    f0 = float(sigma.value(np.float64(u0))) - kink
    f1 = float(sigma.value(np.float64(u1))) - kink
    if f0 == 0.0 or f1 == 0.0 or f0 * f1 > 0:
        return None
    from ..roots import brentq

    u = brentq(lambda x: float(sigma.value(np.float64(x))) - kink, u0, u1, xtol=ULPS)
    if u - u0 < INTERIOR * (u1 - u0) or u1 - u < INTERIOR * (u1 - u0):
        return None
    return float(u)


def _unknown(path: str, value: Any, table: Mapping) -> DesignError:
    names = sorted(table)
    listed = " | ".join(f'"{n}"' for n in names)
    got = "nothing" if value is None else describe(value)
    return DesignError(f"expected one of {listed}, got {got}{near_miss(value, names)}", path)


def build_design(design: Design, progress: Progress | None = None) -> Built:
    """Build the mesh a design describes.

    Parameters
    ----------
    design : Design
    progress : Progress, optional
        Told the build stages as they run (generators, mesh, transforms);
        see :mod:`ruledmesh.progress`.  Default: silent.

    Returns
    -------
    Built
        The mesh, its smooth reference surface and the rulings.

    Raises
    ------
    DesignError
        Naming the file and field for any malformed value.
    GeometryError
        When the geometry cannot be meshed as asked.
    """
    try:
        built = _build(design, progress or SILENT)
    except DesignError as exc:
        raise (exc if exc.source else exc.with_source(design.source)) from None
    except RuledMeshError as exc:
        raise type(exc)(f"{design.source}: {exc}") from None
    return built


def build_file(path: str | os.PathLike, progress: Progress | None = None) -> Built:
    """:func:`build_design` of :func:`load_design` (``path``)."""
    return build_design(load_design(path), progress)
