"""The primary's division graded for faces of even shape.

"The mesh can be refined by changing ... the subdivision on the first generator"
(paper §5.1).  An even division of the primary lands unevenly on the other
generators: their rows are Moebius images of the primary's.  On a strongly
twisted surface (a hyperboloid close to its asymptotic cone) a generator far
from the primary takes its rows from a stretch of the primary far beyond the
patch, where even steps land ten to fifteen times closer together than its
strips are wide: every face there is a sliver, and the runs are cut again and
again.

A graded division spaces the rows for faces of about square shape.  The face
centred at a point of generator ``g_i`` has one diagonal across the two strips
there, ``2 w / sin(a)`` long (``w`` the mean distance to the neighbouring
generators, ``a`` the angle at which the hop line crosses ``g_i``:
:mod:`ruledmesh.analysis.asymptotic`), and the other on ``g_i``, two row steps
long: square when the row step is ``w / sin(a)``.  That step over the rate at
which ``g_i``'s parameter moves with the primary's (the derivative of its
Moebius map) is the step a row landing there needs on the primary.  The
division takes the smallest over the generators each row lands on, so no
generator gets rows farther apart than its faces need, and is scaled so that
the median generator carries ``rows`` steps over the patch, as an even division
does on the primary.

Square faces grow with the strips: where the generators fan out towards a rim,
their square steps can be tens of times the median, and the rows there so far
apart that the teeth of triangles along the border cut off by the director curve
are the main share of the area outside quads.  The *bounded* division (``division
= "bounded"``) takes no generator's square step as more than :data:`BOUND` times
their median, so the rows reach the rims closer together and the rest of the
patch, scaled to the same median count, a little less close.
"""

from __future__ import annotations

import numpy as np

from ..._arrays import median
from ...analysis.asymptotic import crossing_angles
from ...tolerances import TINY
from .extension import LANDING_SLACK

__all__ = ["BOUND", "graded_rows", "square_steps"]

# Points per generator the square step is measured at (interpolated between).
_SAMPLES = 17
# The crossing angle's sine is taken at least this: in slender regions (5.7 degrees and
# under) the faces are long whatever the division, and the rows need not crowd for them.
_MIN_SINE = 0.1
# Points of the primary's parameter per expected row at which the density is measured ...
_PER_ROW = 8
# ... within these bounds, and generator x point evaluations held at a time.
_MIN_POINTS, _MAX_POINTS = 4097, 131_073
_CHUNK = 1 << 21
# Generator x point landing masks kept between the two passes of graded_rows (bytes).
_KEPT_MASKS = 1 << 24
# The bounded division's largest square step, in medians of the run's square steps.  Tried
# beside the graded division by a design build (MEASURED at _GRADINGS in design/pq.py): at 2,
# twisted-bspline-arc-150deg went from 27.3 to 17.2 % of the area in triangles; at 3, to
# 26.6 %; at 5 no design of the regression set changed.
BOUND = 2.0
# Where no generator's patch is reached, the rows step by at most this many times their
# smallest step elsewhere: they are the margin, and are thinned out later anyway.
_EMPTY = 1e3


def square_steps(a: np.ndarray, d: np.ndarray) -> np.ndarray:
    """(m, k) the row step (in units of each generator's length) for square faces, at
    :data:`_SAMPLES` points from ``t = 0`` to ``t = 1`` of each generator ``a + t d``, ``m >= 3``."""
    t = np.linspace(0.0, 1.0, _SAMPLES)
    angles, _ = crossing_angles(a, a + d, t)
    angles = np.concatenate([angles[:1], angles, angles[-1:]])   # the end generators: as the next
    P = a[:, None, :] + t[None, :, None] * d[:, None, :]
    width = np.zeros((len(a), _SAMPLES))
    width[1:] += _to_lines(P[1:], a[:-1], d[:-1])
    width[:-1] += _to_lines(P[:-1], a[1:], d[1:])
    width[1:-1] *= 0.5
    sine = np.maximum(np.sin(np.radians(angles)), _MIN_SINE)
    return width / sine / np.maximum(np.linalg.norm(d, axis=1), TINY)[:, None]


def _to_lines(P: np.ndarray, a: np.ndarray, d: np.ndarray) -> np.ndarray:
    """(m, k) distances of points ``P`` (m, k, 3) to the lines ``a + s d`` (m, 3)."""
    u = d / np.maximum(np.linalg.norm(d, axis=1), TINY)[:, None]
    v = P - a[:, None, :]
    along = np.einsum("mkj,mj->mk", v, u)
    return np.linalg.norm(v - along[..., None] * u[:, None, :], axis=-1)


