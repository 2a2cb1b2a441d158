"""Rows thinned where they fail towards a torsal generator (pq_mesh(thin=True), [mesh] thin).

The surface is the director-curve pair of benchmarks/quality/skew-bspline-301x300.toml
(a cubic and a quartic B-spline, three torsal generators) at 101 x 100.  Next to its
torsal generators the hop lines cross the generators at a few degrees, the faces there
grow slender, and a run restarted on the way fails: without thinning the rest of the way
carries no rows (all triangles).
"""

from __future__ import annotations

import numpy as np
import pytest
from _shared import check_exact
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.faces import area_shares, convexity, face_min_angles
from ruledmesh.analysis.planar import face_planarity
from ruledmesh.design import build_design, parse_design
from ruledmesh.errors import DesignError, ParameterError
from ruledmesh.pq import pq_mesh

C1 = [[0.0, 1.34, -1.68], [2.5, -1.44, -0.62], [5.0, 1.66, -0.92], [7.5, -2.19, 0.96], [10.0, 1.63, -1.61]]
C2 = [[0.0, -0.52, 4.67], [2.5, -2.47, 3.40], [5.0, -1.19, 5.13], [7.5, -0.39, 4.77], [10.0, -1.97, 3.66]]


def _design(count: int = 101, rows: int = 100, extra: str = "") -> str:
    return (f'[curves.c1]\ntype = "bspline"\ndegree = 3\npoints = {C1}\n'
            f'[curves.c2]\ntype = "bspline"\ndegree = 4\npoints = {C2}\n'
            f'[rulings]\nbetween = ["c1", "c2"]\ndistribution = "arc-length"\ncount = {count}\n'
            f"[mesh]\nrows = {rows}\n{extra}")


@pytest.fixture(scope="module")
def generators():
    r = build_design(parse_design(_design(extra="refine = false\n"))).rulings
    return np.asarray(r.a), np.asarray(r.b)


@pytest.mark.parametrize("rows_from", ["primary", "c2"])
def test_thinned_rows_put_more_of_the_area_in_quads(generators, rows_from):
    a, b = generators
    plain = pq_mesh(a, b, rows=100, rows_from=rows_from)
    thin = pq_mesh(a, b, rows=100, rows_from=rows_from, thin=True)
    assert thin.info["thin"] and not plain.info["thin"]
    # Measured: 58.6 -> 53.0 % (primary) and 58.1 -> 52.0 % (c2) of the area in triangles.
    assert area_shares(thin)["triangles"] < area_shares(plain)["triangles"] - 0.03
    # Thinned rows make fewer, longer faces, and here no new splinter.
    assert thin.n_faces < plain.n_faces
    assert face_min_angles(thin).min() >= min(face_min_angles(plain).min(), 3.0)
    quads = thin.valences == 4
    assert face_planarity(thin)[quads].max() <= 1e-12
    assert convexity(thin).all()
    # Every vertex on its generator.
    g = np.asarray(thin.vertex_data["generator"])
    t = np.asarray(thin.vertex_data["t"])
    assert np.abs(a[g] + t[:, None] * (b[g] - a[g]) - thin.vertices).max() <= 1e-12 * thin.diagonal()


def test_thin_false_is_the_default_and_the_mesh_without_thinning(generators):
    a, b = generators
    one, two = pq_mesh(a, b, rows=100), pq_mesh(a, b, rows=100, thin=False)
    assert np.array_equal(one.vertices, two.vertices)
    assert np.array_equal(one.face_indices, two.face_indices)


def test_a_design_with_thin_true_meshes_with_thinned_rows():
    built = build_design(parse_design(_design(extra='refine = false\nrows_from = "c2"\nthin = true\n')))
    assert built.mesh.info["thin"]
    check_exact(built)
    assert face_min_angles(built.mesh).min() >= 2.9


def _options(**kw) -> dict:
    """The options build_pq hands the mesher for this design (rows 100)."""
    return {"rows": 100, "primary": "middle", "option": 0, "extend": "auto", "trim": True,
            "max_extend": 20.0, "planarity_tolerance": 1e-12, "respace": False, "rows_from": "primary",
            "division": "even", "thin": False, **kw}


