"""Mesh quality of ruledmesh builds, measured from the OBJ files the CLI writes.

Usage::

    python benchmarks/quality.py                    # every surface of benchmarks/quality/
    python benchmarks/quality.py --large            # ... and the 300 x 300 ones
    python benchmarks/quality.py my.toml --json q.json
    python benchmarks/quality.py --only corner --keep out/
    python benchmarks/quality.py --baseline benchmarks/quality-before.json   # new (was old)

Each design is built with ``python -m ruledmesh.cli build DESIGN -o X.obj`` in a
subprocess; the OBJ is read back with the reader below and measured with the
code below, independently of ``ruledmesh.analysis``.  Only the *input* comes
from ruledmesh: the design's generators and a dense sampling of its smooth
ruled surface (``ruledmesh.design`` / ``ruledmesh.rulings``), which are what
the mesh is measured against.

Figures per surface (lengths relative to the diagonal of the smooth patch's
bounding box):

* faces by size (3, 4, 5+), area share of triangles and of non-quads;
* smallest corner angle over all faces (degrees), faces with an angle < 3 deg;
* planarity of quads: distance between the two diagonal lines divided by the
  mean diagonal length (the paper's measure); of 5+-gons: largest distance to
  the least-squares plane divided by the polygon's diameter; and the part of
  it beyond what rounding the coordinates to float64 can explain (far from
  the origin, half an ulp of 2.6e6 already bends a 1 m quad by ~1e-10);
* bow-ties: quads whose diagonals do not cross strictly inside both, and
  non-convex 5+-gons;
* degenerate faces: area <= 1e-9 x (longest edge)^2;
* distance of the vertices to the nearest *design* generator line, and to the
  nearest generator of the smooth surface (which admits generators the mesher
  inserted); the overshoot of vertices beyond the patch ``0 <= t <= 1``;
* for quadric line sets, the distance of the vertices to the quadric;
* coverage: mesh area / area of the smooth patch (a dense bilinear
  tessellation from a much finer generator sampling);
* slender share: the share of the patch where every exact face with a generator
  diagonal is at least a 10:1 panel, whatever the rows (the line through a point
  that meets the two neighbouring generators crosses its own at under 5.7 deg:
  nearly developable parts, the bands at torsal generators); what exact mode
  cannot put into quads of good shape;
* gap: the largest distance from a point of the smooth patch to the mesh
  (exact point-triangle distances), with the surface parameters (u, t) of the
  worst point.

A design may carry a ``# quality: ...`` comment line with flags: ``general``
(a general skew surface: the 25 % triangle-share bound applies in exact mode),
``near-developable``, ``large`` (only with ``--large``), ``quadric``.
``[mesh] planarity_tolerance`` marks a tolerance-mode design.  A build that
fails is reported with its error (``design-error`` for exit code 2) instead of
figures.  ``tests/test_quality.py`` asserts the bar on these figures.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import queue
import subprocess
import sys
import tempfile
import time
import tomllib
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

ROOT = Path(__file__).resolve().parents[1]
SURFACES = Path(__file__).resolve().parent / "quality"
EXTRA = (ROOT / "examples" / "skew.toml", ROOT / "examples" / "fig10-skew-surface.toml")

SPLINTER_DEG = 3.0          # a face with a smaller corner angle is a splinter
DEGENERATE = 1e-9           # area <= DEGENERATE * longest_edge**2 (as ruledmesh fabricate)
CROSS_MARGIN = 1e-9         # diagonals must cross inside (margin, 1 - margin) of both
# Planarity a face can get from writing its coordinates to float64 alone, per unit of
# (largest |coordinate| / face size): four corners each off by up to half an ulp.
ROUNDING = 4 * np.finfo(np.float64).eps
REF_GENERATORS = 1601       # generators of the dense reference sampling
REF_ROWS = 96               # divisions of each reference generator
GAP_U = 200                 # reference generators used as gap sample lines ...
GAP_T = 49                  # ... sampled at this many t; refined around the worst (max_gap)
EXIT_DESIGN_ERROR = 2


# --------------------------------------------------------------------------
# surfaces
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class Surface:
    """A design file to measure.

    Attributes
    ----------
    name : str
        File stem.
    path : Path
    description : str
        The file's first comment line.
    flags : frozenset of str
        From the ``# quality:`` line (``general``, ``near-developable``,
        ``large``, ``quadric``); ``tolerance`` is added for designs with
        ``[mesh] planarity_tolerance``.
    tolerance : float or None
        ``[mesh] planarity_tolerance`` of the design, if any.
    """

    name: str
    path: Path
    description: str = ""
    flags: frozenset = field(default_factory=frozenset)
    tolerance: float | None = None


def read_surface(path: str | os.PathLike) -> Surface:
    """The :class:`Surface` of a design file (description, flags, tolerance)."""
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    description = lines[0].lstrip("# ").strip() if lines and lines[0].startswith("#") else ""
    flags: set[str] = set()
    for line in lines:
        if line.startswith("# quality:"):
            flags.update(line.split(":", 1)[1].split())
    try:
        mesh = tomllib.loads(text).get("mesh", {})
    except tomllib.TOMLDecodeError:
        mesh = {}
    tol = mesh.get("planarity_tolerance") if isinstance(mesh, dict) else None
    if isinstance(tol, (int, float)) and not isinstance(tol, bool):
        flags.add("tolerance")
        tol = float(tol)
    else:
        tol = None
    return Surface(path.stem, path, description, frozenset(flags), tol)


def default_surfaces(large: bool = False) -> list[Surface]:
    """The designs of ``benchmarks/quality/`` and the two bundled skew examples."""
    out = [read_surface(p) for p in sorted(SURFACES.glob("*.toml"))]
    out += [read_surface(p) for p in EXTRA]
    out = [s if s.path.parent == SURFACES else _as_general(s) for s in out]
    return [s for s in out if large or "large" not in s.flags]


def _as_general(s: Surface) -> Surface:
    return Surface(s.name, s.path, s.description, s.flags | {"general"}, s.tolerance)


# --------------------------------------------------------------------------
# building and reading
# --------------------------------------------------------------------------

@dataclass
class BuildResult:
    """Outcome of one ``ruledmesh build``: exit code, wall time, messages."""

    returncode: int
    seconds: float
    stdout: str
    stderr: str
    obj: Path


def _cli_env() -> dict[str, str]:
    env = dict(os.environ)
    src = str(ROOT / "src")
    env["PYTHONPATH"] = src + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env


def build(design: Path, obj: Path, timeout: float = 900.0) -> BuildResult:
    """Run ``python -m ruledmesh.cli build design -o obj`` and time it."""
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "ruledmesh.cli", "build", str(design), "-o",
                           str(obj)], capture_output=True, text=True, timeout=timeout, env=_cli_env(),
                          check=False)
    return BuildResult(proc.returncode, time.perf_counter() - t0, proc.stdout, proc.stderr, obj)


# A worker of BuildPool: one design path and OBJ path per line in, one JSON result per line
# out; each build runs the command line's own entry point with its output captured.
_WORKER = """
import contextlib, io, json, os, sys, time
# The results go out on a copy of stdout; anything written to file descriptor 1 itself
# (below Python's sys.stdout) goes to stderr, not into the results.
results = os.fdopen(os.dup(1), "w")
os.dup2(2, 1)
from ruledmesh.cli import main
for line in sys.stdin:
    design, obj = json.loads(line)
    out, err = io.StringIO(), io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(["build", design, "-o", obj])
        except SystemExit as exc:
            rc = 0 if exc.code is None else exc.code if isinstance(exc.code, int) else 1
        except BaseException as exc:
            print(f"{type(exc).__name__}: {exc}", file=sys.stderr)
            rc = 3
    seconds = time.perf_counter() - t0
    results.write(json.dumps([rc, seconds, out.getvalue(), err.getvalue()]) + "\\n")
    results.flush()
