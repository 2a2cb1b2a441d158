"""Distances to the smooth ruled surface a mesh was built from.

:class:`RuledReference` wraps a :class:`~ruledmesh.rulings.RuledSurface`
(``point(u, t)``, ``partials(u, t)``, ``area()``) and measures how far points
are from the design patch ``0 <= u, t <= 1``: a nearest sample on a fine grid
seeds a few vectorised Gauss-Newton steps on ``|S(u, t) - p|^2`` with
``(u, t)`` clamped to the patch.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..tolerances import SETTLED, TINY

# Up to this many point-sample pairs the nearest seeds are found by comparing all pairs.
_BRUTE_FORCE = 2_000_000
# Points per block of that comparison.
_BLOCK = 64

__all__ = ["RuledReference"]


@dataclass(frozen=True, eq=False)
class RuledReference:
    """Closeness and area of a smooth ruled surface patch.

    Parameters
    ----------
    surface : RuledSurface
        Has ``point(u, t)``, ``partials(u, t)`` and ``area()``.
    samples : int
        Grid resolution of the seeding samples per direction.
    generator_u : (m,) float64, optional
        The surface parameter ``u`` of each generator that a mesh's
        ``vertex_data["generator"]`` indexes (its vertex ``a_g + t (b_g - a_g)`` is
        ``point(u_g, t)``): :meth:`vertex_parameters` then knows where on the patch
        each vertex lies, and the search needs no samples.
    """

    surface: RuledPatch
    samples: int = 64
    generator_u: np.ndarray | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    def vertex_parameters(self, mesh) -> tuple[np.ndarray, np.ndarray] | None:
        """(V,) ``u`` and ``t`` of each vertex of ``mesh``, where :attr:`generator_u` says.

        None without them, or when the mesh's vertex data do not index them
        (another mesh than the one built with these generators).
        """
        data = mesh.vertex_data
        if self.generator_u is None or "generator" not in data or "t" not in data:
            return None
        g = np.asarray(data["generator"], dtype=np.int64)
        if g.size != mesh.n_vertices or (g.size and (g.min() < 0 or g.max() >= len(self.generator_u))):
            return None
        return np.asarray(self.generator_u, dtype=np.float64)[g], np.asarray(data["t"], dtype=np.float64)

    def _seeds(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Sample points of the patch and their parameters ``u``, ``t``."""
        if "seeds" not in self._cache:
            u = np.linspace(0.0, 1.0, self.samples)
            t = np.linspace(0.0, 1.0, max(self.samples // 4, 9))
            uu, tt = np.meshgrid(u, t, indexing="ij")
            pts = self.surface.point(uu.ravel(), tt.ravel())
            self._cache["seeds"] = (pts, uu.ravel(), tt.ravel())
        return self._cache["seeds"]

    def _nearest_seeds(self, points: np.ndarray, k: int) -> np.ndarray:
        """(n, k) int64: the ``k`` samples nearest to each point (in no particular order)."""
        pts = self._seeds()[0]
        if len(points) * len(pts) <= _BRUTE_FORCE:
            # A small analysis (a designer edit, a small build) compares every pair in numpy
            # instead of importing scipy.spatial for a k-d tree.  Centred first: at site
            # coordinates the expanded squares would round the distances away.
            centre = pts.mean(axis=0)
            p, q = points - centre, pts - centre
            if k >= len(pts):
                return np.broadcast_to(np.arange(len(pts)), (len(points), len(pts)))
            pp, qq, qt = np.einsum("ij,ij->i", p, p), np.einsum("ij,ij->i", q, q)[None, :], q.T
            out = np.empty((len(points), k), dtype=np.int64)
            # In blocks of rows: the block's distances stay in the cache (the whole matrix
            # is 16 MB at the limit) and each row's selection is the same.
            for lo in range(0, len(points), _BLOCK):
                d = pp[lo:lo + _BLOCK, None] - 2.0 * p[lo:lo + _BLOCK] @ qt
                d += qq
                out[lo:lo + _BLOCK] = np.argpartition(d, k - 1, axis=1)[:, :k]
            return out
        if "tree" not in self._cache:
            from scipy.spatial import cKDTree

            self._cache["tree"] = cKDTree(pts)
        _, nearest = self._cache["tree"].query(points, k=k)
        return np.asarray(nearest).reshape(len(points), k)

    def closest(self, points: np.ndarray, iterations: int = 12,
                seeds: int = 6) -> tuple[np.ndarray, np.ndarray]:
        """Parameters ``(u, t)`` of the nearest point of the patch to each point.

        Gauss-Newton runs from the ``seeds`` nearest samples at once and the
        best result is kept: where the surface passes close to itself (a
        Pluecker conoid through its double line, a helicoid's turns) the single
        nearest sample may lie on the other sheet.

        Parameters
        ----------
        points : (n, 3) float64

        Returns
        -------
        u, t : (n,) float64
        """
        _, us, ts = self._seeds()
        k = min(seeds, len(us))
        nearest = self._nearest_seeds(points, k)
        u, t = self._descend(np.repeat(points, k, axis=0), us[nearest].ravel(), ts[nearest].ravel(),
                             iterations)
        d = np.linalg.norm(self.surface.point(u, t) - np.repeat(points, k, axis=0), axis=1)
        best = np.argmin(d.reshape(-1, k), axis=1) + k * np.arange(len(points))
        return u[best], t[best]

    def _descend(self, points: np.ndarray, u: np.ndarray, t: np.ndarray,
                 iterations: int) -> tuple[np.ndarray, np.ndarray]:
        """Gauss-Newton on ``|S(u, t) - p|^2`` from ``(u, t)``, clamped to the patch.

        A point whose step no longer moves it (by more than :data:`SETTLED` in
        ``u`` and ``t``: converged, or held at the patch border) takes no further
        steps, so the work follows the points still moving.
        """
        u, t = u.copy(), t.copy()
        live = np.arange(len(u))
        both = getattr(self.surface, "point_partials", None)
        for _ in range(iterations):
            if live.size == 0:
                break
            uu, tt, pp = u[live], t[live], points[live]
            if both is not None:        # the rails evaluated once for the point and its partials
                s, su, st = both(uu, tt)
            else:
                s = self.surface.point(uu, tt)
                su, st = self.surface.partials(uu, tt)
            r = s - pp
            a = np.einsum("ij,ij->i", su, su)
            b = np.einsum("ij,ij->i", su, st)
            c = np.einsum("ij,ij->i", st, st)
            gu = np.einsum("ij,ij->i", su, r)
            gt = np.einsum("ij,ij->i", st, r)
            det = a * c - b * b
            safe = np.where(np.abs(det) > TINY, det, 1.0)
            du = np.where(np.abs(det) > TINY, (c * gu - b * gt) / safe, 0.0)
            dt = np.where(np.abs(det) > TINY, (a * gt - b * gu) / safe, 0.0)
            nu = np.clip(uu - du, 0.0, 1.0)
            nt = np.clip(tt - dt, 0.0, 1.0)
            u[live], t[live] = nu, nt
            moving = (np.abs(nu - uu) > SETTLED) | (np.abs(nt - tt) > SETTLED)
            live = live[moving]
        return u, t

    def distance(self, points: np.ndarray, near: tuple[np.ndarray, np.ndarray] | None = None,
                 beyond: float = 0.0) -> np.ndarray:
        """(n,) float64: distance of each point from the patch.

        ``near``: (n,) ``u`` and ``t`` of a point of the patch near each point (a
        vertex's own, a face's mean of its corners'): the descent starts there
        instead of at the nearest samples, and only the points it leaves farther
        than ``beyond`` from the patch are searched from the samples as well (the
        nearer result kept).  A mesh's vertices and most of its faces then need
        no search.
        """
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if len(points) == 0:
            return np.zeros(0)
        if near is None:
            u, t = self.closest(points)
            return np.linalg.norm(self.surface.point(u, t) - points, axis=1)
        u0 = np.clip(np.asarray(near[0], dtype=np.float64), 0.0, 1.0)
        t0 = np.clip(np.asarray(near[1], dtype=np.float64), 0.0, 1.0)
        u, t = self._descend(points, u0, t0, 12)
        d = np.linalg.norm(self.surface.point(u, t) - points, axis=1)
        far = np.flatnonzero(d > beyond)
        if far.size:
            # The start's own part of the surface may not hold the nearest point (a face
            # across a fold, a strip quad spanning a torsal band).
            d[far] = np.minimum(d[far], self.distance(points[far]))
        return d

    def area(self) -> float:
        """Area of the smooth patch."""
        if "area" not in self._cache:
            self._cache["area"] = float(self.surface.area())
        return self._cache["area"]


class RuledPatch(Protocol):
    """What :class:`RuledReference` needs of a smooth surface patch ``0 <= u, t <= 1``."""

    def point(self, u: np.ndarray, t: np.ndarray) -> np.ndarray: ...

    def partials(self, u: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...

    def area(self) -> float: ...
