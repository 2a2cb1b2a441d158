"""Director curves: lines, polylines, circular arcs, B-splines and helices.

Every curve is an immutable object parametrised over ``u`` in ``[0, 1]``; all
methods are vectorised over ``u`` of any shape ``(...)`` and return
``(..., 3)`` points.  Beyond evaluation the curves answer the questions the
distributions of generators (paper §5, :mod:`ruledmesh.rulings`) ask:

* arc length and its inverse (``arclength``, ``param_at_length``,
  ``arclength_params``), tabulated: the speed sampled at Gauss-Legendre nodes
  of each smooth piece and integrated as its Legendre interpolant, so lengths
  and their inverse (Newton on that series from a cubic Hermite start) need
  no further curve evaluation;
* plane intersections (``intersect_plane``: every root; ``plane_sweep``: one
  branch followed continuously through a pencil of parallel planes).

Plane problems are reduced to a *level function* ``g(u) = n . c(u)`` cut into
monotone pieces at its critical points (found by bracketing the sign changes
of ``g'`` on a grid that is fine for the curve type).  On a monotone piece a
level has at most one root, so ``brentq`` finds it; a touch shows up as a
piece end within tolerance of the level; a branch *ends* where the sweep
passes a piece end at which ``g`` turns back, or an end of the curve.

:func:`ruledmesh.design.curves.curve_from_spec` reads the ``[curves.*]`` tables
of a design file and ``Curve.to_spec`` writes them back
(``curve_from_spec(c.to_spec(), p) == c``).

B-splines are evaluated as one polynomial per knot span (Taylor coefficients
from de Boor's algorithm, once per curve; Horner's rule per call), in numpy, so
building from curves needs no ``scipy`` import: scipy is imported where it is
needed (interpolation through points).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, fields
from enum import Enum
from functools import cached_property
from typing import Any

import numpy as np

from ._arrays import diagonal, unique
from ._validation import (
    check_float,
    check_int,
    check_points,
    check_vector,
    describe,
)
from .errors import GeometryError, ParameterError
from .tolerances import CONVERGED, DEFAULT, PARAMETER_SLACK, ROOT_RTOL, ROOT_XTOL, ROUNDING, TINY, ULPS, Tolerances

__all__ = [
    "CubicHermite",
    "Curve",
    "Line",
    "Polyline",
    "Arc",
    "BSpline",
    "Helix",
    "CurveType",
    "LevelSet",
]

# Gauss-Legendre nodes per arc-length piece; with pieces no longer than half a
# knot span this integrates the speed of smooth splines to ~1e-13.
_GL_NODES = 20
_NEWTON_ITERATIONS = 60
# Arc-length pieces per B-spline knot span (each with _GL_NODES speed samples).
_LENGTH_PIECES_PER_SPAN = 8
# A Newton step this small (in u) ends the iteration.
_NEWTON_FINAL_STEP = ULPS


# --------------------------------------------------------------------------
# small vector helpers
# --------------------------------------------------------------------------

def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def perpendicular(axis: np.ndarray) -> np.ndarray:
    """A deterministic unit vector perpendicular to ``axis``.

    Projects the coordinate axis least aligned with ``axis``, so the same axis
    always gives the same frame (curves read back from a design are equal).
    """
    a = _unit(axis)
    e = np.zeros(3)
    e[int(np.argmin(np.abs(a)))] = 1.0
    return _unit(e - (e @ a) * a)


def _frozen(arr: np.ndarray) -> np.ndarray:
    arr = np.array(arr, dtype=np.float64)
    arr.setflags(write=False)
    return arr


def _params(u: Any, name: str = "u") -> np.ndarray:
    """Curve parameters as a float array of the same shape; finite."""
    try:
        arr = np.asarray(u, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(f"expected numbers, got {describe(u)}", name) from None
    if not np.all(np.isfinite(arr)):
        raise ParameterError("expected finite numbers, got NaN or infinity", name)
    return arr


def _unit_params(u: Any, name: str = "u") -> np.ndarray:
    """Parameters that must lie in [0, 1] (rounding slack allowed, then clipped)."""
    arr = _params(u, name)
    if arr.size and (arr.min() < -ROUNDING or arr.max() > 1.0 + ROUNDING):
        raise ParameterError(
            f"expected values in [0, 1], got values in [{arr.min():g}, {arr.max():g}]", name)
    return np.clip(arr, 0.0, 1.0)


@functools.lru_cache(maxsize=4)
def _gauss_legendre(n: int = _GL_NODES) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


@functools.lru_cache(maxsize=4)
def _legendre_fit(n: int = _GL_NODES) -> tuple[np.ndarray, np.ndarray]:
    """Matrices from values at the ``n`` Gauss-Legendre nodes of [0, 1] to the Legendre
    coefficients (on [0, 1]) of their interpolant ``(n, n)`` and of its antiderivative
    that is zero at 0 ``(n, n + 1)``: discrete orthogonality, exact for degree < n."""
    leg = np.polynomial.legendre
    x, w = leg.leggauss(n)
    basis = leg.legvander(x, n - 1)  # (nodes, degree)
    fit = (basis * w[:, None]).T * ((2 * np.arange(n) + 1) / 2)[:, None]
    # On [0, 1] (xi = 2u - 1) the antiderivative in u is half that in xi.
    integ = 0.5 * leg.legint(np.eye(n), lbnd=-1.0, axis=0).T  # (degree, degree + 1)
    return fit, fit.T @ integ


# (-1)^j: a Legendre series at xi = -1 is sum_j (-1)^j c_j (and at +1, sum_j c_j).
_ALTERNATING = (-1.0) ** np.arange(_GL_NODES + 2)


def _clenshaw(coef: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """(N,) values at ``xi (N,)`` of Legendre series whose ``j``-th coefficients are ``coef[j]``.

    ``coef`` is ``(n, N)``, coefficient first, so each step of the recurrence
    reads one contiguous row (gathered per point from a table stored that way).
    """
    n = coef.shape[0]
    if n == 1:
        return coef[0] + xi * 0.0 - 0.0
    # The first two steps with their zero terms left out: adding a product with a zero
    # b (or subtracting +0) changes no value but the sign of an exact zero.
    b2 = coef[n - 1]
    b1 = coef[n - 2] + (2 * n - 3) / (n - 1) * xi * b2 if n > 2 else b2
    for j in range(n - 3, 0, -1):
        b1, b2 = coef[j] + (2 * j + 1) / (j + 1) * xi * b1 - (j + 1) / (j + 2) * b2, b1
    if n == 2:
        return coef[0] + xi * b1
    return coef[0] + xi * b1 - 0.5 * b2


@dataclass
class _Bracketed:
    """Points of a bracketed Newton solve on the tabulated arc length: piece, iterate, bracket, target."""

    piece: np.ndarray
    u: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    target: np.ndarray

    def keep(self, live: np.ndarray) -> _Bracketed:
        return _Bracketed(self.piece[live], self.u[live], self.lo[live], self.hi[live], self.target[live])


def _newton_on_lengths(both: np.ndarray, pieces: np.ndarray, cum: np.ndarray, pts: _Bracketed,
                       scale: float) -> np.ndarray:
    """(N,) parameters where the arc-length series reach ``pts.target``: Newton kept in the bracket.

    Parameters
    ----------
    both : (n, 2, p) float64
        The arc-length and speed series per piece (:attr:`Curve._newton_series`).
    pieces, cum : (p + 1,) float64
        Piece ends and the arc length there.
    pts : _Bracketed
        The start: iterates inside their brackets ``[lo, hi]`` on their pieces.
    scale : float
        A residual below :data:`CONVERGED` times this is exact.

    Returns
    -------
    (N,) float64
        A step of at most :data:`_NEWTON_FINAL_STEP` ends a point's iteration (or
        an exact residual, or :data:`_NEWTON_ITERATIONS` steps).
    """
    out = pts.u.copy()
    todo = np.arange(out.size)
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(_NEWTON_ITERATIONS):
            k, u = pts.piece, pts.u
            width = pieces[k + 1] - pieces[k]
            xi = 2.0 * (u - pieces[k]) / width - 1.0
            # Both series in one pass: the arc lengths, then the speeds, side by side.
            m = k.size
            series = _clenshaw(both[:, :, k].reshape(len(both), 2 * m), np.concatenate([xi, xi]))
            f = cum[k] + width * series[:m] - pts.target
            lo, hi = np.where(f < 0, u, pts.lo), np.where(f > 0, u, pts.hi)
            new = u - f / series[m:]
            new = np.where(~np.isfinite(new) | (new < lo) | (new > hi), 0.5 * (lo + hi), new)
            exact = np.abs(f) <= CONVERGED * scale
            step = np.where(exact, u, new)
            out[todo] = step
            live = ~(exact | (np.abs(new - u) <= _NEWTON_FINAL_STEP))
            if not live.any():
                break
            pts = _Bracketed(k, step, lo, hi, pts.target).keep(live)
            todo = todo[live]
    return out


class CubicHermite:
    """The piecewise cubic through ``(x, y)`` with slopes ``dydx`` (C1), in numpy.

    Parameters
    ----------
    x : (n,) float64
        Strictly increasing.
    y, dydx : (n, ...) float64

    Calling it with ``(...)`` points gives ``(..., *y.shape[1:])`` values
    (``nu=1``: first derivatives); outside ``[x[0], x[-1]]`` the end cubics
    continue.  The same interpolant as ``scipy.interpolate.CubicHermiteSpline``.
    """

    def __init__(self, x: np.ndarray, y: np.ndarray, dydx: np.ndarray):
        self.x = np.asarray(x, dtype=np.float64)
        self.y = np.asarray(y, dtype=np.float64)
        self.dydx = np.asarray(dydx, dtype=np.float64)

    def __call__(self, u: Any, nu: int = 0) -> np.ndarray:
        u = np.asarray(u, dtype=np.float64)
        x = self.x
        k = np.clip(np.searchsorted(x, u, side="right") - 1, 0, len(x) - 2)
        h = x[k + 1] - x[k]
        t = (u - x[k]) / h
        extra = (slice(None),) * u.ndim + (None,) * (self.y.ndim - 1)
        y0, y1 = self.y[k], self.y[k + 1]
        m0, m1 = self.dydx[k] * h[extra], self.dydx[k + 1] * h[extra]
        t = t[extra]
        if nu == 0:
            t2 = t * t
            t3 = t2 * t
            return ((2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + t) * m0
                    + (-2 * t3 + 3 * t2) * y1 + (t3 - t2) * m1)
        t2 = t * t
        return ((6 * t2 - 6 * t) * (y0 - y1) + (3 * t2 - 4 * t + 1) * m0
                + (3 * t2 - 2 * t) * m1) / h[extra]


def _de_boor(knots: np.ndarray, control: np.ndarray, degree: int, x: np.ndarray) -> np.ndarray:
    """(..., d) points of the B-spline ``(knots, control, degree)`` at knot values ``x``.

    Each ``x`` is evaluated on the knot span that holds it (the first or last
    valid span outside the domain, so the end polynomials continue), by de
    Boor's algorithm: one array operation per step of the triangle.
    """
    n = len(control)
    flat = x.ravel()
    span = np.clip(np.searchsorted(knots, flat, side="right") - 1, degree, n - 1)
    # d[:, j] is the triangle's entry j; each step updates the entries r..degree at once
    # (from the previous step's values, as the classic loop from j = degree down does).
    d = control[span[:, None] + np.arange(-degree, 1)]  # (N, degree + 1, dim)
    j = np.arange(degree + 1)
    for r in range(1, degree + 1):
        left = knots[span[:, None] + (j[r:] - degree)]
        denom = knots[span[:, None] + (j[r:] + 1 - r)] - left
        alpha = np.divide(flat[:, None] - left, denom, out=np.zeros(denom.shape), where=denom > 0)
        d[:, r:] = (1.0 - alpha)[..., None] * d[:, r - 1:-1] + alpha[..., None] * d[:, r:]
    return d[:, degree].reshape(x.shape + (control.shape[1],))


# From this many points, curves are evaluated one coordinate at a time: numpy's loops over
# the innermost axis of (N, 3) arrays run 3 numbers per call, several times slower than the
# arithmetic on a few thousand points (the closeness analysis evaluates tens of thousands).
# Below it the whole points are cheaper.  The numbers are the same either way.
_BY_COLUMNS = 256


def _by_columns(column: Callable[[int], np.ndarray], shape: tuple[int, ...]) -> np.ndarray:
    """``(*shape, 3)`` points whose coordinate ``x`` is ``column(x)`` (an array of ``shape``)."""
    out = np.empty(shape + (3,))
    for x in range(3):
        out[..., x] = column(x)
    return out


def _horner_by_columns(u: np.ndarray, start: np.ndarray, width: np.ndarray,
                       coef: np.ndarray) -> np.ndarray:
    """(N, 3): the span polynomials ``coef`` (spans, terms, 3) at ``u`` (N,), one coordinate at
    a time, with the steps of :meth:`BSpline._poly`'s Horner rule (so the same numbers)."""
    if len(start) == 1:
        tau = (u - start[0]) / width[0]
        terms = coef[0]
    else:
        k = np.clip(np.searchsorted(start, u, side="right") - 1, 0, len(start) - 1)
        tau = (u - start[k]) / width[k]
        terms = coef[k].transpose(1, 2, 0)  # (terms, 3, N): a row per coefficient and coordinate

    def column(x: int) -> np.ndarray:
        out = np.broadcast_to(terms[-1, x], u.shape)
        for j in range(terms.shape[0] - 2, -1, -1):
            out = out * tau + terms[j, x]
        return out

    return _by_columns(column, u.shape)


