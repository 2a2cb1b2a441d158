"""numba kernels of the per-face measures of :mod:`ruledmesh.analysis.faces`.

Each kernel is the numpy function's arithmetic in the numpy function's order,
one face per loop iteration, reading the corners through the face indices
instead of gathering an (F, k, 3) copy first.  The order of the sums matters
for bit-identical results and follows what numpy does: ``einsum("ij,ij->i")``
over three components adds ``(x0 y0 + x2 y2) + x1 y1`` onto +0, ``norm(axis=1)``
adds the squares left to right, and ``add.reduceat`` adds the first row to the
sum of the others.  The tests compare every kernel with its numpy reference.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._arrays import ATAN_EVEN, ATAN_HI, ATAN_LO, ATAN_ODD, DEGREES, HALF_PI
from ..tolerances import ROUNDING_SQ, TINY

__all__ = ["collapse_measures", "crossing", "flip_pairs", "ghosts_kept", "min_angles", "newell", "polygon_angles",
           "quad_planarity"]

E0, E1, E2, E3, E4, E5 = ATAN_EVEN
O0, O1, O2, O3, O4 = ATAN_ODD
# numpy's pairwise sum adds up to 128 terms in one unrolled block: the Newell kernel
# follows its order for faces of up to 129 corners (the first plus 128).
_MAX_CORNERS = 129


@nb.njit(cache=True, inline="always")
def _max(x: float, y: float) -> float:
    """np.maximum: NaN if either is NaN."""
    if x != x or y != y:
        return math.nan
    return x if x >= y else y


@nb.njit(cache=True, inline="always")
def _dot(x0: float, x1: float, x2: float, y0: float, y1: float, y2: float) -> float:
    """einsum("ij,ij->i") of three components, in numpy's order.

    einsum accumulates onto a zero, so a sum of negative zeros is +0 (and the
    sign of a zero cosine decides between 0 and 180 degrees in ``atan2``).
    """
    return 0.0 + ((x0 * y0 + x2 * y2) + x1 * y1)


@nb.njit(cache=True, inline="always")
def _corner_angle(sin: float, cos: float) -> float:
    """:func:`ruledmesh._arrays.corner_angle` of one corner, operation for operation.

    Not ``math.atan2``: numpy's ``arctan2`` differs from it in the last bit on
    some machines, and the numpy path must decide as the kernels do.
    """
    ac = abs(cos)
    steep = sin > ac
    num, den = (ac, sin) if steep else (sin, ac)
    x = 0.0 if den == 0.0 else num / den
    if x < 0.4375:
        y = x
    elif x < 0.6875:
        y = (2.0 * x - 1.0) / (2.0 + x)
    else:
        y = (x - 1.0) / (x + 1.0)
    z = y * y
    w = z * z
    s1 = z * (E0 + w * (E1 + w * (E2 + w * (E3 + w * (E4 + w * E5)))))
    s2 = w * (O0 + w * (O1 + w * (O2 + w * (O3 + w * O4))))
    ys = y * (s1 + s2)
    if x < 0.4375:
        atan = y - ys
    elif x < 0.6875:
        atan = ATAN_HI[0] - ((ys - ATAN_LO[0]) - y)
    else:
        atan = ATAN_HI[1] - ((ys - ATAN_LO[1]) - y)
    turn = math.copysign(1.0, cos) < 0.0
    if steep:
        rad = HALF_PI + atan if turn else HALF_PI - atan
    else:
        rad = 2.0 * HALF_PI - atan if turn else atan
    return rad * DEGREES


@nb.njit(cache=True, inline="always")
def _norm(x0: float, x1: float, x2: float) -> float:
    """np.linalg.norm(axis=1) of three components, in numpy's order."""
    return math.sqrt((x0 * x0 + x1 * x1) + x2 * x2)


