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

__all__ = [
    "DEFAULT",
    "FLIP_ACTIVE_DEG",
    "FLIP_MAX_BEND_DEG",
    "FLIP_MAX_SAG",
    "FLIP_MIN_GAIN_DEG",
    "RESTART_ANGLE_DEG",
    "TINY",
    "Tolerances",
]


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

# Edge flips of the triangles a PQ mesh keeps (ruledmesh.pq.flips): a flip must
# raise the pair's smallest angle by this much (degrees), so rounds end; the two
# triangles may bend against each other by at most this angle before and after
# (a flip across a ridge would cut it off); and the new diagonal may lie at most
# this share of the patch diagonal off the old pair (the mesh keeps to the surface).
FLIP_MIN_GAIN_DEG = 1e-3
FLIP_MAX_BEND_DEG = 20.0
FLIP_MAX_SAG = 2.5e-4
# Only triangles with an angle below this (and their neighbours) are worth flipping.
FLIP_ACTIVE_DEG = 20.0

# A §4.3 face whose smallest angle is below this (degrees) counts as failing: runs
# end before such faces (ruledmesh.pq.runs).  The splinter bar of the analysis
# (ruledmesh.analysis.faces.SPLINTER_DEG); 4 deg cost 4 more points of triangle
# share at 301 x 300 for 24 fewer splinters out of 200 000 faces.
RESTART_ANGLE_DEG = 3.0
