"""Strips between polygons with pairwise parallel edges (paper §2.1, Fig. 3).

If ``c_{k+1} = s_k c_k + t_k`` (a homothety or translation of ``c_k``), the
edges of consecutive polygons are pairwise parallel, so each quad between them
is a trapezoid: planar because two of its opposite edges are parallel.
Congruent polygons (``s = 1``) give a prism, similar ones a pyramid (§3.1).
The general case lets each edge scale by its own factor (the polygons then
have parallel edges without being similar).
"""

from __future__ import annotations

import numpy as np

from .._validation import check_points
from ..errors import ParameterError
from ._grid import grid_mesh

__all__ = ["similar_strips", "parallel_edge_strips"]


def similar_strips(polygon: np.ndarray, scales, translations, *, closed: bool = False):
    """Polygons ``c_{k+1} = s_k c_k + t_k`` and the trapezoid strips between them.

    Parameters
    ----------
    polygon : (n, 3) float64
        ``c_0``.
    scales : (K,) float64
        ``s_k``, non-zero (1 for congruent polygons).
    translations : (K, 3) float64
        ``t_k``.
    closed : bool
        The polygon is closed (its last vertex joins the first).

    Returns
    -------
    Mesh
        ``K * (n - 1)`` (or ``K * n`` closed) trapezoids.
    """
    c0 = check_points(polygon, "polygon", min_count=2)
    s = np.asarray(scales, dtype=np.float64).reshape(-1)
    t = check_points(np.asarray(translations, dtype=np.float64).reshape(-1, 3), "translations",
                     min_count=0)
    if s.size != len(t) or s.size == 0:
        raise ParameterError(f"expected as many scales as translations (at least 1), got "
                             f"{s.size} and {len(t)}", "scales")
    if np.any(s == 0) or not np.all(np.isfinite(s)):
        raise ParameterError("expected finite non-zero scales", "scales")
    # c_k = S_k c_0 + T_k with cumulative products/sums: no loop over vertices.
    S = np.concatenate([[1.0], np.cumprod(s)])
    T = np.zeros((s.size + 1, 3))
    for k in range(s.size):  # one step per polygon, each a (3,) update
        T[k + 1] = s[k] * T[k] + t[k]
    grid = S[:, None, None] * c0[None] + T[:, None, :]
    mesh = grid_mesh(grid, wrap_v=closed, collapse=False,
                     info={"construction": "similar strips"})
    return mesh


def parallel_edge_strips(polygon: np.ndarray, starts: np.ndarray, edge_factors: np.ndarray):
    """Open polylines with pairwise parallel edges, each edge scaled by its own factor.

    ``c_{k+1}[0] = starts[k]`` and ``c_{k+1}[j+1] - c_{k+1}[j] = f_{k,j} (c_k[j+1] - c_k[j])``.

    Parameters
    ----------
    polygon : (n, 3) float64
    starts : (K, 3) float64
    edge_factors : (K, n - 1) float64, non-zero

    Returns
    -------
    Mesh
    """
    c0 = check_points(polygon, "polygon", min_count=2)
    starts = check_points(starts, "starts", min_count=1)
    f = np.asarray(edge_factors, dtype=np.float64)
    if f.shape != (len(starts), len(c0) - 1):
        raise ParameterError(f"expected shape ({len(starts)}, {len(c0) - 1}), got {f.shape}",
                             "edge_factors")
    if np.any(f == 0) or not np.all(np.isfinite(f)):
        raise ParameterError("expected finite non-zero factors", "edge_factors")
    edges = np.diff(c0, axis=0)
    # Every edge of c_k is parallel to the same edge of c_0: scale by the products.
    scale = np.cumprod(f, axis=0)
    rows = starts[:, None, :] + np.concatenate(
        [np.zeros((len(starts), 1, 3)), np.cumsum(scale[..., None] * edges[None], axis=1)], axis=1)
    grid = np.concatenate([c0[None], rows], axis=0)
    return grid_mesh(grid, collapse=False, info={"construction": "parallel-edge strips"})
