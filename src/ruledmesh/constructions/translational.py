"""Translational surfaces (paper §2.2): ``X[i, j] = p_i + q_j - q_0``.

Every quad ``p_i + q_j, p_{i+1} + q_j, p_{i+1} + q_{j+1}, p_i + q_{j+1}`` is a
parallelogram (its opposite edges are the same vectors), so it is planar
whatever the profiles.  The profile ``p`` lies on the surface as given; ``q``
is translated along it.
"""

from __future__ import annotations

import numpy as np

from .._validation import check_points
from ..errors import ParameterError
from ..surfaces import parametric_area
from ._grid import grid_mesh
from .profiles import Profile

__all__ = ["translational_mesh", "TranslationalPatch"]


def translational_mesh(p: np.ndarray, q: np.ndarray, *, info: dict | None = None):
    """The parallelogram mesh ``X[i, j] = p_i + (q_j - q_0)``.

    Parameters
    ----------
    p : (m, 3) float64
        First profile (lies on the surface).
    q : (n, 3) float64
        Second profile, translated along ``p``.

    Returns
    -------
    Mesh
        ``(m - 1)(n - 1)`` parallelograms.
    """
    p = check_points(p, "p", min_count=2)
    q = check_points(q, "q", min_count=2)
    grid = p[:, None, :] + (q - q[0])[None, :, :]
    return grid_mesh(grid, collapse=False, info=dict(info or {"construction": "translational"}))


class TranslationalPatch:
    """``S(u, t) = p(u) + q(t) - q(0)`` on ``[0, 1]^2`` for analytic profiles.

    Has ``point``, ``partials`` and ``area`` as
    :class:`~ruledmesh.surfaces.RuledReference` expects.
    """

    def __init__(self, p: Profile, q: Profile):
        if p.derivative is None or q.derivative is None:
            raise ParameterError("expected analytic profiles (a polyline has no derivative)", "p")
        self.p, self.q = p, q
        self._dp, self._dq = p.derivative, q.derivative
        self._q0 = q.point(np.zeros(1))[0]

    def point(self, u, t):
        return self.p.point(np.asarray(u)) + self.q.point(np.asarray(t)) - self._q0

    def partials(self, u, t):
        return self._dp(np.asarray(u)), self._dq(np.asarray(t))

    def area(self) -> float:
        return parametric_area(self.partials, (0.0, 1.0), (0.0, 1.0))