def graded_rows(a: np.ndarray, d: np.ndarray, M: np.ndarray, lo: float, hi: float, rows: int,
                shift: bool, bounded: bool = False) -> np.ndarray:
    """Root parameters of a graded division from ``lo`` to ``hi``, a-rows at even places.

    Parameters
    ----------
    a, d : (m, 3) float64
        The run's generators, ``m >= 3``.
    M : (m, 2, 2) float64
        Composed row maps from the primary's parameter.
    lo, hi : float
        The range of the primary's parameter that covers the patch.
    rows : int
        Steps the median generator carries over its part on the patch.
    shift : bool
        Start with a b-row instead (the checkerboard colour the primary carries).
    bounded : bool
        Take no square step as more than :data:`BOUND` times their median.

    Returns
    -------
    (2n,) float64
        Increasing.
    """
    steps = square_steps(a, d)
    if bounded:
        steps = np.minimum(steps, BOUND * median(steps.ravel()))
    n = int(np.clip(_PER_ROW * rows * max(hi - lo, 1.0), _MIN_POINTS, _MAX_POINTS))
    g = np.linspace(lo, hi, n)
    rho = np.zeros(n)
    reached = np.zeros(len(a))
    width = np.gradient(g)
    chunk = max(1, _CHUNK // n)
    # The landing masks of the first pass serve the second where they fit in _KEPT_MASKS
    # (most builds: a design's refinement grades dozens of runs), else they are made again.
    masks: list[np.ndarray] | None = [] if len(a) * n <= _KEPT_MASKS else None
    for k in range(0, len(a), chunk):
        dens, inside = _density(M[k:k + chunk], steps[k:k + chunk], g)
        rho = np.maximum(rho, dens.max(axis=0))
        reached[k:k + chunk] = (inside * width).sum(axis=1)
        if masks is not None:
            masks.append(inside)
    if not (rho > 0).any():             # no generator reached: an even division
        rho[:] = rows
    rho = np.maximum(rho, rho.max() / _EMPTY)
    # Each generator's rows over its patch: the density integrated where its rows land there.
    counts = np.zeros(len(a))
    for i, k in enumerate(range(0, len(a), chunk)):
        inside = masks[i] if masks is not None else _density(M[k:k + chunk], steps[k:k + chunk], g)[1]
        counts[k:k + chunk] = (inside * rho * width).sum(axis=1)
    counts = counts[reached > 0]
    rho *= rows / max(float(median(counts)), TINY) if counts.size else 1.0
    F = np.concatenate([[0.0], np.cumsum(0.5 * (rho[1:] + rho[:-1]) * np.diff(g))])
    # Rows from end to end of the range (its ends are the margin: _covering's range holds
    # the patch of every generator it can), a whole even number of steps.  No rows beyond:
    # where no generator is reached the density is tiny, and rows that far out would land
    # beside those through the primary's other end (both near its point at infinity).
    count = max(int(np.ceil(F[-1])) + 1, 4)
    tau = np.interp(np.linspace(0.0, F[-1], count + count % 2), F, g)
    if not shift:
        return tau
    # The a-rows become b-rows and the other way round, one more row behind (a step no
    # longer than the median).
    gaps = np.diff(tau)
    return np.append(tau[1:], tau[-1] + min(gaps[-1], median(gaps)))


def _density(M: np.ndarray, steps: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, n) the rows per unit of the primary's parameter that generators ``M`` (k, 2, 2)
    need at the points ``g`` (0 where the row misses their patch), and (k, n) whether the
    row lands on their part ``0 <= t <= 1``."""
    num = M[:, 0, 0, None] * g + M[:, 0, 1, None]
    den = M[:, 1, 0, None] * g + M[:, 1, 1, None]
    det = np.abs(M[:, 0, 0] * M[:, 1, 1] - M[:, 0, 1] * M[:, 1, 0])[:, None]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t = num / den
        rate = det / den ** 2
    lands = np.isfinite(t) & np.isfinite(rate) & (t > -LANDING_SLACK) & (t < 1.0 + LANDING_SLACK)
    x = np.clip(np.where(lands, t, 0.0), 0.0, 1.0) * (_SAMPLES - 1)
    j = np.minimum(x.astype(np.int64), _SAMPLES - 2)
    f = x - j
    rows = np.arange(len(M))[:, None]
    step = steps[rows, j] * (1.0 - f) + steps[rows, j + 1] * f
    dens = np.where(lands, rate / np.maximum(step, TINY), 0.0)
    return dens, lands & (t >= 0.0) & (t <= 1.0)
