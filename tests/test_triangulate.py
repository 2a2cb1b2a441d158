"""Triangulation without splinters: coverage, orientation, optimality, recovery."""

from __future__ import annotations

import math

import export_meshes as E  # a helper module of tests/ (see conftest.py)
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.faces import face_normals
from ruledmesh.analysis.report import analyze
from ruledmesh.analysis.triangles import aspect_ratios, compare_tessellations, parameter_grid, triangle_quality
from ruledmesh.errors import ParameterError
from ruledmesh.mesh import Mesh
from ruledmesh.triangulate import (
    MAX_TEMPLATE_VALENCE,
    polygon_templates,
    recover_polygons,
    triangle_angles,
    triangulate,
)


def _tri_normals(vertices, triangles):
    p = vertices[triangles]
    return 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])


def check_triangulation(mesh: Mesh, quads="shorter"):
    """Each face gives valence-2 triangles on its own corners, all turning like
    the face, whose areas add up to the face's area: an exact cover."""
    tri = triangulate(mesh, quads)
    assert tri.n_triangles == int((mesh.valences - 2).sum())
    np.testing.assert_array_equal(np.diff(tri.offsets), mesh.valences - 2)
    np.testing.assert_array_equal(tri.face_of, np.repeat(np.arange(mesh.n_faces), mesh.valences - 2))
    for f in range(mesh.n_faces):
        assert set(tri.triangles[tri.face_of == f].reshape(-1)) <= set(mesh.face(f).tolist())
    # Centred: Newell sums of far-off absolute coordinates lose digits.
    centred = mesh.vertices - mesh.bounding_box().mean(axis=0)
    normals, areas = face_normals(mesh.with_vertices(centred))
    tn = _tri_normals(centred, tri.triangles)
    signed = np.einsum("ij,ij->i", tn, normals[tri.face_of])
    assert np.all(signed > 0)
    summed = np.bincount(tri.face_of, weights=signed, minlength=mesh.n_faces)
    np.testing.assert_allclose(summed, areas, rtol=1e-12, atol=1e-15 * mesh.diagonal() ** 2)
    return tri


def test_catalan_number_of_templates():
    for k in range(3, MAX_TEMPLATE_VALENCE + 1):
        n = k - 2
        assert len(polygon_templates(k)) == math.comb(2 * n, n) // (n + 1)
        # Every template uses each diagonal-free triangulation edge set once: the
        # triangles of a template cover the k-gon's angle sum exactly.
        assert polygon_templates(k).shape[1:] == (k - 2, 3)


@pytest.mark.parametrize("name", ["hp", "hyperboloid", "mixed", "far"])
def test_triangulation_covers_every_face(name):
    check_triangulation(E.all_meshes()[name])
    check_triangulation(E.all_meshes()[name], "best")


def test_quads_split_along_shorter_diagonal():
    mesh = E.hp_translational(a=0.9, b=0.1)
    tri = triangulate(mesh)
    quads = mesh.padded_faces()
    d02 = np.linalg.norm(mesh.vertices[quads[:, 2]] - mesh.vertices[quads[:, 0]], axis=1)
    d13 = np.linalg.norm(mesh.vertices[quads[:, 3]] - mesh.vertices[quads[:, 1]], axis=1)
    first = tri.triangles[tri.offsets[:-1]]
    # The cut is the edge shared by the face's two triangles.
    second = tri.triangles[tri.offsets[:-1] + 1]
    for f in range(mesh.n_faces):
        cut = set(first[f].tolist()) & set(second[f].tolist())
        want = {quads[f, 0], quads[f, 2]} if d02[f] <= d13[f] else {quads[f, 1], quads[f, 3]}
        assert cut == want


def test_non_convex_quad_uses_inner_diagonal():
    # Arrowhead with reflex corner 1: the shorter diagonal 0-2 (length 2) lies
    # outside, so the longer 1-3 (length 4) must be used.
    v = np.array([[-1.0, 0, 0], [0, 1, 0], [1, 0, 0], [0, 5.0, 0]])
    mesh = Mesh.from_faces(v, [[0, 1, 2, 3]])
    tri = check_triangulation(mesh)
    cut = set(tri.triangles[0].tolist()) & set(tri.triangles[1].tolist())
    assert cut == {1, 3}


def _fans(points):
    """All fan triangulations of a convex polygon, as corner index triples."""
    k = len(points)
    return [np.array([[a, (a + i) % k, (a + i + 1) % k] for i in range(1, k - 1)]) for a in range(k)]


@settings(max_examples=60, deadline=None)
@given(k=st.integers(3, 12), seed=st.integers(0, 2**32 - 1))
def test_polygon_split_has_no_avoidable_sliver(k, seed):
    """The chosen split's smallest angle is at least that of every fan (for
    k <= MAX_TEMPLATE_VALENCE it is optimal over all triangulations)."""
    rng = np.random.default_rng(seed)
    ang = np.sort(rng.uniform(0, 2 * np.pi, k))
    if np.min(np.diff(np.r_[ang, ang[0] + 2 * np.pi])) < 1e-3:
        ang = np.linspace(0, 2 * np.pi, k, endpoint=False)
    ellipse = np.stack([3 * np.cos(ang), np.sin(ang), np.zeros(k)], axis=1)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    pts = ellipse @ q.T + rng.normal(size=3)
    mesh = Mesh.from_faces(pts, [list(range(k))])
    # Quads follow the shorter-diagonal rule by default (tested above); "best"
    # is the max-min-angle rule the other valences always use.
    tri = check_triangulation(mesh, "best")
    got = triangle_angles(pts[tri.triangles]).min()
    best_fan = max(triangle_angles(pts[f]).min() for f in _fans(pts))
    if k <= MAX_TEMPLATE_VALENCE:
        assert got >= best_fan - 1e-9
        every = max(triangle_angles(pts[t]).min() for t in polygon_templates(k))
        assert got == pytest.approx(every, abs=1e-9)
    else:
        # Greedy ear clipping: no worse than the worst fan, and a valid cover.
        assert got >= min(triangle_angles(pts[f]).min() for f in _fans(pts)) - 1e-9


