"""True-shape nesting of the unrolled panels, through ``spyrrow`` (jagua-rs).

``spyrrow`` solves *strip packing*: place polygons (free rotation, no
mirroring, a minimum separation) in a strip of fixed height and the smallest
width.  Sheets come from one strip solve: the strip has the sheets' usable
height (sheet height minus the border gap on both sides); the first sheet
takes every panel that lies within the sheet's usable width from the
strip's left end, the next sheet starts at the leftmost panel not yet taken,
and so on.  Panels never move relative to each other, so the separation the
solver kept holds on every sheet; each sheet loses only the space left by
the panels pushed to the next one.

Requires the optional dependency ``spyrrow`` (``pip install 'ruledmesh[nesting]'``).
"""

from __future__ import annotations

import numpy as np

from .unroll import Unrolled, corner_structure

__all__ = ["available", "sheets_from_strip", "strip_pack"]


def available() -> bool:
    """True when ``spyrrow`` can be imported."""
    try:
        import spyrrow  # noqa: F401
    except ImportError:
        return False
    return True


def strip_pack(unrolled: Unrolled, height: float, gap: float, seconds: int = 4,
               seed: int = 0, workers: int | None = 1) -> tuple[np.ndarray, np.ndarray, float]:
    """Strip-pack every unrolled panel into a strip of ``height``.

    Parameters
    ----------
    unrolled : Unrolled
    height : float
        Strip height (mesh units).
    gap : float
        Minimum distance between panels.
    seconds : int
        Time budget of the solver (it may take up to about twice as long).
    seed : int
        Solver seed.
    workers : int, optional
        Solver threads (default 1, to share the machine; ``None``: all cores).
        The solver stops on time, so layouts can differ between runs.

    Returns
    -------
    rotation : (F,) float64
        Counter-clockwise rotation of each panel about its unrolled origin, radians.
    translation : (F, 2) float64
        Applied after the rotation.
    width : float
        Strip width used.
    """
    from ..io import require

    spyrrow = require("spyrrow", "nesting", "true-shape nesting")
    off = unrolled.face_offsets
    polys = np.split(unrolled.points, off[1:-1])
    items = [spyrrow.Item(str(f), [tuple(p) for p in poly.tolist()], demand=1,
                          allowed_orientations=None) for f, poly in enumerate(polys)]
    instance = spyrrow.StripPackingInstance("ruledmesh", strip_height=float(height), items=items)
    config = spyrrow.StripPackingConfig(total_computation_time=max(int(seconds), 1), seed=seed,
                                        num_workers=workers,
                                        min_items_separation=float(gap) if gap > 0 else None)
    solution = instance.solve(config)
    rotation = np.zeros(len(polys))
    translation = np.zeros((len(polys), 2))
    for placed in solution.placed_items:
        f = int(placed.id)
        rotation[f] = np.radians(placed.rotation)
        translation[f] = placed.translation
    return rotation, translation, float(solution.width)


def _placed(unrolled: Unrolled, rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    face, _, _ = corner_structure(unrolled.face_offsets)
    c, s = np.cos(rotation)[face], np.sin(rotation)[face]
    p = unrolled.points
    return np.stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]], axis=1) + translation[face]


def sheets_from_strip(unrolled: Unrolled, rotation: np.ndarray, translation: np.ndarray,
                      usable_width: float) -> tuple[np.ndarray, np.ndarray]:
    """Cut a strip layout into sheets of ``usable_width`` without moving panels apart.

    Returns
    -------
    sheet : (F,) int64
        Sheet of each panel.
    start : (S,) float64
        Strip x where each sheet's usable area begins.
    """
    off = unrolled.face_offsets
    pts = _placed(unrolled, rotation, translation)
    lo = np.minimum.reduceat(pts[:, 0], off[:-1])
    hi = np.maximum.reduceat(pts[:, 0], off[:-1])
    sheet = np.full(unrolled.n_faces, -1, dtype=np.int64)
    starts: list[float] = []
    # One step per sheet (a handful), each vectorised over the panels.
    while np.any(sheet < 0):
        free = sheet < 0
        s = float(lo[free].min())
        take = free & (hi <= s + usable_width * (1 + 1e-12))
        if not take.any():  # a panel turned wider than the sheet by the solver
            take = free & (lo == s)
        sheet[take] = len(starts)
        starts.append(s)
    return sheet, np.asarray(starts)
