"""Patch corners re-cut where an end generator meets a rim in a splinter (skew/pq/corners.py).

The surface: lines between two arcs of 200 degrees turned against each other by 155 degrees
(a hyperboloid of revolution), its rows through the generators' end points on both arcs.
Those rows leave a gap at the two corners where an end generator meets a rim, and the border
quad through the corner gave the triangle closing the gap an angle of 1.17 degrees there.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ruledmesh.analysis import planarity
from ruledmesh.analysis.faces import SPLINTER_DEG, face_min_angles
from ruledmesh.pq import pq_mesh
from ruledmesh.skew.pq.corners import rezip_corners


def _twisted(m: int = 57) -> tuple[np.ndarray, np.ndarray]:
    th = np.radians(np.linspace(-20.0, 180.0, m))
    a = np.stack([5 * np.cos(th), 5 * np.sin(th), np.zeros(m)], axis=1)
    b = np.stack([4.5 * np.cos(th + np.radians(155)), 4.5 * np.sin(th + np.radians(155)), np.full(m, 2.5)], axis=1)
    return a, b


@pytest.fixture(scope="module")
def built():
    a, b = _twisted()
    return a, b, pq_mesh(a, b, rows=26, rows_from="both")


def test_both_corners_are_re_cut_without_splinters(built):
    _, _, mesh = built
    assert mesh.info["corners"] == 2
    ang = face_min_angles(mesh)
    assert ang.min() >= SPLINTER_DEG
    assert planarity(mesh)[mesh.valences == 4].max() <= 1e-12
    # the rows through both arcs' end points: almost all quads
    V, off, val = mesh.vertices, mesh.face_offsets, mesh.valences
    area = np.zeros(mesh.n_faces)
    for k in range(1, val.max() - 1):
        has = val > k + 1
        p0, p1, p2 = (V[mesh.face_indices[off[:-1][has] + j]] for j in (0, k, k + 1))
        area[has] += 0.5 * np.linalg.norm(np.cross(p1 - p0, p2 - p0), axis=1)
    assert area[val == 4].sum() / area.sum() > 0.9


def test_the_re_cut_mesh_is_a_clean_mesh_on_its_generators(built):
    a, b, mesh = built
    # every vertex on its generator, at its parameter
    g, t = mesh.vertex_data["generator"], mesh.vertex_data["t"]
    assert np.abs(a[g] + t[:, None] * (b[g] - a[g]) - mesh.vertices).max() <= 1e-12 * np.abs(a).max()
    # oriented (no edge twice in one direction) and a manifold
    idx = mesh.face_indices
    directed = idx * mesh.n_vertices + idx[mesh.next_corners()]
    assert np.unique(directed).size == directed.size
    assert mesh.edge_uses()[1].max() <= 2
    # the members run along single generators, through every vertex on the end generators
    assert (g[mesh.members[:, 0]] == g[mesh.members[:, 1]]).all()
    for end in (0, len(a) - 1):
        on = np.flatnonzero(g == end)
        chain = mesh.members[(g[mesh.members[:, 0]] == end)]
        assert len(chain) == on.size - 1
        assert set(chain.reshape(-1).tolist()) == set(on.tolist())


def test_a_mesh_without_such_corners_is_returned_as_it_is(built):
    _, _, mesh = built
    again, n = rezip_corners(mesh)
    assert n == 0 and again is mesh


def test_an_untrimmed_mesh_has_no_corners_beyond_the_patch():
    # A hyperbolic paraboloid z = x y extended far beyond its patch and not trimmed: its end
    # generators carry hundreds of vertices outside the patch (t < 0 or t > 1).  Only the four
    # points where they meet the director curves are patch corners; taking every vertex
    # outside for one re-cut 128 "corners" of this mesh, faces far from any corner among them.
    x = np.linspace(-1.0, 1.0, 9)
    a = np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=1)
    b = np.stack([x, np.ones_like(x), x], axis=1)
    mesh = pq_mesh(a, b, rows=6, extend=100, max_extend=1000, trim=False)
    t = mesh.vertex_data["t"]
    assert (t < -1.0).sum() > 100                   # far beyond the patch: the case in question
    assert mesh.info["corners"] == 0
    assert rezip_corners(mesh)[1] == 0


def test_a_design_keeps_the_mesh_through_both_arcs_end_points():
    from ruledmesh.design import build_design, parse_design

    # The same arcs at 57 generators (arc length) and 26 rows, of the quality set.
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "quality" / "twisted-arcs-155deg.toml"
    text = path.read_text()
    mesh = build_design(parse_design(text, path.name)).mesh
    assert mesh.info["rows_from"] == "both"
    assert face_min_angles(mesh).min() >= SPLINTER_DEG
    # 26.3 % of the area in triangles (3,092 faces) before the corners were re-cut
    assert (mesh.valences == 3).sum() < 0.15 * mesh.n_faces