@nb.njit(cache=True, inline="always")
def _crossing_one(V, i0, i1, i2, i3, f, out_s, out_t, out_gap, out_plan):
    """Diagonal crossing (and planarity when ``out_plan`` has rows) of quad ``f``: ``V[[i0, i1, i2, i3]]``."""
    o0, o1, o2 = V[i0, 0], V[i0, 1], V[i0, 2]
    scale = 0.0
    for i in (i0, i1, i2, i3):
        for j in range(3):
            scale = _max(scale, abs(V[i, j] - V[i0, j]))
    scale = _max(scale, TINY)
    p0, p1, p2 = (V[i0, 0] - o0) / scale, (V[i0, 1] - o1) / scale, (V[i0, 2] - o2) / scale
    q0, q1, q2 = (V[i1, 0] - o0) / scale, (V[i1, 1] - o1) / scale, (V[i1, 2] - o2) / scale
    u0 = (V[i2, 0] - o0) / scale - p0
    u1 = (V[i2, 1] - o1) / scale - p1
    u2 = (V[i2, 2] - o2) / scale - p2
    v0 = (V[i3, 0] - o0) / scale - q0
    v1 = (V[i3, 1] - o1) / scale - q1
    v2 = (V[i3, 2] - o2) / scale - q2
    w0, w1, w2 = p0 - q0, p1 - q1, p2 - q2
    a = _dot(u0, u1, u2, u0, u1, u2)
    b = _dot(u0, u1, u2, v0, v1, v2)
    c = _dot(v0, v1, v2, v0, v1, v2)
    d = _dot(u0, u1, u2, w0, w1, w2)
    e = _dot(v0, v1, v2, w0, w1, w2)
    den = a * c - b * b
    parallel = den <= ROUNDING_SQ * _max(a * c, TINY)
    if parallel:
        s = 0.0
        t = e / _max(c, TINY)
        x0, x1, x2 = w1 * u2 - w2 * u1, w2 * u0 - w0 * u2, w0 * u1 - w1 * u0
        gap = _norm(x0, x1, x2) / math.sqrt(_max(a, TINY))
    else:
        s = (b * e - c * d) / den
        t = (a * e - b * d) / den
        x0, x1, x2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
        gap = abs(_dot(w0, w1, w2, x0, x1, x2)) / _max(_norm(x0, x1, x2), TINY)
    gap = gap * scale
    out_s[f] = s
    out_t[f] = t
    out_gap[f] = gap
    if out_plan.shape[0]:
        l1 = _norm(V[i2, 0] - V[i0, 0], V[i2, 1] - V[i0, 1], V[i2, 2] - V[i0, 2])
        l2 = _norm(V[i3, 0] - V[i1, 0], V[i3, 1] - V[i1, 1], V[i3, 2] - V[i1, 2])
        out_plan[f] = gap / _max(0.5 * (l1 + l2), TINY)


@nb.njit(cache=True, nogil=True)
def _crossing(V, Q, want_plan):
    """Over quads ``V[Q]``; ``Q`` with no columns: the quads are ``V[4 f : 4 f + 4]``."""
    F = Q.shape[0] if Q.shape[1] else V.shape[0] // 4
    s = np.empty(F)
    t = np.empty(F)
    gap = np.empty(F)
    plan = np.empty(F if want_plan else 0)
    if Q.shape[1]:
        for f in range(F):
            _crossing_one(V, Q[f, 0], Q[f, 1], Q[f, 2], Q[f, 3], f, s, t, gap, plan)
    else:
        for f in range(F):
            _crossing_one(V, 4 * f, 4 * f + 1, 4 * f + 2, 4 * f + 3, f, s, t, gap, plan)
    return s, t, gap, plan


_CORNERS = np.zeros((1, 0), np.int64)


