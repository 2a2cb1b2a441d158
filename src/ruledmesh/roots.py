"""Brent's method for a bracketed scalar root, without importing ``scipy.optimize``.

``scipy.optimize`` takes about two and a half times as long to import as numpy
itself, and a design with a polyline director curve needs one bracketed root
per crease: importing it would dominate the start-up of a small build.  This
is the algorithm of ``scipy.optimize.brentq`` (Brent 1973, as in scipy's
``Zeros/brentq.c``), step for step, so the roots are the same; the tests
compare the two.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable

from .errors import GeometryError
from .tolerances import BRENTQ_XTOL

__all__ = ["brentq"]

_EPS = sys.float_info.epsilon


def brentq(f: Callable[[float], float], a: float, b: float, xtol: float = BRENTQ_XTOL,
           rtol: float = 4 * _EPS, maxiter: int = 100) -> float:
    """A root of ``f`` in ``[a, b]``, where ``f(a)`` and ``f(b)`` differ in sign.

    Parameters
    ----------
    f : callable
        Continuous scalar function of a float.
    a, b : float
        The bracket.
    xtol, rtol : float
        The root is found to ``xtol + rtol * |x|`` (scipy's defaults).
    maxiter : int

    Returns
    -------
    float

    Raises
    ------
    GeometryError
        If ``f(a)`` and ``f(b)`` have the same sign, or no convergence.

    >>> round(brentq(lambda x: x * x - 2.0, 0.0, 2.0), 12)
    1.414213562373
    """
    xpre, xcur = float(a), float(b)
    fpre, fcur = float(f(xpre)), float(f(xcur))
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    if (fpre > 0) == (fcur > 0):
        raise GeometryError(f"no sign change of the function between {a!r} and {b!r}")
    xblk = fblk = spre = scur = 0.0
    for _ in range(maxiter):
        if fpre != 0.0 and fcur != 0.0 and (math.copysign(1.0, fpre) != math.copysign(1.0, fcur)):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                den = dblk * dpre * (fblk - fpre)
                # Two equal values (a flat stretch of f): no parabola through the three
                # points; C's division gives inf there and the step is refused, so bisect.
                stry = -fcur * (fblk * dblk - fpre * dpre) / den if den != 0.0 else math.inf
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
                spre, scur = scur, stry  # a good short step
            else:
                spre = scur = sbis  # bisect
        else:
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = float(f(xcur))
    raise GeometryError(f"no root found to {xtol:g} within {maxiter} steps")
