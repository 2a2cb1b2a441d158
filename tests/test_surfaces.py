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


def _design(name: str) -> str:
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    path = root / "examples" / f"{name}.toml"
    return str(path if path.exists() else root / "benchmarks" / "quality" / f"{name}.toml")


def test_closeness_starts_at_each_vertex_own_place():
    """A §4.3 build tells the reference each generator's u: every vertex is point(u_g, t).
    On the linear-directrix example the search from samples had left vertices 1.3e-2 of
    the diagonal off the surface they lie on (to rounding); from their own place they read
    rounding, and the analysis reports that."""
    from ruledmesh.analysis.report import analyze
    from ruledmesh.api import build_full

    built = build_full(_design("linear-directrix"))
    assert built.reference.vertex_parameters(built.mesh) is not None
    assert analyze(built.mesh, built.reference)["closeness"]["vertices_max"] <= 1e-14
    searched = built.reference.distance(built.mesh.vertices) / built.mesh.diagonal()
    assert searched.max() > 1e-3            # what the search alone finds there


def test_closeness_searches_where_a_face_start_is_on_another_part():
    """On the Pluecker conoid two faces' mean parameters descend to a foot 2.3e-2 of the
    diagonal away, where the nearest point is 4.6e-4 away: those (everything farther than
    CLOSENESS_SEARCH) are searched from samples as well, so the figure is the search's."""
    from ruledmesh.analysis.faces import face_centroids
    from ruledmesh.api import build_full
    from ruledmesh.tolerances import CLOSENESS_SEARCH

    built = build_full(_design("plucker-conoid"))
    mesh, ref = built.mesh, built.reference
    u, t = ref.vertex_parameters(mesh)
    near = tuple(np.add.reduceat(x[mesh.face_indices], mesh.face_offsets[:-1]) / mesh.valences
                 for x in (u, t))
    c, diag = face_centroids(mesh), mesh.diagonal()
    seeded_only = ref.distance(c, near=near, beyond=np.inf) / diag
    checked = ref.distance(c, near=near, beyond=CLOSENESS_SEARCH * diag) / diag
    searched = ref.distance(c) / diag
    assert seeded_only.max() > 10 * searched.max()
    assert np.all(checked <= seeded_only)
    assert checked.max() == pytest.approx(searched.max(), rel=1e-6)
