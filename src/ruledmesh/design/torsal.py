"""Torsal bands spanned by one exactly coplanar pair of generators.

Where the twist of a skew surface changes sign (a torsal generator) the §4.3
rows bunch towards the torsal point: the strips around it carry no rows and are
closed by triangles.  Two generators that are coplanar carry planar quads of any
division (paper §3.1), and the surface offers such pairs across every torsal
generator: the twist ``f(u, v) = det(d(u), d(v), a(v) - a(u))`` of the pair
``(u, v)`` is symmetric, vanishes to second order at ``u = v``, and its leading
term at the midpoint is the twist there, which changes sign across the torsal
generator.  So for a band of strips around it there is a pair ``(u, v)``
straddling it with ``f(u, v) = 0`` exactly (to rounding), found by bracketing
and Brent's method (:func:`ruledmesh.roots.brentq`, no scipy import).  Where
the design gives director curves the generators are ours to choose: the
generators inside the band are left out and the pair bounds one flat strip,
which the mesher fills with strip quads.  A pair is taken only
if the smooth surface between stays within :data:`~ruledmesh.tolerances.FLAT_PAIR_MAX_SAG`
of the patch diagonal from the flat strip they bound (out of its plane, and
within it where the director curves leave its straight ends).  The sag grows with the square of the
pair's width, so where the generators beside the torsal one are too far apart for
that, generators of the smooth surface are added around the band (halving their
spacing, twice at most) and the pair is sought among them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .._arrays import member, unique
from ..hop import coplanarity, sense_changes
from ..roots import brentq
from ..tolerances import FLAT_PAIR_MAX_SAG, ROOT_XTOL, TINY

__all__ = ["span_torsal_bands", "twist_changes"]

# How many strips a band may reach beyond the torsal strip on each side, how many
# more strips the search for the partner generator may look across, and how many
# samples it brackets the root with.
_MAX_REACH = 1
_SEARCH = 3
_SAMPLES = 40
# Halvings of the generator spacing around a band whose pair sags too far (see _denser_pair).
_DENSER_LEVELS = 2


def twist_changes(a: np.ndarray, d: np.ndarray, scale: float) -> np.ndarray:
    """Generators ``k`` where strips ``k - 1`` and ``k`` twist in opposite senses.

    Unlike the mesher's cuts (:func:`ruledmesh.hop.sense_changes` with the coplanar pairs
    taken as senseless), a change across a strip that is flat to the degenerate
    tolerance counts: a pair spanning it and its neighbours is still worth trying.

    Parameters
    ----------
    a, d : (m, 3) float64
        Generator points and directions.
    scale : float
        The patch diagonal.

    Returns
    -------
    (k,) int64
    """
    twist = coplanarity(a, d, scale)
    return np.flatnonzero(sense_changes(twist, np.zeros(len(twist), bool)))


def _twist(surface, u: float, v: np.ndarray, scale: float) -> np.ndarray:
    """(n,) scale-free twist of the pairs (u, v_k): :func:`ruledmesh.hop.coplanarity` of
    the generators u, v_0, u, v_1, ... taken pair by pair."""
    uu = np.empty(2 * len(v))
    uu[0::2], uu[1::2] = u, v
    a = surface.a(uu)
    return coplanarity(a, surface.b(uu) - a, scale)[0::2]


def _partner(surface, u: float, lo: float, hi: float, scale: float, last: bool) -> float | None:
    """A ``v`` in [lo, hi] with the pair (u, v) coplanar: the first root (the last if ``last``)."""
    grid = np.linspace(lo, hi, _SAMPLES)
    f = _twist(surface, u, grid, scale)
    ch = np.flatnonzero(np.sign(f[1:]) != np.sign(f[:-1]))
    if ch.size == 0:
        return None
    k = int(ch[-1] if last else ch[0])
    return float(brentq(lambda v: float(_twist(surface, u, np.array([v]), scale)[0]),
                        grid[k], grid[k + 1], xtol=ROOT_XTOL))


def _pair(surface, u: np.ndarray, lo: int, hi: int, scale: float) -> tuple[float, float] | None:
    """The narrowest coplanar pair found spanning generators ``lo`` to ``hi``.

    One end stays on a generator (first ``lo``, then ones further left) and the
    partner is sought beyond the other end of the band.
    """
    m = len(u)
    for left in range(lo, max(lo - _SEARCH, 0) - 1, -1):
        v = _partner(surface, u[left], u[hi], u[min(hi + _SEARCH, m - 1)], scale, last=False)
        if v is not None:
            return float(u[left]), v
        w = _partner(surface, u[hi], u[max(left - _SEARCH, 0)], u[left], scale, last=True)
        if w is not None:
            return w, float(u[hi])
    return None


def _denser_pair(surface, u: np.ndarray, lo: int, hi: int, scale: float):
    """A coplanar pair within the sag bound across the band lo..hi, the generators around it
    halved in spacing until one is found: ``(pair, added parameters)`` or ``(None, [])``.

    The sag of a pair grows with the square of its width, and the pair can only be
    as narrow as the generators beside the torsal one: where the given spacing is
    too coarse, generators of the smooth surface are added in the strips around
    the band (each level halves their spacing), as the refinement would add them
    strip by strip, and the pair is sought among those.
    """
    w_lo, w_hi = max(lo - 1, 0), min(hi + 1, len(u) - 1)
    local = u[w_lo:w_hi + 1]
    for _ in range(_DENSER_LEVELS):
        local = unique(np.r_[local, 0.5 * (local[1:] + local[:-1])])
        a = surface.a(local)
        d = surface.b(local) - a
        ch = twist_changes(a, d, scale)
        if ch.size == 0:
            return None, np.zeros(0)
        # The change nearest the middle of the window is the band's torsal generator.
        g = int(ch[np.argmin(np.abs(local[ch] - 0.5 * (u[lo] + u[hi])))])
        if g - 1 < 1 or g + 1 > len(local) - 2:
            return None, np.zeros(0)
        pair = _pair(surface, local, g - 1, g + 1, scale)
        if pair is not None and _sag(surface, pair, scale) <= FLAT_PAIR_MAX_SAG:
            # local is sorted and unique already (the loop's unique).
            return pair, local[~member(local, u)]
    return None, np.zeros(0)


def _sag(surface, pair: tuple[float, float], scale: float) -> float:
    """Largest distance of the smooth surface between the pair from the flat strip they bound,
    over ``scale``.

    The strip's quads join points of equal ``t`` on the two generators, so a point
    ``(s, t)`` of the surface between them is measured from the rung at its ``t``:
    the distance holds the bulge out of the pair's plane and, at the strip's ends,
    the director curves bowing away from its straight edges within it (the whole gap
    there; inside, a bound on it).
    """
    ends = np.asarray(pair)
    a, b = surface.a(ends), surface.b(ends)
    s = np.linspace(ends[0], ends[1], 9)[1:-1]
    t = np.linspace(0.0, 1.0, 5)
    p = surface.point(s[:, None], t[None, :])                     # (7, 5, 3)
    lo = a[0] + t[:, None] * (b[0] - a[0])                        # (5, 3): the rungs' ends
    hi = a[1] + t[:, None] * (b[1] - a[1])
    rung = hi - lo
    w = np.einsum("stk,tk->st", p - lo, rung) / np.maximum(np.einsum("tk,tk->t", rung, rung), TINY)
    foot = lo + np.clip(w, 0.0, 1.0)[..., None] * rung
    return float(np.linalg.norm(p - foot, axis=-1).max()) / scale


def span_torsal_bands(rulings, trouble: np.ndarray, scale: float, changes: np.ndarray | None = None):
    """``rulings`` with each torsal band spanned by one coplanar pair of generators.

    Parameters
    ----------
    rulings : Rulings
        With a smooth ``surface``.
    trouble : (m - 1,) bool
        Strips mostly outside quads in the mesh of ``rulings``: a band reaches
        from the torsal generator over such strips (at most ``_MAX_REACH`` on
        each side).
    scale : float
        The patch diagonal.
    changes : (k,) int, optional
        :func:`twist_changes` of ``rulings``, if the caller has them.

    Returns
    -------
    rulings : Rulings or None
        None where no band could be spanned; else with the pairs' generators and
        those added around the bands (see :func:`_denser_pair`) counted in
        ``info["inserted"]``.
    bands : list of (int, int)
        The generators of ``rulings`` (the new ones) that bound the flat strips.
    left_out : int
        Generators of the given ``rulings`` left out inside the bands.
    """
    surface = rulings.surface
    u = np.asarray(rulings.u)
    a = np.asarray(rulings.a)
    d = np.asarray(rulings.b) - a
    m = len(u)
    creases = np.asarray(rulings.info.get("crease_generators") or [], dtype=np.int64)
    keep = np.ones(m, bool)
    pairs: list[tuple[float, float]] = []
    denser: list[np.ndarray] = []
    for g in (twist_changes(a, d, scale) if changes is None else changes).tolist():
        lo, hi = g - 1, g
        while lo > 0 and trouble[lo - 1] and g - lo < _MAX_REACH:
            lo -= 1
        while hi < m - 2 and trouble[hi] and hi - g < _MAX_REACH - 1:
            hi += 1
        hi += 1
        if lo < 1 or hi > m - 2 or (pairs and u[lo] <= pairs[-1][1]) \
                or np.any((creases >= lo) & (creases <= hi)):
            continue
        pair = _pair(surface, u, lo, hi, scale)
        extra = np.zeros(0)
        if pair is None or _sag(surface, pair, scale) > FLAT_PAIR_MAX_SAG:
            pair, extra = _denser_pair(surface, u, lo, hi, scale)
            if pair is None:
                continue
        pairs.append(pair)
        keep &= ~((u > pair[0]) & (u < pair[1]))
        denser.append(extra)
    if not pairs:
        return None, [], 0
    ends = np.asarray(pairs).reshape(-1)
    added = np.concatenate(denser)
    # No added generator may fall inside a pair (its own or a neighbouring band's): the
    # pair bounds one flat strip.
    inside = np.zeros(added.size, bool)
    for p, q in pairs:
        inside |= (added > p) & (added < q)
    new_u = unique(np.r_[u[keep], ends, added[~inside]])
    info = dict(rulings.info)
    info["inserted"] = int(info.get("inserted", 0)) + int((~member(new_u, u)).sum())
    if len(creases):
        info["crease_generators"] = np.searchsorted(new_u, u[creases]).tolist()
    bands = [(int(np.searchsorted(new_u, p)), int(np.searchsorted(new_u, q))) for p, q in pairs]
    spanned = replace(rulings, a=surface.a(new_u), b=surface.b(new_u), u=new_u, info=info)
    return spanned, bands, int((~keep).sum())
