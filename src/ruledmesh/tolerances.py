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

The module-level constants below are the fixed thresholds of the numerical
kernels (root finders, degeneracy tests, rounding slack).  They are not meant
to be changed per call; each says why it has its value.  A test
(``tests/test_tolerances.py``) keeps float literals of this kind out of the
other modules.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["BORDER_TRIM_MAX_GAP", "BRENTQ_XTOL", "CLOSENESS_SEARCH", "COLLAPSE_MAX_SAG",
           "COLLINEAR", "COLLINEAR_SQ", "CONGRUENCE_ANGLE_DEG", "CONVERGED", "COORDINATE_ROUNDING", "DEFAULT",
           "DEPTH_BIAS", "EVEN_MAX_ADDED", "EVEN_MAX_HALVINGS", "EVEN_PINCH_SHARE", "EVEN_PINCH_STEP_PER_WIDTH",
           "EVEN_STEP_PER_WIDTH", "FLAT_PAIR_MAX_SAG", "FLIP_ACTIVE_DEG", "FLIP_MAX_BEND_DEG",
           "FLIP_MAX_SAG", "FLIP_MIN_GAIN_DEG", "FLOAT32_WARNING", "INTERIOR", "KKT_REGULARISATION", "MIN_EXTENT",
           "MIN_HALF_ANGLE", "MIN_RELATIVE_EXTENT", "MITRE_FLOOR", "NEARLY_DEVELOPABLE",
           "OCCT_FACE", "ON_BORDER", "PARAMETER_SLACK", "PLANARITY_FLOOR", "RESTART_ANGLE_DEG",
           "ROOT_RTOL", "ROOT_XTOL", "ROUNDING", "ROUNDING_SQ", "SAME_ROOT", "SETTLED", "SNAP_GAP",
           "SLOPE_STEP", "SNAP_MIN_GAIN_DEG", "SPAN_HALVED_ABOVE", "SPAN_MAX_GAP", "SPLINTER_AREA_WORTH",
           "SPLINTER_FLIP_MAX_SAG",
           "TINY", "ULPS", "Tolerances"]


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


#: The tolerances every function uses unless given others (its ``tol`` argument).
DEFAULT = Tolerances()

#: The positive floor a division by a length, area or norm is guarded with (``x / max(n, TINY)``).
#: Not a tolerance: far below any rounding level, it only keeps 0 / 0 out of the arrays.
TINY = 1e-300

# --------------------------------------------------------------------------
# Rounding slack: values equal in exact arithmetic, compared after float64 work
# --------------------------------------------------------------------------

#: Relative slack for a computed value compared with a bound it equals in exact
#: arithmetic (a parameter at the end of [0, 1], a length against the width it
#: must fit, a full turn of 2 pi).  About 4500 ulps of a unit-size double: above
#: the rounding of the few dozen operations that produce such values, far below
#: any length a design can mean.
ROUNDING = 1e-12
#: :data:`ROUNDING` squared, for tests on products of two squared lengths
#: (``|u x w|**2 <= ROUNDING_SQ * |u|**2 |w|**2`` is ``sin(angle) <= ROUNDING``).
ROUNDING_SQ = 1e-24
#: What the rounding of its stored corners alone can make of a face's planarity, per unit of
#: (largest absolute coordinate / longest edge): each coordinate is stored to half an ulp
#: (2**-53 of it), a corner moves by up to sqrt(3) times that, the gap between the diagonals by
#: twice that, and a convex quad's mean diagonal is at least half its longest edge:
#: 4 sqrt(3) 2**-53 = 7.7e-16, rounded up.  Near the origin far below PLANARITY; building
#: coordinates 5e6 m out store a 1 m panel's corners to 9e-10 m (analysis.planar).
COORDINATE_ROUNDING = 1e-15
#: A few ulps of a unit-size number: values that differ only in their last digits
#: (a unit vector's component against 1, two sorted candidates, a Newton step).
ULPS = 1e-15
#: Relative distance or sine of an angle below which two directions are parallel
#: or a point lies on an axis, where the inputs carry a few operations of rounding
#: more than :data:`ULPS` allows (a profile point on the rotation axis, a sliver
#: triangle seen edge-on).
COLLINEAR = 1e-14
#: :data:`COLLINEAR` squared, for tests on ``|u x w|**2`` against ``|u|**2 |w|**2``.
COLLINEAR_SQ = 1e-28
#: Looser slack for a parameter found by iteration (Newton, a root solve) that
#: must lie in [0, 1]: the iteration stops at about 1e-12 relative, so a
#: thousandfold margin keeps every true in-range solution in range.
PARAMETER_SLACK = 1e-9
#: A Gauss-Newton step smaller than this (in parameter space) no longer moves the point:
#: the nearest-point search of the closeness analysis stops there.
SETTLED = 1e-13
#: The closeness analysis starts each vertex's descent at its own place on the patch (where
#: the mesher says it) and searches from samples too only where that ends farther than this
#: share of the diagonal (a face across a fold of the surface).  Most faces of a mesh of the
#: regression designs lie closer; the search costs 8-35 times the seeded descent.
CLOSENESS_SEARCH = 1e-4
#: Two roots of the same equation closer than this (in parameter space) are one root.
SAME_ROOT = 1e-8