"""


class BuildPool:
    """``ruledmesh build`` of many designs in ``jobs`` long-lived worker processes.

    Each worker runs the command line's entry point (``ruledmesh.cli.main``) in-process for
    one design after another, so the interpreter's start and the imports (about 2 s a
    build, most of a small design's time) are paid once per worker; the build times then
    leave them out.  A worker that dies is replaced for the next design.
    """

    def __init__(self, jobs: int) -> None:
        self._idle: queue.Queue[subprocess.Popen] = queue.Queue()
        for _ in range(jobs):
            self._idle.put(self._start())
        self._threads = ThreadPoolExecutor(jobs)

    @staticmethod
    def _start() -> subprocess.Popen:
        return subprocess.Popen([sys.executable, "-c", _WORKER], stdin=subprocess.PIPE,
                                stdout=subprocess.PIPE, text=True, env=_cli_env())

    def submit(self, design: Path, obj: Path) -> Future:
        """Start building ``design`` into ``obj``; the future gives its :class:`BuildResult`."""
        return self._threads.submit(self._build, design, obj)

    def _build(self, design: Path, obj: Path) -> BuildResult:
        proc = self._idle.get()
        assert proc.stdin is not None and proc.stdout is not None
        try:
            proc.stdin.write(json.dumps([str(design), str(obj)]) + "\n")
            proc.stdin.flush()
            line = proc.stdout.readline()
        except OSError:
            line = ""
        if not line:
            code = proc.wait()
            self._idle.put(self._start())
            return BuildResult(code or 1, 0.0, "", f"the build worker ended (exit {code})", obj)
        self._idle.put(proc)
        rc, seconds, out, err = json.loads(line)
        return BuildResult(rc, seconds, out, err, obj)

    def close(self) -> None:
        """Stop the workers (builds not started are dropped)."""
        self._threads.shutdown(cancel_futures=True)
        while not self._idle.empty():
            proc = self._idle.get()
            if proc.stdin is not None:
                proc.stdin.close()
            proc.wait()


@dataclass
class ObjMesh:
    """A polygon mesh read from OBJ.

    Attributes
    ----------
    vertices : (n, 3) float64
    faces : dict int -> (f_k, k) int64
        Faces grouped by size, 0-based vertex indices in boundary order.
    groups : dict int -> (f_k,) object
        The ``g`` group name each face was written under (``""`` for none).
    """

    vertices: np.ndarray
    faces: dict[int, np.ndarray]
    groups: dict[int, np.ndarray]


def read_obj(path: str | os.PathLike) -> ObjMesh:
    """Read ``v``, ``f`` and ``g`` statements of an OBJ file (``v/vt/vn`` forms, negative indices)."""
    text = Path(path).read_text(encoding="utf-8")
    vlines: list[str] = []
    flines: list[list[str]] = []
    fgroup: list[str] = []
    group = ""
    for line in text.splitlines():
        tag = line[:2]
        if tag == "v ":
            vlines.append(line[2:])
        elif tag == "f ":
            flines.append(line[2:].split())
            fgroup.append(group)
        elif tag == "g ":
            group = line[2:].strip()
    verts = np.array(" ".join(vlines).split(), dtype=np.float64).reshape(-1, 3)
    faces: dict[int, np.ndarray] = {}
    groups: dict[int, np.ndarray] = {}
    sizes = np.array([len(f) for f in flines], dtype=np.int64)
    garr = np.array(fgroup, dtype=object)
    for k in np.unique(sizes):
        sel = np.flatnonzero(sizes == k)
        toks = [t.split("/", 1)[0] for i in sel for t in flines[i]]
        idx = np.array(toks, dtype=np.int64).reshape(-1, int(k))
        faces[int(k)] = np.where(idx > 0, idx - 1, len(verts) + idx)
        groups[int(k)] = garr[sel]
    return ObjMesh(verts, faces, groups)


# --------------------------------------------------------------------------
# per-face measures (vectorised per face size)
# --------------------------------------------------------------------------

def _norm(x: np.ndarray) -> np.ndarray:
    return np.sqrt(np.einsum("...i,...i->...", x, x))


@dataclass
class FaceMeasures:
    """Measures of the faces of one size ``k``.

    Attributes
    ----------
    area : (f,) float64
        Norm of the vector area (exact for planar faces).
    min_angle : (f,) float64
        Smallest corner angle of each face, degrees (reflex corners count as
        ``360 - angle``).
    planarity : (f,) float64
        Quads: distance between the diagonal lines / mean diagonal length;
        triangles: 0; 5+-gons: largest distance to the least-squares plane /
        diameter.
    convex : (f,) bool
        Quads: the diagonals cross strictly inside both; 5+-gons: every corner
        turns the same way about the face normal; triangles: not degenerate.
    degenerate : (f,) bool
        ``area <= DEGENERATE * longest_edge ** 2``.
    size : (f,) float64
        The length the planarity is relative to: mean diagonal (quads),
        diameter (5+-gons), longest edge (triangles).
    """

    area: np.ndarray
    min_angle: np.ndarray
    planarity: np.ndarray
    convex: np.ndarray
    degenerate: np.ndarray
    size: np.ndarray


def quad_diagonals(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest points of the diagonal lines 0-2 and 1-3 of quads.

    Parameters
    ----------
    q : (f, 4, 3) float64
        Corners, preferably in coordinates local to each face.

    Returns
    -------
    s, t : (f,) float64
        Parameters of the closest points on 0->2 and on 1->3 (``nan`` for
        parallel diagonals).
    planarity : (f,) float64
        Distance between the diagonal lines / mean diagonal length.
    """
    d1 = q[:, 2] - q[:, 0]
    d2 = q[:, 3] - q[:, 1]
    w = q[:, 0] - q[:, 1]
    n = np.cross(d1, d2)
    nn = _norm(n)
    l1, l2 = _norm(d1), _norm(d2)
    par = nn <= 1e-14 * l1 * l2
    with np.errstate(invalid="ignore", divide="ignore"):
        gap = np.where(par, _norm(np.cross(w, d1)) / np.where(l1 > 0, l1, 1.0),
                       np.abs(np.einsum("ij,ij->i", w, n)) / np.where(par, 1.0, nn))
        # Closest points: p0 + s d1 = p1 + t d2 (least squares).
        a, b, c = l1 * l1, np.einsum("ij,ij->i", d1, d2), l2 * l2
        d, e = np.einsum("ij,ij->i", d1, w), np.einsum("ij,ij->i", d2, w)
        den = np.where(par, np.nan, a * c - b * b)
        s = (b * e - c * d) / den
        t = (a * e - b * d) / den
        plan = gap / np.maximum(0.5 * (l1 + l2), 1e-300)
    return s, t, plan


