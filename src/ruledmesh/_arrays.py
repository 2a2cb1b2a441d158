"""Array helpers that numpy has, but slowly: sorted unique values, cross products, box diagonals,
percentiles and medians; and the ranks within groups of given sizes, which numpy has not.
Last, corner angles that come out the same on every machine (:func:`corner_angle`).

numpy 2.3+ finds the unique values of a plain ``np.unique(x)`` through a hash
table and sorts them afterwards; on arrays of a million edge keys or vertex
indices that is 30-70 times slower than sorting first (the table misses the
cache at every insertion), and its first call imports ``numpy.ma`` (about 20 ms)
to ask whether the array is masked.  :func:`unique` is numpy's own
sorting method, so its result is the same array.  ``np.percentile`` and
``np.median`` import ``numpy.ma`` too (through ``np.unique`` and a masked-NaN
check), which is a third of a small build's analysis on a cold start:
:func:`percentile` and :func:`median` take the same order statistics and
interpolate as numpy does, so their values are numpy's.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["corner_angle", "cross", "diagonal", "extent", "lookup", "median", "member", "norm", "percentile",
           "ranks", "unique"]


def unique(values: np.ndarray) -> np.ndarray:
    """Sorted unique values of ``values`` (flattened): ``np.unique(values)``, by sorting.

    Parameters
    ----------
    values : array_like
        Any shape; flattened first.

    Returns
    -------
    (k,) ndarray
        Of the same dtype; NaNs (for floats) collapsed into one at the end, as
        ``np.unique`` does with its default ``equal_nan=True``.
    """
    arr = np.sort(np.asarray(values).ravel())
    if arr.size == 0:
        return arr
    keep = np.empty(arr.shape, dtype=bool)
    keep[0] = True
    np.not_equal(arr[1:], arr[:-1], out=keep[1:])
    if arr.dtype.kind in "fc" and arr[-1] != arr[-1]:
        # NaNs sort last and differ from each other: keep the first of them only.
        first = int(np.searchsorted(arr, arr[-1], side="left")) if arr.dtype.kind == "f" else \
            int(np.flatnonzero(np.isnan(arr))[0])
        keep[first + 1:] = False
    return arr[keep]


def member(values: np.ndarray, among: np.ndarray) -> np.ndarray:
    """Which of ``values`` occur in ``among``: ``np.isin(values, among)``, by sorting.

    ``np.isin`` on larger arrays takes the plain ``np.unique`` of ``among``, and
    with it the ``numpy.ma`` import (see the module's docstring).

    Parameters
    ----------
    values : array_like
        Any shape.
    among : array_like
        Any shape; flattened.

    Returns
    -------
    ndarray of bool
        The shape of ``values``; NaN is in nothing, as with ``np.isin``.
    """
    v = np.asarray(values)
    s = unique(among)
    if s.size == 0:
        return np.zeros(v.shape, dtype=bool)
    i = np.minimum(np.searchsorted(s, v), s.size - 1)
    return s[i] == v


def lookup(keys: np.ndarray, table: np.ndarray) -> np.ndarray:
    """Position of each of ``keys`` in the sorted ``table``, -1 where it is absent.

    Parameters
    ----------
    keys : (k,) array_like
    table : (n,) sorted array

    Returns
    -------
    (k,) int
    """
    if table.size == 0:
        return np.full(np.shape(keys), -1)
    pos = np.minimum(np.searchsorted(table, keys), table.size - 1)
    return np.where(table[pos] == keys, pos, -1)


def percentile(values: np.ndarray, q: float) -> float:
    """``np.percentile(values, q)`` (its default, linear method), without importing ``numpy.ma``.

    Parameters
    ----------
    values : (n,) array_like of float, n >= 1
        Flattened first.  A NaN among them makes the result NaN, as in numpy.
    q : float in [0, 100]

    Returns
    -------
    float
        The same number as numpy's: the order statistics at ``floor`` and
        ``ceil`` of ``(n - 1) q / 100``, blended by numpy's own lerp (from the
        upper one when the weight is at least one half).
    """
    arr = np.sort(np.asarray(values, dtype=np.float64).ravel())
    if np.isnan(arr[-1]):  # NaNs sort last
        return float("nan")
    virtual = (arr.size - 1) * (q / 100)
    lo = min(math.floor(virtual), arr.size - 1)
    hi = min(lo + 1, arr.size - 1)
    a, b, t = arr[lo], arr[hi], virtual - lo
    diff = b - a
    return float(b - diff * (1 - t) if t >= 0.5 else a + diff * t)


def median(values: np.ndarray) -> float:
    """``np.median(values)`` without importing ``numpy.ma``: the middle value, or the mean of the two.

    Parameters
    ----------
    values : (n,) array_like of float, n >= 1
        Flattened first; a NaN among them makes the result NaN, as in numpy.
    """
    arr = np.sort(np.asarray(values, dtype=np.float64).ravel())
    if np.isnan(arr[-1]):
        return float("nan")
    mid = arr.size // 2
    # numpy takes the mean of the middle slice: (a + b) / 2 for an even count.
    return float(arr[mid] if arr.size % 2 else (arr[mid - 1] + arr[mid]) / 2)


# Up to this many numbers per operand, :func:`cross` gathers the components (faster on a
# few vectors, much slower on many).
_SMALL = 768
_NEXT = np.array([1, 2, 0])
_LAST = np.array([2, 0, 1])


def cross(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``np.cross`` of (..., 3) arrays: the same products and differences, bit for bit.

    Without ``np.cross``'s axis handling (two ``moveaxis`` and their checks per
    call), which costs more than the arithmetic on the few faces of a small
    mesh or a run's generators.
    """
    if x.shape == y.shape and x.size <= _SMALL:
        # Few vectors: the components in cyclic order by one gather each, four array
        # operations in all (the products and differences are the same numbers).
        return x.take(_NEXT, axis=-1) * y.take(_LAST, axis=-1) \
            - x.take(_LAST, axis=-1) * y.take(_NEXT, axis=-1)
    x0, x1, x2 = x[..., 0], x[..., 1], x[..., 2]
    y0, y1, y2 = y[..., 0], y[..., 1], y[..., 2]
    out = np.empty(np.broadcast_shapes(x.shape, y.shape), dtype=np.result_type(x, y))
    np.subtract(x1 * y2, x2 * y1, out=out[..., 0])
    np.subtract(x2 * y0, x0 * y2, out=out[..., 1])
    np.subtract(x0 * y1, x1 * y0, out=out[..., 2])
    return out


