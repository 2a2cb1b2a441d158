"""Cutting paths for a line-swept tool: a 4-axis hot-wire cutter.

A ruled surface is what a straight wire sweeps (paper §1: a hot wire
through foam, a diamond wire through stone).  A 4-axis cutter holds the wire
between two towers that move in two parallel planes, the *tower planes*;
each tower positions its end of the wire in its own plane.  For each
generator of the mesh, its intersections with the two planes are where the
two wire ends must be when the wire lies on that generator, so the sequence
of generators gives two synchronised 2-D paths: ``(X, Y)`` in the first
tower plane and ``(U, V)`` in the second.  Between two generators both
towers move linearly and together, so the wire sweeps the ruled strip with
exactly those two generators as edges (a bilinear patch, as close to the
design as the generators are dense).

Machine axes.  ``span`` is the mesh axis across the towers (the tower planes
are ``span = a`` and ``span = b``, ``a < b``; the XY tower stands at ``a``).
``up`` is the mesh axis the towers lift along (Y and V); the horizontal
tower axes (X and U) run along ``depth = up x span``, so that looking from
the UV tower towards the XY tower, X/U point right and Y/V up.  Coordinates
are shifted so the smallest X/U and Y/V are 0 (the work zero is the lower
front corner of the path); the shift is recorded in the outputs.

Kerf.  The wire melts a slot of width ``kerf`` centred on its path.  With
``kerf > 0`` each tower's path is offset by ``kerf / 2`` to ``kerf_side``:
``"left"`` or ``"right"`` of the direction of travel in the view above (X/U
right, Y/V up).  The designed surface then lies on the edge of the slot and
the material on the other side keeps its size: put the offset on the waste
side.  With ``kerf = 0`` (default) the wire centre runs on the surface.

G-code dialect: "XYUV", the RS-274 second linear pair used by 4-axis foam
cutters (GMFC, DevFoam, LinuxCNC and Mach3/4 foam configurations):
``G1 X.. Y.. U.. V.. F..``, absolute coordinates (``G90``), ``G21`` and
millimetres for metric meshes, ``G20`` and inches for imperial ones, the
wire heated with ``M3`` and switched off with ``M5`` (configurable: some
controllers use ``M8``/``M9``); lead-in, lead-out and safe rapids as
:mod:`.machine` describes, comments as ``;`` lines without G-code words.  GRBL-family boards
without U/V words need the axes renamed (e.g. U->Z, V->A).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from .._validation import check_float
from ..errors import GeometryError, ParameterError
from ..mesh import Mesh
from ..tolerances import DEFAULT, MITRE_FLOOR, TINY, Tolerances
from .machine import Machine, check, program
from .schedules import member_schedule

__all__ = ["AXES", "WirePath", "comment", "gcode", "path_table", "wire_paths"]

AXES = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True, eq=False)
class WirePath:
    """Synchronised tower paths for a 4-axis hot-wire cutter.

    Attributes
    ----------
    generator : (n,) int64
        The generator (``member_id``) each step puts the wire on, in cutting order.
    xy : (n, 2) float64
        Positions of the wire end in the first tower plane (X, Y), kerf applied.
    uv : (n, 2) float64
        Positions in the second tower plane (U, V), kerf applied.
    point_a, point_b : (n, 3) float64
        The generators' intersections with the two tower planes, in mesh coordinates.
    span, up, depth : str
        Mesh axes (``depth`` may carry a ``-`` sign).
    planes : (2,) float64
        Coordinates of the two tower planes along ``span``.
    shift : (2,) float64
        Subtracted from (depth, up) coordinates to put the work zero at the minimum.
    kerf : float
    kerf_side : str
    """

    generator: np.ndarray
    xy: np.ndarray
    uv: np.ndarray
    point_a: np.ndarray
    point_b: np.ndarray
    span: str
    up: str
    depth: str
    planes: np.ndarray
    shift: np.ndarray
    kerf: float
    kerf_side: str


def _offset_path(path: np.ndarray, distance: float) -> np.ndarray:
    """(n, 2): a polyline offset by ``distance`` to the left of its direction (mitred).

    Consecutive equal points (a tower standing still) keep the neighbours' normal.
    """
    if len(path) < 2 or distance == 0.0:
        return path.copy()
    d = np.diff(path, axis=0)
    ln = np.hypot(d[:, 0], d[:, 1])
    moving = ln > 0
    if not moving.any():
        return path.copy()
    t = np.where(moving[:, None], d / np.where(moving, ln, 1.0)[:, None], np.nan)
    # A standing segment borrows the direction of the nearest moving one before it (or after).
    idx = np.where(moving, np.arange(len(t)), -1)
    np.maximum.accumulate(idx, out=idx)
    first = int(np.flatnonzero(moving)[0])
    idx = np.where(idx < 0, first, idx)
    t = t[idx]
    n = np.stack([-t[:, 1], t[:, 0]], axis=1)
    before = np.vstack([n[:1], n])
    after = np.vstack([n, n[-1:]])
    m = before + after
    # Mitre: the offset corner lies distance away from both offset segments.
    scale = 1.0 + np.einsum("ij,ij->i", before, after)
    m = m / np.maximum(scale, MITRE_FLOOR)[:, None]
    return path + distance * m


def wire_paths(mesh: Mesh, *, span: str = "auto", up: str | None = None,
               planes: tuple[float, float] | None = None, kerf: float = 0.0,
               kerf_side: str = "left", tol: Tolerances = DEFAULT) -> WirePath:
    """Tower paths that put the wire on every generator of ``mesh`` in turn.

    Parameters
    ----------
    mesh : Mesh
        Its members grouped by ``member_id`` are the generators, cut in
        increasing ``member_id`` order.
    span : {"auto", "x", "y", "z"}
        Mesh axis across the towers; ``"auto"`` picks the axis the generators
        are least parallel to.
    up : {"x", "y", "z"}, optional
        Mesh axis of Y/V; default ``"z"`` (``"y"`` when ``span`` is ``"z"``).
    planes : (a, b), optional
        Positions of the tower planes along ``span``; default the mesh's extent.
    kerf : float
        Slot width of the wire, in mesh units (0: no compensation).
    kerf_side : {"left", "right"}
        Side of the offset, see the module notes.
    tol : Tolerances

    Returns
    -------
    WirePath

    Raises
    ------
    GeometryError
        No generators, or a generator parallel (within ``tol.degenerate``) to the
        tower planes, or meeting them farther than ``tol.far`` diagonals away.
    """
    if not isinstance(mesh, Mesh):
        raise ParameterError(f"expected a Mesh, got {type(mesh).__name__}", "mesh")
    table = member_schedule(mesh)
    if table["generator"].size == 0:
        raise GeometryError("the mesh has no generators (members) to cut along")
    p0 = np.stack([table["x0"], table["y0"], table["z0"]], axis=1)
    p1 = np.stack([table["x1"], table["y1"], table["z1"]], axis=1)
    d = p1 - p0
    dn = d / np.maximum(np.linalg.norm(d, axis=1), TINY)[:, None]
    if span == "auto":
        span = "xyz"[int(np.argmax(np.abs(dn).min(axis=0)))]
    if span not in AXES:
        raise ParameterError(f'expected "auto", "x", "y" or "z", got {span!r}', "span")
    if up is None:
        up = "y" if span == "z" else "z"
    if up not in AXES or up == span:
        raise ParameterError(f'expected an axis other than the span axis "{span}", got {up!r}', "up")
    if kerf_side not in ("left", "right"):
        raise ParameterError(f'expected "left" or "right", got {kerf_side!r}', "kerf_side")
    kerf = check_float(kerf, "kerf", lo=0.0)
    w, h = AXES[span], AXES[up]
    depth_vec = np.cross(np.eye(3)[h], np.eye(3)[w])
    di = int(np.flatnonzero(depth_vec)[0])
    dsign = float(depth_vec[di])

    parallel = np.abs(dn[:, w]) <= tol.degenerate
    if parallel.any():
        bad = table["generator"][parallel]
        raise GeometryError(
            f"{bad.size} generators are parallel to the tower planes ({span} = const), so the wire "
            f"cannot lie on them (first: generator {int(bad[0])}); choose another span axis "
            f"(the generators are least parallel to the {'xyz'[int(np.argmax(np.abs(dn).min(axis=0)))]} "
            "planes) or rotate the mesh")
    lo, hi = mesh.bounding_box()
    if planes is None:
        planes = (lo[w], hi[w])
    if isinstance(planes, str) or np.ndim(planes) != 1 or len(planes) != 2:
        raise ParameterError(f"expected two positions (a, b), got {planes!r}", "planes")
    a = check_float(planes[0], "planes")
    b = check_float(planes[1], "planes")
    if not a < b:
        raise ParameterError(f"expected a < b, got ({a:g}, {b:g})", "planes")
    s_a = (a - p0[:, w]) / d[:, w]
    s_b = (b - p0[:, w]) / d[:, w]
    pa = p0 + s_a[:, None] * d
    pb = p0 + s_b[:, None] * d
    pa[:, w], pb[:, w] = a, b
    diag = mesh.diagonal() or 1.0
    centre = 0.5 * (lo + hi)
    far = np.maximum(np.linalg.norm(pa - centre, axis=1), np.linalg.norm(pb - centre, axis=1)) > tol.far * diag
    if far.any():
        raise GeometryError(
            f"{int(far.sum())} generators are so nearly parallel to the tower planes that the wire "
            f"ends would be over {tol.far:g} mesh diagonals away (first: generator "
            f"{int(table['generator'][far][0])}); choose another span axis or rotate the mesh")
    xy = np.stack([dsign * pa[:, di], pa[:, h]], axis=1)
    uv = np.stack([dsign * pb[:, di], pb[:, h]], axis=1)
    sign = 1.0 if kerf_side == "left" else -1.0
    xy = _offset_path(xy, sign * kerf / 2)
    uv = _offset_path(uv, sign * kerf / 2)
    shift = np.minimum(xy.min(axis=0), uv.min(axis=0))
    return WirePath(table["generator"], xy - shift, uv - shift, pa, pb, span, up,
                    ("-" if dsign < 0 else "") + "xyz"[di], np.array([a, b]), shift, kerf, kerf_side)


def path_table(path: WirePath) -> dict[str, np.ndarray]:
    """The path as table columns (for :func:`~ruledmesh.fabricate.schedules.csv_bytes`).

    Columns: ``step``, ``generator``, ``X``, ``Y``, ``U``, ``V`` (machine
    coordinates) and ``ax``, ``ay``, ``az``, ``bx``, ``by``, ``bz`` (the
    generator's points on the two tower planes, mesh coordinates, no kerf).
    """
    return {"step": np.arange(path.generator.size), "generator": path.generator,
            "X": path.xy[:, 0], "Y": path.xy[:, 1], "U": path.uv[:, 0], "V": path.uv[:, 1],
            "ax": path.point_a[:, 0], "ay": path.point_a[:, 1], "az": path.point_a[:, 2],
            "bx": path.point_b[:, 0], "by": path.point_b[:, 1], "bz": path.point_b[:, 2]}


def _minus(name: str, shift: float) -> str:
    return f"{name} {'minus' if shift >= 0 else 'plus'} {abs(shift):.10g}"


# A letter right before a digit is what G-code parsers read as a word (G1, M3, X0.5),
# even inside comments for some (gcodeparser); parentheses and ';' nest badly.
_WORDLIKE = re.compile(r"([A-Za-z])(?=[-+.]?\d)")


def comment(text: str) -> str:
    """A ``;`` comment line that no G-code parser reads as words.

    >>> comment("tower XY (left) at y=0.5; G1 moves")
    '; tower XY left at y=0.5, G 1 moves'
    """
    text = text.replace(";", ",").replace("(", "").replace(")", "")
    return "; " + _WORDLIKE.sub(r"\1 ", text).replace("  ", " ")


def gcode(path: WirePath, *, feed: float = 300.0, units: str = "mm", wire_on: str = "M3",
          wire_off: str = "M5", preheat: float = 1.0, decimals: int = 4,
          machine: Machine | None = None) -> str:
    """The path as a shop-ready XYUV G-code program (see :mod:`.machine`).

    Parameters
    ----------
    path : WirePath
    feed : float
        Feed rate in machine units per minute (``machine.feed`` when a machine is given).
    units : str
        Unit of the mesh coordinates (``"m"``, ``"cm"``, ``"mm"``, ``"in"``, ``"ft"``):
        coordinates are written in millimetres with ``G21`` (metric) or in
        inches with ``G20`` (imperial).
    wire_on, wire_off : str
        Commands heating the wire and switching it off.
    preheat : float
        Seconds to dwell (``G4 P``) after heating, before moving.
    decimals : int
    machine : Machine, optional
        Lead-in/out length and safe height; checked with :func:`.machine.check`.

    Raises
    ------
    GeometryError
        When the program does not fit ``machine``.
    """
    machine = Machine(feed=feed) if machine is None else machine
    preheat = check_float(preheat, "preheat", lo=0.0)
    prog = program(path, units, machine)
    check(prog, machine)
    f = f".{decimals}f"

    def move(word: str, rows: np.ndarray) -> list[str]:
        return [f"{word} X{x:{f}} Y{y:{f}} U{u:{f}} V{v:{f}}" for x, y, u, v in rows.tolist()]

    lines = [comment("ruledmesh hot-wire program, XYUV dialect: G1 with X Y U V and F"),
             comment(f"tower XY in plane {path.span} = {path.planes[0]:.10g}, tower UV in plane "
                     f"{path.span} = {path.planes[1]:.10g} mesh units"),
             comment(f"X and U along mesh {_minus(path.depth, path.shift[0])}, Y and V along mesh "
                     f"{_minus(path.up, path.shift[1])}, then shifted by the lead-in"),
             comment(f"kerf {path.kerf:g}, offset to the {path.kerf_side} of travel, "
                     f"{path.generator.size} generators, lead {prog.lead:g} {prog.unit}"),
             comment(f"needs travel {prog.extent()[0]:.1f} by {prog.extent()[1]:.1f} {prog.unit}, "
                     f"wire tilt up to {prog.tilt_deg:.1f} degrees"),
             "G90", "G21" if prog.unit == "mm" else "G20"]
    lines += move("G0", prog.rapid_in)
    lines.append(wire_on)
    if preheat:
        lines.append(f"G4 P{preheat:g}")
    cut = move("G1", prog.cut[1:])
    cut[0] += f" F{machine.feed:g}"
    lines += cut
    lines.append(wire_off)
    lines += move("G0", prog.rapid_out)
    lines.append("M30")
    return "\n".join(lines) + "\n"
