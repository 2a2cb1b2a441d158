"""Sheets: unrolled panels placed on rectangular sheets.

Two packers, chosen by ``method``:

* ``"true-shape"``: the panels' real outlines nested with free rotation by
  jagua-rs through ``spyrrow`` (:mod:`.true_shape`; optional extra
  ``nesting``); ``"auto"`` uses it when it is installed (the default of
  :func:`~ruledmesh.fabricate.output.fabricate`);
* ``"shelf"``: each panel turned to its smallest bounding box, laid on its
  long side (:func:`~ruledmesh.fabricate.unroll.min_area_rotation`), the
  boxes packed first-fit by decreasing height into horizontal shelves, a new
  sheet opening when no shelf has room.  It wastes the space between a panel
  and its box, but it is predictable, fast and needs nothing installed.

Panels never overlap, keep ``gap`` between them and from the sheet border,
and rotations are proper (no mirroring): every panel keeps the face
normal's side up.  The default gap is the cutter's diameter or kerf
(``tool``, default 3 mm in the mesh's units), not a fraction of the panels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import check_float
from ..errors import ParameterError
from ..progress import Progress
from ..tolerances import DEFAULT
from .unroll import Unrolled, corner_structure, min_area_rotation

__all__ = ["DEFAULT_TOOL_MM", "METHODS", "Layout", "auto_sheet", "default_gap", "layout"]


@dataclass(frozen=True, eq=False)
class Layout:
    """Unrolled panels placed on sheets.

    Attributes
    ----------
    unrolled : Unrolled
    points : (N, 2) float64
        Corners on their sheet (same layout as ``unrolled.points``); the sheet
        spans ``[0, width] x [0, height]`` with y up.
    sheet : (F,) int64
        Sheet of each panel (0-based).
    rotation : (F,) float64
        Rotation (radians, counter-clockwise) applied to each unrolled panel.
    offset : (F, 2) float64
        Translation applied after the rotation.
    box : (F, 2) float64
        Width and height of each placed panel's bounding box.
    sheet_size : (2,) float64
        Width and height of every sheet.
    n_sheets : int
    gap : float
        Clearance kept between panels and from the sheet border.
    method : str
        ``"true-shape"`` or ``"shelf"``: the packer that made the layout.
    """

    unrolled: Unrolled
    points: np.ndarray
    sheet: np.ndarray
    rotation: np.ndarray
    offset: np.ndarray
    box: np.ndarray
    sheet_size: np.ndarray
    n_sheets: int
    gap: float
    method: str = "shelf"

    def panel_area(self) -> float:
        """Total area of the panels."""
        off = self.unrolled.face_offsets
        if self.unrolled.n_faces == 0:
            return 0.0
        p = self.points
        _, nxt, _ = corner_structure(off)
        cross = p[:, 0] * p[nxt, 1] - p[nxt, 0] * p[:, 1]
        return float(np.abs(0.5 * np.add.reduceat(cross, off[:-1])).sum())

    def utilisation(self) -> float:
        """Panel area over the area of all sheets used (0 without panels)."""
        area = self.n_sheets * float(np.prod(self.sheet_size))
        return self.panel_area() / area if area else 0.0

    def utilisation_trimmed(self) -> float:
        """Like :meth:`utilisation`, the last sheet counted only up to its rightmost panel
        plus the gap (the rest is a reusable offcut): comparable to strip packing."""
        if self.n_sheets == 0:
            return 0.0
        last = self.panels_on(self.n_sheets - 1)
        off = self.unrolled.face_offsets
        xs = np.concatenate([self.points[off[f]:off[f + 1], 0] for f in last.tolist()])
        used = min(float(xs.max()) + self.gap, float(self.sheet_size[0]))
        area = float(np.prod(self.sheet_size)) * (self.n_sheets - 1) + used * float(self.sheet_size[1])
        return self.panel_area() / area

    def panels_on(self, s: int) -> np.ndarray:
        """(k,) int64: the faces placed on sheet ``s``."""
        return np.flatnonzero(self.sheet == s)

    def polygon(self, f: int) -> np.ndarray:
        """(k, 2) float64: corners of face ``f`` on its sheet."""
        off = self.unrolled.face_offsets
        return self.points[off[f]:off[f + 1]]


def auto_sheet(box: np.ndarray, gap: float) -> tuple[float, float]:
    """A square sheet that holds every panel and about all of them at once.

    Parameters
    ----------
    box : (F, 2) float64
        Panel bounding boxes (width, height).
    gap : float
    """
    padded = box + gap
    side = max(float(np.sqrt(np.prod(padded, axis=1).sum()) * 1.3), float(padded.max()) + 2 * gap)
    return side, side


# Cutter diameter (router bit, waterjet or laser kerf) assumed when none is given, in mm.
DEFAULT_TOOL_MM = 3.0
METHODS = ("auto", "true-shape", "shelf")


def default_gap(units: str = "m") -> float:
    """The default clearance: :data:`DEFAULT_TOOL_MM` in ``units``.

    >>> default_gap("mm"), default_gap("m")
    (3.0, 0.003)
    """
    from ..units import conversion_factor

    return DEFAULT_TOOL_MM * conversion_factor("mm", units)


def _boxes(unrolled: Unrolled) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Smallest-box rotation of each panel, the rotated corners, box minimum and size."""
    off = unrolled.face_offsets
    if unrolled.n_faces == 0:
        return np.zeros(0), unrolled.points, np.zeros((0, 2)), np.zeros((0, 2))
    face, _, _ = corner_structure(off)
    rot = min_area_rotation(unrolled.points, off)
    rp = _rotate(unrolled.points, rot[face])
    lo = np.stack([np.minimum.reduceat(rp[:, i], off[:-1]) for i in (0, 1)], axis=1)
    hi = np.stack([np.maximum.reduceat(rp[:, i], off[:-1]) for i in (0, 1)], axis=1)
    return rot, rp, lo, hi - lo