def _vq(V: np.ndarray, Q: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    if Q is None:
        return np.ascontiguousarray(V, dtype=np.float64).reshape(-1, 3), _CORNERS
    return np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(Q, dtype=np.int64)


def crossing(V: np.ndarray, Q: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`ruledmesh.analysis.faces.quad_diagonal_crossing` of quads ``V[Q]``.

    Parameters
    ----------
    V : (n, 3) float64
        Points; (F, 4, 3) corners when ``Q`` is None.
    Q : (F, 4) int, optional
        Quad corners (indices into ``V``) in boundary order.

    Returns
    -------
    s, t, gap : (F,) float64
        As :func:`~ruledmesh.analysis.faces.quad_diagonal_crossing`, bit for bit.
    """
    s, t, gap, _ = _crossing(*_vq(V, Q), False)
    return s, t, gap


def quad_planarity(V: np.ndarray, Q: np.ndarray | None = None) -> np.ndarray:
    """:func:`ruledmesh.analysis.faces.quad_planarity` of quads ``V[Q]``, bit for bit.

    Parameters
    ----------
    V : (n, 3) float64
        Points; (F, 4, 3) corners when ``Q`` is None.
    Q : (F, 4) int, optional

    Returns
    -------
    (F,) float64
    """
    return _crossing(*_vq(V, Q), True)[3]


@nb.njit(cache=True, inline="always")
def _pairwise(x, lo, n):
    """numpy's pairwise sum of ``x[lo:lo + n]`` (n <= 128, the unrolled block)."""
    if n < 8:
        res = -0.0
        for i in range(lo, lo + n):
            res += x[i]
        return res
    r0, r1, r2, r3 = x[lo], x[lo + 1], x[lo + 2], x[lo + 3]
    r4, r5, r6, r7 = x[lo + 4], x[lo + 5], x[lo + 6], x[lo + 7]
    i = 8
    while i < n - n % 8:
        r0 += x[lo + i]
        r1 += x[lo + i + 1]
        r2 += x[lo + i + 2]
        r3 += x[lo + i + 3]
        r4 += x[lo + i + 4]
        r5 += x[lo + i + 5]
        r6 += x[lo + i + 6]
        r7 += x[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += x[lo + i]
        i += 1
    return res


@nb.njit(cache=True, nogil=True)
def _newell(V, idx, off):
    F = off.shape[0] - 1
    vec = np.zeros((F, 3))
    area = np.empty(F)
    normals = np.empty((F, 3))
    cr = np.empty((3, _MAX_CORNERS))
    for f in range(F):
        lo, hi = off[f], off[f + 1]
        n = hi - lo
        o = idx[lo]
        for k in range(n):
            i = idx[lo + k]
            j = idx[lo + k + 1] if k + 1 < n else idx[lo]
            x0, x1, x2 = V[i, 0] - V[o, 0], V[i, 1] - V[o, 1], V[i, 2] - V[o, 2]
            y0, y1, y2 = V[j, 0] - V[o, 0], V[j, 1] - V[o, 1], V[j, 2] - V[o, 2]
            cr[0, k] = x1 * y2 - x2 * y1
            cr[1, k] = x2 * y0 - x0 * y2
            cr[2, k] = x0 * y1 - x1 * y0
        for c in range(3):
            if n == 0:
                continue
            vec[f, c] = 0.5 * (cr[c, 0] + _pairwise(cr[c], 1, n - 1)) if n > 1 else 0.5 * cr[c, 0]
        area[f] = _norm(vec[f, 0], vec[f, 1], vec[f, 2])
        g = _max(area[f], TINY)
        for c in range(3):
            normals[f, c] = vec[f, c] / g
    return normals, area


def newell(V: np.ndarray, idx: np.ndarray, off: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`ruledmesh.analysis.faces.face_normals` of a polygon mesh, bit for bit.

    Parameters
    ----------
    V : (n, 3) float64
    idx : (N,) int
        Face corners, face after face.
    off : (F + 1,) int
        Start of each face in ``idx``.

    Returns
    -------
    normals : (F, 3) float64
    areas : (F,) float64
        Or None for a mesh with a face of more than :data:`_MAX_CORNERS`
        corners (numpy sums those in recursive halves): the caller runs numpy.
    """
    if len(off) > 1 and int(np.diff(off).max()) > _MAX_CORNERS:
        return None
    return _newell(np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(idx),
                   np.ascontiguousarray(off))


@nb.njit(cache=True, nogil=True)
def _min_angles(V, idx, off):
    F = off.shape[0] - 1
    out = np.empty(F)
    for f in range(F):
        lo, hi = off[f], off[f + 1]
        best = math.inf
        nan = False
        for k in range(lo, hi):
            i = idx[k]
            p = idx[k - 1] if k > lo else idx[hi - 1]
            q = idx[k + 1] if k + 1 < hi else idx[lo]
            x0, x1, x2 = V[p, 0] - V[i, 0], V[p, 1] - V[i, 1], V[p, 2] - V[i, 2]
            y0, y1, y2 = V[q, 0] - V[i, 0], V[q, 1] - V[i, 1], V[q, 2] - V[i, 2]
            cos = _dot(x0, x1, x2, y0, y1, y2)
            sin = _norm(x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0)
            ang = _corner_angle(sin, cos)
            if ang != ang:
                nan = True
            elif ang < best:
                best = ang
        out[f] = math.nan if nan else best
    return out


def min_angles(V: np.ndarray, idx: np.ndarray, off: np.ndarray) -> np.ndarray:
    """:func:`ruledmesh.analysis.faces.face_min_angles` of a polygon mesh (degrees).

    Parameters
    ----------
    V : (n, 3) float64
    idx : (N,) int
    off : (F + 1,) int
        Every face has at least one corner.

    Returns
    -------
    (F,) float64
    """
    return _min_angles(np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(idx),
                       np.ascontiguousarray(off))


@nb.njit(cache=True, nogil=True)
def _polygon_angles(P):
    F, k = P.shape[0], P.shape[1]
    out = np.empty((F, k))
    for f in range(F):
        for j in range(k):
            p = j - 1 if j > 0 else k - 1
            q = j + 1 if j + 1 < k else 0
            x0, x1, x2 = P[f, p, 0] - P[f, j, 0], P[f, p, 1] - P[f, j, 1], P[f, p, 2] - P[f, j, 2]
            y0, y1, y2 = P[f, q, 0] - P[f, j, 0], P[f, q, 1] - P[f, j, 1], P[f, q, 2] - P[f, j, 2]
            cos = _dot(x0, x1, x2, y0, y1, y2)
            sin = _norm(x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0)
            out[f, j] = _corner_angle(sin, cos)
    return out


def polygon_angles(corners: np.ndarray) -> np.ndarray:
    """:func:`ruledmesh.analysis.faces.polygon_angles`, bit for bit, without the (F, k, 3) temporaries.

    Parameters
    ----------
    corners : (F, k, 3) float64, k >= 1

    Returns
    -------
    (F, k) float64
        Interior angles, degrees.
    """
    return _polygon_angles(np.ascontiguousarray(corners, dtype=np.float64))


@nb.njit(cache=True, inline="always")
def _angle(X, p, j, q):
    """Interior angle (degrees) at ``X[j]`` between ``X[p]`` and ``X[q]``, as ``polygon_angles``."""
    x0, x1, x2 = X[p, 0] - X[j, 0], X[p, 1] - X[j, 1], X[p, 2] - X[j, 2]
    y0, y1, y2 = X[q, 0] - X[j, 0], X[q, 1] - X[j, 1], X[q, 2] - X[j, 2]
    cos = _dot(x0, x1, x2, y0, y1, y2)
    sin = _norm(x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0)
    return _corner_angle(sin, cos)


@nb.njit(cache=True)
def angle_at(X, p, j, q):
    """:func:`_angle` as a function of its own, for kernels that take many angles: numba
    compiles each inlined copy of its arctangent anew (seven in the grid's sliver test took
    about 9 s to compile), and the called function runs as fast."""
    return _angle(X, p, j, q)


@nb.njit(cache=True, inline="always")
def _triangle_min(V, i, j, k):
    """``polygon_angles(V[[i, j, k]]).min()``: NaN if an angle is."""
    a0, a1, a2 = _angle(V, k, i, j), _angle(V, i, j, k), _angle(V, j, k, i)
    if a0 != a0 or a1 != a1 or a2 != a2:
        return math.nan
    return min(a0, min(a1, a2))


@nb.njit(cache=True)
def _smallest_angle(V, i, j, k):
    """:func:`_triangle_min` as a function of its own: inlined three times over in a kernel it
    took numba ten seconds to compile."""
    return _triangle_min(V, i, j, k)


@nb.njit(cache=True, inline="always")
def _unit_normal(V, p, q, r):
    """``flips._unit_normals`` of one triangle: cross(q - p, r - p) over its norm (at least TINY)."""
    x0, x1, x2 = V[q, 0] - V[p, 0], V[q, 1] - V[p, 1], V[q, 2] - V[p, 2]
    y0, y1, y2 = V[r, 0] - V[p, 0], V[r, 1] - V[p, 1], V[r, 2] - V[p, 2]
    n0, n1, n2 = x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0
    g = _max(_norm(n0, n1, n2), TINY)
    return n0 / g, n1 / g, n2 / g


@nb.njit(cache=True, nogil=True)
def _flip_pairs(V, a, b, c, d, old, gain, bend, max_sag):
    P = a.shape[0]
    new = np.empty(P)
    ok = np.empty(P, np.bool_)
    for k in range(P):
        A, B, C, D = a[k], b[k], c[k], d[k]
        x, y = _smallest_angle(V, A, B, D), _smallest_angle(V, A, D, C)
        nw = math.nan if x != x or y != y else min(x, y)
        new[k] = nw
        p0, p1, p2 = _unit_normal(V, A, B, C)
        q0, q1, q2 = _unit_normal(V, B, D, C)
        r0, r1, r2 = _unit_normal(V, A, B, D)
        s0, s1, s2 = _unit_normal(V, A, D, C)
        e0, e1, e2 = p0 + q0, p1 + q1, p2 + q2
        g = _max(_norm(e0, e1, e2), TINY)
        e0, e1, e2 = e0 / g, e1 / g, e2 / g
        w0 = 0.5 * (V[A, 0] + V[D, 0]) - 0.5 * (V[B, 0] + V[C, 0])
        w1 = 0.5 * (V[A, 1] + V[D, 1]) - 0.5 * (V[B, 1] + V[C, 1])
        w2 = 0.5 * (V[A, 2] + V[D, 2]) - 0.5 * (V[B, 2] + V[C, 2])
        sag = abs(_dot(w0, w1, w2, e0, e1, e2))
        ok[k] = (nw > old[k] + gain and _dot(p0, p1, p2, q0, q1, q2) >= bend
                 and _dot(r0, r1, r2, s0, s1, s2) >= bend and _dot(r0, r1, r2, e0, e1, e2) >= bend
                 and _dot(s0, s1, s2, e0, e1, e2) >= bend and sag <= max_sag and A != D)
    return new, ok


def flip_pairs(V: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray,
               old: np.ndarray, gain: float, bend: float, max_sag: float) -> tuple[np.ndarray, np.ndarray]:
    """The measures of :func:`ruledmesh.skew.pq.flips._pair_measures`, bit for bit.

    Parameters
    ----------
    V : (n, 3) float64
    a, b, c, d : (P,) int
        Pairs of triangles ``(b, c, a)`` and ``(c, b, d)``; the flip makes ``(a, b, d)``, ``(a, d, c)``.
    old : (P,) float64
        The smaller smallest angle of each pair (degrees).
    gain : float
        Degrees the flip must gain.
    bend : float
        Cosine of the largest bend allowed between the normals.
    max_sag : float
        Largest height of the flipped pair over the old one.

    Returns
    -------
    new : (P,) float64
        The flipped pair's smaller smallest angle.
    ok : (P,) bool
        Whether the flip gains and keeps to the surface.
    """
    c_ = np.ascontiguousarray
    return _flip_pairs(c_(V, dtype=np.float64), c_(a, dtype=np.int64), c_(b, dtype=np.int64),
                       c_(c, dtype=np.int64), c_(d, dtype=np.int64), c_(old, dtype=np.float64),
                       float(gain), float(bend), float(max_sag))


@nb.njit(cache=True, inline="always")
def _min(x: float, y: float) -> float:
    """np.minimum: NaN if either is NaN."""
    if x != x or y != y:
        return math.nan
    return x if x <= y else y


@nb.njit(cache=True, inline="always")
def _segment_distance(p0, p1, p2, a0, a1, a2, b0, b1, b2):
    """``collapses._segment_distance`` of one point and segment."""
    e0, e1, e2 = b0 - a0, b1 - a1, b2 - a2
    w0, w1, w2 = p0 - a0, p1 - a1, p2 - a2
    s = _dot(w0, w1, w2, e0, e1, e2) / _max(_dot(e0, e1, e2, e0, e1, e2), TINY)
    # np.clip: NaN stays NaN (both comparisons are false).
    if s < 0.0:
        s = 0.0
    elif s > 1.0:
        s = 1.0
    return _norm(w0 - s * e0, w1 - s * e1, w2 - s * e2)


@nb.njit(cache=True, inline="always")
def _edge_side(x0, x1, x2, y0, y1, y2, q0, q1, q2, n0, n1, n2) -> bool:
    """Whether ``q`` is on the inner side of the edge ``x y`` of a triangle with normal ``n``."""
    e0, e1, e2 = y0 - x0, y1 - x1, y2 - x2
    f0, f1, f2 = q0 - x0, q1 - x1, q2 - x2
    return _dot(e1 * f2 - e2 * f1, e2 * f0 - e0 * f2, e0 * f1 - e1 * f0, n0, n1, n2) >= 0.0


@nb.njit(cache=True)
def _triangle_distance(p0, p1, p2, V, i, j, k):
    """``collapses._triangle_distance`` of the point ``p`` and the triangle ``V[[i, j, k]]``."""
    A0, A1, A2 = V[i, 0], V[i, 1], V[i, 2]
    B0, B1, B2 = V[j, 0], V[j, 1], V[j, 2]
    C0, C1, C2 = V[k, 0], V[k, 1], V[k, 2]
    n0, n1, n2 = _unit_normal(V, i, j, k)
    h = _dot(p0 - A0, p1 - A1, p2 - A2, n0, n1, n2)
    q0, q1, q2 = p0 - h * n0, p1 - h * n1, p2 - h * n2
    if (_edge_side(A0, A1, A2, B0, B1, B2, q0, q1, q2, n0, n1, n2)
            and _edge_side(B0, B1, B2, C0, C1, C2, q0, q1, q2, n0, n1, n2)
            and _edge_side(C0, C1, C2, A0, A1, A2, q0, q1, q2, n0, n1, n2)):
        return abs(h)
    return _min(_min(_segment_distance(p0, p1, p2, A0, A1, A2, B0, B1, B2),
                     _segment_distance(p0, p1, p2, B0, B1, B2, C0, C1, C2)),
                _segment_distance(p0, p1, p2, C0, C1, C2, A0, A1, A2))


@nb.njit(cache=True, inline="always")
def _with(x: int, at: int, corner: int, u: int) -> int:
    """Corner ``at`` of a triangle whose corner ``corner`` is now ``u``; ``x`` was there."""
    return u if at == corner else x


@nb.njit(cache=True)
def _to_collapsed_star(p0, p1, p2, V, tri, order, lo, hi, u, near):
    """``near`` and the distances of ``p`` from the triangles ``order[lo:hi] // 3`` of ``tri``
    with their corner ``order % 3`` moved to ``u``, those on an edge to ``u`` left out; the
    smallest (NaN if one is)."""
    for q in range(lo, hi):
        h = order[q] // 3
        i, j, k = tri[h, 0], tri[h, 1], tri[h, 2]
        if i == u or j == u or k == u:
            continue
        e = order[q] % 3
        near = _min(near, _triangle_distance(p0, p1, p2, V, _with(i, 0, e, u), _with(j, 1, e, u),
                                             _with(k, 2, e, u)))
    return near


@nb.njit(cache=True, nogil=True)
def _collapse_measures(V, tri, order, tri_start, nbr, nbr_start, keys, faces_at, v, u, gain_min,
                       bend, restart, max_sag):
    C, n = v.shape[0], V.shape[0]
    gain = np.empty(C)
    ok = np.zeros(C, np.bool_)
    for c in range(C):
        vc, uc = v[c], u[c]
        lo, hi = tri_start[vc], tri_start[vc + 1]
        old_min, new_min = 180.0, 180.0
        s0, s1, s2 = 0.0, 0.0, 0.0
        for r in range(lo, hi):
            f = order[r] // 3
            i, j, k = tri[f, 0], tri[f, 1], tri[f, 2]
            old_min = _min(old_min, _smallest_angle(V, i, j, k))
            x0, x1, x2 = V[j, 0] - V[i, 0], V[j, 1] - V[i, 1], V[j, 2] - V[i, 2]
            y0, y1, y2 = V[k, 0] - V[i, 0], V[k, 1] - V[i, 1], V[k, 2] - V[i, 2]
            s0 += x1 * y2 - x2 * y1
            s1 += x2 * y0 - x0 * y2
            s2 += x0 * y1 - x1 * y0
        g = _max(_norm(s0, s1, s2), TINY)
        s0, s1, s2 = s0 / g, s1 / g, s2 / g
        good = True
        removed = 0
        for r in range(lo, hi):
            f = order[r] // 3
            i, j, k = tri[f, 0], tri[f, 1], tri[f, 2]
            if i == uc or j == uc or k == uc:
                removed += 1
                third = max(i if i != vc and i != uc else -1,
                            max(j if j != vc and j != uc else -1, k if k != vc and k != uc else -1))
                if faces_at[third if third >= 0 else faces_at.shape[0] - 1] < 2:
                    good = False
                continue
            e = order[r] % 3
            a, b, d = _with(i, 0, e, uc), _with(j, 1, e, uc), _with(k, 2, e, uc)
            new_min = _min(new_min, _smallest_angle(V, a, b, d))
            m0, m1, m2 = _unit_normal(V, a, b, d)
            o0, o1, o2 = _unit_normal(V, i, j, k)
            bent = not (_dot(o0, o1, o2, m0, m1, m2) >= bend or (
                _smallest_angle(V, i, j, k) < restart and _dot(s0, s1, s2, m0, m1, m2) >= bend))
            if bent or _norm(m0, m1, m2) < 0.5:
                good = False
        gain[c] = new_min - old_min
        if not (good and gain[c] > gain_min and removed >= 1 and hi - lo > removed):
            continue
        # Link condition: the neighbours u and v share are the corners opposite their edge.
        common = 0
        for r in range(nbr_start[vc], nbr_start[vc + 1]):
            w = nbr[r]
            if w == uc:
                continue
            key = min(uc, w) * n + max(uc, w)
            at = np.searchsorted(keys, key)
            if at < keys.shape[0] and keys[at] == key:
                common += 1
        if common != removed:
            continue
        # How far the surface moves: v's distance from the faces left around it.
        sag = _to_collapsed_star(V[vc, 0], V[vc, 1], V[vc, 2], V, tri, order, lo, hi, uc, math.inf)
        ok[c] = sag <= max_sag
    return gain, ok


def collapse_measures(V: np.ndarray, tri: np.ndarray, order: np.ndarray, tri_start: np.ndarray,
                      nbr: np.ndarray, nbr_start: np.ndarray, keys: np.ndarray, faces_at: np.ndarray,
                      v: np.ndarray, u: np.ndarray, gain: float, bend: float, restart: float,
                      max_sag: float) -> tuple[np.ndarray, np.ndarray]:
    """The measures of :func:`ruledmesh.skew.pq.collapses._evaluate`, bit for bit.

    Parameters
    ----------
    V : (n, 3) float64
    tri : (T, 3) int
        The triangles around the candidates.
    order, tri_start : (3 T,) int, (n + 1,) int
        The corners of ``tri`` by vertex (``collapses._Stars``).
    nbr, nbr_start : (2 E,) int, (n + 1,) int
        Every vertex's neighbours by vertex.
    keys : (E,) int64
        Sorted undirected edge keys ``lo * n + hi``.
    faces_at : (n,) int
        Faces of the whole mesh at each vertex.
    v, u : (C,) int
        The collapses ``v -> u``.
    gain : float
        Degrees a collapse must gain.
    bend : float
        Cosine of the largest bend of a face's normal.
    restart : float
        Smallest angle (degrees) below which a face's own normal is noise.
    max_sag : float
        Largest distance of ``v`` from the faces left around it.

    Returns
    -------
    gain : (C,) float64
        Gain in smallest angle, degrees.
    ok : (C,) bool
        Whether each collapse may be taken.
    """
    c_ = np.ascontiguousarray
    i64 = np.int64
    return _collapse_measures(c_(V, dtype=np.float64), c_(tri, dtype=i64), c_(order, dtype=i64),
                              c_(tri_start, dtype=i64), c_(nbr, dtype=i64), c_(nbr_start, dtype=i64),
                              c_(keys, dtype=i64), c_(faces_at, dtype=i64), c_(v, dtype=i64),
                              c_(u, dtype=i64), float(gain), float(bend), float(restart),
                              float(max_sag))


@nb.njit(cache=True, nogil=True)
def _ghosts_kept(V, tri, order, tri_start, v, u, ghosts, anchors, by_anchor, sorted_anchors, bound):
    C = v.shape[0]
    ok = np.ones(C, np.bool_)
    seen = np.full(ghosts.shape[0], -1, np.int64)
    for c in range(C):
        vc, uc = v[c], u[c]
        lo, hi = tri_start[vc], tri_start[vc + 1]
        for r in range(lo, hi):
            f = order[r] // 3
            for x in (tri[f, 0], tri[f, 1], tri[f, 2]):
                g_lo = np.searchsorted(sorted_anchors, x)
                g_hi = np.searchsorted(sorted_anchors, x, side="right")
                for s in range(g_lo, g_hi):
                    g = by_anchor[s]
                    if seen[g] == c:
                        continue
                    seen[g] = c
                    p0, p1, p2 = ghosts[g, 0], ghosts[g, 1], ghosts[g, 2]
                    # The collapse's new faces ...
                    near = _to_collapsed_star(p0, p1, p2, V, tri, order, lo, hi, uc, math.inf)
                    # ... or the triangles at the anchor that do not have v for a corner.
                    a = anchors[g]
                    for q in range(tri_start[a], tri_start[a + 1]):
                        h = order[q] // 3
                        i, j, k = tri[h, 0], tri[h, 1], tri[h, 2]
                        if i == vc or j == vc or k == vc:
                            continue
                        near = _min(near, _triangle_distance(p0, p1, p2, V, i, j, k))
                    if near > bound:
                        ok[c] = False
    return ok


def ghosts_kept(V: np.ndarray, tri: np.ndarray, order: np.ndarray, tri_start: np.ndarray, v: np.ndarray,
                u: np.ndarray, ghosts: np.ndarray, anchors: np.ndarray, bound: float) -> np.ndarray:
    """:func:`ruledmesh.skew.pq.collapses._keeps_ghosts`, bit for bit.

    Parameters
    ----------
    V : (n, 3) float64
    tri : (T, 3) int
        The triangles around the candidates.
    order, tri_start : (3 T,) int, (n + 1,) int
        The corners of ``tri`` by vertex (``collapses._Stars``).
    v, u : (C,) int
        The collapses ``v -> u``.
    ghosts : (k, 3) float64
        Vertices removed earlier ...
    anchors : (k,) int
        ... and the vertex each went into.
    bound : float
        Largest distance of a ghost from the faces near it.

    Returns
    -------
    (C,) bool
        The collapses that leave every ghost near a face.
    """
    c_ = np.ascontiguousarray
    i64 = np.int64
    anchors = c_(anchors, dtype=i64)
    by_anchor = np.argsort(anchors, kind="stable")
    return _ghosts_kept(c_(V, dtype=np.float64), c_(tri, dtype=i64), c_(order, dtype=i64),
                        c_(tri_start, dtype=i64), c_(v, dtype=i64), c_(u, dtype=i64),
                        c_(ghosts, dtype=np.float64), anchors, by_anchor, anchors[by_anchor],
                        float(bound))

