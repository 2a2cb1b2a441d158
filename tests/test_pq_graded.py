"""The primary's division graded for faces of even shape (pq_mesh(division="graded")).

The surfaces are hyperboloids of revolution between two half circles of radius 4, the top
one at height 3 turned by 160-170 degrees: close to their asymptotic cone, where the even
division's far rows crowd into slivers on the generators far from the primary.
"""


import numpy as np
import pytest
from _shared import bench_module
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.faces import area_shares, convexity, face_min_angles
from ruledmesh.analysis.planar import face_planarity
from ruledmesh.design import build_design, parse_design
from ruledmesh.errors import DesignError, ParameterError
from ruledmesh.pq import pq_mesh
from ruledmesh.skew.pq.grading import graded_rows, square_steps
from ruledmesh.skew.pq.maps import chain_maps, compose, hop_maps
from ruledmesh.skew.pq.runs import Division, mesh_run
from ruledmesh.tolerances import DEFAULT

twisted_arcs = bench_module("twisted_arcs")

RADIUS, HEIGHT = 4.0, 3.0


def _arcs(turn_deg: float, count: int):
    th = np.linspace(0.0, np.pi, count)
    tw = th + np.radians(turn_deg)
    a = np.stack([RADIUS * np.cos(th), RADIUS * np.sin(th), np.zeros(count)], axis=1)
    b = np.stack([RADIUS * np.cos(tw), RADIUS * np.sin(tw), np.full(count, HEIGHT)], axis=1)
    return a, b


def _off_hyperboloid(v: np.ndarray, turn_deg: float) -> np.ndarray:
    """Relative distance from the hyperboloid of revolution through the generators."""
    r0 = RADIUS * np.cos(np.radians(turn_deg) / 2)          # the throat, half way up
    z = (v[:, 2] - HEIGHT / 2) / (HEIGHT / 2)
    return np.abs(v[:, 0] ** 2 + v[:, 1] ** 2 - r0 ** 2 - (RADIUS ** 2 - r0 ** 2) * z ** 2) / RADIUS ** 2


def test_the_warning_names_the_cone_as_the_cause():
    # 170 degrees: most generators take rows only from beyond the primary's point at
    # infinity; the share warning says so (not "few generators"), a hyperboloid far from its
    # cone does not.
    near = pq_mesh(*_arcs(170.0, 45), rows=30, division="graded")
    said = [w for w in near.info["warnings"] if "not in quads" in w]
    assert said and "close to a cone" in said[0] and "few generators" not in said[0]
    count = int(said[0].split("the rows reach ")[1].split()[0])
    assert 3 <= count <= 45
    far = pq_mesh(*_arcs(60.0, 45), rows=30, division="graded")
    assert not any("close to a cone" in w for w in far.info["warnings"])


@pytest.mark.parametrize("turn", [160.0, 165.0, 170.0])
def test_graded_rows_keep_the_faces_fat_near_the_cone(turn):
    a, b = _arcs(turn, 45)
    even = pq_mesh(a, b, rows=24)
    graded = pq_mesh(a, b, rows=24, division="graded")
    assert graded.info["division"] == "graded" and even.info["division"] == "even"
    # The even rows are cut again and again (and leave splinters from 165 degrees on); the
    # graded ones make one run without splinters, with more of the area in quads.
    assert even.info["restarts"] >= 4 and graded.info["restarts"] == 0
    assert face_min_angles(graded).min() >= 3.0
    if turn >= 165.0:
        assert face_min_angles(even).min() < 3.0
    assert area_shares(graded)["quads"] > area_shares(even)["quads"] + 0.04
    # Exact: planar quads, convex faces, every vertex on the quadric.
    assert face_planarity(graded).max() <= 1e-12
    assert convexity(graded).all()
    assert _off_hyperboloid(graded.vertices, turn).max() <= 1e-12


def test_each_generator_gets_about_as_many_rows():
    """The point of the grading: the faces centred on each generator of the first run are
    about as many (the even rows crowd on the generators far from the primary)."""
    a, b = _arcs(165.0, 41)
    d = b - a
    counts = {}
    for graded in (False, True):
        run = mesh_run(a, d, 0, 20, Division(24, graded=graded), DEFAULT, 8.0, [])
        counts[graded] = run.on_patch[2:-2]
    assert counts[False].max() > 3 * counts[False].min()
    assert counts[True].max() <= 1.5 * counts[True].min()
    assert 0.5 * 12 <= np.median(counts[True]) <= 1.5 * 12     # rows / 2 faces per generator


def test_graded_rows_are_increasing_with_both_colours():
    a, b = _arcs(165.0, 21)
    d = b - a
    hops = hop_maps(a, d)
    M = compose(chain_maps(a, d, 10, hops), len(a))
    taus = [graded_rows(a, d, M, -2.0, 3.0, 16, shift) for shift in (False, True)]
    for tau in taus:
        assert tau.size % 2 == 0 and tau.size >= 4 and (np.diff(tau) > 0).all()
    assert taus[0][0] == -2.0 and taus[0][-1] == pytest.approx(3.0)
    # The other colour: the a-rows of one are the b-rows of the other.
    assert np.array_equal(taus[1][:-1], taus[0][1:]) and taus[1][-1] > 3.0
    steps = square_steps(a, d)
    assert steps.shape == (21, 17) and (steps > 0).all()