def face_measures(poly: np.ndarray) -> FaceMeasures:
    """:class:`FaceMeasures` of polygons of one size.

    Parameters
    ----------
    poly : (f, k, 3) float64
        Corners in boundary order.
    """
    f, k = poly.shape[:2]
    q = poly - poly.mean(axis=1, keepdims=True)       # local coordinates: no cancellation far out
    nxt, prv = np.roll(q, -1, axis=1), np.roll(q, 1, axis=1)
    vec = 0.5 * np.cross(q, nxt).sum(axis=1)
    area = _norm(vec)
    normal = vec / np.maximum(area, 1e-300)[:, None]
    e_out, e_in = nxt - q, prv - q
    cr = np.cross(e_out, e_in)
    ang = np.degrees(np.arctan2(_norm(cr), np.einsum("fki,fki->fk", e_out, e_in)))
    turn = np.einsum("fki,fi->fk", cr, normal)
    # A corner turning against the face normal is reflex.
    ang = np.where(turn < 0, 360.0 - ang, ang)
    edge = _norm(e_out)
    degenerate = area <= DEGENERATE * edge.max(axis=1) ** 2
    if k == 3:
        planarity = np.zeros(f)
        convex = ~degenerate
        size = edge.max(axis=1)
    elif k == 4:
        s, t, planarity = quad_diagonals(q)
        size = 0.5 * (_norm(q[:, 2] - q[:, 0]) + _norm(q[:, 3] - q[:, 1]))
        m = CROSS_MARGIN
        with np.errstate(invalid="ignore"):
            convex = (s > m) & (s < 1 - m) & (t > m) & (t < 1 - m)
    else:
        _, _, vt = np.linalg.svd(q)
        dist = np.abs(np.einsum("fki,fi->fk", q, vt[:, 2]))
        diam = _norm(q[:, :, None, :] - q[:, None, :, :]).max(axis=(1, 2))
        planarity = dist.max(axis=1) / np.maximum(diam, 1e-300)
        convex = np.all(turn > 0, axis=1) & ~degenerate
        size = diam
    return FaceMeasures(area, ang.min(axis=1), planarity, convex, degenerate, size)


# --------------------------------------------------------------------------
# the input: generators and the smooth patch (from ruledmesh, the input side)
# --------------------------------------------------------------------------

@dataclass
class Reference:
    """What a mesh of a ruled design is measured against.

    Attributes
    ----------
    a, b : (m, 3) float64
        The design's generators (t = 0 and t = 1 ends).
    grid : (N, T + 1, 3) float64
        Dense sampling of the smooth patch: ``N`` generators, ``T + 1``
        points from t = 0 to t = 1 on each.
    grid_u : (N,) float64
        Surface parameter of each dense generator.
    surface : object or None
        ``ruledmesh.rulings.RuledSurface`` (``a(u)``, ``b(u)``, rails with
        ``deriv``) for the nearest-generator search; None for explicit lines.
    from_lines : bool
        The generators were given as lines (the design's own set is exact).
    """

    a: np.ndarray
    b: np.ndarray
    grid: np.ndarray
    grid_u: np.ndarray
    surface: Any
    from_lines: bool

    @property
    def diagonal(self) -> float:
        """Diagonal of the bounding box of the smooth patch."""
        pts = self.grid.reshape(-1, 3)
        return float(_norm(pts.max(axis=0) - pts.min(axis=0)))

    def area(self) -> float:
        """Area of the dense bilinear tessellation (two triangles per cell)."""
        g = self.grid - self.grid.reshape(-1, 3).mean(axis=0)
        p00, p10, p01, p11 = g[:-1, :-1], g[1:, :-1], g[:-1, 1:], g[1:, 1:]
        return float(0.5 * (_norm(np.cross(p10 - p00, p11 - p00)).sum()
                            + _norm(np.cross(p11 - p00, p01 - p00)).sum()))


def reference_of(design: Path, n_ref: int = REF_GENERATORS, rows: int = REF_ROWS) -> Reference | None:
    """The generators and dense smooth patch of a ruled design; None for catalogue designs.

    The dense patch re-samples the design's rulings with ``n_ref`` generators
    (``between`` two curves and ``conoid``); for three directrices and explicit
    lines it evaluates the rulings' smooth surface at ``n_ref`` parameters.
    Designs with ``[[transform]]`` tables are not supported (None).
    """
    from ruledmesh.design import load_design
    from ruledmesh.design.curves import curve_from_spec
    from ruledmesh.design.rulings import rulings_from_spec

    d = load_design(design)
    data = d.data
    if "rulings" not in data or data.get("transform"):
        return None
    curves = {name: curve_from_spec(spec, f"curves.{name}")
              for name, spec in data.get("curves", {}).items()}
    spec = dict(data["rulings"])
    rulings = rulings_from_spec(spec, curves, base_dir=d.base_dir)
    lines = "lines" in spec or "file" in spec
    resample = "conoid" in spec or len(spec.get("between", ())) == 2
    t = np.linspace(0.0, 1.0, rows + 1)
    n_ref = max(n_ref, 4 * (len(rulings) - 1) + 1)          # well finer than the design
    if resample:
        dense = rulings_from_spec({**spec, "count": n_ref}, curves, base_dir=d.base_dir)
        ga, gb, gu = dense.a, dense.b, dense.u
    elif rulings.surface is not None:
        surf = rulings.surface
        gu = np.unique(np.concatenate([np.linspace(rulings.u[0], rulings.u[-1], n_ref), rulings.u]))
        ga, gb = surf.a(gu), surf.b(gu)
    else:                                   # no smooth surface: the generators' own strips
        gu = np.asarray(rulings.u)
        ga, gb = np.asarray(rulings.a), np.asarray(rulings.b)
    grid = ga[:, None, :] + t[None, :, None] * (gb - ga)[:, None, :]
    return Reference(np.asarray(rulings.a), np.asarray(rulings.b), grid, np.asarray(gu),
                     rulings.surface, lines)


