"""Scale-free meshing: the meshers see their input centred and of unit size.

Every decision a mesher takes (is this pair coplanar, is this vertex on the border,
has this face collapsed) compares lengths with tolerances.  Relative tolerances
make most of them independent of the scale, but products of lengths (areas,
determinants, squared norms) overflow above about 1e77 and underflow below
1e-77, and absolute floors such as ``1e-300`` decide differently at different
scales.  So the entry points (:func:`ruledmesh.pq.pq_mesh`,
:func:`ruledmesh.skew.hybrid_mesh`, :func:`ruledmesh.skew.compound_mesh`)
mesh a copy of their input moved to the origin and scaled by a **power of two**
to a box whose longest side is in [1, 2), then map the vertices back.  Scaling by a power of two
is exact in binary floating point, so a design scaled by ``2**k`` gives the same
mesh, scaled, bit for bit; a translated design gives the same faces.

Inputs whose coordinates are beyond :data:`MAX_COORDINATE` (or whose extent is
below :data:`MIN_EXTENT`) are refused with a message naming that range: the
mesh, its analysis and every file format would meet overflow or underflow there.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np

from ._arrays import extent as _extent
from .errors import GeometryError
from .tolerances import MIN_EXTENT, MIN_RELATIVE_EXTENT

__all__ = ["MAX_COORDINATE", "MIN_EXTENT", "check_range", "normalised", "unit_frame"]

# |x| of any input coordinate.  The meshers and the mesh-only figures work in the
# unit frame at any scale; the closeness to the smooth surface is measured at the
# design's own scale, with products of four lengths (Gauss-Newton determinants),
# measured exact to 1e+-70; 1e+-60 leaves a margin.
MAX_COORDINATE = 1e60
# MIN_EXTENT and MIN_RELATIVE_EXTENT (the smallest extents accepted) live in tolerances.

F = TypeVar("F", bound=Callable[..., Any])


def check_range(points: np.ndarray, what: str = "the generators") -> tuple[float, float]:
    """Refuse coordinates outside the range ruledmesh meshes faithfully.

    Parameters
    ----------
    points : (n, 3) float64
        Finite points (already validated).
    what : str
        What the points are, for the message.

    Returns
    -------
    extent, largest : float
        The bounding-box diagonal and the largest absolute coordinate.

    Raises
    ------
    GeometryError
        Naming the accepted range.
    """
    largest = float(np.abs(points).max()) if points.size else 0.0
    if largest > MAX_COORDINATE:
        raise GeometryError(f"{what} reach {largest:.3g}; coordinates must lie within "
                            f"+-{MAX_COORDINATE:g} (scale the design, or move it nearer "
                            "the origin)")
    lo, hi = _extent(points)
    extent = float(np.linalg.norm(hi - lo))
    if 0.0 < extent < MIN_EXTENT:
        raise GeometryError(f"{what} span {extent:.3g}; the design must be at least "
                            f"{MIN_EXTENT:g} across (scale it up)")
    if 0.0 < extent < MIN_RELATIVE_EXTENT * largest:
        raise GeometryError(f"{what} span {extent:.3g} at {largest:.3g} from the origin: below "
                            f"the float64 resolution there ({MIN_RELATIVE_EXTENT:g} of the "
                            "distance); move the design nearer the origin")
    return extent, largest


def unit_frame(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre and power-of-two scale taking ``points`` to a box whose longest side is in [1, 2).

    Works for any finite points, even those spanning the whole float64 range
    (the half-sides are formed first, so nothing overflows).

    Returns
    -------
    centre : (3,) float64
        Middle of the bounding box.
    scale : float
        ``2**k``; ``(points - centre) / scale`` fits a box with longest side in [1, 2).
    """
    lo, hi = _extent(points)
    centre = 0.5 * lo + 0.5 * hi
    half = float(np.max(0.5 * hi - 0.5 * lo))
    if half == 0.0 or not math.isfinite(half):
        return np.zeros(3), 1.0
    return centre, math.ldexp(1.0, math.frexp(half)[1])


def normalised(fn: F) -> F:
    """Decorate a mesher ``fn(a, b, ...) -> Mesh`` to mesh in the unit frame of ``a`` and ``b``.

    Arguments that are not arrays of points are passed through; ``a`` and ``b``
    that do not form (n, 3) arrays of finite numbers go to ``fn`` untouched, so
    its own validation reports them.
    """

    @functools.wraps(fn)
    def wrapper(a: Any, b: Any, *args: Any, **kwargs: Any) -> Any:
        try:
            A = np.asarray(a, dtype=np.float64)
            B = np.asarray(b, dtype=np.float64)
        except (TypeError, ValueError):
            return fn(a, b, *args, **kwargs)
        pts = np.concatenate([A.reshape(-1, 3), B.reshape(-1, 3)]) if (
            A.ndim == 2 and B.ndim == 2 and A.shape[1:] == (3,) == B.shape[1:]) else None
        if pts is None or pts.size == 0 or not np.all(np.isfinite(pts)):
            return fn(a, b, *args, **kwargs)
        check_range(pts)
        centre, scale = unit_frame(pts)
        mesh = fn((A - centre) / scale, (B - centre) / scale, *args, **kwargs)
        return mesh.with_vertices(mesh.vertices * scale + centre)

    return wrapper  # type: ignore[return-value]
