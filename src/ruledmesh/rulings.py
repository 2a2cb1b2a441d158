"""Generators (rulings) from director curves, lines or files (paper §5).

A :class:`Rulings` set holds ``m`` generators ``g_i`` from ``a_i`` (t = 0, on
director curve c1) to ``b_i`` (t = 1, on c2), their surface parameters ``u_i``
and the smooth :class:`RuledSurface` they sample,
``S(u, t) = (1 - t) A(u) + t B(u)``.

Constructors, one per way the paper gives a ruled surface:

* :func:`between` two director curves with a *distribution* (§5.2):
  (a) equal arc length, (b) equal curve parameter, (c) a director plane (the
  pencil of parallel planes ``n . x = s`` cuts both curves), (d) a linear
  directrix ``d`` (the planes through ``d`` cut both curves);
* :func:`three_directrices`: the lines meeting three curves (§5, general case);
* :func:`conoid`: one curve, a line directrix and a director plane (§5.1);
* :func:`from_lines`: explicit generators (a CSV file of them is read by
  :func:`ruledmesh.design.rulings.from_csv`, the ``[rulings]`` table of a design
  file by :func:`ruledmesh.design.rulings.rulings_from_spec`).

The smooth reference surface.  For curve-based rulings ``A(u) = c1(sigma1(u))``
lies exactly on c1 (likewise B on c2); only the correspondence ``sigma`` is
interpolated.  ``sigma`` is the identity (parameter distribution), the
closed-form arc-length inverse (lines, polylines, arcs, helices), or a cubic
Hermite interpolant of a dense sampling (at least 1025 samples, including the
generators) with *exact* slopes from implicit differentiation of the
correspondence (B-spline arc length, director plane, linear directrix, three
directrices): fourth order, so the surface does not depend on ``count`` to
~1e-12.  PCHIP replaces it where a slope is infinite (a range end at a
tangency).  For explicit lines, ``A`` and ``B`` are C2 cubic splines
(``scipy`` ``CubicSpline``, not-a-knot) through the endpoints, with ``u`` the
cumulative mean chord length of the endpoints,
``(|a_{i+1} - a_i| + |b_{i+1} - b_i|) / 2``, normalised: uneven spacing of the
given lines is then followed rather than smoothed over.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from enum import Enum
from typing import Any

import numpy as np

from ._arrays import diagonal, unique
from ._validation import (
    check_choice,
    check_int,
    check_points,
    check_vector,
    describe,
)

# scipy is imported where it is used (lines through points, PCHIP at tangencies, root
# brackets), so building from director curves starts without it.
from .budget import MAX_GENERATORS, PQ_BYTES_PER_GRID_POINT
from .curves import BSpline, CubicHermite, Curve, LevelSet, Line, perpendicular
from .errors import GeometryError, ParameterError
from .tolerances import (
    DEFAULT,
    PARAMETER_SLACK,
    ROOT_RTOL,
    ROOT_XTOL,
    ROUNDING,
    SAME_ROOT,
    SLOPE_STEP,
    TINY,
    ULPS,
    Tolerances,
)

__all__ = [
    "Distribution",
    "Rulings",
    "RuledSurface",
    "between",
    "three_directrices",
    "conoid",
    "from_lines",
    "check_line",
    "MAX_GENERATORS",
]

# dense samples of a numerically found correspondence (PCHIP nodes)
_DENSE = 1024


class Distribution(Enum):
    """How generators are distributed between two director curves (paper §5.2)."""

    PARAMETER = "parameter"
    ARC_LENGTH = "arc-length"
    DIRECTOR_PLANE = "director-plane"
    LINEAR_DIRECTRIX = "linear-directrix"


# --------------------------------------------------------------------------
# the smooth reference surface
# --------------------------------------------------------------------------

class _Identity:
    def value(self, u):
        return u

    def deriv(self, u):
        return np.ones_like(u)


@dataclass(frozen=True, eq=False)
class _ArcLength:
    """sigma(u) = the curve parameter at arc length u L (exact inverse)."""

    curve: Curve

    def value(self, u):
        return self.curve.param_at_fraction(u)

    def deriv(self, u):
        return self.curve.length() / self.curve.speed_at(self.value(u))


def _arc_sigma(curve: Curve, count: int) -> Any:
    """sigma(u) = the curve parameter at arc-length fraction u.

    Exact where the inverse is closed-form (lines, polylines, arcs, helices);
    for B-splines a cubic Hermite interpolant of exact samples and slopes as
    dense as the dense grid (exact at the generators, see :func:`_dense_sigma`),
    so that evaluating the reference surface needs no Newton solve.
    """
    exact = _ArcLength(curve)
    if not isinstance(curve, BSpline):
        return exact
    grid, k = dense_grid(count)
    nodes = _dense_sigma(curve, exact, grid, k)
    grid, values = nodes if nodes is not None else (grid, exact.value(grid))
    speed = curve.speed_at(values)
    if np.all(speed > ROUNDING * curve.length()):
        return _Pchip.of(grid, values, curve.length() / speed)
    # A cusp (zero speed, e.g. a spline doubling back) has an infinite slope
    # there: use the monotone interpolant of the samples instead.
    return _Pchip.of(grid, values)


def _dense_sigma(curve: BSpline, exact: _ArcLength, grid: np.ndarray,
                 k: int) -> tuple[np.ndarray, np.ndarray] | None:
    """Nodes ``(u, sigma(u))`` of the interpolant: exact inverses at the generators' ``u``
    (every ``k``-th node of ``grid``), forward arc lengths in between.

    Between two generators the parameters are spaced evenly and their arc-length
    fractions taken from the tabulated arc length (one series evaluation each,
    where the inverse costs a Newton solve), so the nodes are as dense as the grid
    and the generators stay exact.  None where the table is not strictly
    increasing there (a cusp): the caller inverts on the grid instead.
    """
    u_gen = grid[::k]
    p_gen = exact.value(u_gen)
    if k == 1:
        return u_gen, p_gen
    j = np.arange(1, k) / k
    p_mid = (p_gen[:-1, None] + (p_gen[1:] - p_gen[:-1])[:, None] * j[None, :])
    u_mid = curve.arclength(p_mid) / curve.length()
    u = _interleaved(u_gen, u_mid)
    p = _interleaved(p_gen, p_mid)
    if not (np.all(np.diff(u) > 0) and np.all(np.diff(p) > 0)):
        return None
    return u, p


def _interleaved(ends: np.ndarray, between: np.ndarray) -> np.ndarray:
    """``ends[0], between[0], ends[1], between[1], ..., ends[-1]``: (m + (m - 1) (k - 1),) float64.

    ``between`` is ``(m - 1, k - 1)``: the values inside each interval of ``ends``.
    """
    rows = np.empty((len(between), between.shape[1] + 1))
    rows[:, 0] = ends[:-1]
    rows[:, 1:] = between
    return np.concatenate([rows.ravel(), ends[-1:]])


@dataclass(frozen=True, eq=False)
class _Pchip:
    """sigma(u): monotone C1 interpolant of dense samples of a correspondence."""

    interp: Any

    @classmethod
    def of(cls, u: np.ndarray, sigma: np.ndarray, dsigma: np.ndarray | None = None) -> _Pchip:
        """PCHIP of the samples, or, given exact slopes ``dsigma`` (implicit
        differentiation of the correspondence), the cubic Hermite interpolant:
        fourth order, so the surface hardly depends on the sampling."""
        if dsigma is not None and np.all(np.isfinite(dsigma)) and (
                np.all(dsigma >= 0) or np.all(dsigma <= 0)):
            return cls(CubicHermite(u, sigma, dsigma))
        from scipy.interpolate import PchipInterpolator

        return cls(PchipInterpolator(u, sigma))

    def value(self, u):
        return np.clip(self.interp(u), 0.0, 1.0)

    def deriv(self, u):
        return self.interp(u, 1)


@dataclass(frozen=True, eq=False)
class _CurveTrack:
    """A(u) = curve(sigma(u)): exactly on the curve."""

    curve: Curve
    sigma: Any

    def value(self, u):
        return self.curve.point_at(self.sigma.value(u))

    def deriv(self, u):
        return self.curve.tangent_at(self.sigma.value(u)) * self.sigma.deriv(u)[..., None]

    def value_deriv(self, u):
        """``(value(u), deriv(u))`` with the correspondence evaluated once."""
        sigma = self.sigma.value(u)
        return self.curve.point_at(sigma), self.curve.tangent_at(sigma) * self.sigma.deriv(u)[..., None]


@dataclass(frozen=True, eq=False)
class _SplineTrack:
    """A(u) = a C2 cubic spline through given points."""

    spline: Any  # scipy.interpolate.CubicSpline

    def value(self, u):
        return self.spline(u)

    def deriv(self, u):
        return self.spline(u, 1)


@dataclass(frozen=True, eq=False)
class _ConoidTrack:
    """B(u) on the line d0 + s e, in the plane through A(u) with normal n."""

    base: Any
    d0: np.ndarray
    e: np.ndarray
    n: np.ndarray

    def value(self, u):
        s = (self.base.value(u) - self.d0) @ self.n / (self.e @ self.n)
        return self.d0 + s[..., None] * self.e

    def deriv(self, u):
        s = self.base.deriv(u) @ self.n / (self.e @ self.n)
        return s[..., None] * self.e


def _value_deriv(rail: Any, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    both = getattr(rail, "value_deriv", None)
    return both(u) if both is not None else (rail.value(u), rail.deriv(u))


@dataclass(frozen=True, eq=False)
class RuledSurface:
    """The smooth ruled surface ``S(u, t) = (1 - t) A(u) + t B(u)``, u, t in [0, 1].

    Parameters
    ----------
    rail_a, rail_b : track
        Objects with vectorised ``value(u)`` and ``deriv(u)`` -> (..., 3): the
        correspondence ``A(u)``, ``B(u)`` of the distribution.
    breaks : (k,) float64
        Parameters where ``A`` or ``B`` may be less smooth (the generators'
        ``u``, kinks): panel ends of the area quadrature.
    """

    rail_a: Any
    rail_b: Any
    breaks: np.ndarray = field(default_factory=lambda: np.array([0.0, 1.0]))

    def a(self, u: Any) -> np.ndarray:
        """A(u): (..., 3), the rail at t = 0 (on c1)."""
        return self.rail_a.value(np.asarray(u, dtype=np.float64))

    def b(self, u: Any) -> np.ndarray:
        """B(u): (..., 3), the rail at t = 1 (on c2)."""
        return self.rail_b.value(np.asarray(u, dtype=np.float64))

    def point(self, u: Any, t: Any) -> np.ndarray:
        """Points ``S(u, t)``; ``u`` and ``t`` broadcast: (..., 3)."""
        u, t = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(t, dtype=np.float64))
        a, b = self.rail_a.value(u), self.rail_b.value(u)
        return a + t[..., None] * (b - a)

    def partials(self, u: Any, t: Any) -> tuple[np.ndarray, np.ndarray]:
        """``(S_u, S_t)``, each (..., 3); ``u`` and ``t`` broadcast."""
        u, t = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(t, dtype=np.float64))
        da, db = self.rail_a.deriv(u), self.rail_b.deriv(u)
        su = da + t[..., None] * (db - da)
        st = self.rail_b.value(u) - self.rail_a.value(u)
        return su, st

    def point_partials(self, u: Any, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(S, S_u, S_t)``, each (..., 3): :meth:`point` and :meth:`partials` with each rail
        evaluated once (a closest-point step needs all three)."""
        u, t = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(t, dtype=np.float64))
        a, da = _value_deriv(self.rail_a, u)
        b, db = _value_deriv(self.rail_b, u)
        st = b - a
        return a + t[..., None] * st, da + t[..., None] * (db - da), st

    def area(self, n: int = 16) -> float:
        """Area of the patch: composite Gauss-Legendre of ``|S_u x S_t|``.

        Parameters
        ----------
        n : int
            Nodes per panel in ``u`` (panels between :attr:`breaks`) and in ``t``.
        """
        n = check_int(n, "n", lo=1)
        x, w = np.polynomial.legendre.leggauss(n)
        x, w = 0.5 * (x + 1.0), 0.5 * w
        br = unique(np.concatenate([[0.0, 1.0], self.breaks]))
        lo, hi = br[:-1], br[1:]
        uu = (lo[:, None] + (hi - lo)[:, None] * x[None, :]).ravel()
        wu = ((hi - lo)[:, None] * w[None, :]).ravel()
        su, st = self.partials(uu[:, None], x[None, :])
        dens = np.linalg.norm(np.cross(su, st), axis=-1)
        return float(wu @ dens @ w)


