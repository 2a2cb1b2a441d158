"""``ruledmesh compare``: PQ (§4.3) and hybrid (§4.1) of one design, side by side."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ruledmesh.cli import main

EXAMPLES = Path(__file__).parent.parent / "examples"

DESIGN = """
[rulings]
lines = [
  [[1.0, 1.0, -1.0], [1.0, -1.0, 1.0]],
  [[0.6299, 1.2666, -1.0], [1.2666, -0.6299, 1.0]],
  [[0.2001, 1.3999, -1.0], [1.3999, -0.2001, 1.0]],
  [[-0.2491, 1.3920, -1.0], [1.3920, 0.2491, 1.0]],
  [[-0.6737, 1.2433, -1.0], [1.2433, 0.6737, 1.0]],
]

[mesh]
method = "pq"
rows = 8
divisions = 6
"""


def test_compare_json(tmp_path, capsys):
    path = tmp_path / "hyp.toml"
    # "divisions" belongs to hybrid only; compare passes each method its own keys.
    path.write_text(DESIGN.replace("divisions = 6\n", ""))
    assert main(["compare", str(path), "--json", "--divisions", "6", "--midpoints", "1"]) == 0
    reports = json.loads(capsys.readouterr().out)
    assert set(reports) == {"pq", "hybrid"}
    pq, hy = reports["pq"], reports["hybrid"]
    for r in (pq, hy):
        assert r["planarity"]["max"] <= 1e-12
        assert 0.5 < r["coverage"]["ratio"] < 1.5
        assert r["closeness"]["centroids_max"] < 0.05
    # Hybrid: 4 strips, one midpoint, 6 divisions: 2 quads per strip (mid column, rows 2, 4).
    assert hy["kinds"]["quad"] == 4 * 2 and hy["faces"] == hy["kinds"]["quad"] + hy["kinds"]["triangle"]
    assert hy["triangle_share"] == pytest.approx(hy["kinds"]["triangle"] / hy["faces"])
    # PQ on one regulus of a hyperboloid: quads inside, triangles only at the border.
    assert pq["triangle_share"] < hy["triangle_share"]


def test_compare_table(tmp_path, capsys):
    path = tmp_path / "hyp.toml"
    path.write_text(DESIGN.replace("divisions = 6\n", ""))
    assert main(["compare", str(path)]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert "pq (§4.3)" in lines[0] and "hybrid (§4.1)" in lines[0]
    labels = [ln.split("  ")[0] for ln in lines[1:]]
    for label in ("faces", "area in triangles", "triangles (of the faces)", "max planarity",
                  "closeness (max, centroids)", "coverage", "min angle (deg)"):
        assert label in labels


def test_compare_refuses_catalogue_surface(capsys):
    assert main(["compare", str(EXAMPLES / "compound-hp-strip.toml")]) == 2
    assert "[rulings]" in capsys.readouterr().err
