"""True-shape nesting of the unrolled panels, through ``spyrrow`` (jagua-rs).

``spyrrow`` solves *strip packing*: place polygons (free rotation, no
mirroring, a minimum separation) in a strip of fixed height and the smallest
width.  Sheets are filled one at a time (:func:`nest_sheets`): the next
panels, in face order (neighbouring faces have similar shapes), are taken
until their area is a little more than the next sheet is expected to hold
(the density of the previous solve), strip-packed at the sheet's usable
height, and the sheet keeps the panels that lie within its usable width; the
others go back to the front of the queue.  Each solve packs one sheet's
worth of panels, which the solver does better in a short time than one long
strip of all of them, and no sheet loses the space that cutting a finished
strip at sheet edges leaves behind (about one panel width per sheet, 10-14 %
on panels a fifth of the sheet wide).

Requires the optional dependency ``spyrrow`` (``pip install 'ruledmesh[nesting]'``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..progress import SILENT, Progress
from ..tolerances import ROUNDING, TINY
from .unroll import Unrolled, corner_structure

__all__ = ["SheetNesting", "available", "nest_sheets", "panel_areas", "strip_pack"]

# First guess of the density a sheet reaches, before any solve has measured it.
_FIRST_DENSITY = 0.8
# Panel area given to a solve, relative to what the expected density fills.  Measured on
# 120 skew panels (1 s per solve): 1.0 -> 0.95 of the strip density, 1.05 -> 0.93,
# 1.1 -> 0.92, 1.2 -> 0.91; more overflow leaves more ragged sheet ends.
_OVERFILL = 1.0


def available() -> bool:
    """True when ``spyrrow`` can be imported."""
    try:
        import spyrrow  # noqa: F401
    except ImportError:
        return False
    return True


def panel_areas(unrolled: Unrolled) -> np.ndarray:
    """(F,) float64: area of every unrolled panel."""
    off = unrolled.face_offsets
    if unrolled.n_faces == 0:
        return np.zeros(0)
    p = unrolled.points
    _, nxt, _ = corner_structure(off)
    cross = p[:, 0] * p[nxt, 1] - p[nxt, 0] * p[:, 1]
    return np.abs(0.5 * np.add.reduceat(cross, off[:-1]))


def strip_pack(unrolled: Unrolled, height: float, gap: float, seconds: int = 4,
               seed: int = 0, workers: int | None = 1,
               faces: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, float]:
    """Strip-pack unrolled panels into a strip of ``height``.

    Parameters
    ----------
    unrolled : Unrolled
    height : float
        Strip height (mesh units).
    gap : float
        Minimum distance between panels.
    seconds : int
        Time budget of the solver, at least 1 (it may take a little longer).
    seed : int
        Solver seed.
    workers : int, optional
        Solver threads (default 1, to share the machine; ``None``: all cores).
        The solver stops on time, so layouts can differ between runs.
    faces : (k,) int64, optional
        The panels to pack (default all).

    Returns
    -------
    rotation : (k,) float64
        Counter-clockwise rotation of each packed panel about its unrolled
        origin, radians, in the order of ``faces``.
    translation : (k, 2) float64
        Applied after the rotation; the strip spans ``[0, width] x [0, height]``.
    width : float
        Strip width used.
    """
    from ..io import require

    spyrrow = require("spyrrow", "nesting", "true-shape nesting")
    off = unrolled.face_offsets
    faces = np.arange(unrolled.n_faces) if faces is None else np.asarray(faces, dtype=np.int64)
    pts = unrolled.points
    items = [spyrrow.Item(str(i), [tuple(p) for p in pts[off[f]:off[f + 1]].tolist()], demand=1,
                          allowed_orientations=None) for i, f in enumerate(faces.tolist())]
    instance = spyrrow.StripPackingInstance("ruledmesh", strip_height=float(height), items=items)
    config = spyrrow.StripPackingConfig(total_computation_time=max(int(seconds), 1), seed=seed,
                                        num_workers=workers,
                                        min_items_separation=float(gap) if gap > 0 else None)
    solution = instance.solve(config)
    rotation = np.zeros(faces.size)
    translation = np.zeros((faces.size, 2))
    for placed in solution.placed_items:
        i = int(placed.id)
        rotation[i] = np.radians(placed.rotation)
        translation[i] = placed.translation
    return rotation, translation, float(solution.width)


@dataclass(frozen=True, eq=False)
class SheetNesting:
    """Panels nested sheet by sheet (:func:`nest_sheets`).

    Attributes
    ----------
    sheet : (F,) int64
        Sheet of each panel.
    rotation : (F,) float64
        Counter-clockwise rotation of each panel about its unrolled origin.
    translation : (F, 2) float64
        Applied after the rotation, in the sheet's usable area
        ``[0, width] x [0, height]``.
    solves : int
        Strip-packing solves run.
    """

    sheet: np.ndarray
    rotation: np.ndarray
    translation: np.ndarray
    solves: int


def _x_extent(unrolled: Unrolled, faces: np.ndarray, rotation: np.ndarray,
              translation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Smallest and largest x of each placed panel in ``faces``."""
    off = unrolled.face_offsets
    val = np.diff(off)[faces]
    starts = np.concatenate([[0], np.cumsum(val)[:-1]])
    rep = np.repeat(np.arange(faces.size), val)
    p = unrolled.points[off[faces][rep] + np.arange(int(val.sum())) - starts[rep]]
    x = np.cos(rotation)[rep] * p[:, 0] - np.sin(rotation)[rep] * p[:, 1] + translation[rep, 0]
    return np.minimum.reduceat(x, starts), np.maximum.reduceat(x, starts)


