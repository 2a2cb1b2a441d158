"""The splinters left after flips and collapses (ruledmesh.skew.pq.splinters).

Each test catches what ``snap_to_border`` and ``open_walled_splinters`` get and
give back inside real builds and checks what they may and may not do: quads
planar and convex, every vertex an old vertex (so on its generator), no more
splinters and never a smaller smallest angle, a manifold, the area in quads
lost bounded by the splinters removed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.faces import face_min_angles, face_normals, quad_diagonal_crossing, quad_planarity
from ruledmesh.design import build_design, build_file, parse_design
from ruledmesh.mesh import FaceKind
from ruledmesh.skew.pq import mesher, splinters
from ruledmesh.tolerances import RESTART_ANGLE_DEG

QUALITY = Path(__file__).resolve().parents[1] / "benchmarks" / "quality"


@pytest.fixture
def caught(monkeypatch):
    """(name, before, after, count) of every snap and opening of the builds in the test."""
    calls: list[tuple] = []
    for name in ("snap_to_border", "trim_border_needles", "open_walled_splinters"):
        real = getattr(splinters, name)

        def spy(mesh, *args, _real=real, _name=name, **kwargs):
            out, n = _real(mesh, *args, **kwargs)
            calls.append((_name, mesh, out, n))
            return out, n

        monkeypatch.setattr(mesher, name, spy)
    return calls


def _point_keys(P):
    # Rounded once for the whole array (rounding row by row took half of the random test).
    return set(map(tuple, np.round(np.asarray(P).reshape(len(P), -1), 12).tolist()))


def _splinters(mesh):
    return int((face_min_angles(mesh) < RESTART_ANGLE_DEG).sum())


def _quads_sound(mesh):
    _, Q = mesh.faces_of_valence(4)
    P = mesh.vertices[Q]
    assert quad_planarity(P).max(initial=0.0) <= 1e-12
    s, t, _ = quad_diagonal_crossing(P)
    assert np.all((s > 0) & (s < 1) & (t > 0) & (t < 1))


def _manifold(mesh):
    _, uses = mesh.edge_uses()
    return int((uses > 2).sum())


def check(name, before, after, n):
    # Only old vertices: every corner is still a point of its generator.
    assert _point_keys(after.vertices) <= _point_keys(before.vertices)
    _quads_sound(after)
    assert _splinters(after) <= _splinters(before)
    # The opening keeps a piece with fewer splinters even where one of them got thinner
    # (splinters.open_walled_splinters); the other passes never make the thinnest face thinner.
    if name != "open_walled_splinters" or _splinters(after) == _splinters(before):
        assert face_min_angles(after).min() >= face_min_angles(before).min() - 1e-9
    assert _manifold(after) <= _manifold(before)
    _, a0 = face_normals(before)
    _, a1 = face_normals(after)
    # The surface keeps its area (flips and collapses move it by a sag bound).
    assert abs(a1.sum() - a0.sum()) <= 1e-3 * a0.sum()
    if name == "trim_border_needles":
        _trimmed_soundly(before, after, n)
    elif name == "snap_to_border":
        assert after.n_vertices == before.n_vertices - n
        # The moved corners sit on generator ends now: no vertex a sliver from one.
        gone = _point_keys(before.vertices) - _point_keys(after.vertices)
        assert len(gone) == n
    else:
        lost = a0[before.valences == 4].sum() - a1[after.valences == 4].sum()
        removed = _splinters(before) - _splinters(after)
        assert lost <= 1.01 * splinters._OPEN_MAX_SHARE * max(removed, 0) * a0.sum() + 1e-12


def _border_edges_at(mesh):
    keys, uses = mesh.edge_uses()
    n = mesh.n_vertices
    b = keys[uses == 1]
    return np.bincount(np.concatenate([b // n, b % n]), minlength=n)


def _trimmed_soundly(before, after, n):
    """Only needle fans at the border went: quads as they were, the border a manifold,
    and the patch within BORDER_TRIM_MAX_GAP of what is left."""
    from ruledmesh._arrays import diagonal
    from ruledmesh.analysis.faces import segment_distances as _segment_distance
    from ruledmesh.tolerances import BORDER_TRIM_MAX_GAP

    assert after.n_vertices == before.n_vertices - n
    quads = [_point_keys(m.vertices[m.faces_of_valence(4)[1]].reshape(-1, 12)) for m in (before, after)]
    assert quads[0] == quads[1]
    assert _border_edges_at(after).max(initial=0) <= max(_border_edges_at(before).max(initial=0), 2)
    gone = np.array(sorted(_point_keys(before.vertices) - _point_keys(after.vertices)))
    assert len(gone) == n
    if n:
        e = after.edges()
        P = after.vertices
        d = np.array([_segment_distance(np.repeat(g[None], len(e), 0), P[e[:, 0]], P[e[:, 1]]).min()
                      for g in gone])
        assert d.max() <= BORDER_TRIM_MAX_GAP * diagonal(before.vertices) * (1 + 1e-9)


def test_needles_at_a_grazing_border_are_trimmed(caught):
    """skew-bspline-b-51x30: where its generators meet a director curve at a grazing angle,
    an end point sat between two needles (2.1 and 2.7 deg) that no flip or collapse could
    fatten, and the refinement kept a mesh with 36 % of its area in triangles (the meshes
    with more generators had that splinter).  Trimmed, the mesh with more generators wins."""
    mesh = build_file(QUALITY / "skew-bspline-b-51x30.toml").mesh
    trims = [c for c in caught if c[0] == "trim_border_needles" and c[3]]
    assert trims
    for call in trims:
        check(*call)
    assert _splinters(mesh) == 0
    _, area = face_normals(mesh)
    assert area[mesh.valences != 4].sum() <= 0.26 * area.sum()


@pytest.mark.parametrize("name", ["corner-90deg", "building-offset", "cusp", "skew-bspline-51x30",
                                  "millimetre-scale"])
def test_splinter_passes_in_real_builds(name, caught):
    mesh = build_file(QUALITY / f"{name}.toml").mesh
    assert {c[0] for c in caught} == {"snap_to_border", "trim_border_needles", "open_walled_splinters"}
    for call in caught:
        check(*call)
    assert mesh.info["opened"] > 0
    # These surfaces had 6-18 splinters each before the passes; none is left.
    assert _splinters(mesh) == 0


def test_snapped_corners_are_ends_of_generator_diagonals(caught):
    build_file(QUALITY / "skew-bspline-51x30.toml")
    snaps = [c for c in caught if c[0] == "snap_to_border" and c[3]]
    assert snaps
    for *_, after, _n in snaps:
        qid, Q = after.faces_of_valence(4)
        gen = np.asarray(after.vertex_data["generator"])
        t = np.asarray(after.vertex_data["t"])
        # Quads that took a snapped corner are border quads with a corner on a director curve.
        border = after.face_kind[qid] == FaceKind.BORDER
        on_curve = ((t[Q] <= 1e-12) | (t[Q] >= 1 - 1e-12)).any(axis=1)
        assert np.all(on_curve | ~border)
        # Diagonals of every quad: one pair of opposite corners on one generator; a strip
        # quad (between two coplanar generators) has two edges on them instead.
        same = (gen[Q[:, 0]] == gen[Q[:, 2]]) | (gen[Q[:, 1]] == gen[Q[:, 3]])
        strip = after.face_kind[qid] == FaceKind.STRIP
        assert same[~strip].all()
        g = np.sort(gen[Q[strip]], axis=1)
        assert np.all((g[:, 0] == g[:, 1]) & (g[:, 2] == g[:, 3]) & (g[:, 1] != g[:, 2]))


def test_opening_stops_where_it_would_cost_too_many_quads(monkeypatch):
    """With no area allowed per splinter, nothing is opened and the splinters stay."""
    from ruledmesh.pq import pq_mesh

    rulings = build_file(QUALITY / "building-offset.toml").rulings
    opened = pq_mesh(rulings.a, rulings.b, rows=30)
    monkeypatch.setattr(splinters, "_OPEN_MAX_SHARE", 0.0)
    closed = pq_mesh(rulings.a, rulings.b, rows=30)
    assert opened.info["opened"] > 0 and closed.info["opened"] == 0
    assert _splinters(closed) > _splinters(opened)


curves = st.lists(st.floats(-2.0, 2.0, allow_subnormal=False), min_size=10, max_size=10)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                HealthCheck.function_scoped_fixture])
@given(y1=curves, y2=curves, count=st.integers(30, 60), rows=st.integers(10, 30))
def test_splinter_passes_on_random_director_curves(caught, y1, y2, count, rows):
    caught.clear()
    x = np.linspace(0.0, 10.0, 5)
    c1 = np.c_[x, y1[:5], 0.5 * np.asarray(y1[5:])]
    c2 = np.c_[x, y2[:5], 4.0 + 0.5 * np.asarray(y2[5:])]
    text = (f'[curves.c1]\ntype = "bspline"\ndegree = 3\npoints = {c1.tolist()}\n'
            f'[curves.c2]\ntype = "bspline"\ndegree = 3\npoints = {c2.tolist()}\n'
            f'[rulings]\nbetween = ["c1", "c2"]\ncount = {count}\n[mesh]\nrows = {rows}\n')
    build_design(parse_design(text))
    for call in caught:
        check(*call)


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 60), data=st.data())
def test_region_pieces_are_the_connected_components(n, data):
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = data.draw(st.integers(0, 3 * n))
    a = np.asarray(data.draw(st.lists(st.integers(0, n - 1), min_size=m, max_size=m)), np.int64)
    b = np.asarray(data.draw(st.lists(st.integers(0, n - 1), min_size=m, max_size=m)), np.int64)
    mine = splinters._components(n, a, b)
    k, ref = connected_components(coo_matrix((np.ones(m), (a, b)), shape=(n, n)), directed=False)
    assert mine.min(initial=0) == 0 and len(np.unique(mine)) == k
    assert len(set(zip(mine.tolist(), ref.tolist()))) == k


def test_snap_measures_a_part_of_the_mesh_with_unused_vertices():
    """Found by the fuzz test: four generators a micrometre long, one row, untrimmed. The snap
    measured its candidates on the faces around them only, whose compaction dropped more
    vertices than the snapped ones, and the new indices pointed past the end (IndexError)."""
    import numpy as np

    from ruledmesh.analysis.faces import planarity
    from ruledmesh.pq import pq_mesh

    a = np.array([[1e-6, 0, 1e-6], [1e-6, 1 / 3e7, 1 / 3e6], [1e-6, 4 / 3e7, -1 / 3e6], [1e-6, 3e-7, -1e-6]])
    b = np.array([[0, 1e-6, 3e-6], [1 / 6e6, 2 / 3e6, 9.4 / 3e6], [1 / 3e6, 1 / 3e6, 3.2e-6], [5e-7, 0, 3.2e-6]])
    mesh = pq_mesh(a, b, rows=1, option=0, trim=False, primary="middle", extend=0.0)
    assert mesh.n_faces and planarity(mesh).max() <= 1e-12
