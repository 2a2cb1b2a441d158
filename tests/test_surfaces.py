"""Smooth reference surfaces (ruledmesh.surfaces): distances against direct formulas."""

from __future__ import annotations

import numpy as np
import pytest

from ruledmesh.surfaces import _segment_distance, pipe_of_polyline, revolution_of_polyline


def _all_pairs(q: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Distance from each point to each segment at once, as (points, segments, k) arrays."""
    a, d = poly[:-1], np.diff(poly, axis=0)
    t = np.clip(np.einsum("nij,ij->ni", q[:, None, :] - a[None], d)
                / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    off = q[:, None] - (a[None] + t[..., None] * d[None])
    return np.sqrt(np.einsum("nij,nij->ni", off, off).min(axis=1))


@pytest.mark.parametrize("k", [2, 3])
def test_segment_distance_is_the_all_pairs_formula(k):
    """Blocked and coordinate by coordinate: in the plane (meridians of surfaces of revolution)
    the same numbers bit for bit; in space einsum adds three products in another order, so
    the foot points, and the distances, may differ by rounding of the coordinates."""
    rng = np.random.default_rng(k)
    for i in range(60):
        n, m = int(rng.integers(1, 300)), int(rng.integers(2, 3000))
        q = rng.normal(size=(n, k)) * 10.0 ** rng.uniform(-3, 3)
        poly = np.cumsum(rng.normal(size=(m, k)), axis=0)
        if i % 5 == 0:
            poly[1] = poly[0]                     # a segment of zero length
        got, want = _segment_distance(q, poly), _all_pairs(q, poly)
        if k == 2:
            assert np.array_equal(got, want)
        else:
            size = max(np.abs(q).max(), np.abs(poly).max())
            np.testing.assert_allclose(got, want, rtol=0, atol=8 * np.finfo(float).eps * size)


def test_pipe_and_revolution_distances():
    pipe = pipe_of_polyline(np.array([[0.0, 0, 0], [10, 0, 0], [10, 10, 0]]), 1.0)
    pts = np.array([[5.0, 3, 0], [5, 0, 1], [12, 5, 0], [10, 12, 0]])
    np.testing.assert_allclose(pipe.distance(pts), [2.0, 0.0, 1.0, 1.0], atol=1e-15)
    cylinder = revolution_of_polyline(np.array([[2.0, 0], [2, 5]]), np.zeros(3), np.array([0.0, 0, 1]),
                                      2 * np.pi, np.array([1.0, 0, 0]))
    np.testing.assert_allclose(cylinder.distance(np.array([[3.0, 0, 1], [0, 0.5, 2], [2, 0, 7]])),
                               [1.0, 1.5, 2.0], atol=1e-15)
