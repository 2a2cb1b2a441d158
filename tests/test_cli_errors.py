"""Wrong invocations: one line naming the user's path as typed, what to do, exit 2, nothing written.

Each case runs the real command in a subprocess from a temporary folder with
relative paths, the way a user types them, and checks that the folder holds
exactly what it held before.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from ruledmesh.cli import main
from ruledmesh.cli._common import InputError, check_output_file, file_kind
from ruledmesh.io import load

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """A folder with a design, its mesh, a CSV of lines, an empty and a face-less mesh."""
    d = tmp_path_factory.mktemp("cli-errors")
    shutil.copy(EXAMPLES / "skew.toml", d / "skew.toml")
    shutil.copy(EXAMPLES / "fig5b-torus.toml", d / "torus.toml")
    shutil.copy(EXAMPLES / "lines-hyperboloid.csv", d / "lines.csv")
    assert main(["build", str(d / "skew.toml"), "-o", str(d / "skew.obj"), "-q"]) == 0
    (d / "empty.obj").write_text("")
    (d / "points.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    (d / "notes.txt").write_text("just some words\n")
    (d / "a-file").write_text("x")
    (d / "folder.obj").mkdir()
    return d


def run(workdir: Path, *argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "ruledmesh.cli", *argv], cwd=workdir,
                          capture_output=True, text=True, timeout=120)


# (argv, text the one line must contain)
CASES = {
    "analyze-missing": (["analyze", "nope.obj"], "nope.obj: file not found"),
    "build-missing": (["build", "nope.toml", "-o", "x.obj"], "nope.toml: file not found"),
    "build-missing-suggests": (["build", "skwe.toml", "-o", "x.obj"],
                               "skwe.toml: file not found; check the path (did you mean skew.toml"),
    "build-mesh-as-design": (["build", "skew.obj", "-o", "x.obj"],
                             "skew.obj: this is an OBJ mesh, not a design file; use `ruledmesh "
                             "analyze skew.obj`"),
    "build-csv-as-design": (["build", "lines.csv", "-o", "x.obj"],
                            "lines.csv: this is a CSV table, not a design file"),
    "design-option-mesh": (["analyze", "skew.obj", "--design", "skew.obj"],
                           "skew.obj: this is an OBJ mesh, not a design file for --design"),
    "analyze-csv": (["analyze", "lines.csv"], "lines.csv: this is a CSV table; ruledmesh reads"),
    "analyze-text": (["analyze", "notes.txt"], "notes.txt: this is a file of unknown kind"),
    "analyze-empty": (["analyze", "empty.obj"], "empty.obj: this is an empty file"),
    "analyze-faceless": (["analyze", "points.obj"], "points.obj: the mesh has no faces (3 vertices)"),
    "analyze-folder": (["analyze", "folder.obj"], "folder.obj: is a folder"),
    "build-out-folder": (["build", "skew.toml", "-o", "folder.obj"],
                         "folder.obj: is a folder; give a file name"),
    "build-out-dot": (["build", "skew.toml", "-o", "."], ".: is a folder"),
    "build-out-noext": (["build", "skew.toml", "-o", "mesh"], "mesh: has no extension"),
    "build-out-unknown": (["build", "skew.toml", "-o", "mesh.xyz"],
                          'mesh.xyz: cannot write ".xyz" files; the extension picks the format'),
    "build-out-no-folder": (["build", "skew.toml", "-o", "nowhere/mesh.obj"],
                            "nowhere/mesh.obj: folder nowhere does not exist"),
    "build-out-under-file": (["build", "skew.toml", "-o", "a-file/mesh.obj"],
                             "a-file/mesh.obj: a-file is a file, not a folder"),
    "export-out-unknown": (["export", "skew.obj", "-o", "skew.step"], 'skew.step: cannot write ".step"'),
    "render-out-unknown": (["render", "skew.obj", "-o", "skew.jpg"], 'skew.jpg: cannot write ".jpg"'),
    "fabricate-out-file": (["fabricate", "skew.obj", "-o", "a-file"], "a-file: is a file, not a folder"),
    "fabricate-scale-negative": (["fabricate", "skew.obj", "-o", "fab", "--scale", "-1"],
                                 "--scale: expected a positive factor, got -1 (a negative factor "
                                 "would mirror"),
    "fabricate-scale-zero": (["fabricate", "skew.obj", "-o", "fab", "--scale", "0"],
                             "--scale: expected a positive factor, got 0"),
    "compare-mesh": (["compare", "skew.obj"], "skew.obj: this is an OBJ mesh"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_wrong_invocation_one_line_exit_2_nothing_written(workdir, case):
    argv, expected = CASES[case]
    before = sorted(p.name for p in workdir.iterdir())
    proc = run(workdir, *argv)
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    # argparse's own errors (--scale) print the usage line first; ours print one line.
    ours = [ln for ln in lines if not ln.startswith("usage:") and not ln.startswith("  ")]
    assert len(ours) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert expected in ours[0], ours[0]
    assert sorted(p.name for p in workdir.iterdir()) == before


def test_output_checked_before_the_build(workdir, monkeypatch):
    """A bad -o is refused before the (possibly long) build starts: the design is never read."""
    import ruledmesh.design as design_module

    def never(*args, **kwargs):
        raise AssertionError("the design was built before the output was checked")

    monkeypatch.setattr(design_module, "build_design", never)
    monkeypatch.chdir(workdir)
    assert main(["build", "skew.toml", "-o", "nowhere/mesh.obj"]) == 2


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux /proc")
def test_unwritable_folder_named_not_a_temp_file(workdir):
    # /proc refuses new files even for root, unlike a chmod-ed folder.
    proc = run(workdir, "build", "skew.toml", "-o", "/proc/mesh.obj")
    assert proc.returncode == 2
    assert proc.stderr.startswith("ruledmesh: error: /proc/mesh.obj: cannot write into /proc")
    assert ".part" not in proc.stderr


def test_missing_optional_library_refused_first(tmp_path, monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "ezdxf" else real(name, *a))
    with pytest.raises(InputError, match=r"out.dxf: writing \.dxf files needs ezdxf: "
                                         r"pip install 'ruledmesh\[dxf\]'"):
        check_output_file(str(tmp_path / "out.dxf").replace(str(tmp_path), "."),
                          [".obj", ".dxf"])


@pytest.mark.parametrize("name, content, kind", [
    ("a.obj", b"# comment\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "an OBJ mesh"),
    ("a.ply", b"ply\nformat ascii 1.0\n", "a PLY mesh"),
    ("a.glb", b"glTF\x02\x00\x00\x00", "a glTF binary (.glb) mesh"),
    ("a.stl", b"solid x\nfacet normal 0 0 1\n", "an STL mesh"),
    ("a.png", b"\x89PNG\r\n\x1a\n", "a PNG image"),
    ("a.svg", b'<?xml version="1.0"?>\n<svg xmlns="http://www.w3.org/2000/svg"/>', "an SVG image"),
    ("a.dxf", b"  0\nSECTION\n  2\nHEADER\n", "a DXF drawing"),
    ("a.ifc", b"ISO-10303-21;\nHEADER;\n", "an IFC model"),
    ("a.toml", b"[rulings]\ncount = 3\n", "a TOML file"),
    ("a.csv", b"x0,y0,z0,x1,y1,z1\n0,0,0,1,1,1\n", "a CSV table"),
    ("a.json", b'{"format": "ruledmesh.mesh", "version": 1}', "a ruledmesh JSON mesh"),
    ("b.json", b'{"asset": {}}', "a JSON file that is not a ruledmesh mesh"),
])
def test_file_kind_by_content(tmp_path, name, content, kind):
    path = tmp_path / ("x" + name)      # the name never decides
    path.write_bytes(content)
    assert file_kind(path) == kind


def test_mesh_with_the_wrong_extension_is_read_by_content(workdir, capsys):
    shutil.copy(workdir / "skew.obj", workdir / "skew-copy.txt")
    try:
        assert main(["analyze", str(workdir / "skew-copy.txt"), "--json"]) == 0
    finally:
        os.unlink(workdir / "skew-copy.txt")
    faces = load(workdir / "skew.obj").n_faces
    assert f'"faces": {faces}' in capsys.readouterr().out


def test_design_errors_name_the_path_as_typed(workdir):
    (workdir / "sub").mkdir(exist_ok=True)
    (workdir / "sub" / "bad.toml").write_text('[rulings]\ncount = "forty"\n')
    (workdir / "sub" / "syntax.toml").write_text('[mesh\nrows = 3\n')
    try:
        proc = run(workdir, "build", "sub/bad.toml", "-o", "x.obj")
        assert proc.returncode == 2 and proc.stderr.startswith("ruledmesh: error: sub/bad.toml: ")
        proc = run(workdir, "build", "sub/syntax.toml", "-o", "x.obj")
        assert proc.returncode == 2
        assert proc.stderr.startswith("ruledmesh: error: sub/syntax.toml: invalid TOML")
    finally:
        shutil.rmtree(workdir / "sub")
    assert not (workdir / "x.obj").exists()


def test_os_errors_name_the_target_not_the_temporary_file():
    from ruledmesh.cli import _published_name

    assert _published_name("/w/.skew.obj.4242.5.0a1b2c3d.part") == "/w/skew.obj"
    assert _published_name("out/.sheet-001.svg.k2j3h4_z.part") == "out/sheet-001.svg"
    assert _published_name("skew.obj") == "skew.obj"
