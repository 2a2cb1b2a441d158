"""analyze states a guarantee only with the figures that confirm it; mismatches are flagged.

Regression tests of three defects: fig5a's "isosceles trapezoids, circular"
printed beside circularity 0.54; a torus design accepted for a skew mesh
(closeness 0.62, coverage 0.43) without a word; an empty mesh analysed as a
table of zeros with exit code 0.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from ruledmesh.analysis.guarantees import check_guarantee, format_guarantee, quad_trapezoid
from ruledmesh.analysis.report import KIND_NOUNS, analyze, format_table, kind_counts
from ruledmesh.cli import main
from ruledmesh.design import build_file, load_design, parse_design
from ruledmesh.errors import GeometryError
from ruledmesh.mesh import FaceKind, Mesh

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
# Only the catalogue's surfaces (a [surface] table) state a guarantee; the ruled examples are
# not built here, at collection, in every worker (25 s of a worker's time when they were).
WITH_GUARANTEE = sorted(p.name for p in EXAMPLES.glob("*.toml")
                        if "surface" in load_design(p).data and "guarantee" in build_file(p).extras)


def test_some_examples_state_guarantees():
    assert len(WITH_GUARANTEE) >= 15


@pytest.mark.parametrize("name", WITH_GUARANTEE)
def test_every_stated_guarantee_is_confirmed_by_the_figures(name, capsys):
    assert main(["analyze", str(EXAMPLES / name), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    check = report["guarantee_check"]
    assert check["claim"] == report["guarantee"] and check["met"], check
    measured = [r for r in check["properties"] if r["status"] == "met"]
    assert measured and all(r["max"] <= r["tolerance"] for r in measured)
    assert not any(w.startswith("guarantee") for w in report["warnings"])


def test_fig5a_transformed_mesh_no_longer_claims_circular(capsys):
    """Regression: a shear then a projective map keep planarity only; the claim says so."""
    assert main(["analyze", str(EXAMPLES / "fig5a-transformed-rotational.toml")]) == 0
    table = capsys.readouterr().out
    row = next(ln for ln in table.splitlines() if ln.startswith("guarantee"))
    assert "circular" not in row and "planar (met: planarity" in row


def _rotational(transform: str) -> dict:
    text = ('[surface]\nkind = "rotational"\nmeridian = [[0.6, 0, 0], [1.1, 0, 0.4], [1.0, 0, 1.0]]\n'
            '[mesh]\nu = 12\nv = 4\n' + transform)
    return build_file_text(text)


def build_file_text(text: str):
    from ruledmesh.design import build_design

    return build_design(parse_design(text, "t.toml"))


@pytest.mark.parametrize("transform, claim, kept", [
    ("", "isosceles trapezoids, circular", {"isosceles trapezoids", "circular"}),
    ('[[transform]]\ntype = "rotate"\naxis = [1, 1, 0]\nangle = 30\n',
     "isosceles trapezoids, circular", {"isosceles trapezoids", "circular"}),
    ('[[transform]]\ntype = "shear"\nxz = 0.4\n', "trapezoids (after a non-similar shear map)",
     {"trapezoids"}),
])
def test_transform_keeps_only_what_it_preserves_and_that_is_met(transform, claim, kept):
    built = _rotational(transform)
    assert built.extras["guarantee"] == claim
    check = check_guarantee(claim, built.mesh)
    assert check["met"] and {r["property"] for r in check["properties"]} == kept


def test_unmet_claim_is_flagged_with_figure_and_tolerance():
    """The raw claim checked on a sheared mesh: both properties fail, with numbers."""
    built = _rotational('[[transform]]\ntype = "shear"\nxz = 0.4\n')
    check = check_guarantee("isosceles trapezoids, circular", built.mesh)
    assert not check["met"]
    text = format_guarantee(check)
    assert "circular \u2014 not met: circularity" in text and "> 1e-10 on" in text
    report = analyze(built.mesh, extras={"guarantee": "isosceles trapezoids, circular"})
    assert any(w.startswith("guarantee: ") and "not met" in w for w in report["warnings"])
    assert "not met" in format_table(report)


def test_border_faces_and_fill_triangles_promise_nothing():
    """Only QUAD faces are measured: a bent BORDER face does not break a trapezoid claim."""
    x = np.array([[0, 0, 0], [4, 0, 0], [3, 1, 0], [1, 1, 0], [5, 2, 0], [0, 3, 1]], float)
    mesh = Mesh.from_faces(x, [[0, 1, 2, 3], [1, 4, 5, 2]],
                           face_kind=[FaceKind.QUAD, FaceKind.BORDER])
    assert check_guarantee("isosceles trapezoids", mesh)["met"]
    kind = mesh.face_kind.copy()
    kind[1] = FaceKind.QUAD
    other = Mesh.from_faces(x, [[0, 1, 2, 3], [1, 4, 5, 2]], face_kind=kind)
    assert not check_guarantee("isosceles trapezoids", other)["met"]


def test_trapezoid_measures():
    square = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    kite = np.array([[[0, 0, 0], [2, -1, 0], [4, 0, 0], [2, 3, 0]]], float)
    right = np.array([[[0, 0, 0], [3, 0, 0], [2, 1, 0], [0, 1, 0]]], float)
    t, i = quad_trapezoid(np.concatenate([square, kite, right]))
    assert t[0] < 1e-15 and i[0] < 1e-15
    assert t[1] > 0.1                                   # no pair of parallel edges
    assert t[2] < 1e-15 and i[2] == pytest.approx(abs(np.sqrt(2) - 1) / ((np.sqrt(2) + 1) / 2))


def test_unmeasurable_property_is_not_checked_not_claimed():
    mesh = build_file(EXAMPLES / "fig7c-hp-generators.toml").mesh
    check = check_guarantee("parallelograms; diagonals are generators of both reguli", mesh)
    status = {r["property"]: r["status"] for r in check["properties"]}
    assert status == {"parallelograms": "met",
                      "diagonals are generators of both reguli": "not checked"}
    assert "(not checked)" in format_guarantee(check)


def test_wrong_design_is_reported(tmp_path, capsys):
    """Regression: a skew mesh measured against the torus design."""
    mesh = tmp_path / "skew.obj"
    assert main(["build", str(EXAMPLES / "skew.toml"), "-o", str(mesh), "-q"]) == 0
    assert main(["analyze", str(mesh), "--design", str(EXAMPLES / "fig5b-torus.toml"),
                 "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["matches_design"] is False
    warning = next(w for w in report["warnings"] if "does not match the design" in w)
    assert "closeness 0.62" in warning and "coverage 0.43" in warning
    assert not report["guarantee_check"]["met"]
    assert main(["analyze", str(mesh), "--design", str(EXAMPLES / "skew.toml"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["matches_design"] is True
    assert not any("does not match" in w for w in report["warnings"])


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.toml")))
def test_every_example_matches_its_own_design(name):
    built = build_file(EXAMPLES / name)
    report = analyze(built.mesh, reference=built.reference, extras=built.extras)
    assert report.get("matches_design", True), report["warnings"]


def test_mesh_without_faces_is_an_error():
    empty = Mesh.from_faces(np.zeros((3, 3)), np.zeros((0, 4), dtype=int))
    with pytest.raises(GeometryError, match="no faces"):
        analyze(empty)


def test_face_counts_in_one_vocabulary(capsys):
    assert set(KIND_NOUNS) == set(FaceKind)
    assert kind_counts({"quad": 633, "border": 9, "fill": 306, "split": 1}) == \
        "633 quads, 9 border faces, 306 fill triangles, 1 split quad"
    counts = build_file(EXAMPLES / "skew.toml").mesh.count_kinds()
    words = ", ".join(f"{counts[k]} {w}" for k, w in
                      [("quad", "quads"), ("border", "border faces"), ("fill", "fill triangles")])
    assert set(counts) == {"quad", "border", "fill"}
    assert main(["analyze", str(EXAMPLES / "skew.toml")]) == 0
    table = capsys.readouterr().out.splitlines()
    row = next(ln for ln in table if ln.startswith("kinds"))
    assert row.split(None, 1)[1] == words
    # the export triangulation's figures are not a face count: their row says so
    assert any(ln.startswith("triangulation ") for ln in table)
    assert not any(ln.startswith("triangles ") for ln in table)


def test_designer_figures_use_the_same_words():
    from ruledmesh.web.session import fast_figures

    mesh = build_file(EXAMPLES / "skew.toml").mesh
    figures = fast_figures(mesh)[0]
    assert figures["kinds_text"] == kind_counts(mesh.count_kinds())
    assert figures["kinds_text"].startswith(f"{figures['kinds']['quad']} quads, ")


def test_designer_planarity_counts_are_analyze_s_also_far_from_the_origin():
    """The designer's legend counts exact faces by analyze's rule: examples/skew moved 5e6 m
    out has every face exact to the rounding of its coordinates in both."""
    from ruledmesh.web.session import fast_figures

    mesh = build_file(EXAMPLES / "skew.toml").mesh
    for m in (mesh, mesh.with_vertices(mesh.vertices + np.array([5e6, 5e6, 100.0]))):
        counts = fast_figures(m)[0]["planarity_counts"]
        report = analyze(m)["planarity"]
        shown = int(np.count_nonzero(m.valences > 3))
        assert counts == {"exact": shown, "over": report["above_tolerance"], "faces": shown}
        assert report["exact"] == m.n_faces