# --------------------------------------------------------------------------
# the rulings set
# --------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Rulings:
    """A discrete set of generators and the smooth surface they sample.

    Parameters
    ----------
    a : (m, 3) float64
        Generator points at t = 0 (on c1).
    b : (m, 3) float64
        Generator points at t = 1 (on c2).
    u : (m,) float64
        Surface parameter of each generator, strictly increasing in [0, 1].
    surface : RuledSurface or None
        The smooth ruled surface; ``surface.point(u[i], t)`` is on ``g_i``.
    info : dict
        ``distribution``, ``warnings`` (list of str) and per-constructor
        details (curve parameters of the endpoints, ...).
    """

    a: np.ndarray
    b: np.ndarray
    u: np.ndarray
    surface: RuledSurface | None = None
    info: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        a = check_points(self.a, "a", min_count=2)
        b = check_points(self.b, "b", min_count=2)
        if a.shape != b.shape:
            raise ParameterError(f"expected as many points as a ({len(a)}), got {len(b)}", "b")
        u = np.asarray(self.u, dtype=np.float64)
        if u.shape != (len(a),) or not np.all(np.isfinite(u)):
            raise ParameterError(f"expected {len(a)} finite numbers, got {describe(self.u)}", "u")
        if np.any(np.diff(u) <= 0) or u[0] < 0 or u[-1] > 1:
            raise ParameterError("expected strictly increasing values in [0, 1]", "u")
        for name, arr in (("a", a), ("b", b), ("u", u)):
            arr = np.array(arr)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        info = dict(self.info)
        info.setdefault("warnings", [])
        object.__setattr__(self, "info", info)

    @property
    def directions(self) -> np.ndarray:
        """(m, 3) float64: ``b - a``."""
        return self.b - self.a

    def __len__(self) -> int:
        return len(self.a)


