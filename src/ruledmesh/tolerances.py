"""Tolerances, in one place.

All tolerances in ruledmesh are *relative*: a length is compared with a
characteristic size of the object it belongs to (the diagonal of the bounding
box, the length of a face's diagonal, ...), so results scale with the design.
Functions that use a tolerance take an optional ``tol`` argument; pass a
modified copy of :data:`DEFAULT` to override it for one call::

    >>> from dataclasses import replace
    >>> from ruledmesh.tolerances import DEFAULT
    >>> loose = replace(DEFAULT, planarity=1e-9)
    >>> loose.planarity
    1e-09
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Tolerances", "DEFAULT", "TINY"]


@dataclass(frozen=True)
class Tolerances:
    """Relative tolerances used across ruledmesh.

    Attributes
    ----------
    planarity : float
        A face is planar when its planarity measure (see
        :func:`ruledmesh.analysis.planarity`) is at most this.  Constructions
        in ruledmesh are planar by construction, so this is a rounding bound.
    on_surface : float
        A vertex lies on an analytic surface when its distance, divided by the
        diagonal of the mesh's bounding box, is at most this.
    circularity : float
        A quad is circular when its fourth vertex is this close (relative to
        the circumradius) to the circle through the other three.
    degenerate : float
        Relative size below which a length, area or determinant is treated as
        zero: a hop plane parallel to the next generator, coincident points, a
        torsal pair of generators.
    convexity : float
        Relative margin by which the diagonals' crossing must lie inside both
        diagonals for a quad to count as convex.
    far : float
        A vertex farther than ``far`` times the patch diagonal from the patch
        is never emitted (the row through it has run off towards infinity).
    """

    planarity: float = 1e-12
    on_surface: float = 1e-10
    circularity: float = 1e-10
    degenerate: float = 1e-9
    convexity: float = 1e-9
    far: float = 1e3


DEFAULT = Tolerances()

#: The positive floor a division by a length, area or norm is guarded with (``x / max(n, TINY)``).
#: Not a tolerance: far below any rounding level, it only keeps 0 / 0 out of the arrays.
TINY = 1e-300
