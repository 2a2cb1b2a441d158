"""The live figures (ruledmesh.analysis.live) against the full report, design by design.

The live pass crosses each quad's diagonals once for planarity and convexity; the
full report takes the same figures from it, so they must be equal exactly, and
each per-face measure must be the one the per-face functions give.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import ruledmesh
from ruledmesh.analysis import faces as F
from ruledmesh.analysis.live import LiveAnalysis, face_measures, live_figures, unit_copy
from ruledmesh.analysis.planar import face_planarity
from ruledmesh.analysis.report import analyze
from ruledmesh.api import build_full
from ruledmesh.cli import main
from ruledmesh.errors import GeometryError
from ruledmesh.mesh import Mesh

# PQ, hybrid (triangles), compound, exact constructions with polygons and a torus, at
# their own scales.
DESIGNS = ["skew", "fig7b-hyperboloid-circular", "hybrid-fig9", "compound-hp-grid", "fig5b-torus",
           "fig6b-pyramid", "sec2-rotational", "three-directrices"]
SHARED = ("vertices", "faces", "members", "kinds", "finite", "diagonal", "planarity", "non_convex", "area")


@pytest.fixture(scope="module", params=DESIGNS)
def built(request):
    return build_full(f"examples/{request.param}.toml")


def test_live_figures_are_the_reports(built):
    report = analyze(built.mesh, reference=built.reference, extras=built.extras)
    live = live_figures(built.mesh)
    assert {k: live[k] for k in SHARED} == {k: report[k] for k in SHARED}
    assert live["quad_area_share"] == report["quality"]["area_share"]["quads"]
    assert set(live["warnings"]) <= set(report["warnings"])
    json.dumps(live, allow_nan=False)


def test_face_measures_are_the_per_face_functions(built):
    mesh = built.mesh
    m = face_measures(mesh)
    assert np.array_equal(m.planarity, face_planarity(mesh))
    assert np.array_equal(m.area, F.face_areas(mesh))
    framed, _ = unit_copy(mesh)
    assert np.array_equal(m.convex, F.convexity(framed))


def _bent_and_bow_tie() -> Mesh:
    """A planar square, a bent quad, a bow-tie, a convex pentagon and a reflex hexagon."""
    v = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],                       # 0-3 square
         [2, 0, 0], [3, 0, 0], [3, 1, 0.3], [2, 1, 0],                     # 4-7 bent
         [4, 0, 0], [5, 1, 0], [5, 0, 0], [4, 1, 0],                       # 8-11 bow-tie
         [6, 0, 0], [7, 0, 0], [7.3, 0.8, 0], [6.5, 1.3, 0], [5.7, 0.8, 0],  # 12-16 pentagon
         [8, 0, 0], [10, 0, 0], [10, 2, 0], [9, 0.5, 0], [8, 2, 0], [8, 1, 0]]  # 17-22 reflex
    return Mesh.from_faces(np.array(v, float) * 1e3 + 5e5,
                           [[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11], [12, 13, 14, 15, 16],
                            [17, 18, 19, 20, 21, 22]])


def test_live_figures_of_bent_non_convex_and_polygon_faces():
    mesh = _bent_and_bow_tie()
    live = live_figures(mesh)
    report = analyze(mesh)
    assert {k: live[k] for k in SHARED} == {k: report[k] for k in SHARED}
    assert live["non_convex"] == 2                      # the bow-tie and the reflex hexagon
    assert live["planarity"]["above_tolerance"] == 2    # the bent quad and the bow-tie
    assert live["planarity"]["exact"] == 3
    assert "2 faces are not convex" in live["warnings"]
    assert live["area"]["total"] == pytest.approx(report["area"]["total"], rel=0)


def test_live_analysis_computes_the_full_report_when_asked():
    full = build_full("examples/fig7b-hyperboloid-circular.toml")
    live = LiveAnalysis(full.mesh, full.reference, full.extras)
    assert live.figures["faces"] == full.mesh.n_faces
    assert "report" not in vars(live)                  # nothing beyond the live pass yet
    assert live.report["closeness"]["vertices_max"] < 1e-6
    assert live.report["planarity"] == live.figures["planarity"]


def test_live_figures_refuse_a_mesh_without_faces():
    with pytest.raises(GeometryError, match="no faces"):
        live_figures(Mesh.from_faces(np.zeros((3, 3)), np.zeros((0, 3), int)))


def test_cli_analyze_quick(tmp_path, capsys):
    out = tmp_path / "skew.obj"
    assert main(["build", "examples/skew.toml", "-o", str(out), "-q"]) == 0
    assert main(["analyze", str(out), "--quick", "--json"]) == 0
    quick = json.loads(capsys.readouterr().out)
    assert main(["analyze", str(out), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert {k: quick[k] for k in SHARED} == {k: report[k] for k in SHARED}
    assert "closeness" not in quick and "quality" not in quick
    assert main(["analyze", str(out), "--quick"]) == 0
    assert "non_convex" in capsys.readouterr().out


@pytest.mark.parametrize("option", [["--design", "examples/skew.toml"], ["--compare"]])
def test_cli_analyze_quick_refuses_full_report_options(option, capsys):
    assert main(["analyze", "examples/skew.obj", "--quick", *option]) == 2
    assert capsys.readouterr().err.startswith("ruledmesh: error: --quick:")


def test_top_level_build_and_live_analysis_agree_on_planarity():
    mesh = ruledmesh.build("examples/skew.toml")
    assert LiveAnalysis(mesh).figures["planarity"]["max"] == ruledmesh.analyze(mesh)["planarity"]["max"]


def test_faces_far_from_the_origin_are_planar_to_their_coordinates_rounding():
    """examples/skew moved 5e6 m out (building coordinates): each corner is stored to about
    5e-10 m, so panels built exact measure up to about 1e-9.  They count as exact to that
    rounding (the report and the live figures say so, with no warning) and fabricate cuts
    them; a panel bent by a millimetre is still bent."""
    from ruledmesh.analysis.guarantees import check_guarantee
    from ruledmesh.analysis.planar import bent_faces, rounding_allowance
    from ruledmesh.fabricate.unroll import unroll

    mesh = build_full("examples/skew.toml").mesh
    far = mesh.with_vertices(mesh.vertices + np.array([5e6, 5e6, 100.0]))
    plan = face_planarity(far)
    assert plan.max() > 1e-11 >= face_planarity(mesh).max() * 100   # the coordinates' rounding
    assert np.all(plan <= rounding_allowance(far) + 1e-12)
    assert rounding_allowance(mesh).max() < 1e-12                     # near the origin: none
    report, live = analyze(far), live_figures(far)
    assert live["planarity"] == report["planarity"]
    assert report["planarity"]["above_tolerance"] == 0
    assert report["planarity"]["exact"] == far.n_faces
    assert report["planarity"]["exact_to_rounding"] == np.count_nonzero(plan > 1e-12) > 0
    assert not any("not planar" in w for w in report["warnings"])
    assert not bent_faces(far)[0].any()
    assert check_guarantee("planar", far)["met"]
    unroll(far)
    quad = int(np.flatnonzero(far.valences == 4)[0])
    v = far.vertices.copy()
    v[far.face(quad)[0], 2] += 1e-3
    bent = far.with_vertices(v)
    assert analyze(bent)["planarity"]["above_tolerance"] >= 1
    assert not check_guarantee("planar", bent)["met"]
    with pytest.raises(GeometryError, match="not planar"):
        unroll(bent)