def _check_generators(a: np.ndarray, b: np.ndarray, what: str, tol: Tolerances) -> None:
    pts = np.concatenate([a, b])
    size = max(diagonal(pts), TINY)
    short = np.nonzero(np.linalg.norm(b - a, axis=1) <= tol.degenerate * size)[0]
    if len(short):
        i = int(short[0])
        raise GeometryError(
            f"{what}: generator {i} has zero length: its ends coincide at "
            f"{np.array2string(a[i], precision=6, separator=', ')}")


def dense_grid(count: int) -> tuple[np.ndarray, int]:
    """A dense u grid holding the ``count`` generator parameters at every k-th node."""
    k = max(1, math.ceil(_DENSE / (count - 1)))
    return np.linspace(0.0, 1.0, k * (count - 1) + 1), k


def _check_curve(c: Any, name: str) -> Curve:
    if not isinstance(c, Curve):
        raise ParameterError(f"expected a curve (ruledmesh.curves.Curve), got {describe(c)}", name)
    return c


def _curve_rulings(c1: Curve, s1: Any, c2: Curve, s2: Any, count: int, info: dict,
                   tol: Tolerances, sig1: np.ndarray | None = None,
                   sig2: np.ndarray | None = None) -> Rulings:
    u = np.linspace(0.0, 1.0, count)
    sig1 = s1.value(u) if sig1 is None else sig1
    sig2 = s2.value(u) if sig2 is None else sig2
    a, b = c1.point_at(sig1), c2.point_at(sig2)
    _check_generators(a, b, info["distribution"], tol)
    info = {**info, "c1_params": sig1, "c2_params": sig2}
    surface = RuledSurface(_CurveTrack(c1, s1), _CurveTrack(c2, s2), u)
    return Rulings(a, b, u, surface, info)


# --------------------------------------------------------------------------
# two director curves
# --------------------------------------------------------------------------

def between(c1: Curve, c2: Curve, count: int, distribution: Distribution | str = "arc-length", *,
            director_plane: Any = None, directrix: Any = None,
            tol: Tolerances = DEFAULT) -> Rulings:
    """Generators between two director curves (paper §5.2).

    Parameters
    ----------
    c1, c2 : Curve
        Director curves; generator ``i`` runs from ``a_i`` on c1 to ``b_i`` on c2.
    count : int >= 2
        Number of generators.
    distribution : Distribution or str
        ``"arc-length"`` (a): equal arc length on both curves;
        ``"parameter"`` (b): equal curve parameter;
        ``"director-plane"`` (c): the planes ``n . x = s``, ``count`` values of
        ``s`` evenly over the range where both curves meet them, each curve's
        intersection followed along one continuous branch (from the end of c1
        nearest ``u = 0``); ``"linear-directrix"`` (d): ``a_i`` at equal arc
        length on c1, ``b_i`` where the plane through ``a_i`` and the line
        ``d`` meets c2 (branch followed from the root nearest ``c2(0)``).
    director_plane : (3,) array_like
        The normal ``n``, for ``"director-plane"`` only.
    directrix : (2, 3) array_like
        Two points of the line ``d``, for ``"linear-directrix"`` only.
    tol : Tolerances

    Returns
    -------
    Rulings
        ``info`` holds ``c1_params``/``c2_params`` (curve parameters of the
        generators' ends) and, for (c), ``levels`` (the values of ``s``).

    Raises
    ------
    GeometryError
        A curve parallel to the director plane or lying in a plane through
        ``d``, curves without a common range of planes, ``d`` through a point
        of c1 or meeting c2, a branch that turns back or runs off a curve
        before the last generator (the message says which generator).
    """
    c1 = _check_curve(c1, "c1")
    c2 = _check_curve(c2, "c2")
    count = check_int(count, "count", lo=2)
    dist = check_choice(distribution, Distribution, "distribution")
    if director_plane is not None and dist is not Distribution.DIRECTOR_PLANE:
        raise ParameterError('only used with distribution "director-plane"', "director_plane")
    if directrix is not None and dist is not Distribution.LINEAR_DIRECTRIX:
        raise ParameterError('only used with distribution "linear-directrix"', "directrix")
    info: dict[str, Any] = {"distribution": dist.value, "warnings": []}
    if dist is Distribution.PARAMETER:
        return _curve_rulings(c1, _Identity(), c2, _Identity(), count, info, tol)
    if dist is Distribution.ARC_LENGTH:
        return _curve_rulings(c1, _arc_sigma(c1, count), c2, _arc_sigma(c2, count), count, info, tol)
    if dist is Distribution.DIRECTOR_PLANE:
        if director_plane is None:
            raise ParameterError('required with distribution "director-plane"', "director_plane")
        return _director_plane(c1, c2, count, check_vector(director_plane, "director_plane",
                                                           nonzero=True), info, tol)
    if directrix is None:
        raise ParameterError('required with distribution "linear-directrix"', "directrix")
    d = check_line(directrix, "directrix")
    return _linear_directrix(c1, c2, count, d, info, tol)