def line_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, chunk: int = 4096) -> np.ndarray:
    """(n,) distance of each point ``p`` (n, 3) to the nearest of the lines ``a_i b_i`` (m, 3).

    The lines worth measuring are found per cell of a grid over the points: a
    line farther from the cell's centre than the nearest one plus twice the
    cell's reach (and a margin far above rounding) is farther from each of the
    cell's points too.  The nearest line of every point is among the others,
    whose distances are the same numbers as from all pairs (:func:`_line_pairs`).
    """
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)
    n, m = len(p), len(a)
    if n * m <= 64 * chunk or not (np.all(dd > 0) and np.isfinite(p).all() and np.isfinite(dd).all()):
        return _line_distance_all(p, a, d, dd, chunk)
    lo = p.min(axis=0)
    extent = float(_norm(p.max(axis=0) - lo))
    # About eight points a cell on a surface (the cells it meets grow as the square).
    h = max(extent / max(np.sqrt(n / 8.0), 1.0), 1e-300)
    cell = np.floor((p - lo) / h).astype(np.int64)
    keys, inv = np.unique(cell, axis=0, return_inverse=True)
    inv = inv.ravel()
    centre = lo + (keys + 0.5) * h
    reach = np.zeros(len(keys))
    np.maximum.at(reach, inv, _norm(p - centre[inv]))
    dc = _line_distance_table(centre, a, d, dd, chunk)                    # (cells, m)
    margin = 1e-9 * (extent + float(np.abs(p).max()) + float(np.abs(a).max()))
    near = dc <= (dc.min(axis=1) + 2.0 * reach + margin)[:, None]
    counts = near.sum(axis=1)
    lines = np.nonzero(near)[1]                                          # by cell, then line
    starts = np.cumsum(counts) - counts
    out = np.empty(n)
    order = np.argsort(inv, kind="stable")
    per = counts[inv[order]]
    step = max(1, (64 * chunk) // max(int(per.max()), 1))
    for s in range(0, n, step):
        pts = order[s:s + step]
        k = per[s:s + step]
        first = np.cumsum(k) - k
        rank = np.arange(int(k.sum())) - np.repeat(first, k)
        li = lines[np.repeat(starts[inv[pts]], k) + rank]
        r2 = _line_pairs(p[np.repeat(pts, k)], a[li], d[li], dd[li])
        out[pts] = np.sqrt(np.minimum.reduceat(r2, first))
    return out


def _line_pairs(p: np.ndarray, a: np.ndarray, d: np.ndarray, dd: np.ndarray) -> np.ndarray:
    """Squared distance of points ``p`` to lines ``(a, d)`` paired row by row: the arithmetic
    of :func:`_line_distance_all`, term for term."""
    w = p - a
    tt = np.einsum("ki,ki->k", w, d) / dd
    r = w - tt[:, None] * d
    return np.einsum("ki,ki->k", r, r)


def _line_distance_table(p: np.ndarray, a: np.ndarray, d: np.ndarray, dd: np.ndarray,
                         chunk: int) -> np.ndarray:
    """(n, m) distance of every point to every line."""
    out = np.empty((len(p), len(a)))
    for s in range(0, len(p), chunk):
        w = p[s:s + chunk, None, :] - a[None, :, :]            # (c, m, 3)
        tt = np.einsum("cmi,mi->cm", w, d) / dd
        r = w - tt[..., None] * d
        out[s:s + chunk] = np.sqrt(np.einsum("cmi,cmi->cm", r, r))
    return out


def _line_distance_all(p: np.ndarray, a: np.ndarray, d: np.ndarray, dd: np.ndarray,
                       chunk: int) -> np.ndarray:
    """:func:`line_distance` over all pairs (few points or lines, or degenerate input)."""
    out = np.empty(len(p))
    for s in range(0, len(p), chunk):
        # The square root is monotone: the nearest of the roots is the root of the nearest.
        out[s:s + chunk] = _line_distance_table(p[s:s + chunk], a, d, dd, chunk).min(axis=1)
    return out


def surface_generator_distance(p: np.ndarray, ref: Reference, iters: int = 100, starts: int = 8,
                               polish: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance of points to the nearest generator of the smooth surface, and its t.

    Starts from the nearest dense patch point and runs Gauss-Newton on the
    generator parameter ``u`` for ``min_u |p - A(u) - t*(u) (B(u) - A(u))|``
    (``t*`` the foot on the line), which converges quadratically for points on
    the surface (more slowly near the ends of the patch, hence up to ``iters`` steps).
    Near a cusp of a director curve every generator passes close to the cusp point,
    and that distance has a local minimum on each side of it: a point the first descent
    leaves off the surface is searched again from the next ``starts`` nearest patch
    points, and the nearest generator found is kept; with ``polish``, what is still off
    is searched once more by golden section on ``u`` around it.  A point counts as on
    a generator within ``1e-12`` of the diagonal or within the rounding of the
    coordinates, whichever is larger: far from the origin (a building in projected
    coordinates, 2.6e6 m) every vertex is "off" by its coordinates' last bits, and the
    searches for all of them took a minute without finding anything nearer.

    Returns
    -------
    dist : (n,) float64
    t : (n,) float64
        Line parameter of the foot (0 on c1, 1 on c2).
    length : (n,) float64
        Length of that generator between c1 and c2.
    """
    T = ref.grid.shape[1]
    tree = cKDTree(ref.grid.reshape(-1, 3))
    _, idx = tree.query(p)
    u = _generator_descent(p, ref.grid_u[idx // T].astype(float), ref, iters)
    dist, t, length = _foot(p, u, ref)
    settled = max(1e-12 * ref.diagonal, ROUNDING * float(np.abs(p).max(initial=0.0)))
    off = np.nonzero(dist > settled)[0]
    if len(off) and starts > 1:
        _, near = tree.query(p[off], k=starts + 1)
        for k in range(1, starts + 1):
            u_k = _generator_descent(p[off], ref.grid_u[near[:, k] // T].astype(float), ref, iters)
            _keep_nearer(p, off, u_k, ref, (u, dist, t, length))
    off = np.nonzero(dist > settled)[0]
    if len(off) and polish:
        # Where the foot moves fast along the generator as u changes (the waist of a
        # surface close to a cone), Gauss-Newton with t held crawls: a golden-section
        # search on u around what it found settles those points.
        h = 2.0 * float(np.max(np.diff(ref.grid_u)))
        _keep_nearer(p, off, _golden(p[off], u[off] - h, u[off] + h, ref), ref, (u, dist, t, length))
        # A golden section never takes the ends of its bracket: a point on the first or
        # last generator whose distance falls towards the end of the patch is measured there
        # too (a linear-directrix surface whose last generator carries vertices at 2.4e-4 of
        # the diagonal by the search, 9e-17 on it).
        off = np.nonzero(dist > settled)[0]
        for end in (ref.grid_u[0], ref.grid_u[-1]):
            _keep_nearer(p, off, np.full(len(off), float(end)), ref, (u, dist, t, length))
        # The few points still off: every dense generator tried, then a golden section
        # around the nearest (where the surface folds towards itself, the nearest patch
        # points can all lie on another sheet: 2.1e-4 of the diagonal by the search, 6e-17
        # from the generator the vertex is on).
        off = np.nonzero(dist > settled)[0][:_SCANNED]
        for k in off:
            row = np.broadcast_to(p[k], (len(ref.grid_u), 3))
            best = float(ref.grid_u[int(np.argmin(_foot(row, ref.grid_u.astype(float), ref)[0]))])
            near = _golden(p[k:k + 1], np.array([best - h]), np.array([best + h]), ref)
            _keep_nearer(p, np.array([k]), near, ref, (u, dist, t, length))
    return dist, t, length


# At most this many points a search leaves off the surface are searched over every dense
# generator (each costs a pass over the dense generators).
_SCANNED = 2000


def _keep_nearer(p: np.ndarray, off: np.ndarray, u_new: np.ndarray, ref: Reference,
                 found: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]) -> None:
    """Where the generator at ``u_new`` is nearer to ``p[off]``, take it into ``found``
    (``u``, distance, foot t, generator length; updated in place)."""
    u, dist, t, length = found
    d_new, t_new, l_new = _foot(p[off], u_new, ref)
    better = d_new < dist[off]
    sel = off[better]
    u[sel], dist[sel], t[sel], length[sel] = u_new[better], d_new[better], t_new[better], l_new[better]


def _golden(p: np.ndarray, lo: np.ndarray, hi: np.ndarray, ref: Reference, iters: int = 90
            ) -> np.ndarray:
    """Golden-section search of the generator nearest to each point ``p`` in ``[lo, hi]`` (clipped)."""
    lo = np.clip(lo, ref.grid_u[0], ref.grid_u[-1])
    hi = np.clip(hi, ref.grid_u[0], ref.grid_u[-1])
    g = (np.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = _foot(p, x1, ref)[0], _foot(p, x2, ref)[0]
    for _ in range(iters):
        left = f1 < f2
        hi = np.where(left, x2, hi)
        lo = np.where(left, lo, x1)
        x2n = np.where(left, x1, lo + g * (hi - lo))
        x1n = np.where(left, hi - g * (hi - lo), x2)
        f_new = _foot(p, np.where(left, x1n, x2n), ref)[0]
        f1, f2 = np.where(left, f_new, f2), np.where(left, f1, f_new)
        x1, x2 = x1n, x2n
    return 0.5 * (lo + hi)


def _generator_descent(p: np.ndarray, u: np.ndarray, ref: Reference, iters: int) -> np.ndarray:
    """Gauss-Newton on ``u`` from the starts ``u`` (n,), see :func:`surface_generator_distance`."""
    surf = ref.surface
    lo, hi = float(ref.grid_u[0]), float(ref.grid_u[-1])
    u = u.copy()
    # A point whose step left its u unchanged is at a fixed point: every later step would
    # start from the same u and compute the same step again.  So only the others are
    # iterated (most points settle in a few steps, a few take many), with the same stop
    # rule over all points: the u found are the same to the bit, for a fraction of the work.
    moving = np.arange(len(p))
    for _ in range(iters):
        um, pm = u[moving], p[moving]
        a, da = _rail_value_deriv(surf.rail_a, um)
        b, db = _rail_value_deriv(surf.rail_b, um)
        d = b - a
        w = pm - a
        t = np.einsum("ij,ij->i", w, d) / np.einsum("ij,ij->i", d, d)
        r = w - t[:, None] * d
        jac = -(da + t[:, None] * (db - da))                     # dr/du with t held (envelope)
        jj = np.einsum("ij,ij->i", jac, jac)
        step = -np.einsum("ij,ij->i", r, jac) / np.where(jj > 0, jj, 1.0)
        u_new = np.clip(um + step, lo, hi)
        done = np.all(np.abs(u_new - um) <= 1e-15)
        u[moving] = u_new
        moving = moving[u_new != um]
        if done:
            break
    return u


def _foot(p: np.ndarray, u: np.ndarray, ref: Reference) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance of ``p`` to the generator at ``u``, the foot's t and the generator's length."""
    a, b = ref.surface.a(u), ref.surface.b(u)
    d = b - a
    t = np.einsum("ij,ij->i", p - a, d) / np.einsum("ij,ij->i", d, d)
    return _norm(p - a - t[:, None] * d), t, _norm(d)


def _rail_value_deriv(rail: Any, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(rail.value(u), rail.deriv(u))``, through the rail's ``value_deriv`` where it has one
    (a curve's rail evaluates its correspondence once there, with the same numbers)."""
    both = getattr(rail, "value_deriv", None)
    return both(u) if both is not None else (rail.value(u), rail.deriv(u))


def quadric_distance(p: np.ndarray, ref: Reference) -> np.ndarray:
    """Distance estimate |Q| / |grad Q| of points to the quadric through the reference patch.

    The quadric is the least-squares null vector of the 10 monomials on the
    dense patch points (centred and scaled), so it is the design's quadric
    when the generators lie on one.  For explicit lines the points are on the
    lines themselves: the patch between them is interpolated, and an
    interpolated surface lies on no quadric (1e-8 of the diagonal off on a
    hyperboloid of 48 lines).
    """
    if ref.from_lines:
        t = np.linspace(0.0, 1.0, 9)[None, :, None]
        pts = (ref.a[:, None, :] + t * (ref.b - ref.a)[:, None, :]).reshape(-1, 3)
    else:
        pts = ref.grid.reshape(-1, 3)
    c = pts.mean(axis=0)
    s = float(np.abs(pts - c).max())

    def mono(x: np.ndarray) -> np.ndarray:
        X, Y, Z = x.T
        one = np.ones_like(X)
        return np.stack([X * X, Y * Y, Z * Z, X * Y, X * Z, Y * Z, X, Y, Z, one], axis=1)

    _, _, vt = np.linalg.svd(mono((pts - c) / s), full_matrices=False)
    q = vt[-1]
    x = (p - c) / s
    X, Y, Z = x.T
    val = mono(x) @ q
    grad = np.stack([2 * q[0] * X + q[3] * Y + q[4] * Z + q[6],
                     2 * q[1] * Y + q[3] * X + q[5] * Z + q[7],
                     2 * q[2] * Z + q[4] * X + q[5] * Y + q[8]], axis=1)
    return s * np.abs(val) / np.maximum(_norm(grad), 1e-300)


# --------------------------------------------------------------------------
# distance from the smooth patch to the mesh
# --------------------------------------------------------------------------

def point_triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(n,) exact distance from points ``p`` to triangles ``abc`` (all (n, 3), paired row by row).

    The closest point is found by the Voronoi regions of the vertices, edges
    and face (Ericson, *Real-Time Collision Detection*, 5.1.5), vectorised.
    """
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = np.einsum("ij,ij->i", ab, ap), np.einsum("ij,ij->i", ac, ap)
    bp = p - b
    d3, d4 = np.einsum("ij,ij->i", ab, bp), np.einsum("ij,ij->i", ac, bp)
    cp = p - c
    d5, d6 = np.einsum("ij,ij->i", ab, cp), np.einsum("ij,ij->i", ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(invalid="ignore", divide="ignore"):
        den = va + vb + vc
        v = np.where(den != 0, vb / den, 0.0)
        w = np.where(den != 0, vc / den, 0.0)
        q = a + v[:, None] * ab + w[:, None] * ac                  # inside the face
        # Edges (clamped projections); the face point is used only when inside.
        t_ab = np.clip(d1 / np.einsum("ij,ij->i", ab, ab), 0, 1)
        t_ac = np.clip(d2 / np.einsum("ij,ij->i", ac, ac), 0, 1)
        bc = c - b
        t_bc = np.clip(np.einsum("ij,ij->i", bc, bp) / np.einsum("ij,ij->i", bc, bc), 0, 1)
    inside = (va >= 0) & (vb >= 0) & (vc >= 0) & (den > 0)
    cands = [np.where(inside, _norm(p - q), np.inf)]
    for base, e, tt in ((a, ab, t_ab), (a, ac, t_ac), (b, bc, t_bc)):
        tt = np.nan_to_num(tt, nan=0.0)
        cands.append(_norm(p - base - tt[:, None] * e))
    return np.min(np.stack(cands), axis=0)


def _triangles(mesh: ObjMesh) -> np.ndarray:
    """(n, 3, 3) fan triangles of every face."""
    tris = [mesh.vertices[f[:, [0, j, j + 1]]] for k, f in mesh.faces.items() for j in range(1, k - 1)]
    return np.concatenate(tris) if tris else np.zeros((0, 3, 3))


def _bisect_large(tris: np.ndarray, target: float, max_rounds: int = 24) -> np.ndarray:
    """Split triangles at the midpoint of their longest edge until each radius <= ``target``.

    The pieces cover exactly the same points, so distances are unchanged; the
    search below only gets tighter bounding spheres.  Each round looks at the
    pieces the round before made only: a piece small enough stays so.
    """
    small = []
    for _ in range(max_rounds):
        cen = tris.mean(axis=1)
        big = _norm(tris - cen[:, None, :]).max(axis=1) > target
        if not big.any():
            break
        small.append(tris[~big])
        t = tris[big]
        e = _norm(t[:, [1, 2, 0]] - t)                        # edge i: corner i -> i + 1
        k = e.argmax(axis=1)
        rows = np.arange(len(t))
        p0, p1, p2 = t[rows, k], t[rows, (k + 1) % 3], t[rows, (k + 2) % 3]
        mid = 0.5 * (p0 + p1)
        tris = np.concatenate([np.stack([p0, mid, p2], 1), np.stack([mid, p1, p2], 1)])
    return np.concatenate(small + [tris])


def distance_to_mesh(p: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """(n,) exact distance from points to the nearest of the triangles (n_t, 3, 3).

    ``MeshDistance(tris)(p)``: to ask for several point sets, prepare the
    triangles once with :class:`MeshDistance`.
    """
    return MeshDistance(tris)(p)


class MeshDistance:
    """Exact distances from points to the nearest of triangles (n_t, 3, 3), prepared once.

    Large triangles are first bisected (same point set) to a few times the
    median size or 1/64 of the extent, whichever is smaller; then an upper
    bound from the triangles with the nearest centroids, then every triangle
    whose bounding sphere reaches within that bound, by classes of triangle
    size (so a few long slivers do not widen every query).  The bisection and
    the centroid trees depend on the triangles only: :func:`max_gap` asks twice.
    """

    def __init__(self, tris: np.ndarray) -> None:
        self.empty = len(tris) == 0
        if self.empty:
            return
        rad0 = _norm(tris - tris.mean(axis=1)[:, None, :]).max(axis=1)
        flat = tris.reshape(-1, 3)
        extent = float(_norm(flat.max(axis=0) - flat.min(axis=0)))
        # Pieces of at most twice the median size and 1/64 of the extent: meshes of a few
        # long strips (developable surfaces) otherwise make every triangle a candidate.
        self.tris = tris = _bisect_large(tris, min(2.0 * float(np.median(rad0)), extent / 64))
        cen = tris.mean(axis=1)
        rad = _norm(tris - cen[:, None, :]).max(axis=1)
        self.tree = cKDTree(cen)
        # Size classes a factor 4 apart, each with its own tree of centroids.
        cls = np.floor(np.log(np.maximum(rad, 1e-300) / max(rad.min(), 1e-300)) / np.log(4.0))
        self.classes = []
        for c in np.unique(cls):
            ids = np.flatnonzero(cls == c)
            self.classes.append((ids, cKDTree(cen[ids]), rad[ids].max()))

    def __call__(self, p: np.ndarray) -> np.ndarray:
        """(n,) distance of each point ``p`` (n, 3) to the nearest triangle."""
        if self.empty:
            return np.full(len(p), np.inf)
        tris = self.tris
        kk = min(4, len(tris))
        _, near = self.tree.query(p, k=kk)
        near = near.reshape(len(p), kk)
        ub = np.full(len(p), np.inf)
        for j in range(kk):
            tr = tris[near[:, j]]
            ub = np.minimum(ub, point_triangle_distance(p, tr[:, 0], tr[:, 1], tr[:, 2]))
        best = ub.copy()
        # Within a class, the k nearest centroids, k growing only for the points whose k-th
        # is still within reach.
        for ids, ctree, rmax in self.classes:
            todo, k, seen = np.arange(len(p)), 8, 0
            while todo.size:
                kk = min(k, len(ids))
                dist, nb = ctree.query(p[todo], k=kk)
                dist, nb = dist.reshape(len(todo), kk)[:, seen:], nb.reshape(len(todo), kk)[:, seen:]
                # The best distance so far bounds the answer: farther spheres cannot matter.
                ok = dist <= (best[todo] * (1 + 1e-9) + rmax)[:, None]
                counts = ok.sum(axis=1)
                pi = np.repeat(todo, counts)
                if pi.size:
                    tr = tris[ids[nb[ok]]]
                    d = point_triangle_distance(p[pi], tr[:, 0], tr[:, 1], tr[:, 2])
                    has = counts > 0                       # pairs come grouped by point
                    starts = (np.cumsum(counts) - counts)[has]
                    hit = todo[has]
                    best[hit] = np.minimum(best[hit], np.minimum.reduceat(d, starts))
                if kk == len(ids):
                    break
                todo, seen, k = todo[ok[:, -1]], kk, 4 * k
        return best


def patch_samples(ref: Reference, n_u: int = GAP_U) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points of the smooth patch where the gap is measured, with where they are.

    ``n_u`` dense generators sampled along their length, plus every dense
    generator's two end points (the borders on c1 and c2, where gaps open).

    Returns
    -------
    points : (n, 3) float64
    gen : (n,) int64
        Index of the dense generator (row of ``ref.grid``) of each point.
    t : (n,) float64
        Line parameter on it.
    """
    N = len(ref.grid)
    t = np.linspace(0.0, 1.0, GAP_T)
    iu = np.unique(np.linspace(0, N - 1, min(n_u, N)).round().astype(np.int64))
    gen = np.concatenate([np.repeat(iu, len(t)), np.arange(N), np.arange(N)])
    tt = np.concatenate([np.tile(t, len(iu)), np.zeros(N), np.ones(N)])
    return _on_generators(ref, gen, tt), gen, tt


def _on_generators(ref: Reference, gen: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points at parameter ``t`` on dense generators ``gen`` (exact: generators are straight)."""
    a, b = ref.grid[gen, 0], ref.grid[gen, -1]
    return a + t[:, None] * (b - a)


def max_gap(ref: Reference, tris: np.ndarray, worst: int = 12, fine: int = 12
            ) -> tuple[float, int, float]:
    """Largest distance from the smooth patch to the triangles, and where (generator, t).

    The coarse samples of :func:`patch_samples` find the region; around each
    of the ``worst`` largest, nine dense generators across one sample spacing
    either side are sampled ``fine`` times as densely in ``t``, so the maximum
    is found to a small fraction of the sample spacing.
    """
    pts, gen, tt = patch_samples(ref)
    to_mesh = MeshDistance(tris)
    gap = to_mesh(pts)
    N = len(ref.grid)
    du = max(1, int(np.ceil((N - 1) / max(GAP_U - 1, 1))))
    dt = 1.0 / (GAP_T - 1)
    top = np.argsort(gap)[::-1][:worst]
    off_u = np.unique(np.linspace(-du, du, 9).round().astype(np.int64))
    off_t = np.linspace(-dt, dt, 2 * fine + 1)
    g2 = np.clip(gen[top, None, None] + off_u[None, :, None], 0, N - 1)
    t2 = np.clip(tt[top, None, None] + off_t[None, None, :], 0.0, 1.0)
    g2, t2 = np.broadcast_arrays(g2, t2)
    g2, t2 = g2.ravel(), t2.ravel()
    gap2 = to_mesh(_on_generators(ref, g2, t2))
    allg = np.concatenate([gap, gap2])
    k = int(np.argmax(allg))
    where_g = np.concatenate([gen, g2])[k]
    where_t = np.concatenate([tt, t2])[k]
    return float(allg[k]), int(where_g), float(where_t)


# --------------------------------------------------------------------------
# one surface
# --------------------------------------------------------------------------

def measure(mesh: ObjMesh, ref: Reference | None, quadric: bool = False) -> dict[str, Any]:
    """The quality figures of a mesh (see the module docstring); JSON-ready."""
    per = {k: face_measures(mesh.vertices[f]) for k, f in mesh.faces.items() if len(f)}
    counts = {k: len(f) for k, f in mesh.faces.items()}
    area = {k: float(m.area.sum()) for k, m in per.items()}
    total = sum(area.values())
    out: dict[str, Any] = {
        "faces": sum(counts.values()),
        "triangles": counts.get(3, 0),
        "quads": counts.get(4, 0),
        "polygons_5plus": sum(n for k, n in counts.items() if k >= 5),
        "vertices": len(np.unique(np.concatenate([f.ravel() for f in mesh.faces.values()])))
        if mesh.faces else 0,
        "area": total,
        "triangle_area_share": area.get(3, 0.0) / total if total > 0 else None,
        "nonquad_area_share": (total - area.get(4, 0.0)) / total if total > 0 else None,
    }
    if not per:
        return out
    verts = mesh.vertices[np.unique(np.concatenate([f.ravel() for f in mesh.faces.values()]))]
    big = float(np.abs(verts).max())
    out.update(_angle_figures(mesh, per))
    out.update(_planarity_figures(per, big))
    out["bowties"] = int(np.count_nonzero(~per[4].convex)) if 4 in per else 0
    out["nonconvex_polygons"] = int(sum(np.count_nonzero(~m.convex) for k, m in per.items() if k >= 5))
    out["degenerate_faces"] = int(sum(np.count_nonzero(m.degenerate) for m in per.values()))
    groups = {}
    for k, g in mesh.groups.items():
        names, n = np.unique(g.astype(str), return_counts=True)
        for name, c in zip(names.tolist(), n.tolist()):
            groups[f"{k}:{name or '-'}"] = c
    out["groups"] = groups
    out["max_abs_coordinate"] = big
    if ref is not None:
        out.update(_against_reference(mesh, verts, total, ref, quadric))
    return out


def _angle_figures(mesh: ObjMesh, per: dict[int, FaceMeasures]) -> dict[str, Any]:
    """Smallest angle (and where), splinter counts, largest triangle aspect ratio."""
    out: dict[str, Any] = {}
    min_angle = np.concatenate([m.min_angle for m in per.values()])
    out["min_angle_deg"] = float(min_angle.min())
    k_worst = min(per, key=lambda k: float(per[k].min_angle.min()))
    i_worst = int(np.argmin(per[k_worst].min_angle))
    group = mesh.groups.get(k_worst)
    out["min_angle_at"] = {
        "centroid": mesh.vertices[mesh.faces[k_worst][i_worst]].mean(axis=0).tolist(),
        "size": k_worst, "group": str(group[i_worst]) if group is not None else ""}
    out["faces_below_3deg"] = int(np.count_nonzero(min_angle < SPLINTER_DEG))
    tri_angle = per[3].min_angle if 3 in per else np.zeros(0)
    out["triangles_below_3deg"] = int(np.count_nonzero(tri_angle < SPLINTER_DEG))
    out["triangles_below_5deg"] = int(np.count_nonzero(tri_angle < 5.0))
    if 3 in per:
        # Aspect ratio: longest edge / shortest altitude = longest^2 / (2 area).
        t = per[3]
        with np.errstate(divide="ignore"):
            aspect = t.size ** 2 / (2.0 * t.area)
        out["max_triangle_aspect"] = float(aspect.max()) if np.isfinite(aspect).all() else None
    return out


def _planarity_figures(per: dict[int, FaceMeasures], big: float) -> dict[str, Any]:
    """Largest planarity of quads, of 5+-gons, and beyond the coordinates' rounding."""
    out: dict[str, Any] = {}
    out["max_planarity_quads"] = float(per[4].planarity.max()) if 4 in per else 0.0
    poly = [m.planarity for k, m in per.items() if k >= 5]
    out["max_planarity_polygons"] = float(np.concatenate(poly).max()) if poly else 0.0
    out["max_planarity"] = max(out["max_planarity_quads"], out["max_planarity_polygons"])
    # Far from the origin the file's own rounding (half an ulp per coordinate) bends faces:
    # the planarity beyond what that rounding can explain.
    excess = [np.maximum(m.planarity - ROUNDING * big / np.maximum(m.size, 1e-300), 0.0)
              for k, m in per.items() if k >= 4]
    out["max_planarity_beyond_rounding"] = float(np.concatenate(excess).max()) if excess else 0.0
    return out


def _against_reference(mesh: ObjMesh, verts: np.ndarray, total: float, ref: Reference,
                       quadric: bool) -> dict[str, Any]:
    diag = ref.diagonal
    out: dict[str, Any] = {"diagonal": diag}
    out["patch_area"] = ref.area()
    out["coverage"] = total / out["patch_area"]
    gd = line_distance(verts, ref.a, ref.b) / diag
    out["max_design_generator_distance"] = float(gd.max())
    if ref.surface is not None and not ref.from_lines:
        sd, t, glen = surface_generator_distance(verts, ref)
        sd = np.minimum(sd / diag, gd)                         # design generators are generators
        out["max_generator_distance"] = float(sd.max())
        out["vertices_off_design_generators"] = int(np.count_nonzero(gd > 1e-9))
        beyond = np.maximum(np.maximum(-t, t - 1.0), 0.0) * glen
        out["max_overshoot"] = float(beyond.max() / diag)
    else:
        out["max_generator_distance"] = out["max_design_generator_distance"]
    if quadric:
        out["max_quadric_distance"] = float(quadric_distance(verts, ref).max() / diag)
    out["slender_share"] = slender_share(ref)
    gap, gen, tg = max_gap(ref, _triangles(mesh))
    out["max_gap"] = gap / diag
    out["max_gap_at"] = {"u": float(ref.grid_u[gen]), "t": tg,
                         "point": _on_generators(ref, np.array([gen]), np.array([tg]))[0].tolist()}
    return out


SLENDER_DEG = float(np.degrees(np.arcsin(0.1)))   # diagonals crossing under this: a 10:1 panel
SLENDER_GENERATORS = 401    # generators of the reference the slender share is measured on


def slender_share(ref: Reference, n: int = SLENDER_GENERATORS) -> float:
    """Share of the patch area where the exact faces of a PQ mesh with generator diagonals
    are at least 10 times as elongated as a square, whatever its rows.

    Such a face's other diagonal lies on the line through a point of its generator that
    meets the two neighbouring generators; where that line crosses the generator at less
    than :data:`SLENDER_DEG`, ``diameter**2 / (2 area) >= 1 / sin(angle) > 10``.  Measured
    on ``n`` generators of the smooth patch (the design's own for explicit lines), at the
    reference's points along each.
    """
    grid = ref.grid
    if len(grid) > n:
        grid = grid[np.unique(np.linspace(0, len(grid) - 1, n).round().astype(int))]
    if len(grid) < 3:
        return 0.0
    a, d = grid[:, :1, :], grid[:, -1:, :] - grid[:, :1, :]      # (N, 1, 3) lines
    p = grid[1:-1]                                               # points of the inner generators
    n_plane = np.cross(d[:-2], a[:-2] - p)                       # plane (p, previous generator)
    den = np.einsum("ijk,ijk->ij", n_plane, np.broadcast_to(d[2:], p.shape))
    num = np.einsum("ijk,ijk->ij", n_plane, p - a[2:])
    ok = np.abs(den) > 1e-14 * _norm(n_plane) * _norm(np.broadcast_to(d[2:], p.shape))
    q = a[2:] + np.where(ok, num / np.where(ok, den, 1.0), 0.0)[..., None] * d[2:]
    e = q - p
    g = np.broadcast_to(d[1:-1], p.shape)
    angle = np.degrees(np.arctan2(_norm(np.cross(e, g)), np.abs(np.einsum("ijk,ijk->ij", e, g))))
    angle = np.where(ok & (_norm(e) > 0), angle, 0.0)
    # Area around each point: the cells of the grid on both sides, halved.
    cell = 0.5 * _norm(np.cross(grid[1:, :-1] - grid[:-1, :-1], grid[:-1, 1:] - grid[:-1, :-1]))
    cell = np.pad(cell, ((0, 0), (0, 1))) + np.pad(cell, ((0, 0), (1, 0)))   # per point, along
    weight = 0.5 * (cell[:-1] + cell[1:])
    total = float(weight.sum())
    return float(weight[angle < SLENDER_DEG].sum()) / total if total > 0 else 0.0


def obj_path(s: Surface, workdir: Path) -> Path:
    """Where the OBJ of ``s`` is written in ``workdir`` (distinct for equal names in two folders)."""
    tag = hashlib.sha1(str(s.path.resolve()).encode()).hexdigest()[:8]
    return workdir / f"{s.path.stem}-{tag}.obj"


def run_surface(s: Surface, workdir: Path, res: BuildResult | None = None) -> dict[str, Any]:
    """Build one design through the CLI and measure it; a failed build is reported, not raised.

    ``res``: the result of :func:`build` run already (e.g. concurrently) into
    :func:`obj_path`.
    """
    obj = obj_path(s, workdir)
    if res is None:
        res = build(s.path, obj)
    row: dict[str, Any] = {"surface": s.name, "path": _relative(s.path, suffix=True),
                           "description": s.description,
                           "flags": sorted(s.flags), "tolerance": s.tolerance,
                           "build_seconds": round(res.seconds, 3), "returncode": res.returncode,
                           "warnings": [ln[len("warning: "):] for ln in res.stderr.splitlines()
                                        if ln.startswith("warning: ")]}
    if res.returncode != 0 or not obj.exists():
        err = [ln for ln in res.stderr.strip().splitlines() if ln.strip()]
        row["status"] = "design-error" if res.returncode == EXIT_DESIGN_ERROR else "build-failed"
        row["error"] = err[-1] if err else f"exit {res.returncode}"
        return row
    row["status"] = "ok"
    t0 = time.perf_counter()
    ref = reference_of(s.path)
    row.update(measure(read_obj(obj), ref, quadric="quadric" in s.flags))
    row["measure_seconds"] = round(time.perf_counter() - t0, 3)
    return row


# --------------------------------------------------------------------------
# report
# --------------------------------------------------------------------------

COLUMNS = (
    ("surface", "surface", "{}"),
    ("kind", "kind", "{}"),
    ("build s", "build_seconds", "{:.1f}"),
    ("F3/F4/F5+", None, None),
    ("tri area", "triangle_area_share", "{:.1%}"),
    ("slender", "slender_share", "{:.0%}"),
    ("non-quad area", "nonquad_area_share", "{:.1%}"),
    ("min angle", "min_angle_deg", "{:.3g}"),
    ("< 3 deg", "faces_below_3deg", "{}"),
    ("planarity", "max_planarity", "{:.1e}"),
    ("bow-ties", "bowties", "{}"),
    ("degen.", "degenerate_faces", "{}"),
    ("on gen.", "max_generator_distance", "{:.1e}"),
    ("coverage", "coverage", "{:.4f}"),
    ("gap", "max_gap", "{:.1e}"),
)


_SHORT = {"general": "gen", "near-developable": "near-dev", "quadric": "quadric", "large": "large"}


def _cell(row: dict, key: str | None, fmt: str | None) -> str:
    if key == "kind":
        tags = [_SHORT[f] for f in row.get("flags", ()) if f in _SHORT]
        tol = row.get("tolerance")
        return " ".join(tags + ([f"tol {tol:g}"] if tol is not None else []))
    if key is None:
        return f"{row.get('triangles', '')}/{row.get('quads', '')}/{row.get('polygons_5plus', '')}"
    value = row.get(key)
    if value is None:
        return "-"
    try:
        return fmt.format(value) if fmt else str(value)
    except (TypeError, ValueError):
        return str(value)


COMPARED = ("triangle_area_share", "min_angle_deg", "faces_below_3deg", "max_gap")


def markdown(rows: list[dict], before: dict[str, dict] | None = None) -> str:
    """The rows as a markdown table; failed builds as one line with the error.

    ``before``: rows of an earlier run by surface name; the compared figures
    then show ``new (was old)``.
    """
    head = "| " + " | ".join(c[0] for c in COLUMNS) + " |"
    sep = "|" + "|".join("---" for _ in COLUMNS) + "|"
    lines = [head, sep]
    for row in rows:
        old = (before or {}).get(row["surface"])
        if row.get("status") != "ok":
            msg = str(row.get("error", "")).replace("|", "\\|")
            lines.append(f"| {row['surface']} | {_cell(row, 'kind', None)} | "
                         f"{row['build_seconds']:.1f} | **{row['status']}**: {msg} |"
                         + " |" * (len(COLUMNS) - 4))
        else:
            cells = [_cell(row, k, f) for _, k, f in COLUMNS]
            if old is not None and old.get("status") == "ok":
                cells = [c + (f" (was {_cell(old, k, f)})" if k in COMPARED else "")
                         for c, (_, k, f) in zip(cells, COLUMNS)]
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _unique_names(surfaces: list[Surface]) -> list[Surface]:
    """Surfaces whose name another one shares are named by their path instead."""
    stems = [s.name for s in surfaces]
    return [s if stems.count(s.name) == 1 else
            Surface(_relative(s.path), s.path, s.description, s.flags, s.tolerance)
            for s in surfaces]


def _relative(path: Path, suffix: bool = False) -> str:
    """``path`` relative to the repository if inside it; without ``.toml`` unless ``suffix``."""
    try:
        rel = path.resolve().relative_to(ROOT)
    except ValueError:
        rel = path
    return str(rel if suffix else rel.with_suffix(""))


def _run_all(surfaces: list[Surface], work: Path, jobs: int) -> list[dict]:
    """Build and measure every surface; with ``jobs > 1`` builds run ahead in a :class:`BuildPool`."""
    pool = BuildPool(jobs) if jobs > 1 else None
    futures = [pool.submit(s.path, obj_path(s, work)) for s in surfaces] if pool else []
    rows = []
    for i, s in enumerate(surfaces):
        row = run_surface(s, work, futures[i].result() if pool else None)
        rows.append(row)
        print(f"{s.name}: {row['status']} ({row['build_seconds']:.1f} s build, "
              f"{row.get('measure_seconds', 0):.1f} s measure)", file=sys.stderr)
    if pool:
        pool.close()
    return rows


def main(argv: list[str] | None = None) -> int:
    """Command line: build and measure the surfaces, print a table, optionally write JSON."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n", 1)[0])
    p.add_argument("designs", nargs="*", help="more design files to measure")
    p.add_argument("--large", action="store_true", help="include the 300 x 300 surfaces")
    p.add_argument("--only", action="append", default=[],
                   help="measure only surfaces whose name contains this (repeatable)")
    p.add_argument("--no-defaults", action="store_true",
                   help="measure only the designs given on the command line")
    p.add_argument("--json", metavar="FILE", help="write the figures as JSON")
    p.add_argument("--keep", metavar="DIR", help="keep the OBJ files in DIR")
    p.add_argument("--baseline", metavar="FILE",
                   help="JSON of an earlier run: show its figures next to the new ones")
    p.add_argument("-j", "--jobs", type=int, default=1,
                   help="builds run at once (default 1: build times undisturbed)")
    args = p.parse_args(argv)
    surfaces = [] if args.no_defaults else default_surfaces(args.large)
    if args.only:
        surfaces = [s for s in surfaces if any(o in s.name for o in args.only)]
    surfaces += [_as_general(read_surface(d)) for d in args.designs]
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(args.keep) if args.keep else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        t0 = time.perf_counter()
        rows = _run_all(_unique_names(surfaces), work, args.jobs)
        total = time.perf_counter() - t0
    before = None
    if args.baseline:
        old = json.loads(Path(args.baseline).read_text(encoding="utf-8"))
        before = {r["surface"]: r for r in old.get("surfaces", [])}
    print(markdown(rows, before))
    print(f"\n{len(rows)} surfaces in {total:.0f} s")
    if args.json:
        doc = {"surfaces": rows, "seconds": round(total, 1),
               "thresholds": {"splinter_deg": SPLINTER_DEG, "degenerate": DEGENERATE,
                              "cross_margin": CROSS_MARGIN}}
        Path(args.json).write_text(json.dumps(doc, indent=2, allow_nan=False, default=_jsonable)
                                   + "\n", encoding="utf-8")
    return 0


def _jsonable(x: Any) -> Any:
    if isinstance(x, (np.integer, np.floating)):
        return x.item()
    raise TypeError(f"not JSON serialisable: {type(x).__name__}")


if __name__ == "__main__":
    sys.exit(main())