def test_the_last_try_keeps_the_thinned_mesh_only_where_it_is_more_fabricable():
    from ruledmesh.design.pq import _fabricable, _mesh, _round, _with_thinned_rows

    rulings = build_design(parse_design(_design(extra="refine = false\n"))).rulings
    kept = _round(rulings, _mesh(rulings, _options()))
    assert kept[4].info["thinnable"] > 0
    chosen = _with_thinned_rows(kept, _options())
    assert chosen[4].info["thin"] and _fabricable(chosen, 0.25) > _fabricable(kept, 0.25)
    # With rows through the end points on both curves nothing fails that thinning would
    # fill: the kept mesh stays, and no other is made.
    kept = _round(rulings, _mesh(rulings, _options(rows_from="both")))
    assert kept[4].info["thinnable"] == 0
    assert _with_thinned_rows(kept, _options()) is kept


def test_the_thinned_try_rebuilds_the_kept_mesh_from_its_info():
    # The last try takes the kept mesh's options from its info (per segment where they
    # differ): without thinning those make the very mesh kept.
    from ruledmesh.design.pq import MESH_KEYS, _segment_options

    built = build_design(parse_design(_design(61, 60, "thin = false\n")))
    info = built.mesh.info
    assert "thin" in MESH_KEYS
    r = built.rulings
    opts = {k: info[k] for k in ("planarity_tolerance", "extend", "respace", "division", "primary")}
    again = pq_mesh(r.a, r.b, rows=60, **opts, **_segment_options(info, len(r.a)))
    assert np.array_equal(again.vertices, built.mesh.vertices)
    assert np.array_equal(again.face_indices, built.mesh.face_indices)


@pytest.mark.parametrize("value", ["yes", 1, 0.5])
def test_bad_thin_values_are_refused_naming_the_field(value):
    text = _design(9, 6, f"thin = {value!r}\n".replace("'", '"'))
    with pytest.raises(DesignError, match=r"mesh\.thin"):
        build_design(parse_design(text))
    a = np.array([[0.0, 0, 0], [1, 0, 0.1], [2, 0, 0]])
    with pytest.raises(ParameterError, match="thin"):
        pq_mesh(a, a + [0, 1, 0.3], rows=4, thin=value)


def _random_design(y1, z1, y2, count, rows) -> str:
    """Two B-splines like skew-bspline-301x300's, their control points' y (and c1's z) given."""
    x = np.linspace(0.0, 10.0, 5)
    c1 = np.stack([x, y1, z1], axis=1)
    c2 = np.stack([x, y2, 4.5 + 0.0 * x], axis=1)
    return (f'[curves.c1]\ntype = "bspline"\ndegree = 3\npoints = {c1.tolist()}\n'
            f'[curves.c2]\ntype = "bspline"\ndegree = 4\npoints = {c2.tolist()}\n'
            f'[rulings]\nbetween = ["c1", "c2"]\ndistribution = "arc-length"\ncount = {count}\n'
            f"[mesh]\nrows = {rows}\n")


coord = st.lists(st.floats(-2.5, 2.5, allow_subnormal=False), min_size=5, max_size=5)
low = st.lists(st.floats(-2.0, 1.0, allow_subnormal=False), min_size=5, max_size=5)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(y1=coord, z1=low, y2=coord, count=st.integers(30, 90), rows=st.integers(10, 80),
       rows_from=st.sampled_from(["primary", "c1", "c2"]))
def test_thinned_rows_keep_the_exact_invariants_on_random_director_curves(y1, z1, y2, count, rows, rows_from):
    # Every quad planar and convex, every vertex on its generator, the patch covered.  (Not
    # free of splinters: a seam's fan of triangles, where a thinned face's half meets the
    # rows it left out, can be thinner than the seam's crossing angle says; found here at
    # 2.86 degrees.  A design build keeps such a mesh only where it is more fabricable.)
    text = _random_design(y1, z1, y2, count, rows) + f'refine = false\nrows_from = "{rows_from}"\n'
    built = build_design(parse_design(text + "thin = true\n"))
    check_exact(built)
    plain = build_design(parse_design(text + "thin = false\n")).mesh
    if not plain.info["thinnable"]:
        assert np.array_equal(built.mesh.vertices, plain.vertices)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(y1=coord, z1=low, y2=coord, count=st.integers(30, 60), rows=st.integers(10, 40))
def test_a_design_build_with_thin_auto_is_never_less_fabricable(y1, z1, y2, count, rows):
    from ruledmesh.design.pq import _fabricable, _round

    text = _random_design(y1, z1, y2, count, rows)
    auto = build_design(parse_design(text))
    never = build_design(parse_design(text + "thin = false\n"))
    assert _fabricable(_round(auto.rulings, auto.mesh), 0.25) >= _fabricable(_round(never.rulings, never.mesh), 0.25)
    check_exact(auto)