def norm(x: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(x, axis=-1)`` of a real (..., k) array: the same squares, sum and root.

    Without ``np.linalg.norm``'s argument handling, which costs more than the
    arithmetic on the few faces of a small mesh.
    """
    return np.sqrt(np.add.reduce(x * x, axis=-1))


def extent(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(points.min(axis=0), points.max(axis=0))``: the corners of the bounding box.

    Column by column: numpy reduces a tall (n, 3) array along its first axis
    several times slower than it reduces each strided column (5,411 points:
    200 against 25 microseconds).  The extremes are the same numbers, a zero's
    sign aside.

    Parameters
    ----------
    points : (n, k) float64, n >= 1

    Returns
    -------
    lo, hi : (k,) float64
    """
    k = points.shape[1]
    return (np.array([points[:, j].min() for j in range(k)]),
            np.array([points[:, j].max() for j in range(k)]))


def diagonal(points: np.ndarray) -> float:
    """``np.linalg.norm(points.max(axis=0) - points.min(axis=0))``: the bounding box's diagonal
    (:func:`extent`; the squares drop a zero's sign).

    Parameters
    ----------
    points : (n, k) float64, n >= 1
    """
    lo, hi = extent(points)
    return float(np.linalg.norm(hi - lo))


def ranks(counts: np.ndarray) -> np.ndarray:
    """``0 .. c - 1`` for each count ``c``, concatenated: the rank of each element in its group.

    Parameters
    ----------
    counts : (k,) int, >= 0

    Returns
    -------
    (sum(counts),) int
    """
    return np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)