def check_line(value: Any, name: str, err: type = ParameterError) -> np.ndarray:
    """(2, 3) float64: two distinct points of a line, checked, errors naming ``name``."""
    d = check_points(value, name, err=err)
    if len(d) != 2:
        raise err(f"expected 2 points of the line, got {len(d)}", name)
    if np.linalg.norm(d[1] - d[0]) <= DEFAULT.degenerate * max(np.abs(d).max(), TINY):
        raise err("the two points coincide; a line needs two distinct points", name)
    return d


def _ended(what: str, curve_name: str, end: tuple, k: int, count: int, extra: str = "") -> GeometryError:
    j, reason, u_end = end
    gen = j / k
    where = (f"between generators {int(gen)} and {int(gen) + 1}" if gen != int(gen)
             else f"at generator {int(gen)}")
    at = f" at u = {u_end:.6g}" if u_end is not None else ""
    return GeometryError(f"{what}: the branch on {curve_name} {reason}{at} {where} of {count}"
                         f"{extra}")


def _director_plane(c1: Curve, c2: Curve, count: int, normal: np.ndarray, info: dict,
                    tol: Tolerances) -> Rulings:
    n = normal / np.linalg.norm(normal)
    levels = [c.height_function(n, tol) for c in (c1, c2)]
    for name, lev in zip(("c1", "c2"), levels):
        lo, hi = lev.range
        if hi - lo <= lev.tol:
            raise GeometryError(
                f"director-plane: {name} lies in a plane parallel to the director plane "
                f"(n . x = {lo:g} with n = {np.array2string(n, precision=6, separator=', ')}): "
                "each plane of the pencil meets it everywhere or nowhere")
    (lo1, hi1), (lo2, hi2) = levels[0].range, levels[1].range
    lo, hi = max(lo1, lo2), min(hi1, hi2)
    if hi - lo <= max(levels[0].tol, levels[1].tol):
        raise GeometryError(
            f"director-plane: no plane n . x = s meets both curves: s spans "
            f"[{lo1:g}, {hi1:g}] on c1 and [{lo2:g}, {hi2:g}] on c2")
    # sweep in the direction that runs along c1 from its start
    forward = levels[0].values[-1] >= levels[0].values[0]
    grid, k = dense_grid(count)
    s = lo + grid * (hi - lo) if forward else hi - grid * (hi - lo)
    sig = []
    for name, lev in zip(("c1", "c2"), levels):
        roots = lev.roots(float(s[0]))
        if len(roots) == 0:  # only by rounding at a range end
            raise GeometryError(f"director-plane: the first plane n . x = {s[0]:g} misses {name}")
        u, _ok, end = lev.follow(s, float(roots[0]))
        if end is not None:
            raise _ended("director-plane", name, end, k, count,
                         ": the planes n . x = s meet it more than once (or not at all) over "
                         f"s in [{lo:g}, {hi:g}]; choose another director plane")
        sig.append(u)
    ds = (s[-1] - s[0])
    with np.errstate(divide="ignore", invalid="ignore"):  # n . c' = 0 at a range end: PCHIP
        slopes = [ds / (c.tangent_at(u) @ n) for c, u in zip((c1, c2), sig)]
    s1, s2 = _Pchip.of(grid, sig[0], slopes[0]), _Pchip.of(grid, sig[1], slopes[1])
    info = {**info, "levels": s[::k].copy(), "director_plane": n}
    return _curve_rulings(c1, s1, c2, s2, count, info, tol, sig[0][::k].copy(), sig[1][::k].copy())


