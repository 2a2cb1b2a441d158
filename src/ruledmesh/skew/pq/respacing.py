"""Rows respaced where a run's division has spread unevenly over its generators.

The rows of a run are the hop lines through the division of its primary: the
maps from the primary to the other generators are projective (paper §4.3), so
on a strongly twisted surface a division even on the primary bunches on the
generators some way off and opens wide gaps elsewhere.  Where the rows bunch
the panels are thin; where they gap, the faces are tall and the border cuts
them into tall teeth, or whole stretches of the patch carry no rows at all.

Restarting the run there with a division *evened* on the restart generator
keeps the rows spaced as planned: the vertices the run left on that generator
stay where they are no closer than half a row step (those rows carry on across
it), and gaps wider than a step and a half get new rows at even steps.  Each
restart costs a column of triangles along its generator, so a run restarts
only where its widest gap on the patch is more than :data:`SPREAD` row steps
(measured on the twisted surfaces of ``benchmarks/quality``, see
``docs/mesh-quality.md``).
"""

from __future__ import annotations

import numpy as np

from ...tolerances import ROUNDING

__all__ = ["SPREAD", "evened", "spread_generators"]

# A generator on which the widest gap between a run's rows (the border counting as a
# row) is more than this many of the division's steps restarts the run.
SPREAD = 2.5
# The evened division keeps rows no closer than this share of a step and fills gaps
# wider than 1 + this share of a step.
_CLOSEST = 0.5


def _step(rows: int) -> float:
    """The division's step on a generator: its vertices lie on every second row."""
    return 2.0 / rows


def spread_generators(t: np.ndarray, gen: np.ndarray, far: np.ndarray, first: int, m: int,
                      rows: int) -> np.ndarray:
    """(m,) bool: the run's generators whose rows have spread beyond :data:`SPREAD` steps.

    Parameters
    ----------
    t, gen, far : (V,) float64, int64, bool
        The run's vertices: parameter on its generator, global generator index,
        beyond the far bound.
    first, m : int
        The run's first global generator and its number of generators.
    rows : int
        The rows of the division (its step is ``2 / rows`` on a generator).

    Generators with fewer than two vertices on the patch are left to the
    torsal and no-rows cases of the mesher.
    """
    out = np.zeros(m, bool)
    on = ~far & (t >= -ROUNDING) & (t <= 1.0 + ROUNDING)
    g, tt = gen[on] - first, np.clip(t[on], 0.0, 1.0)
    if g.size == 0:
        return out
    order = np.lexsort((tt, g))
    g, tt = g[order], tt[order]
    count = np.bincount(g, minlength=m)
    start = np.flatnonzero(np.r_[True, g[1:] != g[:-1]])
    end = np.r_[start[1:], g.size] - 1
    inner = np.where(g[1:] == g[:-1], tt[1:] - tt[:-1], 0.0)
    widest = np.zeros(m)
    if inner.size:
        np.maximum.at(widest, g[1:], inner)
    # The border counts as a row: the trim closes what lies beyond the last one.
    widest[g[start]] = np.maximum(widest[g[start]], tt[start])
    widest[g[end]] = np.maximum(widest[g[end]], 1.0 - tt[end])
    return (count >= 2) & (widest > SPREAD * _step(rows))


def evened(t: np.ndarray, rows: int) -> np.ndarray:
    """A division close to ``t`` whose spacing stays within half and one and a half steps.

    Parameters
    ----------
    t : (k,) float64
        Increasing parameters of a run's vertices on the restart generator.
    rows : int
        The rows of the division.

    Returns
    -------
    (j,) float64
        Increasing parameters: the entries of ``t`` kept (the first and last
        always), every one at least half a step from the one before, and even
        steps inserted into the gaps wider than a step and a half.
    """
    t = np.asarray(t, dtype=np.float64)
    if t.size < 2:
        return t
    step = _step(rows)
    # The greedy pass walks the division (a few dozen entries, once per restart).
    keep = [0]
    for k in range(1, t.size - 1):
        if t[k] - t[keep[-1]] >= _CLOSEST * step:
            keep.append(k)
    if len(keep) > 1 and t[-1] - t[keep[-1]] < _CLOSEST * step:
        keep.pop()
    kept = t[np.r_[keep, t.size - 1]]
    gaps = np.diff(kept)
    pieces = np.maximum(np.ceil(gaps / step - _CLOSEST), 1).astype(np.int64)
    base = np.repeat(kept[:-1], pieces)
    frac = np.arange(pieces.sum()) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    return np.r_[base + np.repeat(gaps / pieces, pieces) * frac, kept[-1]]
