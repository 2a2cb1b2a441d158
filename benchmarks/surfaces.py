"""The design surfaces of the benchmark, the same for every method.

Each surface gives

* ``generators(n)``: ``n`` generators ``a_i b_i`` lying exactly on it (what
  ruledmesh meshes), ordered along the surface;
* ``naive_grid(n)``: the parameter-grid quad mesh ``a_i + t_j (b_i - a_i)``
  with ``n x n`` vertices (what a designer would feed an optimiser); its
  vertices are on the surface, its quads are not planar;
* ``distance(points)``: distance from the design surface - exact foot points
  for the two quadrics, :class:`ruledmesh.surfaces.RuledReference` for
  the general skew surface (which measures to the patch ``0 <= u, t <= 1``);
* ``diagonal``: the bounding-box diagonal of the design patch, the unit of
  every displacement figure.

Why the hyperboloid is cut by oblique planes: the ruled parameter grid of a
one-sheet hyperboloid cut by horizontal planes is an affine image of a
rotational mesh (generators and parallel ellipses), so its quads are already
planar trapezoids and there would be nothing to optimise.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = ["BenchSurface", "SURFACES", "grid_quads"]


def grid_quads(rows: int, cols: int) -> np.ndarray:
    """(F, 4) int64: quads of a ``rows x cols`` vertex grid stored row-major."""
    idx = np.arange(rows * cols).reshape(rows, cols)
    return np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]],
                    axis=-1).reshape(-1, 4)


@dataclass(eq=False)
class BenchSurface:
    """A design surface: generators on it, its naive grid and a distance."""

    name: str
    description: str
    generators: Callable[[int], tuple[np.ndarray, np.ndarray]]
    distance: Callable[[np.ndarray], np.ndarray]
    _diag: float | None = field(default=None, repr=False)

    def naive_grid(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Vertices (n*n, 3) and quads ((n-1)^2, 4) of the parameter grid."""
        a, b = self.generators(n)
        t = np.linspace(0.0, 1.0, n)
        V = a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]
        return V.reshape(-1, 3), grid_quads(n, n)

    @property
    def diagonal(self) -> float:
        """Bounding-box diagonal of the patch (from a fine parameter grid)."""
        if self._diag is None:
            V, _ = self.naive_grid(201)
            self._diag = float(np.linalg.norm(V.max(0) - V.min(0)))
        return self._diag


# ------------------------------------------------------------- hyperbolic paraboloid
def _hp_generators(n: int) -> tuple[np.ndarray, np.ndarray]:
    # z = x y on |x|, |y| <= 1: the lines x = const are one regulus.
    x = np.linspace(-1.0, 1.0, n)
    one = np.ones(n)
    return np.stack([x, -one, -x], 1), np.stack([x, one, x], 1)


def _hp_distance(p: np.ndarray, iterations: int = 60) -> np.ndarray:
    """Exact distance from z = x y (Lagrange foot point, Newton in one unknown).

    In the frame X = (x + y)/sqrt 2, Y = (x - y)/sqrt 2 the surface is
    z = (X^2 - Y^2)/2; the foot point is X/(1 + l), Y/(1 - l), z + l for the
    root l of the constraint nearest 0 (|l| < 1).
    """
    p = np.asarray(p, dtype=np.float64).reshape(-1, 3)
    X = (p[:, 0] + p[:, 1]) / np.sqrt(2.0)
    Y = (p[:, 0] - p[:, 1]) / np.sqrt(2.0)
    z = p[:, 2]
    lam = np.zeros(len(p))
    lo, hi = np.full(len(p), -1.0), np.full(len(p), 1.0)
    for _ in range(iterations):
        u, v = 1.0 + lam, 1.0 - lam
        g = 0.5 * (X**2 / u**2 - Y**2 / v**2) - z - lam
        dg = -X**2 / u**3 - Y**2 / v**3 - 1.0          # < 0: g decreases in lam
        hi = np.where(g < 0, lam, hi)
        lo = np.where(g > 0, lam, lo)
        step = lam - g / dg
        # Newton, bisecting whenever it would leave the bracket (|l| < 1 keeps the foot finite).
        lam = np.where((step >= lo) & (step <= hi), step, 0.5 * (lo + hi))
    foot = np.stack([X / (1 + lam), Y / (1 - lam), z + lam], 1)
    return np.linalg.norm(foot - np.stack([X, Y, z], 1), axis=1)