def _rotate(p: np.ndarray, angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]], axis=1)


def _check_fits(box: np.ndarray, gap: float, sw: float, sh: float) -> None:
    """Refuse panels too large for the sheet, naming them and the sheet that would fit."""
    from .labels import panel_labels

    long, short = box.max(axis=1), box.min(axis=1)
    big_side, small_side = max(sw, sh), min(sw, sh)
    bad = np.flatnonzero((long + 2 * gap > big_side) | (short + 2 * gap > small_side))
    if not bad.size:
        return
    names = panel_labels(len(box))
    listed = ", ".join(f"{names[f]} ({long[f]:.6g} x {short[f]:.6g})" for f in bad[:5].tolist())
    more = f" and {bad.size - 5} more" if bad.size > 5 else ""
    need = (float(long.max() + 2 * gap), float(short.max() + 2 * gap))
    count = "1 panel does" if bad.size == 1 else f"{bad.size} panels do"
    raise ParameterError(
        f"{count} not fit on a {sw:g} x {sh:g} sheet with gap {gap:.3g}: {listed}{more}; "
        f"the smallest sheet that fits every panel is {need[0]:.6g} x {need[1]:.6g}", "sheet")


def layout(unrolled: Unrolled, sheet: tuple[float, float] | None = None, *, gap: float | None = None,
           units: str = "m", method: str = "shelf", seconds: int = 2, seed: int = 0,
           progress: Progress | None = None) -> Layout:
    """Place the unrolled panels on sheets.

    Parameters
    ----------
    unrolled : Unrolled
    sheet : (width, height), optional
        Sheet size in mesh units; by default a square that takes every panel
        (:func:`auto_sheet`).
    gap : float, optional
        Clearance between panels and from the border; by default
        :func:`default_gap` (a 3 mm cutter) in ``units``.
    units : str
        The mesh unit (for the default gap).
    method : {"shelf", "true-shape", "auto"}
        Packer (see the module notes); ``"auto"``: true-shape when ``spyrrow``
        is installed.  The default here is the fast shelf packer; ``ruledmesh
        fabricate`` defaults to ``"auto"``.
    seconds : int
        Time budget of the true-shape solver per sheet (at least 1; a sheet
        takes one or two solves).
    seed : int
        Seed of the true-shape solver.
    progress : Progress, optional
        Told the panels placed, sheet by sheet (true-shape nesting).

    Returns
    -------
    Layout

    Raises
    ------
    ParameterError
        If a panel does not fit on the sheet even turned, naming the panels,
        their sizes and the smallest sheet that fits them all.
    """
    if method not in METHODS:
        raise ParameterError(f'expected "auto", "true-shape" or "shelf", got {method!r}', "method")
    nf = unrolled.n_faces
    rot, rp, lo, box = _boxes(unrolled)
    gap = check_float(default_gap(units) if gap is None else gap, "gap", lo=0.0)
    if sheet is None:
        sheet = auto_sheet(box, gap) if nf else (1.0, 1.0)
    if isinstance(sheet, str) or np.ndim(sheet) != 1 or len(sheet) != 2:
        raise ParameterError(f"expected (width, height), got {sheet!r}", "sheet")
    sw = check_float(sheet[0], "sheet", lo=0.0, lo_open=True)
    sh = check_float(sheet[1], "sheet", lo=0.0, lo_open=True)
    _check_fits(box, gap, sw, sh)
    if method == "auto":
        from .true_shape import available

        method = "true-shape" if available() and nf else "shelf"
    if method == "true-shape" and nf:
        lay = _true_shape(unrolled, gap, sw, sh, seconds, seed, progress)
        if lay is not None:
            return lay
    return _shelf(unrolled, rot, rp, lo, box, gap, sw, sh)


