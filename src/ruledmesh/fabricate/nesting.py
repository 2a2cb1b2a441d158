"""Sheets: unrolled panels placed on rectangular sheets by a shelf packer.

Each panel is first turned to its smallest bounding box, laid on its long
side (:func:`~ruledmesh.fabricate.unroll.min_area_rotation`); the boxes are
then packed first-fit by decreasing height into horizontal shelves, a new
sheet opening when no shelf has room.  Shelf packing wastes the space between
a panel and its box, but it is predictable, needs no optimiser, and panels
never overlap (their boxes do not, with ``gap`` between them).  Rotations
are proper (no mirroring): every panel keeps the face normal's side up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import check_float
from ..errors import ParameterError
from .unroll import Unrolled, corner_structure, min_area_rotation

__all__ = ["Layout", "layout", "auto_sheet"]


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


def layout(unrolled: Unrolled, sheet: tuple[float, float] | None = None, *, gap: float | None = None) -> Layout:
    """Place the unrolled panels on sheets.

    Parameters
    ----------
    unrolled : Unrolled
    sheet : (width, height), optional
        Sheet size in mesh units; by default a square that takes every panel
        (:func:`auto_sheet`).
    gap : float, optional
        Clearance between panels and from the border; by default 2 % of the
        largest panel dimension.

    Returns
    -------
    Layout

    Raises
    ------
    ParameterError
        If a panel does not fit on the sheet even turned by 90 degrees.
    """
    off = unrolled.face_offsets
    nf = unrolled.n_faces
    face, _, _ = corner_structure(off)
    rot = min_area_rotation(unrolled.points, off)
    c, s = np.cos(rot)[face], np.sin(rot)[face]
    p = unrolled.points
    rp = np.stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]], axis=1)
    lo = np.stack([np.minimum.reduceat(rp[:, 0], off[:-1]), np.minimum.reduceat(rp[:, 1], off[:-1])],
                  axis=1) if nf else np.zeros((0, 2))
    hi = np.stack([np.maximum.reduceat(rp[:, 0], off[:-1]), np.maximum.reduceat(rp[:, 1], off[:-1])],
                  axis=1) if nf else np.zeros((0, 2))
    box = hi - lo
    if gap is None:
        gap = 0.02 * float(box.max()) if nf else 0.0
    gap = check_float(gap, "gap", lo=0.0)
    if sheet is None:
        sheet = auto_sheet(box, gap) if nf else (1.0, 1.0)
    if isinstance(sheet, str) or np.ndim(sheet) != 1 or len(sheet) != 2:
        raise ParameterError(f"expected (width, height), got {sheet!r}", "sheet")
    sw = check_float(sheet[0], "sheet", lo=0.0, lo_open=True)
    sh = check_float(sheet[1], "sheet", lo=0.0, lo_open=True)

    # A panel too wide for the sheet but fitting when stood up is turned by 90 degrees.
    too_wide = (box[:, 0] + 2 * gap > sw) & (box[:, 1] + 2 * gap <= sw) & (box[:, 0] + 2 * gap <= sh)
    if too_wide.any():
        rot = rot + np.where(too_wide, np.pi / 2, 0.0)
        lo = np.where(too_wide[:, None], np.stack([-hi[:, 1], lo[:, 0]], axis=1), lo)
        box = np.where(too_wide[:, None], box[:, ::-1], box)
        c, s = np.cos(rot)[face], np.sin(rot)[face]
        rp = np.stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]], axis=1)
    big = np.flatnonzero((box[:, 0] + 2 * gap > sw) | (box[:, 1] + 2 * gap > sh))
    if big.size:
        f = int(big[0])
        raise ParameterError(f"panel {f} ({box[f, 0]:.6g} x {box[f, 1]:.6g} plus gap {gap:.3g}) "
                             f"does not fit on a {sw:g} x {sh:g} sheet", "sheet")

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
                  np.array([sw, sh]), len(top) if nf else 0, gap)