def _rim_share(mesh) -> float:
    """The share of the vertices inside the patch that lie in its outer fifths along the generators."""
    t = mesh.vertex_data["t"]
    inner = (t > 1e-9) & (t < 1.0 - 1e-9)
    return float((inner & ((t < 0.2) | (t > 0.8))).sum() / inner.sum())


@pytest.mark.parametrize("turn", [150.0, 160.0])
def test_bounded_rows_reach_the_rims_closer_together(turn):
    """``division = "bounded"``: no square step counts for more than BOUND medians, so more
    of the rows land towards the rims, where the generators fan out and graded rows are far
    apart (150 degrees: 17.8 -> 19.5 % of the vertices; 160: 13.8 -> 16.6 %); the mesh stays
    exact and without splinters."""
    a, b = _arcs(turn, 45)
    graded = pq_mesh(a, b, rows=24, division="graded")
    bounded = pq_mesh(a, b, rows=24, division="bounded")
    assert bounded.info["division"] == "bounded"
    assert _rim_share(bounded) > _rim_share(graded) + 0.01
    assert face_planarity(bounded).max() <= 1e-12 and convexity(bounded).all()
    assert _off_hyperboloid(bounded.vertices, turn).max() <= 1e-12
    assert face_min_angles(bounded).min() >= 3.0


def test_the_checkerboards_and_primaries_of_a_graded_division():
    a, b = _arcs(160.0, 31)
    for option in (0, 1):
        for primary in (10, 15, "middle"):
            mesh = pq_mesh(a, b, rows=16, division="graded", option=option, primary=primary)
            assert face_planarity(mesh).max() <= 1e-12 and convexity(mesh).all()
    with pytest.raises(ParameterError, match="division"):
        pq_mesh(a, b, division="gradual")


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), m=st.integers(12, 61), rows=st.integers(4, 40),
       option=st.integers(0, 1))
def test_graded_division_keeps_the_invariants(seed, m, rows, option):
    """Random skew surfaces between two smooth curves: every face planar, convex and with
    area, every vertex on its generator inside the patch."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1.0, m)[:, None]
    k1, k2 = rng.normal(size=(2, 3)), rng.normal(size=(2, 3))
    c1 = np.c_[10 * s, np.zeros_like(s), np.zeros_like(s)] + np.sin(3 * s) * k1[0] + s ** 2 * k1[1]
    c2 = np.c_[10 * s, 2 + 0 * s, 4 + 0 * s] + np.cos(2 * s) * k2[0] + s ** 3 * k2[1]
    mesh = pq_mesh(c1, c2, rows=rows, option=option, division="graded")
    assert face_planarity(mesh).max() <= 1e-12 and convexity(mesh).all()
    assert np.isfinite(mesh.vertices).all()
    g, t = mesh.vertex_data["generator"], mesh.vertex_data["t"]
    assert np.abs(mesh.vertices - (c1[g] + t[:, None] * (c2 - c1)[g])).max() <= 1e-12 * 12
    assert ((t >= -1e-12) & (t <= 1 + 1e-12)).all()


def _design(turn: float, count: int, rows: int, mesh: str = "") -> str:
    return twisted_arcs.design(turn, 180, RADIUS, HEIGHT, count=count, rows=rows, mesh=mesh)[1]


def test_a_design_chooses_the_graded_rows_where_they_do_better():
    """``[mesh] division`` left free: the 165-degree surface (61 x 24) had all of its area in
    triangles (the meshes with even rows had splinters); with the graded rows tried too,
    more than half of it is in quads, none below 3 degrees, and a note says so."""
    built = build_design(parse_design(_design(165.0, 61, 24)))
    mesh = built.mesh
    # Graded and bounded end within 0.1 points of each other here (58.3 and 58.4 % quads).
    assert mesh.info["division"] in ("graded", "bounded")
    assert any(f'division = "{mesh.info["division"]}"' in w for w in mesh.info["warnings"])
    assert area_shares(mesh)["quads"] >= 0.5
    assert face_min_angles(mesh).min() >= 3.0 and face_planarity(mesh).max() <= 1e-12


def test_division_in_a_design_file():
    built = build_design(parse_design(_design(160.0, 31, 16, 'division = "graded"\nrefine = false')))
    assert built.mesh.info["division"] == "graded"
    even = build_design(parse_design(_design(160.0, 31, 16, 'division = "even"')))
    assert even.mesh.info["division"] == "even"
    assert not any("graded" in w for w in even.mesh.info["warnings"])
    bounded = build_design(parse_design(_design(160.0, 31, 16, 'division = "bounded"\nrefine = false')))
    assert bounded.mesh.info["division"] == "bounded"
    with pytest.raises(DesignError, match=r"mesh\.division.*graded.*bounded"):
        build_design(parse_design(_design(160.0, 31, 16, 'division = "gradd"')))