# --------------------------------------------------------------------------
# Root finding
# --------------------------------------------------------------------------

#: Absolute parameter tolerance handed to brentq where the root should be found to
#: full precision (the parameters live in [0, 1], so this is below one ulp there).
ROOT_XTOL = 1e-16
#: Relative tolerance for those roots: scipy's brentq refuses anything below
#: ``4 * eps`` = 8.88e-16, and this is the smallest round number above it.
ROOT_RTOL = 8.9e-16
#: A Newton update smaller than this relative to the iterate (about two ulps)
#: changes only the last bits: the iteration has converged.
CONVERGED = 4e-16
#: Default absolute tolerance of :func:`ruledmesh.roots.brentq`, scipy's own default.
BRENTQ_XTOL = 2e-12

# --------------------------------------------------------------------------
# Sizes and clearances
# --------------------------------------------------------------------------

#: Extent (bounding-box diagonal) of the input below which it is refused: products
#: of four lengths must stay normal doubles (see :mod:`ruledmesh.normalise`).
MIN_EXTENT = 1e-60
#: Extent relative to the largest coordinate below which float64 cannot hold the
#: shape: it is :data:`ROUNDING`, the relative precision the constructions need.
MIN_RELATIVE_EXTENT = 1e-12
#: Relative clearance kept between a point chosen inside an interval and the
#: interval's ends (a kink split, the first step of a distribution): far above
#: rounding, so the point is really interior, and far below any spacing a user sees.
INTERIOR = 1e-6
#: Step (of a parameter in [0, 1]) of the central differences that give a closed-form
#: correspondence its slope: its error (the step squared) and rounding (1e-16 over the
#: step) are both near 1e-10, and the slope serves tangents, never a vertex.
SLOPE_STEP = 1e-6
#: Parameters this close to 0 or 1 are on the patch border (rounding of t).
ON_BORDER = 1e-12
#: A border made by snapping stays this close (share of the diagonal) to the director curve.
SNAP_GAP = 1e-3
#: A corner snapped onto the border must raise the smallest angle around it by this much
#: (degrees): a move that leaves it as it was gains rounding noise, 9e-15 at one scale of the
#: skew example and 0 at three times it, and the meshes differed.
SNAP_MIN_GAIN_DEG = 1e-3
#: Regularisation of the KKT matrix of the parallel-offset fit, relative to its
#: unit-size rows: small enough that refinement converges in a few steps, large
#: enough for a stable sparse LU.
KKT_REGULARISATION = 1e-10
#: Floor of ``1 + cos(turn)`` at a mitred corner of a hot-wire path: a turn
#: sharper than about 177 degrees is mitred as if it were this one, so the
#: offset corner stays at a finite distance.
MITRE_FLOOR = 1e-3
#: Smallest half angle (radians) between two panels at a beam node; below it the
#: panels are treated as folded flat and the set-back stays finite.
MIN_HALF_ANGLE = 1e-6

# --------------------------------------------------------------------------
# Fabrication, export and figures
# --------------------------------------------------------------------------

#: Default angle tolerance (degrees) under which two panels are congruent: well
#: below any cutting precision, well above the rounding of corner angles.
CONGRUENCE_ANGLE_DEG = 1e-4
#: Warn when float32 rounding (STL) moves corners by more than this fraction of the mesh size.
FLOAT32_WARNING = 1e-5
#: Planarity below this is rounding noise in float64; clamping keeps a log colour scale finite.
PLANARITY_FLOOR = 1e-17
#: Depth bias of the visibility test in figures, relative to the depth of the
#: scene: a face does not hide itself or its neighbours along a shared edge.
DEPTH_BIAS = 1e-6
#: Tolerance handed to Open CASCADE's face builder for the reference surface
#: (the figures are compared at the unit scale, where this is below any deflection asked for).
OCCT_FACE = 1e-9