# atan on [0, 1] by fdlibm's method (s_atan.c): reduction at 7/16 and 11/16, then an odd
# polynomial in x**2 split into even and odd powers of x**4; error below one ulp.
ATAN_HI = (4.63647609000806093515e-01, 7.85398163397448278999e-01)   # atan(1/2), atan(1)
ATAN_LO = (2.26987774529616870924e-17, 3.06161699786838301793e-17)
ATAN_EVEN = (3.33333333333329318027e-01, 1.42857142725034663711e-01, 9.09088713343650656196e-02,
             6.66107313738753120669e-02, 4.97687799461593236017e-02, 1.62858201153657823623e-02)
ATAN_ODD = (-1.99999999998764832476e-01, -1.11111104054623557880e-01, -7.69187620504482999495e-02,
            -5.83357013379057348645e-02, -3.65315727442169155270e-02)
HALF_PI = 1.57079632679489655800e+00
DEGREES = 180.0 / math.pi


def corner_angle(sin: np.ndarray, cos: np.ndarray) -> np.ndarray:
    """``np.degrees(np.arctan2(sin, cos))`` for ``sin >= 0``, the same bits on every machine.

    numpy's ``arctan2`` differs from the C library's in the last bit on about 7 %
    of arguments where numpy has SIMD loops for it (AVX-512 machines), and the
    compiled kernels (:mod:`ruledmesh.kernels`) can only call the C library's: both
    take this function instead (the kernels its scalar copy, operation for
    operation), so that flips and splinter checks decide alike, whatever the
    machine and whichever path runs.

    Parameters
    ----------
    sin : (...) float64
        Norm of the cross product of the two edges (``>= 0``, or NaN).
    cos : (...) float64
        Their dot product; the sign of a zero decides between 0 and 180 degrees,
        as in ``atan2``.

    Returns
    -------
    (...) float64
        The angle in degrees, within an ulp or two of ``arctan2``; NaN where
        an argument is.

    Examples
    --------
    >>> corner_angle(np.array([0.0, 1.0, 1.0, 0.0]), np.array([1.0, 1.0, -0.0, -0.0])).tolist()
    [0.0, 45.0, 90.0, 180.0]
    """
    s = np.asarray(sin, dtype=np.float64)
    c = np.asarray(cos, dtype=np.float64)
    ac = np.abs(c)
    steep = s > ac                          # nearer 90 degrees: atan(|cos| / sin)
    num = np.where(steep, ac, s)
    den = np.where(steep, s, ac)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.where(den == 0.0, 0.0, num / den)       # 0 / 0: a zero edge, 0 or 180
        atan = _atan_unit(r)
    turn = np.signbit(c)
    rad = np.where(steep, np.where(turn, HALF_PI + atan, HALF_PI - atan),
                   np.where(turn, 2.0 * HALF_PI - atan, atan))
    return rad * DEGREES


def _atan_unit(x: np.ndarray) -> np.ndarray:
    """atan(x) for x in [0, 1] (NaN through), by :data:`ATAN_HI` and the polynomials."""
    mid = (2.0 * x - 1.0) / (2.0 + x)
    one = (x - 1.0) / (x + 1.0)
    low = x < 0.4375
    middle = ~low & (x < 0.6875)
    y = np.where(low, x, np.where(middle, mid, one))
    z = y * y
    w = z * z
    e, o = ATAN_EVEN, ATAN_ODD
    s1 = z * (e[0] + w * (e[1] + w * (e[2] + w * (e[3] + w * (e[4] + w * e[5])))))
    s2 = w * (o[0] + w * (o[1] + w * (o[2] + w * (o[3] + w * o[4]))))
    ys = y * (s1 + s2)
    hi = np.where(middle, ATAN_HI[0], ATAN_HI[1])
    lo = np.where(middle, ATAN_LO[0], ATAN_LO[1])
    return np.where(low, y - ys, hi - ((ys - lo) - y))