# --------------------------------------------------------------------------
# level functions: monotone pieces, all roots, branch following
# --------------------------------------------------------------------------

class _LiesInLevel(Exception):
    """The level function equals the target everywhere (curve in the plane)."""


class LevelSet:
    """A continuous scalar function ``g`` on [0, 1] cut into monotone pieces.

    Parameters
    ----------
    g, dg : callable
        Vectorised ``g(u)`` and ``g'(u)``; ``g`` continuous on [0, 1], smooth
        between the nodes of ``grid``.
    grid : (k,) float64
        Sorted parameters including every kink; fine enough that ``g'``
        changes sign at most once between neighbours.
    tol : float
        Absolute tolerance on ``g`` (touches, in-plane test).
    """

    def __init__(self, g: Callable, dg: Callable, grid: np.ndarray, tol: float):
        grid = unique(np.concatenate([[0.0, 1.0], np.clip(grid, 0.0, 1.0)]))
        a, b = grid[:-1], grid[1:]
        # one-sided derivatives just inside each interval, so kinks at nodes
        # never fake a critical point inside an interval
        delta = PARAMETER_SLACK * (b - a)
        dl, dr = dg(a + delta), dg(b - delta)
        def slope(x):
            return float(dg(np.float64(x)))

        crit = []
        signs = np.nonzero(dl * dr < 0)[0]
        if signs.size:
            from .roots import brentq
        for i in signs:
            lo, hi = a[i] + delta[i], b[i] - delta[i]
            # Evaluated one by one, a derivative at rounding level (a curve
            # lying almost in a level plane) may lose its sign change: no root.
            if slope(lo) * slope(hi) < 0:
                crit.append(brentq(slope, lo, hi, xtol=ROOT_XTOL, rtol=ROOT_RTOL))
        self.g, self.dg = g, dg
        self.tol = float(tol)
        self.nodes = unique(np.concatenate([grid, crit]))
        self.values = np.asarray(g(self.nodes), dtype=np.float64)

    @property
    def range(self) -> tuple[float, float]:
        return float(self.values.min()), float(self.values.max())

    def solve(self, pieces: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """Roots of ``g = targets[i]`` on monotone ``pieces[i]``, vectorised.

        Safeguarded Newton (bisection when a step leaves the bracket); a
        target just beyond the piece's range (within tolerance) gives the
        nearer end.
        """
        pieces = np.asarray(pieces, dtype=np.int64)
        targets = np.asarray(targets, dtype=np.float64)
        a, b = self.nodes[pieces].copy(), self.nodes[pieces + 1].copy()
        fa = self.values[pieces] - targets
        fb = self.values[pieces + 1] - targets
        outside = fa * fb > 0
        x = np.where(np.abs(fa) <= np.abs(fb), a, b)
        live = ~outside & (fa != 0) & (fb != 0)
        if np.any(live):
            den = np.where(live, fb - fa, 1.0)
            x = np.where(live, a - fa * (b - a) / den, x)
            x = np.clip(x, a, b)
            for _ in range(_NEWTON_ITERATIONS):
                fx = np.asarray(self.g(x), dtype=np.float64) - targets
                same = np.sign(fx) == np.sign(fa)
                a, fa = np.where(same, x, a), np.where(same, fx, fa)
                b, fb = np.where(same, b, x), np.where(same, fb, fx)
                d = np.asarray(self.dg(x), dtype=np.float64)
                with np.errstate(divide="ignore", invalid="ignore"):
                    new = x - fx / d
                bad = ~np.isfinite(new) | (new <= np.minimum(a, b)) | (new >= np.maximum(a, b))
                new = np.where(bad, 0.5 * (a + b), new)
                done = (fx == 0) | (np.abs(new - x) <= CONVERGED * np.maximum(np.abs(x), TINY))
                x = np.where(live & ~done, new, x)
                live = live & ~done
                if not np.any(live):
                    break
        return np.where(fa == 0, a, np.where(fb == 0, b, x))

    def roots(self, target: float) -> np.ndarray:
        """All ``u`` with ``g(u) = target``, sorted; touches within ``tol``.

        Raises ``_LiesInLevel`` when ``g`` equals ``target`` everywhere.
        """
        f = self.values - target
        # monotone pieces: node values bound g everywhere
        if np.all(np.abs(f) <= self.tol):
            raise _LiesInLevel
        cross = np.nonzero(f[:-1] * f[1:] < 0)[0]
        cand = np.concatenate([self.solve(cross, np.full(len(cross), target)),
                               self.nodes[np.abs(f) <= self.tol]])
        if len(cand) == 0:
            return np.zeros(0)
        cand = np.sort(cand)
        err = np.abs(np.asarray(self.g(cand)) - target)
        mids = np.abs(np.asarray(self.g(0.5 * (cand[:-1] + cand[1:]))) - target)
        # merge neighbours with g within tol all the way between them (one
        # touch seen from several nodes), keeping the most accurate one
        keep = [0]
        for j in range(1, len(cand)):
            i = keep[-1]
            same = cand[j] - cand[i] <= ULPS or (
                err[i] <= self.tol and err[j] <= self.tol and mids[j - 1] <= self.tol)
            if same:
                if err[j] < err[i]:
                    keep[-1] = j
            else:
                keep.append(j)
        return cand[keep]

    def _reaches(self, piece: int, target: float) -> bool:
        lo, hi = sorted((self.values[piece], self.values[piece + 1]))
        return lo - self.tol <= target <= hi + self.tol

    def _start_piece(self, u0: float, target: float | None) -> int:
        """The piece holding ``u0``; at a node, the one moving towards ``target``."""
        k = len(self.nodes) - 1
        j = int(np.clip(np.searchsorted(self.nodes, u0, side="right") - 1, 0, k - 1))
        cands = [j]
        if u0 == self.nodes[j] and j > 0:
            cands = [j, j - 1]  # ties go towards u = 1
        if target is None or len(cands) == 1:
            return cands[0]
        g0 = float(self.g(np.float64(u0)))
        for p in cands:
            far = self.values[p + 1] if p == j else self.values[p]
            if (far - g0) * (target - g0) > 0:
                return p
        return cands[0]

    def follow(self, targets: np.ndarray, u0: float) -> tuple[np.ndarray, np.ndarray, tuple | None]:
        """Follow the branch through ``u0`` along the level sequence ``targets``.

        ``targets[0]`` is ``g(u0)`` (within tolerance); the sequence need not
        be monotone.  Returns ``(u, ok, end)``: ``u`` (k,) with the last
        reached value repeated after the branch ends, ``ok`` (k,) bool, and
        ``end`` = ``None`` or ``(index, reason, u_end)``: where and why the
        branch ended.
        """
        k_last = len(self.nodes) - 1
        n = len(targets)
        pieces = np.zeros(n, dtype=np.int64)
        end = None
        piece = self._start_piece(u0, float(targets[1]) if n > 1 else None)
        reached = n
        for i in range(1, n):
            target = float(targets[i])
            while end is None and not self._reaches(piece, target):
                v0, v1 = self.values[piece], self.values[piece + 1]
                if v1 != v0:
                    forward = (v1 - v0) * (target - v1) > 0
                else:  # flat piece: go on towards the neighbour that moves towards target
                    forward = piece + 2 <= k_last and (
                        (self.values[piece + 2] - v1) * (target - v1) > 0)
                node = piece + 1 if forward else piece
                if node == 0 or node == k_last:
                    end = (i, "reaches the end of the curve", float(self.nodes[node]))
                    break
                nxt = node if forward else node - 1
                step = self.values[nxt + 1] - self.values[nxt]
                if not forward:
                    step = -step
                if step * (target - self.values[node]) < 0:
                    end = (i, "turns back", float(self.nodes[node]))
                    break
                piece = nxt
            if end is not None:
                reached = i
                break
            pieces[i] = piece
        u = np.empty(n)
        u[0] = u0
        if reached > 1:
            u[1:reached] = self.solve(pieces[1:reached], np.asarray(targets[1:reached], float))
        u[reached:] = u[reached - 1]
        ok = np.zeros(n, dtype=bool)
        ok[:reached] = True
        return u, ok, end


# --------------------------------------------------------------------------
# the curve base class
# --------------------------------------------------------------------------

class CurveType(Enum):
    """Curve types of a design file's ``[curves.*]`` tables."""

    LINE = "line"
    POLYLINE = "polyline"
    ARC = "arc"
    BSPLINE = "bspline"
    HELIX = "helix"


class Curve:
    """Base of the curve types: arc length, plane intersections, specs.

    Subclasses are frozen dataclasses implementing ``_eval(u)``,
    ``_deriv(u, order)``, ``_breaks()`` (parameters of kinks and smooth
    pieces, including 0 and 1), ``_level_grid()`` (a grid on which a plane's
    level function has at most one critical point per interval) and
    ``to_spec()``.
    """

    # --- equality on field values (fields are arrays) ---------------------
    def _key(self) -> tuple:
        out = []
        for f in fields(self):  # type: ignore[arg-type]
            v = getattr(self, f.name)
            if isinstance(v, np.ndarray):
                out.append((v.shape, v.tobytes()))
            else:
                out.append(v)
        return (type(self).__name__, tuple(out))

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    # --- to implement ------------------------------------------------------
    def _eval(self, u: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _deriv(self, u: np.ndarray, order: int) -> np.ndarray:
        raise NotImplementedError

    def _breaks(self) -> np.ndarray:
        return np.array([0.0, 1.0])

    def _level_grid(self) -> np.ndarray:
        return np.linspace(0.0, 1.0, 65)

    def to_spec(self) -> dict:
        """A design-file table that :func:`~ruledmesh.design.curves.curve_from_spec` reads back."""
        raise NotImplementedError

    # --- evaluation --------------------------------------------------------
    def evaluate(self, u: Any) -> np.ndarray:
        """Points of the curve.

        Parameters
        ----------
        u : (...) array_like of float
            Parameters, normally in [0, 1] (outside, the curve's natural
            extension is returned).

        Returns
        -------
        points : (..., 3) float64
        """
        return self._eval(_params(u))

    def derivative(self, u: Any, order: int = 1) -> np.ndarray:
        """Derivative of order ``order`` (>= 1) with respect to ``u``.

        Parameters
        ----------
        u : (...) array_like of float
        order : int

        Returns
        -------
        vectors : (..., 3) float64
            At a kink (polyline vertex) the derivative of the piece after it.
        """
        order = check_int(order, "order", lo=1)
        return self._deriv(_params(u), order)

    def sample(self, count: int) -> np.ndarray:
        """``count`` points at equal parameter steps, ends included: (count, 3)."""
        count = check_int(count, "count", lo=2)
        return self._eval(np.linspace(0.0, 1.0, count))

    # --- kernels: for callers that already hold float64 parameter arrays -----
    # The checked methods above validate their input; these skip the checks
    # (the generators evaluate curves inside Newton and root-finding loops, where
    # a non-finite iterate must give NaN, not an error) and compute the same values.
    def point_at(self, u: np.ndarray) -> np.ndarray:
        """Points ``c(u)`` at float64 parameters, unchecked: what :meth:`evaluate` computes.

        Parameters
        ----------
        u : (...) float64

        Returns
        -------
        points : (..., 3) float64
        """
        return self._eval(u)

    def tangent_at(self, u: np.ndarray) -> np.ndarray:
        """First derivatives ``c'(u)`` at float64 parameters, unchecked.

        Parameters
        ----------
        u : (...) float64

        Returns
        -------
        vectors : (..., 3) float64
            At a kink the derivative of the piece after it.
        """
        return self._deriv(u, 1)

    def speed_at(self, u: np.ndarray) -> np.ndarray:
        """Speeds ``|c'(u)|`` (arc length per unit of ``u``) at float64 parameters: (...) float64."""
        return self._speed(u)

    def param_at_fraction(self, f: np.ndarray) -> np.ndarray:
        """Parameters at arc-length fractions ``f`` of the whole length, clipped to [0, 1].

        Parameters
        ----------
        f : (...) float64
            Fractions of :meth:`length`; outside [0, 1] they clip to the ends.

        Returns
        -------
        u : (...) float64 in [0, 1]
        """
        return self._param_at_length(f * self.length())

    @property
    def size(self) -> float:
        """Characteristic size (diagonal of a sampled bounding box) that relative tolerances scale by."""
        return self._size

    def breaks(self) -> np.ndarray:
        """Parameters of the kinks and smooth-piece ends, 0 and 1 included: (k,) float64 sorted."""
        return self._breaks()

    def level_grid(self) -> np.ndarray:
        """Parameters between which a plane's height function has at most one critical point: (k,) float64."""
        return self._level_grid()

    def height_function(self, unit_normal: np.ndarray, tol: Tolerances = DEFAULT) -> LevelSet:
        """The height ``u -> unit_normal . c(u)`` cut into monotone pieces, for plane intersections.

        Parameters
        ----------
        unit_normal : (3,) float64, unit length
        tol : Tolerances
            ``tol.degenerate`` times :attr:`size` is the absolute tolerance of touches.

        Returns
        -------
        LevelSet
        """
        return self._plane_level(unit_normal, tol)

    @cached_property
    def _size(self) -> float:
        """Characteristic size (diagonal of a sampled bounding box) for tolerances."""
        pts = self._eval(np.linspace(0.0, 1.0, 129))
        diag = diagonal(pts)
        return diag if diag > 0 else 1.0

    def bounding_box(self) -> np.ndarray:
        """Axis-aligned bounding box ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]``: (2, 3).

        Exact up to root finding: each coordinate's extremes are taken at the
        ends, the kinks and the critical points of that coordinate.
        """
        lo, hi = np.empty(3), np.empty(3)
        for k in range(3):
            e = np.zeros(3)
            e[k] = 1.0
            level = self._plane_level(e, DEFAULT)
            lo[k], hi[k] = level.range
        return np.stack([lo, hi])

    # --- arc length ----------------------------------------------------------
    def _speed(self, u: np.ndarray) -> np.ndarray:
        return np.linalg.norm(self._deriv(u, 1), axis=-1)

    @cached_property
    def _length_table(self) -> tuple[np.ndarray, np.ndarray]:
        """Piece starts (p,) + end, and cumulative length at each of them."""
        pieces, cum, _, _ = self._length_series
        return pieces, cum

    @cached_property
    def _length_series(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The tabulated arc length: per piece, Legendre series of the speed and of its integral.

        The speed is sampled at :data:`_GL_NODES` Gauss-Legendre nodes of
        each piece; its interpolant integrates to the Gauss-Legendre sum over
        the whole piece (so the lengths at piece ends are the quadrature's),
        and in between its antiderivative is the arc length, to the same
        accuracy, without evaluating the curve again.

        Returns
        -------
        pieces : (p + 1,) float64
        cum : (p + 1,) float64
            Arc length at each piece end.
        speed : (p, n) float64
            Legendre coefficients (on each piece, ``u`` mapped to [-1, 1]) of
            the speed, d s / d u.
        length : (p, n + 1) float64
            Coefficients of the arc length from the piece start (in units of
            the piece width: multiply by it).
        """
        pieces = self._length_pieces()
        x, w = _gauss_legendre()
        a, b = pieces[:-1], pieces[1:]
        nodes = a[:, None] + (b - a)[:, None] * x[None, :]
        values = self._speed(nodes)
        seg = (b - a) * (values @ w)
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        fit, integ = _legendre_fit()
        speed, length = values @ fit.T, values @ integ
        # Drop the trailing coefficients that are below rounding on every piece: smooth
        # pieces need far fewer than the nodes, and each one costs a Clenshaw step.
        keep = np.abs(length).max(axis=0) > ULPS * max(float(np.abs(length).max()), TINY)
        n = max(int(np.flatnonzero(keep)[-1]) + 1 if keep.any() else 1, 2)
        return pieces, cum, speed[:, :max(n - 1, 1)], length[:, :n]

    def _length_pieces(self) -> np.ndarray:
        return self._breaks()

    @cached_property
    def _newton_series(self) -> np.ndarray:
        """(n, 2, p) float64: coefficient ``j`` of each piece's arc-length series (``[j, 0]``)
        and of its speed series (``[j, 1]``, a zero appended: a leading zero changes no
        value of Clenshaw's sum), laid out for :func:`_clenshaw` to read rows of."""
        _, _, speed, length = self._length_series
        both = np.zeros((length.shape[1], 2, len(length)))
        both[:, 0] = length.T
        both[:speed.shape[1], 1] = speed.T
        return both

    def length(self) -> float:
        """Total arc length."""
        return float(self._length_table[1][-1])

    def _series_at(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Piece index, local coordinate in [-1, 1] and piece width at each ``u``."""
        pieces = self._length_series[0]
        k = np.clip(np.searchsorted(pieces, u, side="right") - 1, 0, len(pieces) - 2)
        width = pieces[k + 1] - pieces[k]
        return k, 2.0 * (u - pieces[k]) / width - 1.0, width

    def _arclength(self, u: np.ndarray) -> np.ndarray:
        cum = self._length_series[1]
        flat = u.ravel()
        k, xi, width = self._series_at(flat)
        return (cum[k] + width * _clenshaw(self._newton_series[:, 0, k], xi)).reshape(u.shape)

    def arclength(self, u: Any) -> np.ndarray:
        """Arc length from ``c(0)`` to ``c(u)``.

        Parameters
        ----------
        u : (...) array_like of float in [0, 1]

        Returns
        -------
        s : (...) float64
        """
        return self._arclength(_unit_params(u))

    def _param_at_length(self, s: np.ndarray) -> np.ndarray:
        pieces, cum, speed_c, _ = self._length_series
        total = cum[-1]
        flat = np.clip(s.ravel(), 0.0, total)
        # The piece holding each length, then Newton on the piece's arc-length series
        # (slope: its speed series, so convergence is quadratic), kept in a bracket.
        k = np.clip(np.searchsorted(cum, flat, side="right") - 1, 0, len(pieces) - 2)
        lo, hi = pieces[k].copy(), pieces[k + 1].copy()
        width = hi - lo
        span = cum[k + 1] - cum[k]
        frac = np.divide(flat - cum[k], span, out=np.zeros_like(flat), where=span > 0)
        u = lo + frac * width
        # Start from the cubic Hermite in s through the piece ends (du/ds = 1 / speed there):
        # then Newton needs a step or two.
        ends = speed_c[k]
        v0, v1 = ends @ _ALTERNATING[:ends.shape[1]], ends.sum(axis=1)  # speed at xi = -1, +1
        with np.errstate(divide="ignore", invalid="ignore"):
            m0, m1 = span / (v0 * width), span / (v1 * width)
            t = frac
            guess = lo + width * ((-2 * t + 3) * t * t + (t * t - 2 * t + 1) * t * m0
                                  + (t * t - t) * t * m1)
        good = np.isfinite(guess) & (guess >= lo) & (guess <= hi) & (v0 > 0) & (v1 > 0)
        u = np.where(good, guess, u)
        u = _newton_on_lengths(self._newton_series, pieces, cum, _Bracketed(k, u, lo, hi, flat),
                               max(total, TINY))
        u = np.where(flat <= 0.0, 0.0, np.where(flat >= total, 1.0, u))
        return u.reshape(s.shape)

    def param_at_length(self, s: Any) -> np.ndarray:
        """Parameter ``u`` with ``arclength(u) == s``: the inverse of :meth:`arclength`.

        Parameters
        ----------
        s : (...) array_like of float in [0, length()]

        Returns
        -------
        u : (...) float64 in [0, 1]
        """
        arr = _params(s, "s")
        total = self.length()
        slack = ROUNDING * max(total, 1.0)
        if arr.size and (arr.min() < -slack or arr.max() > total + slack):
            raise ParameterError(
                f"expected lengths in [0, {total:g}], got values in [{arr.min():g}, {arr.max():g}]",
                "s")
        return self._param_at_length(arr)

    def arclength_params(self, count: int) -> np.ndarray:
        """Parameters dividing the curve into ``count - 1`` arcs of equal length.

        Returns
        -------
        u : (count,) float64, ``u[0] == 0`` and ``u[-1] == 1``
        """
        count = check_int(count, "count", lo=2)
        u = self._param_at_length(np.linspace(0.0, self.length(), count))
        u[0], u[-1] = 0.0, 1.0
        return u

    # --- planes ----------------------------------------------------------------
    def _plane_level(self, unit_normal: np.ndarray, tol: Tolerances) -> LevelSet:
        n = unit_normal
        return LevelSet(lambda u: self._eval(np.asarray(u, dtype=np.float64)) @ n,
                      lambda u: self._deriv(np.asarray(u, dtype=np.float64), 1) @ n,
                      np.concatenate([self._level_grid(), self._breaks()]),
                      tol.degenerate * self._size)

    def intersect_plane(self, normal: Any, offset: float, *, tol: Tolerances = DEFAULT) -> np.ndarray:
        """All parameters where the curve meets the plane ``normal . x = offset``.

        Parameters
        ----------
        normal : (3,) array_like, non-zero (need not be a unit vector)
        offset : float
        tol : Tolerances
            ``tol.degenerate`` (relative to the curve's size) decides touches
            and the in-plane test.

        Returns
        -------
        u : (k,) float64, sorted, in [0, 1]; empty when the curve misses the
            plane.  A tangential touch counts once.

        Raises
        ------
        GeometryError
            The curve lies in the plane.
        """
        n = check_vector(normal, "normal", nonzero=True)
        offset = check_float(offset, "offset")
        scale = float(np.linalg.norm(n))
        level = self._plane_level(n / scale, tol)
        try:
            return level.roots(offset / scale)
        except _LiesInLevel:
            raise GeometryError(
                f"the {type(self).__name__.lower()} lies in the plane {_plane_text(n, offset)}: "
                "its intersection is the whole curve, not isolated points") from None

    def plane_sweep(self, normal: Any, offsets: Any, *, start_u: float | None = None,
                    tol: Tolerances = DEFAULT) -> tuple[np.ndarray, np.ndarray]:
        """Follow one intersection point through the planes ``normal . x = offsets[i]``.

        The branch starts at the root for ``offsets[0]`` nearest ``u = 0`` (or
        nearest ``start_u``) and continues through the monotone piece of
        ``normal . c(u)`` that holds it, so it is the continuous branch, not
        just the nearest root.  It ends where the curve turns back (the planes
        become tangent) or the curve ends.

        Parameters
        ----------
        normal : (3,) array_like, non-zero
        offsets : (k,) array_like, monotone (non-decreasing or non-increasing)
        start_u : float, optional
        tol : Tolerances

        Returns
        -------
        u : (k,) float64
            The branch's parameters; after the branch ends, the last reached
            value is repeated (never NaN).
        ok : (k,) bool
            True where the branch meets the plane.
        """
        u, ok, _ = self._sweep(normal, offsets, start_u, tol)
        return u, ok

    def _sweep(self, normal: Any, offsets: Any, start_u: float | None,
               tol: Tolerances) -> tuple[np.ndarray, np.ndarray, tuple | None]:
        n = check_vector(normal, "normal", nonzero=True)
        s = _params(offsets, "offsets")
        if s.ndim != 1 or len(s) == 0:
            raise ParameterError(f"expected a non-empty list of numbers, got {describe(offsets)}",
                                 "offsets")
        d = np.diff(s)
        if not (np.all(d >= 0) or np.all(d <= 0)):
            raise ParameterError("expected a monotone sequence of offsets", "offsets")
        if start_u is not None:
            start_u = check_float(start_u, "start_u", lo=0.0, hi=1.0)
        scale = float(np.linalg.norm(n))
        level = self._plane_level(n / scale, tol)
        targets = s / scale
        try:
            roots = level.roots(float(targets[0]))
        except _LiesInLevel:
            raise GeometryError(
                f"the {type(self).__name__.lower()} lies in the plane "
                f"{_plane_text(n, float(s[0]))}") from None
        if len(roots) == 0:
            u = np.full(len(s), 0.0 if start_u is None else start_u)
            return u, np.zeros(len(s), dtype=bool), (0, "does not meet the first plane", None)
        ref = 0.0 if start_u is None else start_u
        u0 = float(roots[np.argmin(np.abs(roots - ref))])
        return level.follow(targets, u0)


def _plane_text(n: np.ndarray, offset: float) -> str:
    return f"{np.array2string(n, separator=', ')} . x = {offset:g}"


def _check_distinct(points: np.ndarray, name: str) -> None:
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    size = diagonal(points)
    bad = np.nonzero(seg <= DEFAULT.degenerate * max(size, TINY))[0]
    if len(bad):
        i = int(bad[0])
        raise ParameterError(f"points {i} and {i + 1} coincide; consecutive points must differ",
                             name)


def _as_list(v: np.ndarray) -> list:
    return np.asarray(v, dtype=np.float64).tolist()


# --------------------------------------------------------------------------
# curve types
# --------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Line(Curve):
    """The segment ``c(u) = p0 + u (p1 - p0)``.

    Parameters
    ----------
    p0, p1 : (3,) float64, distinct
    """

    p0: np.ndarray
    p1: np.ndarray

    def __post_init__(self) -> None:
        p0 = check_vector(self.p0, "p0")
        p1 = check_vector(self.p1, "p1")
        if np.linalg.norm(p1 - p0) <= DEFAULT.degenerate * max(np.abs(p0).max(), np.abs(p1).max(), TINY):
            raise ParameterError("p0 and p1 coincide; a line needs two distinct points", "p1")
        object.__setattr__(self, "p0", _frozen(p0))
        object.__setattr__(self, "p1", _frozen(p1))

    def _eval(self, u):
        return self.p0 + u[..., None] * (self.p1 - self.p0)

    def _deriv(self, u, order):
        d = (self.p1 - self.p0) if order == 1 else np.zeros(3)
        return np.broadcast_to(d, u.shape + (3,)).copy()

    def _level_grid(self):
        return np.array([0.0, 1.0])

    def length(self) -> float:
        return float(np.linalg.norm(self.p1 - self.p0))

    def _arclength(self, u):
        return u * self.length()

    def _param_at_length(self, s):
        return np.clip(s / self.length(), 0.0, 1.0)

    def to_spec(self) -> dict:
        return {"type": "line", "points": [_as_list(self.p0), _as_list(self.p1)]}


@dataclass(frozen=True, eq=False)
class Polyline(Curve):
    """A polygon through ``points``, ``u`` proportional to cumulative chord length.

    Parameters
    ----------
    points : (n, 3) float64, n >= 2, consecutive points distinct
    """

    points: np.ndarray

    def __post_init__(self) -> None:
        pts = check_points(self.points, "points", min_count=2)
        _check_distinct(pts, "points")
        object.__setattr__(self, "points", _frozen(pts))

    @cached_property
    def _knots(self) -> np.ndarray:
        seg = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        k = cum / cum[-1]
        k[-1] = 1.0
        return k

    def _segment(self, u):
        k = self._knots
        return np.clip(np.searchsorted(k, u, side="right") - 1, 0, len(k) - 2)

    def _eval(self, u):
        k = self._knots
        i = self._segment(u)
        f = (u - k[i]) / (k[i + 1] - k[i])
        p = self.points
        if f.size >= _BY_COLUMNS:
            return _by_columns(lambda x: p[i, x] + f * (p[i + 1, x] - p[i, x]), f.shape)
        return p[i] + f[..., None] * (p[i + 1] - p[i])

    def _deriv(self, u, order):
        if order > 1:
            return np.zeros(u.shape + (3,))
        k = self._knots
        i = self._segment(u)
        p, h = self.points, k[i + 1] - k[i]
        if h.size >= _BY_COLUMNS:
            return _by_columns(lambda x: (p[i + 1, x] - p[i, x]) / h, h.shape)
        return (p[i + 1] - p[i]) / h[..., None]

    def _breaks(self):
        return self._knots

    def _level_grid(self):
        return self._knots

    def length(self) -> float:
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    def _arclength(self, u):
        return u * self.length()

    def _param_at_length(self, s):
        return np.clip(s / self.length(), 0.0, 1.0)

    def bounding_box(self) -> np.ndarray:
        return np.stack([self.points.min(axis=0), self.points.max(axis=0)])

    def to_spec(self) -> dict:
        return {"type": "polyline", "points": _as_list(self.points)}


@dataclass(frozen=True, eq=False)
class Arc(Curve):
    """A circular arc, ``angle(u) = start_angle + u (end_angle - start_angle)``.

    ``c(u) = center + radius (cos a X + sin a Y)`` with ``X`` the part of
    ``x_axis`` perpendicular to ``normal`` (normalised) and ``Y = N x X``:
    angles in degrees, counter-clockwise about ``normal``.  Build with
    :meth:`through` or :meth:`from_center`; the fields are stored as given so
    that a curve read back from its spec is equal.

    Parameters
    ----------
    center : (3,) float64
    radius : float > 0
    normal : (3,) float64, non-zero
    x_axis : (3,) float64, not parallel to ``normal``
    start_angle, end_angle : float, degrees, different
    """

    center: np.ndarray
    radius: float
    normal: np.ndarray
    x_axis: np.ndarray
    start_angle: float
    end_angle: float

    def __post_init__(self) -> None:
        center = check_vector(self.center, "center")
        radius = check_float(self.radius, "radius", lo=0.0, lo_open=True)
        normal = check_vector(self.normal, "normal", nonzero=True)
        x_axis = check_vector(self.x_axis, "x_axis", nonzero=True)
        a0 = check_float(self.start_angle, "start_angle")
        a1 = check_float(self.end_angle, "end_angle")
        if a0 == a1:
            raise ParameterError(f"expected an angle different from start_angle, got {a1:g}",
                                 "end_angle")
        nn = _unit(normal)
        xp = x_axis - (x_axis @ nn) * nn
        if np.linalg.norm(xp) <= DEFAULT.degenerate * np.linalg.norm(x_axis):
            raise ParameterError("x_axis is parallel to normal; it must span the arc's plane",
                                 "x_axis")
        object.__setattr__(self, "center", _frozen(center))
        object.__setattr__(self, "radius", radius)
        object.__setattr__(self, "normal", _frozen(normal))
        object.__setattr__(self, "x_axis", _frozen(x_axis))
        object.__setattr__(self, "start_angle", a0)
        object.__setattr__(self, "end_angle", a1)

    @classmethod
    def through(cls, start: Any, mid: Any, end: Any) -> Arc:
        """The arc from ``start`` through ``mid`` to ``end``.

        Raises
        ------
        ParameterError
            The points are collinear or two of them coincide.
        """
        p0 = check_vector(start, "start")
        p1 = check_vector(mid, "mid")
        p2 = check_vector(end, "end")
        a, b = p1 - p0, p2 - p0
        w = np.cross(a, b)
        scale = max(np.linalg.norm(a), np.linalg.norm(b), np.linalg.norm(p2 - p1))
        if scale == 0 or np.linalg.norm(w) <= DEFAULT.degenerate * scale * scale:
            raise ParameterError(
                "the three points are collinear (or two coincide): no circular arc passes "
                "through them", "points")
        # circumcentre of the triangle p0, p1, p2
        center = p0 + np.cross(a @ a * b - b @ b * a, w) / (2.0 * (w @ w))
        radius = float(np.linalg.norm(p0 - center))
        normal = _unit(w)  # p0 -> p1 -> p2 counter-clockwise about normal
        x = _unit(p0 - center)
        y = np.cross(normal, x)
        r2 = p2 - center
        sweep = math.degrees(math.atan2(float(r2 @ y), float(r2 @ x))) % 360.0
        return cls(center, radius, normal, x, 0.0, sweep)

    @classmethod
    def from_center(cls, center: Any, radius: float, normal: Any, start_angle: float,
                    end_angle: float, x_axis: Any = None) -> Arc:
        """The arc about ``center`` in the plane with ``normal``; angles in degrees.

        ``x_axis`` (the direction of angle 0) defaults to a fixed direction
        perpendicular to ``normal``.
        """
        normal = check_vector(normal, "normal", nonzero=True)
        if x_axis is None:
            x_axis = perpendicular(normal)
        return cls(center, radius, normal, x_axis, start_angle, end_angle)

    @cached_property
    def _frame(self) -> tuple[np.ndarray, np.ndarray]:
        n = _unit(self.normal)
        x = _unit(self.x_axis - (self.x_axis @ n) * n)
        return x, np.cross(n, x)

    @property
    def _sweep_rad(self) -> float:
        return math.radians(self.end_angle - self.start_angle)

    def _eval(self, u):
        x, y = self._frame
        a = math.radians(self.start_angle) + u * self._sweep_rad
        return self.center + self.radius * (np.cos(a)[..., None] * x + np.sin(a)[..., None] * y)

    def _deriv(self, u, order):
        x, y = self._frame
        w = self._sweep_rad
        a = math.radians(self.start_angle) + u * w
        # d^k/da^k (cos, sin) = (cos, sin)(a + k pi/2)
        ak = a + order * math.pi / 2
        return (self.radius * w ** order) * (np.cos(ak)[..., None] * x + np.sin(ak)[..., None] * y)

    def _level_grid(self):
        return np.linspace(0.0, 1.0, max(9, math.ceil(abs(self.end_angle - self.start_angle) / 10.0) + 1))

    def length(self) -> float:
        return self.radius * abs(self._sweep_rad)

    def _arclength(self, u):
        return u * self.length()

    def _param_at_length(self, s):
        return np.clip(s / self.length(), 0.0, 1.0)

    def to_spec(self) -> dict:
        return {"type": "arc", "center": _as_list(self.center), "radius": self.radius,
                "normal": _as_list(self.normal), "x_axis": _as_list(self.x_axis),
                "start_angle": self.start_angle, "end_angle": self.end_angle}


def _default_knots(n: int, degree: int) -> np.ndarray:
    inner = np.linspace(0.0, 1.0, n - degree + 1)[1:-1]
    return np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])


@dataclass(frozen=True, eq=False)
class BSpline(Curve):
    """A B-spline curve; clamped uniform knots by default.

    The curve parameter ``u`` in [0, 1] maps affinely onto the knot domain
    ``[knots[degree], knots[-degree-1]]``.

    Parameters
    ----------
    control_points : (n, 3) float64, n >= degree + 1
    degree : int, 1..5
    knots : (n + degree + 1,) float64, optional
        Non-decreasing, interior multiplicity <= degree (so the curve is
        continuous).  Default: clamped and uniform on [0, 1].
    """

    control_points: np.ndarray
    degree: int = 3
    knots: np.ndarray | None = None

    def __post_init__(self) -> None:
        degree = check_int(self.degree, "degree", lo=1, hi=5)
        cp = check_points(self.control_points, "control_points")
        n = len(cp)
        if n < degree + 1:
            raise ParameterError(
                f"a degree-{degree} B-spline needs at least {degree + 1} control points, got {n}",
                "control_points")
        # A repeated point gives a piece of zero length (degree 1) or zero speed
        # at an end (higher degrees): arc length and tangents divide by zero.
        _check_distinct(cp, "control_points")
        if np.ptp(cp, axis=0).max() <= DEFAULT.degenerate * max(float(np.abs(cp).max()), TINY):
            # a point, not a curve: arc length and tangents would divide by zero
            raise ParameterError("all control points coincide; a curve needs two distinct points",
                                 "control_points")
        if self.knots is None:
            knots = _default_knots(n, degree)
        else:
            knots = _params(self.knots, "knots")
            if knots.shape != (n + degree + 1,):
                raise ParameterError(
                    f"expected {n + degree + 1} knots (control points + degree + 1), got "
                    f"{describe(self.knots) if knots.ndim != 1 else len(knots)}", "knots")
            if np.any(np.diff(knots) < 0):
                raise ParameterError("expected non-decreasing knots", "knots")
            if not knots[degree] < knots[n]:
                raise ParameterError("the knot domain knots[degree]..knots[n] is empty", "knots")
            inner = knots[degree + 1:n]
            if len(inner):
                _, mult = np.unique(inner, return_counts=True)
                if mult.max() > degree:
                    raise ParameterError(
                        f"an interior knot repeats {mult.max()} times; at most degree "
                        f"({degree}) keeps the curve continuous", "knots")
        object.__setattr__(self, "degree", degree)
        object.__setattr__(self, "control_points", _frozen(cp))
        object.__setattr__(self, "knots", _frozen(knots))

    @classmethod
    def interpolate(cls, points: Any, degree: int = 3) -> BSpline:
        """The B-spline through ``points`` at chord-length parameters.

        Parameters
        ----------
        points : (n, 3) array_like, n >= degree + 1, consecutive points distinct
        degree : int, 1..5

        Returns
        -------
        BSpline
            Not-a-knot end conditions (``scipy.interpolate.make_interp_spline``).
        """
        degree = check_int(degree, "degree", lo=1, hi=5)
        pts = check_points(points, "points", min_count=degree + 1)
        _check_distinct(pts, "points")
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        x = np.concatenate([[0.0], np.cumsum(seg)]) / seg.sum()
        x[-1] = 1.0
        from scipy.interpolate import make_interp_spline

        spl = make_interp_spline(x, pts, k=degree)
        return cls(np.asarray(spl.c), degree, np.asarray(spl.t))

    @property
    def _knot_vector(self) -> np.ndarray:
        # __post_init__ always sets the knots; the None is only the constructor's default
        if self.knots is None:
            raise GeometryError("the B-spline has no knot vector")
        return self.knots

    @cached_property
    def _derivative_nets(self) -> list[tuple[np.ndarray, np.ndarray, int]]:
        """(knots, control points, degree) of the curve and its derivatives up to the degree.

        The derivative of a degree-p B-spline is the degree-(p-1) B-spline on
        the knots without their ends, control points
        ``p (c[i+1] - c[i]) / (t[i+p+1] - t[i+1])`` (zero over empty spans).
        """
        nets = [(self._knot_vector, self.control_points, self.degree)]
        for _ in range(self.degree):
            t, c, p = nets[-1]
            denom = (t[p + 1:-1] - t[1:-p - 1])[:, None]
            diff = np.divide(p * np.diff(c, axis=0), denom, out=np.zeros((len(c) - 1, 3)),
                             where=denom > 0)
            nets.append((t[1:-1], diff, p - 1))
        return nets

    @cached_property
    def _pieces(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The curve as polynomials per knot span, in ``u``.

        Returns span starts ``(m,)`` and lengths ``(m,)`` in ``u``, and
        coefficients ``(m, degree + 1, 3)``: on span ``k`` the curve is
        ``sum_j C[k, j] tau^j``, ``tau = (u - start[k]) / length[k]``, from the
        derivatives at each span's start (de Boor, right-sided), i.e. exact
        Taylor polynomials.
        """
        t0, t1 = self._domain
        b = self._breaks()
        start, width = b[:-1], np.diff(b)
        x = t0 + start * (t1 - t0)
        coef = np.empty((len(start), self.degree + 1, 3))
        fact = 1.0
        for j, (knots, control, degree) in enumerate(self._derivative_nets):
            fact *= max(j, 1)
            d = _de_boor(knots, control, degree, x) * (t1 - t0) ** j
            coef[:, j] = d * (width ** j / fact)[:, None]
        return start, width, coef

    @cached_property
    def _derivative_pieces(self) -> list[np.ndarray]:
        """Per derivative order ``m``: coefficients ``(spans, degree + 1 - m, 3)`` in ``tau``
        of the ``m``-th derivative with respect to ``u`` (span lengths divided out)."""
        _, width, coef = self._pieces
        out = []
        for m in range(self.degree + 1):
            scale = np.array([math.perm(j, m) for j in range(m, self.degree + 1)], float)
            out.append(coef[:, m:] * scale[None, :, None] / (width ** m)[:, None, None])
        return out

    def _poly(self, u: np.ndarray, order: int) -> np.ndarray:
        """(..., 3): the ``order``-th derivative from the span polynomials (Horner)."""
        start, width, _ = self._pieces
        c = self._derivative_pieces[order]
        flat = u.ravel()
        if flat.size >= _BY_COLUMNS:
            return _horner_by_columns(flat, start, width, c).reshape(u.shape + (3,))
        if len(start) == 1:  # one span: no gather
            tau = ((flat - start[0]) / width[0])[:, None]
            out = np.broadcast_to(c[0, -1], (flat.size, 3))
            for j in range(c.shape[1] - 2, -1, -1):
                out = out * tau + c[0, j]
        else:
            k = np.clip(np.searchsorted(start, flat, side="right") - 1, 0, len(start) - 1)
            tau = ((flat - start[k]) / width[k])[:, None]
            out = c[k, -1]
            for j in range(c.shape[1] - 2, -1, -1):
                out = out * tau + c[k, j]
        return np.array(out, copy=True).reshape(u.shape + (3,))

    @property
    def _domain(self) -> tuple[float, float]:
        n = len(self.control_points)
        return float(self._knot_vector[self.degree]), float(self._knot_vector[n])

    def _eval(self, u):
        return self._poly(np.asarray(u, dtype=np.float64), 0)

    def _deriv(self, u, order):
        if order > self.degree:
            return np.zeros(np.shape(u) + (3,))
        return self._poly(np.asarray(u, dtype=np.float64), order)

    def _breaks(self):
        t0, t1 = self._domain
        k = unique(self._knot_vector)
        k = k[(k >= t0) & (k <= t1)]
        u = (k - t0) / (t1 - t0)
        u[0], u[-1] = 0.0, 1.0
        return u

    def _length_pieces(self):
        # Each knot span cut into equal pieces: the speed's Legendre interpolant on a
        # piece (the tabulated arc length) then reaches rounding except near cusps.
        b = self._breaks()
        steps = np.linspace(0.0, 1.0, _LENGTH_PIECES_PER_SPAN + 1)[:-1]
        return np.concatenate([(b[:-1, None] + np.diff(b)[:, None] * steps).ravel(), [1.0]])

    def _level_grid(self):
        b = self._breaks()
        per = 4 * self.degree + 4
        steps = np.linspace(0.0, 1.0, per + 1)[:-1]
        return np.concatenate([(b[:-1, None] + (b[1:] - b[:-1])[:, None] * steps).ravel(), [1.0]])

    def to_spec(self) -> dict:
        spec = {"type": "bspline", "degree": self.degree, "points": _as_list(self.control_points)}
        if not np.array_equal(self._knot_vector, _default_knots(len(self.control_points), self.degree)):
            spec["knots"] = _as_list(self._knot_vector)
        return spec


@dataclass(frozen=True, eq=False)
class Helix(Curve):
    """A circular helix about ``axis``.

    ``c(u) = center + radius (cos a X + sin a Y) + pitch turns u A`` with
    ``a = start_angle + 360 turns u`` (degrees), ``A`` the unit axis, ``X`` a
    fixed unit vector perpendicular to it and ``Y = A x X``: right-handed for
    ``pitch > 0``.  ``center`` is the axis point level with ``c(0)``.

    Parameters
    ----------
    center : (3,) float64
    axis : (3,) float64, non-zero
    radius : float > 0
    pitch : float
        Rise per full turn along ``axis``.
    turns : float > 0
    start_angle : float, degrees
    """

    center: np.ndarray
    axis: np.ndarray
    radius: float
    pitch: float
    turns: float
    start_angle: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _frozen(check_vector(self.center, "center")))
        object.__setattr__(self, "axis", _frozen(check_vector(self.axis, "axis", nonzero=True)))
        object.__setattr__(self, "radius", check_float(self.radius, "radius", lo=0.0, lo_open=True))
        object.__setattr__(self, "pitch", check_float(self.pitch, "pitch"))
        object.__setattr__(self, "turns", check_float(self.turns, "turns", lo=0.0, lo_open=True))
        object.__setattr__(self, "start_angle", check_float(self.start_angle, "start_angle"))

    @cached_property
    def _frame(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        a = _unit(self.axis)
        x = perpendicular(a)
        return a, x, np.cross(a, x)

    def _eval(self, u):
        a, x, y = self._frame
        ang = math.radians(self.start_angle) + 2.0 * math.pi * self.turns * u
        return (self.center + self.radius * (np.cos(ang)[..., None] * x + np.sin(ang)[..., None] * y)
                + (self.pitch * self.turns * u)[..., None] * a)

    def _deriv(self, u, order):
        a, x, y = self._frame
        w = 2.0 * math.pi * self.turns
        ang = math.radians(self.start_angle) + w * u + order * math.pi / 2
        out = (self.radius * w ** order) * (np.cos(ang)[..., None] * x + np.sin(ang)[..., None] * y)
        if order == 1:
            out = out + self.pitch * self.turns * a
        return out

    def _level_grid(self):
        return np.linspace(0.0, 1.0, max(17, math.ceil(32 * self.turns) + 1))

    def length(self) -> float:
        return self.turns * math.hypot(2.0 * math.pi * self.radius, self.pitch)

    def _arclength(self, u):
        return u * self.length()

    def _param_at_length(self, s):
        return np.clip(s / self.length(), 0.0, 1.0)

    def to_spec(self) -> dict:
        return {"type": "helix", "center": _as_list(self.center), "axis": _as_list(self.axis),
                "radius": self.radius, "pitch": self.pitch, "turns": self.turns,
                "start_angle": self.start_angle}