def test_concave_polygons_are_covered():
    # Star caps of 8 (templates) and 10 (ear clipping) corners, a collinear corner.
    for k in (8, 10):
        ang = np.arange(k) * 2 * np.pi / k
        r = np.where(np.arange(k) % 2 == 0, 1.0, 0.35)
        pts = np.stack([r * np.cos(ang), r * np.sin(ang), 0.2 * r * np.sin(ang)], axis=1)
        check_triangulation(Mesh.from_faces(pts, [list(range(k))]))
    square_with_midpoint = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0.0]])
    tri = check_triangulation(Mesh.from_faces(square_with_midpoint, [[0, 1, 2, 3, 4]]))
    assert triangle_angles(square_with_midpoint[tri.triangles]).min() > 20


def test_recover_polygons_from_triangles():
    mesh = E.mixed()
    tri = triangulate(mesh)
    rng = np.random.default_rng(1)
    perm = rng.permutation(tri.n_triangles)  # order must not matter
    off, idx = recover_polygons(tri.triangles[perm], tri.face_of[perm])
    np.testing.assert_array_equal(off, mesh.face_offsets)
    for f in range(mesh.n_faces):
        want = mesh.face(f)
        got = idx[off[f]:off[f + 1]]
        shift = int(np.flatnonzero(want == got[0])[0])
        np.testing.assert_array_equal(np.roll(want, -shift), got)


def test_bad_quad_rule_names_parameter():
    with pytest.raises(ParameterError, match="quads"):
        triangulate(E.hp_translational(), "longest")


def test_aspect_ratio_and_quality_values():
    right = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    # Right isosceles: R = sqrt(2)/2, r = (2 - sqrt(2))/2.
    want = (np.sqrt(2) / 2) / (2 - np.sqrt(2))
    assert aspect_ratios(right[None])[0] == pytest.approx(want, rel=1e-12)
    q = triangle_quality(right, np.array([[0, 1, 2]]))
    assert q["min_angle_deg"] == pytest.approx(45.0)
    assert q["splinters"] == 0 and sum(q["aspect_histogram"].values()) == 1


def _hyperboloid_patch(a, c, K, L, h):
    """The smooth patch (phi, s) the checkerboard mesh covers, as point(u, t)."""
    smax = np.tan(L * h)
    p0, p1 = -L * h, (K + L) * h
    return lambda u, t: E.hyperboloid_point(a, c, p0 + (p1 - p0) * u, -smax + 2 * smax * t)


@pytest.mark.parametrize("a, c", [(1.0, 1.0), (1.0, 0.5), (1.0, 0.3)])
def test_stl_min_angle_beats_parameter_grid_on_hyperboloid(tmp_path, a, c):
    """Paper §6: the standard parameter-grid tessellation of a twisted ruled
    surface has splinters; the PQ mesh split along short diagonals does not.
    The STL is read back with numpy-stl."""
    stl_mesh = pytest.importorskip("stl.mesh")
    from ruledmesh.io import save

    K, L, h = 12, 4, np.pi / 24
    mesh = E.hyperboloid_pq(a, c, K, L, h)
    save(tmp_path / "h.stl", mesh)
    tris = stl_mesh.Mesh.from_file(str(tmp_path / "h.stl")).vectors.astype(np.float64)
    ours = triangle_angles(tris).min()
    rows = compare_tessellations(mesh, _hyperboloid_patch(a, c, K, L, h), occt=False)
    grid = rows[1]
    assert grid["tessellation"].startswith("parameter grid")
    # Comparable resolution: within 15 % of our triangle count.
    assert abs(grid["triangles"] - len(tris)) <= 0.15 * len(tris)
    assert ours > grid["min_angle_deg"]
    assert rows[0]["min_angle_deg"] == pytest.approx(ours, abs=1e-3)  # float32 file


def test_parameter_grid_counts_and_diagonals():
    v, t = parameter_grid(lambda u, s: np.stack([u, s, u * s], axis=1), 4, 3)
    assert v.shape == (20, 3) and t.shape == (24, 3)
    v2, t2 = parameter_grid(lambda u, s: np.stack([u, s, u * s], axis=1), 4, 3, "shorter")
    np.testing.assert_array_equal(v, v2)
    assert triangle_angles(v2[t2]).min() >= triangle_angles(v[t]).min() - 1e-12


def test_occt_comparison_when_available():
    pytest.importorskip("OCP")
    K, L, h = 12, 4, np.pi / 24
    mesh = E.hyperboloid_pq(1.0, 0.5, K, L, h)
    rows = compare_tessellations(mesh, _hyperboloid_patch(1.0, 0.5, K, L, h))
    occt = [r for r in rows if r["tessellation"] == "OCCT BRepMesh"]
    assert occt and occt[0]["triangles"] > 0
    assert rows[0]["min_angle_deg"] > occt[0]["min_angle_deg"]


def test_analyze_reports_export_triangle_quality():
    mesh = E.mixed()
    report = analyze(mesh)
    tri = triangulate(mesh)
    assert report["triangles"]["triangles"] == tri.n_triangles
    assert report["triangles"]["min_angle_deg"] == pytest.approx(
        triangle_angles(mesh.vertices[tri.triangles]).min())