# Edge flips of the triangles a PQ mesh keeps (ruledmesh.skew.pq.flips).
#: A flip must raise the pair's smallest angle by this much (degrees), so the rounds end.
FLIP_MIN_GAIN_DEG = 1e-3
#: The two triangles may bend against each other by at most this angle (degrees), before
#: and after: a flip across a ridge would cut it off.
FLIP_MAX_BEND_DEG = 20.0
#: The new diagonal may lie at most this share of the patch diagonal off the old pair, so
#: the mesh keeps to the surface (the gap goal is 2e-3).
FLIP_MAX_SAG = 2.5e-4
#: A splinter left by the flips may still be flipped (ruledmesh.skew.pq.flips.flip_splinters)
#: where the two diagonals lie at most this share of the patch diagonal apart: a quarter of
#: the gap goal (2e-3), and only where the mesh had a splinter.
SPLINTER_FLIP_MAX_SAG = 5e-4
# Only triangles with an angle below this (and their neighbours) are worth flipping.
FLIP_ACTIVE_DEG = 20.0
#: A triangle-only vertex collapsed into a neighbour (ruledmesh.skew.pq.collapses) may lie
#: at most this share of the patch diagonal off the plane of each face it leaves behind.
COLLAPSE_MAX_SAG = 2.5e-4
#: A build warns where a triangle lies farther than this share of the patch diagonal off a
#: generator it spans without a corner on it (ruledmesh.analysis.spans): the gap goal.
SPAN_MAX_GAP = 2e-3
#: Triangles farther off the generators they span than this share of the gap goal are
#: halved (ruledmesh.skew.pq.halving): the measure takes five points along each stretch of
#: the discrete generators, and the quality checker, sampling the smooth surface between
#: them too, read up to a fifth more (docs/mesh-quality.md).
SPAN_HALVED_ABOVE = 0.8
#: An end point whose faces are all needles may be dropped with them
#: (ruledmesh.skew.pq.splinters.trim_border_needles) when it lies at most this share of
#: the patch diagonal from their far edges: the patch stays within half the gap goal (2e-3).
BORDER_TRIM_MAX_GAP = 1e-3
#: A torsal band is spanned by one coplanar pair of generators (ruledmesh.design.torsal)
#: only if the smooth surface between stays within this share of the patch diagonal from
#: the flat strip they bound (their plane, and the strip's straight ends where the director
#: curves leave them): half the gap goal (2e-3).
FLAT_PAIR_MAX_SAG = 1e-3
#: A strip whose strip quads are planar within this (the planarity tolerance the mesher's
#: warnings suggest) counts as nearly developable in a build's warnings.
NEARLY_DEVELOPABLE = 1e-3

#: A step of an even division (generators without §4.3 rows) this many times longer than
#: the distance to a neighbouring generator there would leave a zipper triangle of about
#: atan(1 / 19) = 3 degrees (the splinter bar): the strip pinches there (a hyperboloid's
#: waist near its asymptotic cone), and the division is graded.
EVEN_PINCH_STEP_PER_WIDTH = 19.0
#: ... where the strip is narrower there than this share of its width at the wider of its
#: ends: it pinches.  Strips narrow from end to end (generators the refinement added close
#: together) are not graded: the collapses join their triangles across several strips.
EVEN_PINCH_SHARE = 0.25
#: Where an even division is graded, its steps are halved until at most this many times the
#: distance to a neighbouring generator: the zipper triangles keep about atan(1 / 9.5) = 6
#: degrees, twice the splinter bar.
EVEN_STEP_PER_WIDTH = 9.5
#: How many times an even division's step is halved at most where the strips pinch (a
#: generator meeting its neighbour has no width to step by).
EVEN_MAX_HALVINGS = 10
#: ... and the halving stops once it has added this many times the division's own vertices
#: on those generators.  Two generators that meet leave a strip of no width, where every
#: step would be halved ten times: a design of 12 x 6 with a control point at 1.2e8 made
#: 15,000 faces and took 25 s to build.  The hyperboloids near their asymptotic cone add at
#: most 6.3 times (turned by 175 degrees, with a planarity tolerance).
EVEN_MAX_ADDED = 8.0

# A §4.3 face whose smallest angle is below this (degrees) counts as failing: runs
# end before such faces (ruledmesh.skew.pq.runs).  The splinter bar of the analysis
# (ruledmesh.analysis.faces.SPLINTER_DEG); 4 deg cost 4 more points of triangle
# share at 301 x 300 for 24 fewer splinters out of 200 000 faces.
RESTART_ANGLE_DEG = 3.0
#: What a splinter is worth in quad area share when the mesher trades one for the other
#: (opening the quads around a splinter): 0.6 % of the mesh's area per face below
#: RESTART_ANGLE_DEG.
SPLINTER_AREA_WORTH = 0.006