def _prefix(area: np.ndarray, target: float) -> int:
    """How many leading panels of ``area`` it takes to exceed ``target`` (at least 1)."""
    return min(int(np.searchsorted(np.cumsum(area), target)) + 1, area.size)


def nest_sheets(unrolled: Unrolled, width: float, height: float, gap: float, *,
                seconds: int = 2, seed: int = 0,
                progress: Progress | None = None) -> SheetNesting | None:
    """Nest the panels on sheets whose usable area is ``width x height``, one sheet at a time.

    Parameters
    ----------
    unrolled : Unrolled
    width, height : float
        Usable sheet size (the sheet less the border gap on both sides).
    gap : float
        Minimum distance between panels.
    seconds : int
        Solver time budget per sheet (a sheet may take one more solve when
        the first left room).
    seed : int
    progress : Progress, optional
        Told the panels as their sheet is settled.

    Returns
    -------
    SheetNesting or None
        None when the solver turned a panel wider than the sheet (the caller
        falls back to another packer).
    """
    nf = unrolled.n_faces
    area = panel_areas(unrolled)
    sheet = np.full(nf, -1, dtype=np.int64)
    rotation = np.zeros(nf)
    translation = np.zeros((nf, 2))
    queue = np.arange(nf)
    density, solves, n_sheets = _FIRST_DENSITY, 0, 0
    capacity = width * height
    with (progress or SILENT).task("nesting", total=nf) as task:
        while queue.size:
            k = _prefix(area[queue], _OVERFILL * density * capacity)
            fill = _fill_one(unrolled, area, queue[:k], width, height, gap, seconds, seed)
            solves += 1
            if k < queue.size and fill.fits:
                fill, more = _second_try(unrolled, area, queue, fill, k, width, height, gap,
                                         seconds, seed)
                solves += more
            if fill.faces.size == 0:
                return None
            density = fill.density
            sheet[fill.faces], rotation[fill.faces] = n_sheets, fill.rotation
            translation[fill.faces] = fill.translation
            n_sheets += 1
            queue = queue[sheet[queue] < 0]
            task.advance(int(fill.faces.size), note=f"sheet {n_sheets}")
    return SheetNesting(sheet, rotation, translation, solves)


def _second_try(unrolled: Unrolled, area: np.ndarray, queue: np.ndarray, fill: _Fill, k: int,
                width: float, height: float, gap: float, seconds: int,
                seed: int) -> tuple[_Fill, int]:
    """A sheet that had room gets one more solve with as much more area as it left.

    Returns the better of the two fills and the number of solves run.  (A
    second solve after an overflow, with another seed, measured no better.)
    """
    k2 = _prefix(area[queue], _OVERFILL * area[fill.faces].sum() * width / fill.used)
    if k2 <= k:
        return fill, 0
    more = _fill_one(unrolled, area, queue[:k2], width, height, gap, seconds, seed)
    return (more if area[more.faces].sum() > area[fill.faces].sum() else fill), 1


@dataclass(frozen=True, eq=False)
class _Fill:
    """One sheet's solve: the panels kept, their placement, and what the solve showed."""

    faces: np.ndarray
    rotation: np.ndarray
    translation: np.ndarray
    fits: bool  # every panel given to the solve is kept
    used: float  # width the kept panels use
    density: float  # panel area over strip area of the whole solve


def _fill_one(unrolled: Unrolled, area: np.ndarray, faces: np.ndarray, width: float,
              height: float, gap: float, seconds: int, seed: int) -> _Fill:
    """Strip-pack ``faces`` and keep those within ``width`` of the strip's start."""
    rot, tr, used = strip_pack(unrolled, height, gap, seconds, seed, faces=faces)
    lo, hi = _x_extent(unrolled, faces, rot, tr)
    start = float(lo.min())
    keep = hi - start <= width * (1 + ROUNDING)
    tr = tr - np.array([start, 0.0])
    density = float(area[faces].sum()) / (max(used - start, TINY) * height)
    fits = bool(keep.all())
    return _Fill(faces[keep], rot[keep], tr[keep], fits, used - start if fits else width, density)