class _PencilAngle:
    """The angle of the plane through line d and a point, continuous along a curve.

    ``theta(x) = atan2(q . (x - d0), p . (x - d0))`` with ``p, q`` an
    orthonormal frame perpendicular to d.  Points on one plane through d have
    the same ``theta`` modulo pi.  Along a curve ``theta`` is unwrapped
    against a piecewise-linear reference through a fine sampling, so it is a
    continuous level function.
    """

    def __init__(self, d: np.ndarray):
        self.d0 = d[0]
        self.e = (d[1] - d[0]) / np.linalg.norm(d[1] - d[0])
        self.p = perpendicular(self.e)
        self.q = np.cross(self.e, self.p)

    def xy(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rel = pts - self.d0
        return rel @ self.p, rel @ self.q

    def raw(self, pts: np.ndarray) -> np.ndarray:
        x, y = self.xy(pts)
        return np.arctan2(y, x)

    def radius(self, pts: np.ndarray) -> np.ndarray:
        x, y = self.xy(pts)
        return np.hypot(x, y)

    def level(self, curve: Curve, name: str, tol: Tolerances) -> LevelSet:
        grid = unique(np.concatenate([curve.level_grid(), curve.breaks()]))
        # the closest approach to d, polished between the neighbours of the
        # nearest sample (there the pencil angle jumps by pi)
        i = int(np.argmin(self.radius(curve.point_at(grid))))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
        def approach(x):  # d/dx of radius^2 / 2: smooth, zero at the closest approach
            x = np.float64(x)
            px, py = self.xy(curve.point_at(x))
            dx, dy = self.xy(curve.tangent_at(x) + self.d0)
            return float(px * dx + py * dy)

        xm = grid[i]
        if approach(lo) < 0 < approach(hi):
            from .roots import brentq

            xm = brentq(approach, lo, hi, xtol=ROOT_XTOL, rtol=ROOT_RTOL)
        rmin = float(self.radius(curve.point_at(np.asarray(xm, dtype=np.float64))))
        if rmin <= tol.degenerate * curve.size:
            raise GeometryError(
                f"linear-directrix: {name} meets the directrix d at u = {xm:.6g}: "
                "every plane through d contains that point")
        for _ in range(6):
            pts = curve.point_at(grid)
            ref = np.unwrap(self.raw(pts))
            if np.max(np.abs(np.diff(ref))) < 0.5:
                break
            grid = unique(np.concatenate([grid, 0.5 * (grid[:-1] + grid[1:])]))
        else:
            raise GeometryError(
                f"linear-directrix: {name} winds around the directrix d too closely to follow")

        def g(u):
            u = np.asarray(u, dtype=np.float64)
            lin = np.interp(u, grid, ref)
            return lin + (np.mod(self.raw(curve.point_at(u)) - lin + np.pi, 2 * np.pi) - np.pi)

        def dg(u):
            u = np.asarray(u, dtype=np.float64)
            x, y = self.xy(curve.point_at(u))
            dx, dy = self.xy(curve.tangent_at(u) + self.d0)
            return (x * dy - y * dx) / (x * x + y * y)

        return LevelSet(g, dg, grid, tol.degenerate)


def _linear_directrix(c1: Curve, c2: Curve, count: int, d: np.ndarray, info: dict,
                      tol: Tolerances) -> Rulings:
    pencil = _PencilAngle(d)
    grid, k = dense_grid(count)
    arc1 = _arc_sigma(c1, count)
    sig1 = arc1.value(grid)
    pts1 = c1.point_at(sig1)
    r1 = pencil.radius(pts1)
    near = int(np.argmin(r1))
    if r1[near] <= tol.degenerate * c1.size:
        gen = near / k
        where = f"a_{int(gen)} (generator {int(gen)})" if gen == int(gen) else (
            f"c1 between generators {int(gen)} and {int(gen) + 1}")
        raise GeometryError(
            f"linear-directrix: the directrix d passes through {where} at "
            f"{np.array2string(pts1[near], precision=6, separator=', ')}: the plane through "
            "it and d is undefined")
    theta1 = np.unwrap(pencil.raw(pts1))
    if np.max(np.abs(np.diff(theta1))) > 0.5:
        raise GeometryError("linear-directrix: c1 winds around the directrix d too closely")
    lev2 = pencil.level(c2, "c2", tol)
    lo, hi = lev2.range
    if hi - lo <= lev2.tol:
        raise GeometryError(
            "linear-directrix: c2 lies in a plane through the directrix d: the planes through d "
            "and the points of c1 meet it everywhere or nowhere")
    # the plane through d and a_0 has angle theta1[0] modulo pi
    starts = []
    for j in range(math.ceil((lo - theta1[0]) / np.pi - ROUNDING),
                   math.floor((hi - theta1[0]) / np.pi + ROUNDING) + 1):
        for r in lev2.roots(float(theta1[0] + j * np.pi)):
            starts.append((float(r), j))
    if not starts:
        raise GeometryError(
            "linear-directrix: the plane through the directrix d and a_0 (generator 0) does not "
            "meet c2")
    v0, j0 = min(starts)
    sig2, _ok, end = lev2.follow(theta1 + j0 * np.pi, v0)
    if end is not None:
        raise _ended("linear-directrix", "c2", end, k, count,
                     ": the planes through d and the points of c1 stop meeting c2 along one "
                     "branch; move d or shorten c1")
    # d sigma2 / du = theta1'(u) / g2'(sigma2), theta1' through the arc length of c1
    x1, y1 = pencil.xy(pts1)
    dx1, dy1 = pencil.xy(c1.tangent_at(sig1) * arc1.deriv(grid)[:, None] + pencil.d0)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope2 = (x1 * dy1 - y1 * dx1) / (x1 * x1 + y1 * y1) / lev2.dg(sig2)
    info = {**info, "directrix": d}
    return _curve_rulings(c1, arc1, c2, _Pchip.of(grid, sig2, slope2), count, info, tol,
                          sig1[::k].copy(), sig2[::k].copy())


# --------------------------------------------------------------------------
# three directrices (§5 general case)
# --------------------------------------------------------------------------

def _newton_3(c2: Curve, c3: Curve, p: np.ndarray, x: np.ndarray, size: float,
              iterations: int = 40) -> tuple[np.ndarray, bool]:
    """Solve c3(w) - p = lam (c2(v) - p) for x = (v, w, lam) by Newton."""
    x = x.copy()
    for _ in range(iterations):
        v, w, lam = x
        q = c2.point_at(np.array(v))
        r = c3.point_at(np.array(w))
        f = r - p - lam * (q - p)
        jac = np.column_stack([-lam * c2.tangent_at(np.array(v)), c3.tangent_at(np.array(w)), p - q])
        try:
            dx = np.linalg.solve(jac, -f)
        except np.linalg.LinAlgError:
            return x, False
        if not np.all(np.isfinite(dx)):
            return x, False
        x = x + dx
        if abs(x[0] - 0.5) > 1.5 or abs(x[1] - 0.5) > 1.5:
            return x, False
        if np.linalg.norm(dx[:2]) <= ULPS and np.linalg.norm(f) <= ROUNDING * size:
            return x, True
    v, w, lam = x
    f = c3.point_at(np.array(w)) - p - lam * (c2.point_at(np.array(v)) - p)
    return x, bool(np.linalg.norm(f) <= ROUNDING * size)


def _first_transversal(c2: Curve, c3: Curve, p: np.ndarray, size: float,
                       samples: int = 160) -> list[np.ndarray]:
    """All lines through p meeting c2 and c3: grid search of the central projections."""
    from scipy.ndimage import minimum_filter

    v = np.linspace(0.0, 1.0, samples)
    q = c2.point_at(v) - p
    r = c3.point_at(v) - p
    qn = q / np.maximum(np.linalg.norm(q, axis=1), TINY)[:, None]
    rn = r / np.maximum(np.linalg.norm(r, axis=1), TINY)[:, None]
    sine = np.linalg.norm(np.cross(qn[:, None, :], rn[None, :, :]), axis=-1)
    minima = (sine == minimum_filter(sine, size=3, mode="nearest")) & (sine < 0.3)
    order = np.argsort(sine[minima])
    iv, iw = np.nonzero(minima)
    found: list[np.ndarray] = []
    for idx in order[:200]:
        i, j = iv[idx], iw[idx]
        lam = float(r[j] @ q[i] / max(q[i] @ q[i], TINY))
        x, ok = _newton_3(c2, c3, p, np.array([v[i], v[j], lam]), size)
        if ok and -ROUNDING <= x[0] <= 1 + ROUNDING and -ROUNDING <= x[1] <= 1 + ROUNDING:
            x[:2] = np.clip(x[:2], 0.0, 1.0)
            if not any(np.linalg.norm(x[:2] - y[:2]) < SAME_ROOT for y in found):
                found.append(x)
    return sorted(found, key=lambda y: (y[0], y[1]))


def three_directrices(c1: Curve, c2: Curve, c3: Curve, count: int, *,
                      start: Any = None, tol: Tolerances = DEFAULT) -> Rulings:
    """The lines meeting three director curves (paper §5, general case).

    For ``u_i`` at equal arc length on c1, find ``v`` on c2 and ``w`` on c3
    with ``c1(u_i)``, ``c2(v)``, ``c3(w)`` collinear: Newton on
    ``c3(w) - a = lam (c2(v) - a)`` (three equations, unknowns ``v, w, lam``),
    continued from the previous solution with step halving, the first from a
    grid search over the central projections of c2 and c3 from ``c1(0)``.

    Where c3 is a line it is taken as the whole line: the lines are those of
    the pencil of planes through it (:func:`_c3_a_line`; in closed form where
    c2 is a line too, :func:`_three_lines`).

    Parameters
    ----------
    c1, c2, c3 : Curve
        Generator ``i`` runs from ``a_i`` on c1 to ``b_i`` on c2 and meets c3
        at ``t = info["c3_t"][i]``.
    count : int >= 2
    start : (2,) array_like, optional
        ``(v, w)`` near the wanted first line, when ``c1(0)`` has several; by
        default the one with the smallest ``v`` (then ``w``); unused for lines c2, c3.

    Raises
    ------
    GeometryError
        No line through ``c1(0)`` meets c2 and c3, or the family ends (the
        line runs off c2 or c3, or the solution turns back) before ``c1(1)``:
        the message gives the generator and the parameter on c1.  For lines
        c2 and c3: no line through a point of c1 meets the segment c2.
    """
    c1 = _check_curve(c1, "c1")
    c2 = _check_curve(c2, "c2")
    c3 = _check_curve(c3, "c3")
    count = check_int(count, "count", lo=2)
    if isinstance(c2, Line) and isinstance(c3, Line):
        return _three_lines(c1, c2, c3, count, tol)
    if isinstance(c3, Line) and start is None:
        return _c3_a_line(c1, c2, c3, count, tol)
    size = max(c1.size, c2.size, c3.size)
    grid, k = dense_grid(count)
    arc1 = _arc_sigma(c1, count)
    sig1 = arc1.value(grid)
    pts1 = c1.point_at(sig1)
    candidates = _first_transversal(c2, c3, pts1[0], size)
    if not candidates:
        raise GeometryError("three directrices: no line through c1(0) meets both c2 and c3")
    if start is not None:
        st = check_vector(start, "start", dim=2)
        x = min(candidates, key=lambda y: float(np.linalg.norm(y[:2] - st)))
    else:
        x = candidates[0]
    sol = np.empty((len(grid), 3))
    sol[0] = x
    a_param = lambda g: float(arc1.value(np.array(g)))
    for i in range(1, len(grid)):
        # continue from grid[i-1] to grid[i] with step halving; a secant predictor
        g0, g1 = grid[i - 1], grid[i]
        cur, prev_step = sol[i - 1].copy(), (sol[i - 1] - sol[i - 2]) if i > 1 else np.zeros(3)
        h_prev = g1 - g0
        g = g0
        h = g1 - g0
        while g < g1:
            h = min(h, g1 - g)
            gn = g1 if g + h >= g1 - ULPS else g + h
            p = c1.point_at(np.array(a_param(gn)))
            pred = cur + prev_step * ((gn - g) / h_prev)
            x, ok = _newton_3(c2, c3, p, pred, size)
            jump = np.linalg.norm(x[:2] - cur[:2]) if ok else np.inf
            if ok and jump <= 0.05 + 4 * np.linalg.norm(prev_step[:2]) * (gn - g) / h_prev:
                inside = (x[:2] >= -PARAMETER_SLACK) & (x[:2] <= 1 + PARAMETER_SLACK)
                if not inside.all():
                    which = "c2" if not inside[0] else "c3"
                    raise _family_end(f"the line runs off the end of {which}", gn, sig1, grid,
                                      k, count)
                prev_step, h_prev = x - cur, gn - g
                cur, g = x, gn
                h = 2 * h
            else:
                h = h / 2
                if h < DEFAULT.degenerate:
                    raise _family_end("the solution turns back (the line becomes tangent to "
                                      "the surface's director curves)", g, sig1, grid, k, count)
        cur[:2] = np.clip(cur[:2], 0.0, 1.0)
        sol[i] = cur
    # implicit differentiation of c3(w) - p - lam (c2(v) - p) = 0 in p = c1(sigma1(u)):
    # J dx/du = (1 - lam) dp/du
    v, w, lam = sol.T
    jac = np.stack([-lam[:, None] * c2.tangent_at(v), c3.tangent_at(w), pts1 - c2.point_at(v)], axis=-1)
    dp = c1.tangent_at(sig1) * arc1.deriv(grid)[:, None]
    try:
        dx = np.linalg.solve(jac, ((1 - lam)[:, None] * dp)[..., None])[..., 0]
    except np.linalg.LinAlgError:
        dx = np.full((len(grid), 3), np.nan)
    s2 = _Pchip.of(grid, sol[:, 0], dx[:, 0])
    info = {"distribution": "three-directrices", "warnings": [],
            "c3_params": sol[::k, 1].copy(), "c3_t": sol[::k, 2].copy()}
    return _curve_rulings(c1, arc1, c2, s2, count, info, tol, sig1[::k].copy(),
                          sol[::k, 0].copy())


def _c3_a_line(c1: Curve, c2: Curve, c3: Line, count: int, tol: Tolerances) -> Rulings:
    """:func:`three_directrices` where c3 is a line (and c2 is not): the lines through a
    point of c1 that meet c3 are those of the plane through both, so the family is that of
    the linear directrix c3 (paper §5.2 (d), :func:`_linear_directrix`): c3 counts as the
    whole line through its points, which the lines may meet beyond them or, parallel to
    it, at infinity.  Its branch is the one from the root nearest ``c2(0)``, as the search
    takes the smallest ``v``."""
    try:
        r = _linear_directrix(c1, c2, count, np.stack([c3.p0, c3.p1]),
                              {"distribution": "three-directrices", "warnings": []}, tol)
    except GeometryError as exc:
        raise GeometryError("three directrices, the line c3 as linear directrix d: "
                            + str(exc).removeprefix("linear-directrix: ")) from None
    # Where each generator meets c3 (NaN where parallel to it), as the search reports it.
    w, lam = _crossing(r.a, r.b - r.a, c3)
    info = {k: v for k, v in r.info.items() if k != "directrix"}
    return replace(r, info={**info, "c3_params": w, "c3_t": lam})


@dataclass(frozen=True)
class _Part:
    """sigma(u) = ``whole``'s at ``lo + u (hi - lo)``: a correspondence over a part of c1."""

    whole: Any
    lo: float
    hi: float

    def value(self, u):
        return self.whole.value(self.lo + np.asarray(u) * (self.hi - self.lo))

    def deriv(self, u):
        return self.whole.deriv(self.lo + np.asarray(u) * (self.hi - self.lo)) * (self.hi - self.lo)


def _transversals(p: np.ndarray, c2: Line, c3: Line) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lines through the points ``p`` (n, 3) meeting the lines of ``c2`` and ``c3``: their
    parameters ``v`` on c2 and ``w`` on c3 and ``lam`` with ``c3(w) - p = lam (c2(v) - p)``
    (NaN where a line is parallel to c2 or c3: it meets that line at infinity; ``w`` and
    ``lam`` are NaN too where it is parallel to c2).

    The line lies in both planes through ``p`` and one of the lines, so its direction is the
    cross product of their normals; each parameter is where it meets that line.
    """
    a2, d2 = c2.p0, c2.p1 - c2.p0
    e = np.cross(np.cross(d2, a2 - p), np.cross(c3.p1 - c3.p0, c3.p0 - p))
    v = _meeting(p, e, a2, d2)
    w, lam = _crossing(p, a2 + v[:, None] * d2 - p, c3)
    return v, w, lam


def _crossing(a: np.ndarray, e: np.ndarray, c3: Line) -> tuple[np.ndarray, np.ndarray]:
    """Where each line ``a + t e`` (n, 3) meets the line of ``c3``: its parameter ``w`` on c3
    and ``t`` (NaN where they are parallel, or the line is undefined)."""
    d3 = c3.p1 - c3.p0
    w = _meeting(a, e, c3.p0, d3)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.einsum("ij,ij->i", c3.p0 + w[:, None] * d3 - a, e) / np.einsum("ij,ij->i", e, e)
    return w, t


def _meeting(p: np.ndarray, e: np.ndarray, a: np.ndarray, d: np.ndarray) -> np.ndarray:
    """(n,) the parameter ``x`` where each line ``p + s e`` (n, 3) meets the line ``a + x d``
    (the nearest point, where they are skew), NaN where they are parallel within rounding
    (relative to both directions): no finite meeting point."""
    c = np.cross(d, e)
    cc = np.einsum("ij,ij->i", c, c)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.einsum("ij,ij->i", np.cross(p - a, e), c) / cc
    flat = cc <= (ROUNDING * np.linalg.norm(d)) ** 2 * np.einsum("ij,ij->i", e, e)
    return np.where(flat, np.nan, x)


def _three_lines(c1: Curve, c2: Line, c3: Line, count: int, tol: Tolerances) -> Rulings:
    """:func:`three_directrices` where c2 and c3 are lines: the lines in closed form.

    c3 counts as the whole line through its two points: it only chooses the family
    (the lines meeting three skew lines are one regulus of a quadric) and bounds no part
    of the patch, so the lines may meet it beyond its points or, parallel to it, at
    infinity.  The patch runs from c1 to the segment c2: where only part of c1's lines
    reach that segment, the generators span that part (the longest), with a warning.
    """
    grid, _ = dense_grid(count)
    arc1 = _arc_sigma(c1, count)
    v = _transversals(c1.point_at(arc1.value(grid)), c2, c3)[0]
    inside = np.isfinite(v) & (v >= -PARAMETER_SLACK) & (v <= 1 + PARAMETER_SLACK)
    if not inside.any():
        raise GeometryError("three directrices: no line through a point of c1 that meets the line "
                            "c3 meets the segment c2")
    warnings = []
    if not inside.all():
        lo, hi = _longest_run(inside)
        g0 = _where_v_leaves(c1, arc1, c2, c3, grid, lo - 1, lo) if lo > 0 else 0.0
        g1 = _where_v_leaves(c1, arc1, c2, c3, grid, hi + 1, hi) if hi < len(grid) - 1 else 1.0
        arc1 = _Part(arc1, g0, g1)
        warnings.append(f"three directrices: the lines through c1 that meet the line c3 reach the "
                        f"segment c2 only from arc-length fraction {g0:.4g} to {g1:.4g} of c1; the "
                        f"{count} generators span that part (lengthen c2 for more)")
    u = np.linspace(0.0, 1.0, count)
    sig1 = arc1.value(u)
    v, w, lam = _transversals(c1.point_at(sig1), c2, c3)
    # c3(w) - a = lam (c2(v) - a): c3 meets the generator at t = lam.
    info = {"distribution": "three-directrices", "warnings": warnings, "c3_params": w, "c3_t": lam}
    return _curve_rulings(c1, arc1, c2, _TransversalSigma(c1, arc1, c2, c3), count, info, tol,
                          sig1, np.clip(v, 0.0, 1.0))


@dataclass(frozen=True)
class _TransversalSigma:
    """sigma2(u): where the line through ``c1(sigma1(u))`` meeting the lines c2 and c3 meets
    c2, in closed form at every ``u`` (the generators the refinement adds lie on the quadric
    to rounding, as the given ones do)."""

    c1: Curve
    sigma1: Any
    c2: Line
    c3: Line

    def value(self, u):
        u = np.asarray(u, dtype=np.float64)
        p = self.c1.point_at(self.sigma1.value(u.reshape(-1)))
        return np.clip(_transversals(p, self.c2, self.c3)[0], 0.0, 1.0).reshape(u.shape)

    def deriv(self, u):
        # Central differences of the closed form, one-sided at the ends: the slope serves
        # tangents (closeness, refinement), never a vertex.
        u = np.asarray(u, dtype=np.float64)
        lo, hi = np.maximum(u - SLOPE_STEP, 0.0), np.minimum(u + SLOPE_STEP, 1.0)
        return (self.value(hi) - self.value(lo)) / (hi - lo)


def _longest_run(mask: np.ndarray) -> tuple[int, int]:
    """First and last index of the longest run of True in ``mask`` (some True)."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    best = int(np.argmax(ends - starts))
    return int(starts[best]), int(ends[best])


def _where_v_leaves(c1: Curve, arc1: Any, c2: Line, c3: Line, grid: np.ndarray, out: int, into: int) -> float:
    """The arc-length fraction between ``grid[out]`` (line off the segment c2) and
    ``grid[into]`` (on it) where the lines leave the segment, by bisection."""
    def on(g: float) -> bool:
        v = _transversals(c1.point_at(arc1.value(np.array([g]))), c2, c3)[0][0]
        # Strictly on the segment: the generator found ends on c2 without being clipped.
        return bool(np.isfinite(v) and 0.0 <= v <= 1.0)

    a, b = float(grid[out]), float(grid[into])
    for _ in range(60):
        mid = 0.5 * (a + b)
        if on(mid):
            b = mid
        else:
            a = mid
    return b


def _family_end(reason: str, g: float, sig1: np.ndarray, grid: np.ndarray, k: int,
                count: int) -> GeometryError:
    gen = g * (count - 1)
    u1 = float(np.interp(g, grid, sig1))
    return GeometryError(
        f"three directrices: the family of lines ends near u = {u1:.6g} on c1 (arc-length "
        f"fraction {g:.6g}, near generator {gen:.3g} of {count}): {reason}")


# --------------------------------------------------------------------------
# conoid (§5.1)
# --------------------------------------------------------------------------

def conoid(curve: Curve, directrix: Any, director_plane: Any, count: int, *,
           tol: Tolerances = DEFAULT) -> Rulings:
    """A conoid: one curve, a line directrix d and a director plane (paper §5.1).

    The curve is divided at equal arc length; the plane through each division
    point parallel to the director plane meets d in the generator's other end.

    Parameters
    ----------
    curve : Curve
        The director curve (``a_i``, t = 0).
    directrix : (2, 3) array_like
        Two points of the line d (``b_i``, t = 1, anywhere on the line).
    director_plane : (3,) array_like
        Its normal ``n``: every generator satisfies ``n . (b_i - a_i) = 0``.
    count : int >= 2

    Raises
    ------
    GeometryError
        d is parallel to the director plane, or the curve meets d.
    """
    curve = _check_curve(curve, "curve")
    d = check_line(directrix, "directrix")
    n = check_vector(director_plane, "director_plane", nonzero=True)
    count = check_int(count, "count", lo=2)
    n = n / np.linalg.norm(n)
    e = d[1] - d[0]
    if abs(n @ e) <= tol.degenerate * np.linalg.norm(e):
        raise GeometryError(
            "conoid: the directrix d is parallel to the director plane: the planes parallel to "
            "the director plane never meet it (or contain it)")
    arc = _arc_sigma(curve, count)
    u = np.linspace(0.0, 1.0, count)
    sig = arc.value(u)
    rail_a = _CurveTrack(curve, arc)
    rail_b = _ConoidTrack(rail_a, d[0], e, n)
    a = curve.point_at(sig)
    b = rail_b.value(u)
    _check_generators(a, b, "conoid", tol)
    info = {"distribution": "conoid", "warnings": [], "c1_params": sig,
            "directrix_params": (a - d[0]) @ n / (e @ n), "director_plane": n, "directrix": d}
    return Rulings(a, b, u, RuledSurface(rail_a, rail_b, u), info)


# --------------------------------------------------------------------------
# explicit lines
# --------------------------------------------------------------------------

def from_lines(lines: Any, *, tol: Tolerances = DEFAULT) -> Rulings:
    """Rulings from explicit generators.

    Parameters
    ----------
    lines : (m, 2, 3) array_like, m >= 2
        ``lines[i] = [a_i, b_i]``.

    Returns
    -------
    Rulings
        ``u`` is the normalised cumulative mean chord length of the endpoints;
        the reference surface interpolates the endpoints with C2 cubic splines
        (not-a-knot) in that ``u``.

    Raises
    ------
    GeometryError
        A generator of zero length, or two consecutive equal generators.
    """
    try:
        arr = np.asarray(lines, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(f"expected numbers, got {describe(lines)}", "lines") from None
    if arr.ndim != 3 or arr.shape[1:] != (2, 3):
        raise ParameterError(
            f"expected a list of lines [[x, y, z], [x, y, z]], got {describe(lines)}", "lines")
    if len(arr) < 2:
        raise ParameterError(f"expected at least 2 lines, got {len(arr)}", "lines")
    if not np.all(np.isfinite(arr)):
        raise ParameterError("expected finite coordinates, got NaN or infinity", "lines")
    a, b = arr[:, 0].copy(), arr[:, 1].copy()
    _check_generators(a, b, "lines", tol)
    step = 0.5 * (np.linalg.norm(np.diff(a, axis=0), axis=1)
                  + np.linalg.norm(np.diff(b, axis=0), axis=1))
    pts = np.concatenate([a, b])
    size = diagonal(pts)
    dup = np.nonzero(step <= tol.degenerate * size)[0]
    if len(dup):
        i = int(dup[0])
        raise GeometryError(f"lines: generators {i} and {i + 1} are the same line")
    u = np.concatenate([[0.0], np.cumsum(step)]) / step.sum()
    u[-1] = 1.0
    from scipy.interpolate import CubicSpline

    surface = RuledSurface(_SplineTrack(CubicSpline(u, a, axis=0)),
                           _SplineTrack(CubicSpline(u, b, axis=0)), u)
    return Rulings(a, b, u, surface, {"distribution": "lines", "warnings": []})


# --------------------------------------------------------------------------
# limits
# --------------------------------------------------------------------------

# The limit on generators and the measured memory per generator and row live in ruledmesh.budget.
BUILD_BYTES_PER_GRID_POINT = PQ_BYTES_PER_GRID_POINT
