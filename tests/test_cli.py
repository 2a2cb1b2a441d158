"""The command line: build, analyze, errors as one line with exit code 2."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ruledmesh.cli import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
RULED_EXAMPLES = ["skew.toml", "fig10-skew-surface.toml", "parameter-distribution.toml",
                  "conoidal-director-plane.toml", "linear-directrix.toml", "right-conoid-arc.toml",
                  "three-directrices.toml", "lines-hyperboloid.toml", "lines-file.toml"]


@pytest.mark.parametrize("name", RULED_EXAMPLES)
def test_every_ruled_example_builds_planar_and_covering(tmp_path, name, capsys):
    out = tmp_path / "m.obj"
    assert main(["build", str(EXAMPLES / name), "-o", str(out), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["finite"] and report["planarity"]["max"] <= 1e-12
    assert report["non_convex"] == 0
    # No splinter (linear-directrix kept a 2.99 degree triangle before flip_splinters).
    assert report["min_angle_deg"] >= 3.0
    # A fabricator's bar on every skew surface (linear-directrix had 29.0 % before the
    # starts and checkerboards per segment).
    assert report["quality"]["area_share"]["triangles"] <= 0.25
    assert report["euler_characteristic"] == 1
    assert abs(report["coverage"]["ratio"] - 1) < 0.02
    meshio = pytest.importorskip("meshio")
    back = meshio.read(out)
    assert sum(len(c.data) for c in back.cells) == report["faces"]
    assert np.all(np.isfinite(back.points))


def test_analyze_mesh_file_and_design(tmp_path, capsys):
    out = tmp_path / "skew.ply"
    assert main(["build", str(EXAMPLES / "skew.toml"), "-o", str(out), "-q"]) == 0
    assert capsys.readouterr().out == ""
    assert main(["analyze", str(out)]) == 0
    table = capsys.readouterr().out
    assert "planarity" in table and "closeness" not in table
    assert main(["analyze", str(out), "--design", str(EXAMPLES / "skew.toml"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["closeness"]["vertices_max"] < 1e-9       # vertices lie on the generators
    assert report["coverage"]["ratio"] == pytest.approx(1, abs=0.02)


def test_quiet_build_writes_the_same_mesh_without_measuring_it(tmp_path, capsys, monkeypatch):
    import ruledmesh.analysis.report as report

    loud, quiet = tmp_path / "loud.obj", tmp_path / "quiet.obj"
    assert main(["build", str(EXAMPLES / "skew.toml"), "-o", str(loud)]) == 0

    def unasked(*args, **kwargs):
        raise AssertionError("a quiet build analysed its mesh")

    monkeypatch.setattr(report, "analyze", unasked)
    capsys.readouterr()
    assert main(["build", str(EXAMPLES / "skew.toml"), "-o", str(quiet), "-q"]) == 0
    assert capsys.readouterr().out == ""
    assert quiet.read_bytes() == loud.read_bytes()


BAD = {
    "count-word": ('[curves.c1]\ntype="line"\npoints=[[0,0,0],[1,0,0]]\n[curves.c2]\ntype="line"\n'
                   'points=[[0,1,1],[1,1,2]]\n[rulings]\nbetween=["c1","c2"]\ncount="forty"\n',
                   'bad.toml: rulings.count: expected an integer >= 3, got "forty"'),
    "unknown-top": ('[rulngs]\ncount=3\n', 'bad.toml: rulngs: unknown key (did you mean "rulings"?)'),
    "toml-syntax": ('[mesh\nrows=3\n', "bad.toml: invalid TOML"),
    "method": ('[rulings]\nlines=[[[0,0,0],[0,1,0]],[[1,0,0],[1,1,1]],[[2,0,0],[2,1,3]]]\n'
               '[mesh]\nmethod="pqq"\n', 'bad.toml: mesh.method: expected one of'),
    "rows": ('[rulings]\nlines=[[[0,0,0],[0,1,0]],[[1,0,0],[1,1,1]],[[2,0,0],[2,1,3]]]\n'
             '[mesh]\nrows=0\n', "bad.toml: mesh.rows: expected an integer >= 1"),
    "mesh-key": ('[rulings]\nlines=[[[0,0,0],[0,1,0]],[[1,0,0],[1,1,1]],[[2,0,0],[2,1,3]]]\n'
                 '[mesh]\nrow=4\n', 'bad.toml: mesh.row: unknown key (did you mean "rows"?)'),
    "zero-generator": ('[rulings]\nlines=[[[0,0,0],[0,1,0]],[[1,0,0],[1,0,0]],[[2,0,0],[2,1,3]]]\n',
                       "bad.toml"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_malformed_design_exits_2_with_one_line_and_writes_nothing(tmp_path, case):
    text, expected = BAD[case]
    design = tmp_path / "bad.toml"
    design.write_text(text)
    out = tmp_path / "out.obj"
    proc = subprocess.run([sys.executable, "-m", "ruledmesh.cli", "build", str(design), "-o", str(out)],
                          capture_output=True, text=True, cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr
    assert expected in lines[0]
    assert not out.exists() and list(tmp_path.iterdir()) == [design]


def test_missing_file_and_unknown_format(tmp_path, capsys):
    assert main(["build", str(tmp_path / "nope.toml"), "-o", str(tmp_path / "x.obj")]) == 2
    assert "nope.toml: file not found" in capsys.readouterr().err
    assert main(["build", str(EXAMPLES / "skew.toml"), "-o", str(tmp_path / "x.xyz")]) == 2
    assert "cannot write" in capsys.readouterr().err
    assert not (tmp_path / "x.xyz").exists()


def test_help_lists_examples(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    text = capsys.readouterr().out
    assert "ruledmesh build examples/skew.toml -o skew.obj" in text
