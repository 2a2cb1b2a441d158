"""Triangles across many strips halved on the generators they span (ruledmesh.skew.pq.halving)."""

from __future__ import annotations

import numpy as np
import pytest

from ruledmesh.analysis.faces import face_min_angles
from ruledmesh.analysis.spans import off_spanned_generators
from ruledmesh.mesh import FaceKind, Mesh, offsets_from_valences
from ruledmesh.skew.pq.halving import halve_spanning_triangles


def _hp(m: int = 9):
    """Generators x = k of z = x y over y in [0, 1] (k = 0 .. m - 1): ``a_k = (k, 0, 0)``,
    ``d_k = (0, 1, k)``, scaled to x in [0, 1]."""
    k = np.arange(m) / (m - 1)
    return np.stack([k, 0 * k, 0 * k], 1), np.stack([0 * k, 1 + 0 * k, k], 1)


def _mesh(a, d, generator, t, faces, kinds, members=None):
    """The faces on generators ``(a, d)``; each generator also has (unused) vertices at its
    ends, so the stretch between them is the mesh's (:mod:`ruledmesh.analysis.spans`)."""
    m = len(a)
    generator = np.r_[generator, np.arange(m), np.arange(m)]
    t = np.r_[np.asarray(t, float), np.zeros(m), np.ones(m)]
    V = a[generator] + t[:, None] * d[generator]
    faces = [np.asarray(f) for f in faces]
    mem = np.zeros((0, 2), np.int64) if members is None else np.asarray(members)
    return Mesh.from_arrays(V, offsets_from_valences([len(f) for f in faces]), np.concatenate(faces),
                            np.asarray(kinds, np.uint8), members=mem, member_id=generator[mem[:, 0]],
                            vertex_data={"t": t, "generator": generator})


def _off(mesh, lines):
    _, tri = mesh.faces_of_valence(3)
    return off_spanned_generators(mesh.vertices, tri, np.asarray(mesh.vertex_data["generator"]),
                                  np.asarray(mesh.vertex_data["t"]), lines, faces=mesh.fan_triangles()[0])


def _parameter_areas(mesh) -> np.ndarray:
    """(F,) signed areas of the faces in the parameter plane (generator, t), fanned."""
    P = np.c_[np.asarray(mesh.vertex_data["generator"], float), mesh.vertex_data["t"]]
    out = np.zeros(mesh.n_faces)
    for f in range(mesh.n_faces):
        q = P[mesh.face(f)]
        out[f] = 0.5 * np.sum(q[:, 0] * np.roll(q[:, 1], -1) - np.roll(q[:, 0], -1) * q[:, 1])
    return out


