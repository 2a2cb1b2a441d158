"""The ``[rulings]`` table of a design file, and CSV files of generators.

Exactly one source of generators: ``between`` two or three ``[curves.*]`` (with a
``distribution``), ``lines`` (given generators), ``file`` (a CSV of them) or
``conoid``.  Every value is checked here once, with messages naming the field
(``rulings.count: expected an integer >= 3, got "forty"``); the constructions of
:mod:`ruledmesh.rulings` get curves, arrays and numbers.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from .._files import MAX_CSV_BYTES, not_a_regular_file, read_capped
from .._validation import check_choice, check_int, check_keys, check_vector, describe
from ..curves import Curve
from ..errors import DesignError, GeometryError, ParameterError
from ..rulings import (
    BUILD_BYTES_PER_GRID_POINT,
    MAX_GENERATORS,
    Distribution,
    Rulings,
    between,
    check_line,
    conoid,
    from_lines,
    three_directrices,
)
from ..tolerances import DEFAULT, Tolerances

__all__ = ["from_csv", "rulings_from_spec"]

_SOURCES = ("between", "lines", "file", "conoid")
_RULINGS_KEYS = ("between", "distribution", "director_plane", "directrix", "count", "lines",
                 "file", "conoid")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def from_csv(path: str | os.PathLike, *, tol: Tolerances = DEFAULT) -> Rulings:
    """Rulings from a CSV file with rows ``x0,y0,z0,x1,y1,z1``.

    A first line that is not numeric is a header; blank lines and lines
    starting with ``#`` are skipped.

    Raises
    ------
    DesignError
        The file cannot be read or a row is malformed; the message names the
        file and the line number, e.g. ``lines.csv: line 4: expected 6 numbers, got 5``.
    """
    name = os.fspath(path)
    try:
        text = read_capped(name, MAX_CSV_BYTES, "a CSV table of lines").decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise DesignError(f"cannot read the file: {reason}", None, name) from None
    rows = []
    first = True
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = [c.strip() for c in stripped.split(",")]
        try:
            values = [float(c) for c in cells]
        except ValueError:
            if first:
                first = False
                continue  # header
            # The cell's position, not its text: the message must not echo a file's content.
            bad = next(k for k, c in enumerate(cells, start=1) if not _is_number(c))
            raise DesignError(f"expected 6 numbers separated by commas; cell {bad} is not a "
                              "number", f"line {number}", name) from None
        first = False
        if len(values) != 6:
            raise DesignError(f"expected 6 numbers (x0,y0,z0,x1,y1,z1), got {len(values)}",
                              f"line {number}", name)
        if not all(math.isfinite(v) for v in values):
            raise DesignError("expected finite numbers, got NaN or infinity", f"line {number}",
                              name)
        rows.append(values)
    if len(rows) < 2:
        raise DesignError(f"expected at least 2 lines (rows), got {len(rows)}", None, name)
    try:
        return from_lines(np.asarray(rows).reshape(-1, 2, 3), tol=tol)
    except GeometryError as exc:
        raise GeometryError(f"{name}: {exc}") from None


def _too_many(n: int, what: str, where: str, err: type = DesignError) -> None:
    """Refuse ``n`` generators above :data:`MAX_GENERATORS`, saying what they would need."""
    if n > MAX_GENERATORS:
        need = n * 21 * BUILD_BYTES_PER_GRID_POINT / 2**30
        raise err(f"expected at most {MAX_GENERATORS} {what}, got {n}: meshing them would need "
                  f"about {need:.1f} GiB of memory at the default 20 rows "
                  f"(~{BUILD_BYTES_PER_GRID_POINT} bytes per generator and row)", where)


class _Table:
    """The ``[rulings]`` table: its keys checked, errors naming ``path.key``."""

    def __init__(self, spec: Mapping, curves: Mapping[str, Curve], path: str):
        self.spec, self.curves, self.path = spec, curves, path

    def field(self, key: str) -> str:
        return f"{self.path}.{key}"

    def refuse(self, *keys: str, why: str) -> None:
        for key in keys:
            if key in self.spec:
                raise DesignError(f"not used {why}", self.field(key))

    def curve(self, name: Any, where: str) -> Curve:
        if not isinstance(name, str):
            raise DesignError(f"expected the name of a [curves.*] table, got {describe(name)}", where)
        if name not in self.curves:
            defined = ", ".join(self.curves) if self.curves else "none"
            raise DesignError(f'no curve named "{name}" (defined: {defined})', where)
        return self.curves[name]

    def count(self) -> int:
        if "count" not in self.spec:
            raise DesignError("missing; expected an integer >= 3 (the number of generators)",
                              self.field("count"))
        n = check_int(self.spec["count"], self.field("count"), lo=3, err=DesignError)
        _too_many(n, "generators", self.field("count"))
        return n


def _lines(t: _Table) -> Rulings:
    raw = t.spec["lines"]
    try:
        arr = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.ndim != 3 or arr.shape[1:] != (2, 3) or len(arr) < 2:
        raise DesignError(f"expected at least 2 lines [[x, y, z], [x, y, z]], got {describe(raw)}",
                          t.field("lines"))
    if not np.all(np.isfinite(arr)):
        raise DesignError("expected finite coordinates, got NaN or infinity", t.field("lines"))
    _too_many(len(arr), "lines", t.field("lines"))
    return from_lines(arr)


def _file(t: _Table, base_dir: str | os.PathLike) -> Rulings:
    fname = t.spec["file"]
    if not isinstance(fname, str) or not fname:
        raise DesignError(f"expected a file name, got {describe(fname)}", t.field("file"))
    full = os.path.join(os.fspath(base_dir), fname)
    if not os.path.exists(full):
        raise DesignError(f'no such file "{fname}" (looked in {os.fspath(base_dir)})',
                          t.field("file"))
    kind = not_a_regular_file(full)
    if kind is not None:
        raise DesignError(f'"{fname}" is {kind}, not a CSV table of lines; give a regular file',
                          t.field("file"))
    rulings = from_csv(full)
    _too_many(len(rulings), "lines (rows)", t.field("file"))
    return rulings


def _conoid(t: _Table) -> Rulings:
    t.refuse("distribution", "director_plane", "directrix",
             why="with conoid (give directrix and director_plane inside the conoid table)")
    table = t.spec["conoid"]
    cpath = t.field("conoid")
    if not isinstance(table, Mapping):
        raise DesignError(f"expected a table {{ curve, directrix, director_plane }}, got "
                          f"{describe(table)}", cpath)
    check_keys(table, ("curve", "directrix", "director_plane"), cpath, err=DesignError)
    for key in ("curve", "directrix", "director_plane"):
        if key not in table:
            raise DesignError("missing", f"{cpath}.{key}")
    c = t.curve(table["curve"], f"{cpath}.curve")
    d = check_line(table["directrix"], f"{cpath}.directrix", err=DesignError)
    n = check_vector(table["director_plane"], f"{cpath}.director_plane", nonzero=True,
                     err=DesignError)
    return conoid(c, d, n, t.count())


def _between(t: _Table) -> Rulings:
    names = t.spec["between"]
    bpath = t.field("between")
    if isinstance(names, str) or not isinstance(names, (list, tuple)) or len(names) not in (2, 3):
        raise DesignError(f"expected two or three curve names, got {describe(names)}", bpath)
    cs = [t.curve(nm, bpath) for nm in names]
    if len(cs) == 3:
        t.refuse("distribution", "director_plane", "directrix",
                 why="with three directrices (the lines meeting all three are the generators)")
        return three_directrices(cs[0], cs[1], cs[2], t.count())
    dist = check_choice(t.spec.get("distribution", "arc-length"), Distribution,
                        t.field("distribution"), err=DesignError)
    plane = directrix = None
    if dist is Distribution.DIRECTOR_PLANE:
        t.refuse("directrix", why='with distribution "director-plane"')
        if "director_plane" not in t.spec:
            raise DesignError('missing; expected the normal [x, y, z] of the director plane for '
                              'distribution "director-plane"', t.field("director_plane"))
        plane = check_vector(t.spec["director_plane"], t.field("director_plane"), nonzero=True,
                             err=DesignError)
    elif dist is Distribution.LINEAR_DIRECTRIX:
        t.refuse("director_plane", why='with distribution "linear-directrix"')
        if "directrix" not in t.spec:
            raise DesignError('missing; expected two points [[x, y, z], [x, y, z]] of the line d '
                              'for distribution "linear-directrix"', t.field("directrix"))
        directrix = check_line(t.spec["directrix"], t.field("directrix"), err=DesignError)
    else:
        t.refuse("director_plane", "directrix", why=f'with distribution "{dist.value}"')
    return between(cs[0], cs[1], t.count(), dist, director_plane=plane, directrix=directrix)


def rulings_from_spec(spec: Mapping, curves: Mapping[str, Curve], *, path: str = "rulings",
                      base_dir: str | os.PathLike = ".") -> Rulings:
    """Build rulings from the ``[rulings]`` table of a design file.

    Parameters
    ----------
    spec : Mapping
        Exactly one of ``between`` (two or three curve names), ``lines``
        (list of ``[[x, y, z], [x, y, z]]``), ``file`` (CSV, relative to
        ``base_dir``) or ``conoid`` (table ``curve``, ``directrix``,
        ``director_plane``); with ``between`` of two curves ``distribution``
        (default ``"arc-length"``) and its ``director_plane`` or
        ``directrix``; ``count`` (>= 3) with ``between`` and ``conoid``.
    curves : Mapping[str, Curve]
        The design's ``[curves.*]``, by name.
    path : str
        Dotted path of the table for error messages.
    base_dir : path
        Directory that ``file`` is relative to.

    Raises
    ------
    DesignError
        With the dotted field path, e.g. ``rulings.count: expected an integer
        >= 3, got "forty"`` or ``rulings.between: no curve named "c3"
        (defined: c1, c2)``.
    GeometryError
        The table is well formed but the generators cannot be built.
    """
    if not isinstance(spec, Mapping):
        raise DesignError(f"expected a table, got {describe(spec)}", path)
    check_keys(spec, _RULINGS_KEYS, path, err=DesignError)
    given = [k for k in _SOURCES if k in spec]
    if not given:
        raise DesignError("expected one of between, lines, file or conoid", path)
    if len(given) > 1:
        raise DesignError(f"give only one of between, lines, file or conoid; also got {given[0]}",
                          f"{path}.{given[1]}")
    source = given[0]
    t = _Table(spec, curves, path)
    try:
        if source in ("lines", "file"):
            t.refuse("count", "distribution", "director_plane", "directrix",
                     why=f"with {source} (the generators are given)")
            return _lines(t) if source == "lines" else _file(t, base_dir)
        return _conoid(t) if source == "conoid" else _between(t)
    except ParameterError as exc:  # pragma: no cover - inputs are checked above
        raise DesignError(exc.detail, f"{path}.{exc.field}" if exc.field else path) from None