# ------------------------------------------------------------------ hyperboloid
_HA, _HB, _HC = 1.0, 1.5, 1.0          # x^2/a^2 + y^2/b^2 - z^2/c^2 = 1
_PHI = (0.0, 0.6 * np.pi)              # range of generators
_CUT0 = (-1.0, 0.25, 0.0)              # c1: z = k0 + kx x + ky y
_CUT1 = (1.0, 0.0, 0.3)                # c2


def _hyperboloid_generators(n: int) -> tuple[np.ndarray, np.ndarray]:
    # Line of one regulus: (a (cos f + s sin f), b (sin f - s cos f), c s); cut by two planes.
    phi = np.linspace(*_PHI, n)
    c, s_ = np.cos(phi), np.sin(phi)
    ends = []
    for k0, kx, ky in (_CUT0, _CUT1):
        # c s = k0 + kx a (c + s sin) + ky b (sin - s cos): linear in s.
        s = (k0 + kx * _HA * c + ky * _HB * s_) / (_HC - kx * _HA * s_ + ky * _HB * c)
        ends.append(np.stack([_HA * (c + s * s_), _HB * (s_ - s * c), _HC * s], 1))
    return ends[0], ends[1]


def _hyperboloid_distance(p: np.ndarray, iterations: int = 60) -> np.ndarray:
    """Exact distance from the hyperboloid (Lagrange foot point x_k = p_k / (1 + l A_k))."""
    p = np.asarray(p, dtype=np.float64).reshape(-1, 3)
    A = np.array([1 / _HA**2, 1 / _HB**2, -1 / _HC**2])
    # 1 + l A_k > 0 for all k: l in (-min(a^2, b^2), c^2); g(l) is decreasing there.
    lo = np.full(len(p), -min(_HA, _HB) ** 2 * (1 - 1e-12))
    hi = np.full(len(p), _HC**2 * (1 - 1e-12))
    lam = np.zeros(len(p))
    for _ in range(iterations):
        q = 1.0 + lam[:, None] * A
        x = p / q
        g = (A * x * x).sum(1) - 1.0
        dg = (-2.0 * A * A * x * x / q).sum(1)
        hi = np.where(g < 0, lam, hi)
        lo = np.where(g > 0, lam, lo)
        step = lam - g / np.where(dg != 0, dg, -1.0)
        lam = np.where((step >= lo) & (step <= hi), step, 0.5 * (lo + hi))
    return np.linalg.norm(p / (1.0 + lam[:, None] * A) - p, axis=1)


# ------------------------------------------------------------- general skew surface
_SKEW_C1 = [[0, 0, 0], [4, 2, 0.5], [8, -1, 0], [12, 1, 0.5]]     # paper Fig. 10 example
_SKEW_C2 = [[0, 3, 4], [4, 1, 5], [8, 5, 4], [12, 3, 5]]
_skew_cache: dict = {}


def _skew_curves():
    from ruledmesh.curves import BSpline

    if "curves" not in _skew_cache:
        _skew_cache["curves"] = (BSpline(np.array(_SKEW_C1, float), 3),
                                 BSpline(np.array(_SKEW_C2, float), 3))
    return _skew_cache["curves"]


def _skew_generators(n: int) -> tuple[np.ndarray, np.ndarray]:
    from ruledmesh.rulings import between

    c1, c2 = _skew_curves()
    r = between(c1, c2, n, "arc-length")
    return np.array(r.a), np.array(r.b)


def _skew_distance(p: np.ndarray) -> np.ndarray:
    from ruledmesh.rulings import between
    from ruledmesh.surfaces import RuledReference

    if "ref" not in _skew_cache:
        c1, c2 = _skew_curves()
        # The smooth surface of the arc-length correspondence does not depend on the count.
        _skew_cache["ref"] = RuledReference(between(c1, c2, 3, "arc-length").surface, samples=256)
    return _skew_cache["ref"].distance(np.asarray(p, dtype=np.float64).reshape(-1, 3))


SURFACES: dict[str, BenchSurface] = {
    s.name: s for s in (
        BenchSurface("hyperbolic-paraboloid", "z = x y, |x|, |y| <= 1, generators x = const",
                     _hp_generators, _hp_distance),
        BenchSurface("hyperboloid", "x^2 + y^2/2.25 - z^2 = 1, one regulus over 0.6 pi, "
                     "cut by the planes z = -1 + 0.25 x and z = 1 + 0.3 y",
                     _hyperboloid_generators, _hyperboloid_distance),
        BenchSurface("skew", "two cubic B-splines (paper Fig. 10 example), generators at equal "
                     "arc length", _skew_generators, _skew_distance),
    )
}