def _true_shape(unrolled: Unrolled, gap: float, sw: float, sh: float, seconds: int,
                seed: int, progress: Progress | None) -> Layout | None:
    """Nest with spyrrow sheet by sheet; None if the solver turned a panel wider than the sheet."""
    from .true_shape import nest_sheets

    off = unrolled.face_offsets
    face, _, _ = corner_structure(off)
    nested = nest_sheets(unrolled, sw - 2 * gap, sh - 2 * gap, gap, seconds=seconds, seed=seed,
                         progress=progress)
    if nested is None:
        return None
    offset = nested.translation + gap
    points = _rotate(unrolled.points, nested.rotation[face]) + offset[face]
    lo = np.stack([np.minimum.reduceat(points[:, i], off[:-1]) for i in (0, 1)], axis=1)
    hi = np.stack([np.maximum.reduceat(points[:, i], off[:-1]) for i in (0, 1)], axis=1)
    eps = DEFAULT.degenerate * max(sw, sh)
    if lo.min() < gap - eps or hi[:, 0].max() > sw - gap + eps or hi[:, 1].max() > sh - gap + eps:
        return None
    return Layout(unrolled, points, nested.sheet, nested.rotation, offset, hi - lo,
                  np.array([sw, sh]), int(nested.sheet.max()) + 1, gap, "true-shape")


def _shelf(unrolled: Unrolled, rot, rp, lo, box, gap: float, sw: float, sh: float) -> Layout:
    """The shelf packer of the module notes."""
    off = unrolled.face_offsets
    nf = unrolled.n_faces
    face, _, _ = corner_structure(off)
    hi = lo + box
    # A panel too wide for the sheet but fitting when stood up is turned by 90 degrees.
    too_wide = (box[:, 0] + 2 * gap > sw) & (box[:, 1] + 2 * gap <= sw) & (box[:, 0] + 2 * gap <= sh)
    if too_wide.any():
        rot = rot + np.where(too_wide, np.pi / 2, 0.0)
        lo = np.where(too_wide[:, None], np.stack([-hi[:, 1], lo[:, 0]], axis=1), lo)
        box = np.where(too_wide[:, None], box[:, ::-1], box)
        rp = _rotate(unrolled.points, rot[face])
    sheet_of = np.zeros(nf, dtype=np.int64)
    corner = np.zeros((nf, 2))
    # Shelves: sheet, y of the shelf's base, its height, and the x where it is free.
    sh_sheet: list[int] = []
    sh_y: list[float] = []
    sh_h: list[float] = []
    sh_x: list[float] = []
    top = [gap]  # y where the next shelf of each sheet would start
    # Sequential by nature (each placement depends on the previous ones); this is
    # layout, run once per export, not a per-face hot path.
    for f in np.lexsort((-box[:, 0], -box[:, 1])):
        w, h = box[f]
        for k in range(len(sh_x)):
            if sh_x[k] + w + gap <= sw and h <= sh_h[k]:
                break
        else:
            if top[-1] + h + gap > sh:
                top.append(gap)
            k = len(sh_x)
            sh_sheet.append(len(top) - 1)
            sh_y.append(top[-1])
            sh_h.append(h)
            sh_x.append(gap)
            top[-1] += h + gap
        sheet_of[f] = sh_sheet[k]
        corner[f] = (sh_x[k], sh_y[k])
        sh_x[k] += w + gap
    offset = corner - lo
    return Layout(unrolled, rp + offset[face], sheet_of, rot, offset, box,
                  np.array([sw, sh]), len(top) if nf else 0, gap, "shelf")