def test_two_triangles_across_eight_strips_are_halved_until_near_the_surface():
    """Two fill triangles across the eight strips of z = x y share their long edge, and a
    quad of the two end generators beside them carries members along both: the halving
    puts corners on the generators between (each on its generator, at the edge's own place
    in the parameter plane) until every triangle lies within the goal of the generators it
    spans; the halves cover what the triangles covered, face the same way, keep their
    kind, and a member along a generator between is cut at the new corner on it."""
    a, d = _hp()
    generator = [0, 8, 8, 0]
    t = [0.0, 0.0, 1.0, 1.0]
    # members: along both end generators, and along generator 4 between its ends (vertices
    # 8 and 17, see _mesh), over the triangles
    mesh = _mesh(a, d, generator, t, [[0, 1, 2], [0, 2, 3]], [FaceKind.FILL, FaceKind.FILL],
                 members=[[0, 3], [1, 2], [8, 17]])
    lines = (a, d)
    goal = 0.01
    before = _off(mesh, lines)
    assert before.max() > 5 * goal
    out, halved, tri, off = halve_spanning_triangles(mesh, lines, goal)
    assert halved > 2
    # the triangles still across strips, each with its distance
    assert len(tri) == len(off) > 0 and (np.ptp(np.asarray(out.vertex_data["generator"])[tri], axis=1) > 1).all()
    assert off.max() <= goal
    assert _off(out, lines).max() <= goal          # measured again, exactly (no bounds)
    g = np.asarray(out.vertex_data["generator"])
    tt = np.asarray(out.vertex_data["t"])
    np.testing.assert_allclose(out.vertices, a[g] + tt[:, None] * d[g], atol=1e-15)
    assert set(g.tolist()) > {0, 8} and (tt >= 0).all() and (tt <= 1).all()
    # the same region of the parameter plane, every face the same way round
    areas = _parameter_areas(out)
    assert (areas > 0).all() and areas.sum() == pytest.approx(8.0)
    assert (out.face_kind == FaceKind.FILL).all() and (out.valences == 3).all()
    # the member along generator 4 is cut where the long edge was halved (t = 0.5)
    mid = np.flatnonzero((g == 4) & (tt == 0.5))
    assert mid.size == 1
    np.testing.assert_array_equal(out.members, [[0, 3], [1, 2], [8, mid[0]], [mid[0], 17]])
    np.testing.assert_array_equal(out.member_id, [0, 8, 4, 4])
    # no corner of a face lies on another face's edge: an edge is used by two faces, or
    # by one on the border of the parameter rectangle
    keys, uses = out.edge_uses()
    ends = np.stack([keys // out.n_vertices, keys % out.n_vertices], 1)
    on_border = (g[ends] == 0).all(1) | (g[ends] == 8).all(1) | (tt[ends] == 0).all(1) | (tt[ends] == 1).all(1)
    assert (uses <= 2).all() and on_border[uses == 1].all()


def test_a_quad_across_the_edge_is_never_cut():
    """The long edge of a triangle across four strips is shared with a quad: that edge is
    not halved (the quad would become a pentagon); the triangle's border edge across the
    four strips is."""
    a, d = _hp(5)
    # triangle (0, 1, 2): 0 = (g0, 0), 1 = (g4, 0), 2 = (g4, 0.5); a quad on 0 -> 2 above it
    generator = [0, 4, 4, 0, 2]
    t = [0.0, 0.0, 0.5, 0.6, 0.9]
    mesh = _mesh(a, d, generator, t, [[0, 1, 2], [0, 2, 4, 3]], [FaceKind.FILL, FaceKind.QUAD])
    out, halved, _, _ = halve_spanning_triangles(mesh, (a, d), 1e-6)
    assert halved >= 1
    quad = out.faces_of_valence(4)[1]
    np.testing.assert_array_equal(quad, [[0, 2, 4, 3]])
    g = np.asarray(out.vertex_data["generator"])
    tt = np.asarray(out.vertex_data["t"])
    n = mesh.n_vertices
    assert g[n] == 2 and tt[n] == 0.0       # the first cut: the border edge, at generator 2


def test_no_halving_below_the_splinter_bar():
    """A triangle whose halves would have an angle below 3 degrees, where its own smallest
    is above that, is left as it is (with the distance it lies off)."""
    from ruledmesh.analysis.faces import min_corner_angles

    a, d = _hp(3)
    d = d * [1.0, 20.0, 1.0]          # generators 20 long, 0.5 apart
    # corners (g0, 0), (g2, 0.5), (g0, 1): the edge across two strips is halved at
    # generator 1, t = 0.25, and the half at (g0, 1) has a corner of 1.9 degrees
    mesh = _mesh(a, d, [0, 2, 0], [0.0, 0.5, 1.0], [[0, 1, 2]], [FaceKind.FILL])
    assert face_min_angles(mesh).min() > 5.0
    W = np.r_[mesh.vertices, (a[1] + 0.25 * d[1])[None]]
    assert min_corner_angles(W, np.array([[0, 3, 2], [3, 1, 2]])).min() < 2.0
    out, halved, _, off = halve_spanning_triangles(mesh, (a, d), 0.0)
    assert halved == 0 and out is mesh and off.size == 1 and off[0] > 0
