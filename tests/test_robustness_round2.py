"""Regression tests of the second robustness round (docs/robustness.md).

One test per reproduced defect: deep nesting, special files, work budgets,
messages with control characters, broken pipes, empty or low-coverage meshes,
strict JSON, one planarity measure, and examples that say what they build.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ruledmesh.cli import main
from ruledmesh.errors import (
    DesignError,
    GeometryError,
    ParameterError,
    RuledMeshError,
    printable,
)

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

TWO_LINES = """
[curves.c1]
type = "line"
points = [[0, 0, 0], [4, 0, 0]]
[curves.c2]
type = "line"
points = [[0, 3, 1], [4, 3, -1]]
"""


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def one_error_line(code: int, err: str) -> str:
    """The one bounded, printable error line of a refused command."""
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ruledmesh: error: "), err
    assert "Traceback" not in err and len(lines[0]) <= 2100
    assert lines[0].isprintable(), repr(lines[0])
    return lines[0]


def hyperboloid_lines(m: int = 12) -> tuple[np.ndarray, np.ndarray]:
    phi = np.linspace(0, np.pi, m)
    a = np.stack([np.cos(phi) - np.sin(phi), np.sin(phi) + np.cos(phi), -np.ones(m)], 1)
    b = np.stack([np.cos(phi) + np.sin(phi), np.sin(phi) - np.cos(phi), np.ones(m)], 1)
    return a, b


# ------------------------------------------------------------ loading
@pytest.mark.parametrize("text", [
    "a = " + "{b = " * 400 + "1" + "}" * 400,          # inline tables 400 deep (6 kB)
    "a = " + "[" * 1000 + "]" * 1000,                  # arrays 1000 deep
    "a = " + "[" * 40 + "]" * 40,                      # readable, but deeper than any design
], ids=["tables-400", "arrays-1000", "arrays-40"])
def test_deeply_nested_toml_is_a_design_error_not_recursion(tmp_path, capsys, text):
    path = tmp_path / "deep.toml"
    path.write_text(text)
    code, _, err = run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))
    line = one_error_line(code, err)
    assert "nested" in line and str(path) in line
    assert not (tmp_path / "o.obj").exists()


@pytest.mark.parametrize("command", ["build", "analyze"])
def test_dev_zero_is_refused_before_reading(tmp_path, capsys, command):
    argv = [command, "/dev/zero"] + (["-o", str(tmp_path / "o.obj")] if command == "build" else [])
    line = one_error_line(*run_cli(capsys, *argv)[::2])
    assert "/dev/zero: this is a character device" in line


def test_named_pipe_is_refused_without_blocking(tmp_path, capsys):
    fifo = tmp_path / "design.toml"
    os.mkfifo(fifo)
    line = one_error_line(*run_cli(capsys, "build", str(fifo), "-o", str(tmp_path / "o.obj"))[::2])
    assert "named pipe" in line


def test_rulings_file_dev_zero_says_what_it_is(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text('[rulings]\nfile = "/dev/zero"\n')
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert 'rulings.file: "/dev/zero" is a character device' in line
    assert "no such file" not in line


def test_load_design_api_refuses_special_files():
    from ruledmesh.design import load_design
    from ruledmesh.design.rulings import from_csv

    with pytest.raises(DesignError, match="character device"):
        load_design("/dev/zero")
    with pytest.raises(DesignError, match="character device"):
        from_csv("/dev/zero")


def test_oversized_design_file_is_refused(tmp_path, capsys):
    from ruledmesh import _files

    path = tmp_path / "big.toml"
    path.write_bytes(b"# " + b"x" * (_files.MAX_DESIGN_BYTES + 10) + b"\n")
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "too large for a design file" in line


# ------------------------------------------------------------ messages
def test_printable_escapes_controls_and_cuts():
    assert printable("a\nb\u202ec\x1b[0m") == "a\\nb\\u202ec\\x1b[0m"
    assert printable("x" * 500) == "x" * 79 + "…"
    assert printable("é ü ∑") == "é ü ∑"


def test_newline_and_rtl_override_in_a_name_stay_on_one_line(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text('[rulings]\nbetween = ["c1", "c2"]\n[curves."x\\ny\\u202e"]\ntype = "lin"\n')
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "x\\ny\\u202e" in line and "\u202e" not in line


def test_huge_user_strings_are_cut(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(f'[surface]\nkind = "{"z" * 100_000}"\n')
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "…" in line and len(line) < 1000


@pytest.mark.parametrize("argv", [["examples"], ["analyze", "examples/skew.toml", "--json"]])
def test_broken_pipe_ends_quietly(argv):
    cmd = [sys.executable, "-m", "ruledmesh", *argv]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT)
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.read(10)
    proc.stdout.close()  # what `| head -c 10` does
    err = proc.stderr.read().decode()
    code = proc.wait(timeout=300)
    assert "Broken pipe" not in err and "Traceback" not in err and "Exception" not in err, err
    assert code in (0, 141)


# ------------------------------------------------------------ work budgets
def test_extend_counts_in_the_design_budget(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(TWO_LINES + '[rulings]\nbetween = ["c1", "c2"]\ncount = 200\n'
                    "[mesh]\nrows = 40\nextend = 1000\ntrim = false\n")
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "mesh.rows: 200 generators x 41 rows x (1 + 2 x extend 1000) would need about" in line
    assert "GiB" in line


def test_hybrid_divisions_count_in_the_design_budget(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(TWO_LINES + '[rulings]\nbetween = ["c1", "c2"]\ncount = 2000\n'
                    '[mesh]\nmethod = "hybrid"\nmidpoints = 100\ndivisions = 100000\n')
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "mesh.divisions:" in line and "GiB" in line


@pytest.mark.parametrize("kwargs", [{"rows": 10**7}, {"rows": 10**7, "extend": 0},
                                    {"rows": 4 * 10**6}, {"rows": 1000, "extend": 1000}])
def test_pq_mesh_refuses_a_huge_grid_with_its_own_error(kwargs):
    from ruledmesh.pq import pq_mesh

    a, b = hyperboloid_lines(5)
    with pytest.raises(GeometryError, match=r"would need about [\d.]+ GiB \(limit 8 GiB\)"):
        pq_mesh(a, b, **kwargs)


def test_hybrid_and_compound_refuse_huge_grids():
    from ruledmesh.skew.compound import compound_mesh
    from ruledmesh.skew.hybrid import hybrid_mesh

    a, b = hyperboloid_lines(200)
    with pytest.raises(ParameterError, match="GiB"):
        hybrid_mesh(a, b, midpoints=1000, divisions=1000)
    P = np.zeros((4, 4, 3))
    P[..., 0], P[..., 1] = np.meshgrid(np.arange(4.0), np.arange(4.0), indexing="ij")
    with pytest.raises(ParameterError, match="GiB"):
        compound_mesh(P, midpoints=10_000, divisions=100_000)


def test_every_refusal_is_a_ruledmesh_error():
    assert issubclass(GeometryError, RuledMeshError) and issubclass(DesignError, RuledMeshError)


# ------------------------------------------------------------ empty and partial meshes
def test_untrimmed_all_torsal_build_is_refused_not_empty(tmp_path, capsys):
    path = tmp_path / "case.toml"
    arcs = "".join(f'[curves.{n}]\ntype = "arc"\ncenter = [0, 0, {z}]\nradius = 1\n'
                   f"normal = [0, 0, 1]\nstart_angle = 0\nend_angle = 180\n"
                   for n, z in (("c1", 0), ("c2", 2)))
    path.write_text(arcs + '[rulings]\nbetween = ["c1", "c2"]\ncount = 9\n[mesh]\nrows = 8\n'
                    "trim = false\n")
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "has no faces" in line and "torsal" in line and "trim = true" in line
    assert not (tmp_path / "o.obj").exists()


def test_far_axis_rotational_is_refused_not_silent(tmp_path, capsys):
    text = (EXAMPLES / "sec2-rotational.toml").read_text().replace("point = [0, 0, 0]",
                                                                    "point = [1e30, 0, 0]")
    path = tmp_path / "case.toml"
    path.write_text(text)
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "has no area" in line and "float64 resolution" in line


def test_tiny_generators_are_refused_with_the_range():
    from ruledmesh.skew.hybrid import hybrid_mesh

    a, b = hyperboloid_lines()
    with pytest.raises(GeometryError, match="at least 1e-60 across"):
        hybrid_mesh(a * 1e-100, b * 1e-100)


def test_low_coverage_is_warned_with_how_much(tmp_path, capsys):
    text = (EXAMPLES / "fig7c-hyperboloid-generators.toml").read_text()
    path = tmp_path / "case.toml"
    path.write_text(text.replace("height = 1.5", "height = 2.0"))
    code, out, err = run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))
    assert code == 0 and "coverage 0.677" in out
    assert "crossings reach |z| = 1.5, not the height 2" in err
    assert "the mesh covers 67.7% of the designed patch" in err


def test_analyze_measures_coverage_against_the_designed_patch():
    from ruledmesh.analysis.report import analyze
    from ruledmesh.api import build_full

    text = (EXAMPLES / "fig7c-hyperboloid-generators.toml").read_text()
    short = build_full(text.replace("height = 1.5", "height = 2.0"))
    report = analyze(short.mesh, reference=short.reference, extras=short.extras)
    # The reference is |z| <= 2 as designed, not the |z| <= 1.5 the mesh reaches.
    assert report["coverage"]["ratio"] == pytest.approx(0.677, abs=0.002)
    assert any("covers 67.7%" in w for w in report["warnings"])


def test_notched_compound_coverage_is_warned(tmp_path, capsys):
    text = (EXAMPLES / "compound-hp-strip.toml").read_text()
    path = tmp_path / "case.toml"
    path.write_text(text.replace('border = "triangles"', 'border = "notched"'))
    code, _, err = run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))
    assert code == 0 and "the mesh covers 72.9% of the designed patch" in err


# ------------------------------------------------------------ scale and strict JSON
@pytest.mark.parametrize("mesher", ["pq", "hybrid"])
def test_meshes_are_the_same_at_every_scale(mesher):
    from ruledmesh.pq import pq_mesh
    from ruledmesh.skew.hybrid import hybrid_mesh

    fn = pq_mesh if mesher == "pq" else hybrid_mesh
    a, b = hyperboloid_lines()
    a, b = a + [0.3, 0.1, 0.7], b + [0.3, 0.1, 0.7]
    ref = fn(a, b)
    for k in (-190, -100, -40, 40, 100, 190):        # 2**k: exact scalings, 1e-57 .. 1e57
        s = 2.0**k
        mesh = fn(a * s, b * s)
        assert np.array_equal(mesh.face_indices, ref.face_indices)
        assert np.array_equal(mesh.vertices, ref.vertices * s)
    for s in (1e-50, 1e-20, 1e20, 1e50):              # other scales: same faces, rounding apart
        mesh = fn(a * s, b * s)
        assert np.array_equal(mesh.face_indices, ref.face_indices)
        np.testing.assert_allclose(mesh.vertices / s, ref.vertices, atol=1e-12)


def test_coordinates_beyond_the_range_are_refused_naming_it():
    from ruledmesh.pq import pq_mesh

    a, b = hyperboloid_lines()
    with pytest.raises(GeometryError, match=r"within \+-1e\+60"):
        pq_mesh(a * 1e100, b * 1e100)


def _strict_loads(text: str) -> dict:
    def refuse(name: str) -> None:
        raise ValueError(f"non-strict JSON constant {name}")

    return json.loads(text, parse_constant=refuse)


def test_analyze_json_of_a_mesh_near_the_float_limit_is_strict(tmp_path, capsys):
    from ruledmesh.io import save
    from ruledmesh.mesh import Mesh

    quad = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float) * 1e307
    path = tmp_path / "big.json"
    save(path, Mesh.from_faces(quad, [[0, 1, 2, 3]]))
    code, out, err = run_cli(capsys, "analyze", str(path), "--json")
    assert code == 0 and err == ""
    report = _strict_loads(out)
    assert report["planarity"]["max"] == 0.0 and report["faces"] == 1
    assert "area.total" in report["non_finite"]
    assert any("beyond float64" in w for w in report["warnings"])


def test_analysis_is_the_same_at_every_scale():
    from ruledmesh.analysis.report import analyze
    from ruledmesh.pq import pq_mesh

    a, b = hyperboloid_lines()
    ref = analyze(pq_mesh(a, b))
    for s in (2.0**-180, 2.0**180):
        rep = analyze(pq_mesh(a * s, b * s))
        assert rep["planarity"] == ref["planarity"]
        assert rep["quality"] == ref["quality"]
        assert rep["area"]["total"] == ref["area"]["total"] * s * s


# ------------------------------------------------------------ one planarity measure
def test_fabricate_accepts_what_build_reports_planar():
    """Needle triangles: the plane fit of the old rule called 18 of 20 "bent panels"."""
    from ruledmesh.analysis.planar import bent_faces
    from ruledmesh.analysis.report import analyze
    from ruledmesh.fabricate.unroll import unroll
    from ruledmesh.mesh import Mesh

    rng = np.random.default_rng(1)
    corners = []
    for _ in range(20):
        a, d, e = rng.normal(size=(3, 3))
        d /= np.linalg.norm(d)
        e -= e.dot(d) * d
        e /= np.linalg.norm(e)
        corners += [a, a + d, a + 0.5 * d + 3e-8 * e]   # area 1.5e-8 of the longest edge squared
    mesh = Mesh.from_faces(np.array(corners), np.arange(60).reshape(20, 3))
    assert analyze(mesh)["planarity"]["above_tolerance"] == 0
    assert not bent_faces(mesh)[0].any()
    assert unroll(mesh).n_faces == 20     # no GeometryError: triangles are planar


def test_fabricate_and_analyze_name_the_same_bent_face():
    from ruledmesh.analysis.report import analyze
    from ruledmesh.errors import GeometryError as GE
    from ruledmesh.fabricate.unroll import unroll
    from ruledmesh.pq import pq_mesh

    a, b = hyperboloid_lines()
    mesh = pq_mesh(a, b)
    v = mesh.vertices.copy()
    v[mesh.face_indices[mesh.face_offsets[3]]] += [0, 0, 1e-3]
    bent = mesh.with_vertices(v)
    report = analyze(bent)
    with pytest.raises(GE, match=f"{report['planarity']['above_tolerance']} faces are not planar"):
        unroll(bent)


# ------------------------------------------------------------ examples tell the truth
def test_lines_hyperboloid_example_is_exact():
    from ruledmesh import build

    v = build(EXAMPLES / "lines-hyperboloid.toml").vertices
    assert np.abs(v[:, 0] ** 2 + v[:, 1] ** 2 - v[:, 2] ** 2 - 1).max() < 1e-14


def _report(name: str) -> dict:
    from ruledmesh.analysis.report import analyze
    from ruledmesh.api import build_full

    built = build_full(EXAMPLES / f"{name}.toml")
    return analyze(built.mesh, reference=built.reference, extras=built.extras)


def test_fig3b_is_labelled_congruent_parallelograms():
    report = _report("fig3b-strips-congruent")
    assert report["guarantee"] == "parallelograms (congruent polygons)"
    assert report["guarantee_check"]["met"]
    assert _report("fig3c-strips-similar")["guarantee"] == "trapezoids (similar polygons)"


@pytest.mark.parametrize("name", ["compound-hp-strip", "compound-hp-grid",
                                  "fig7c-hyperboloid-generators"])
def test_examples_cover_their_design(name):
    report = _report(name)
    assert abs(report["coverage"]["ratio"] - 1) < 0.01
    assert not any("covers" in w for w in report["warnings"])


# ------------------------------------------------------------ reports say what they count
def test_compare_reports_the_triangle_share_by_area_and_labels_the_count(capsys):
    code, out, _ = run_cli(capsys, "compare", str(EXAMPLES / "fig10-skew-surface.toml"),
                           "--rows", "16")
    assert code == 0
    rows = {ln[:28].strip(): ln[28:].split() for ln in out.splitlines()[1:]}
    assert "area in triangles" in rows and "triangles (of the faces)" in rows
    area_pq, count_pq = (float(rows[k][0].rstrip("%")) for k in
                         ("area in triangles", "triangles (of the faces)"))
    assert area_pq < count_pq  # the PQ mesh's triangles are small: area and count differ


def test_hybrid_torsal_lines_t_junction_is_reported():
    report = _report("hybrid-torsal-lines")
    assert report["t_junctions"]["count"] == 1
    v, a, b = report["t_junctions"]["first"][0]
    from ruledmesh import build

    P = build(EXAMPLES / "hybrid-torsal-lines.toml").vertices
    np.testing.assert_allclose(P[v], 0.5 * (P[a] + P[b]), atol=1e-12)   # at the midpoint
    said = [w for w in report["warnings"] if "T-junction" in w]
    assert len(said) == 1 and said[0].startswith("1 T-junction: ") and "conforming by connectivity" in said[0]
    assert _report("hybrid-fig9")["t_junctions"]["count"] == 0


def test_a_closed_surfaces_seam_is_named_in_the_t_junction_warning():
    """A Pluecker conoid from 15 lines over half a turn: the last line is the first, reversed,
    and the two sides of that seam carry different divisions.  The T-junctions there are
    named as the seam (the generators that coincide), not as faces failing to meet."""
    from ruledmesh.analysis.report import analyze
    from ruledmesh.design import build_design, parse_design

    th = np.linspace(0, np.pi, 15)
    lines = [[[-3 * np.cos(t), -3 * np.sin(t), 1.5 * np.sin(2 * t)],
              [3 * np.cos(t), 3 * np.sin(t), 1.5 * np.sin(2 * t)]] for t in th]
    text = f'name = "seam"\n[rulings]\nlines = {np.round(lines, 12).tolist()}\n[mesh]\nrows = 8\n'
    report = analyze(build_design(parse_design(text)).mesh)
    assert report["t_junctions"]["count"] > 0
    said = [w for w in report["warnings"] if "T-junction" in w]
    assert len(said) == 1 and "generators 0 and 14 coincide there (the seam of a closed surface)" in said[0]
    assert "conforming by connectivity" not in said[0]


# ------------------------------------------------------------ found by tests/test_fuzz_cli.py
@pytest.mark.parametrize(("example", "old", "new", "message"), [
    ("fig7b-hyperboloid-circular", "a = 1.0", "a = 5e-324",
     "surface.a: expected 0 or a number of magnitude at least 1e-60"),
    ("fig7b-hyperboloid-circular", "height = 2.0", "height = 1e308",
     "surface.height: expected a number within +-1e+60"),
    ("right-conoid-arc", "end_angle = 180", "end_angle = 5e-324",
     "curves.arc.end_angle: expected 0 or a number of magnitude at least 1e-60"),
    ("skew", "[3, 1, 0]", "[3, 1e308, 0]", "curves.c1.points[1][1]: expected a number within"),
])
def test_design_numbers_that_would_overflow_are_refused(tmp_path, capsys, example, old, new,
                                                         message):
    text = (EXAMPLES / f"{example}.toml").read_text()
    assert old in text
    path = tmp_path / "case.toml"
    path.write_text(text.replace(old, new, 1))
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert message in line


def test_arc_start_angle_of_6e301_degrees_is_refused(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(TWO_LINES.replace('type = "line"\npoints = [[0, 0, 0], [4, 0, 0]]',
                                      'type = "arc"\ncenter = [0, 0, 0]\nradius = 2\n'
                                      "normal = [0, 0, 1]\nstart_angle = 6e301\nend_angle = 90")
                    + '[rulings]\nbetween = ["c1", "c2"]\n')
    code, out, err = run_cli(capsys, "analyze", str(path), "--json")
    assert "start_angle: expected a number within" in one_error_line(code, err) and out == ""


def test_compound_seed_far_out_of_proportion_does_not_overflow(tmp_path, capsys):
    import warnings

    text = (EXAMPLES / "compound-hp-grid.toml").read_text()
    path = tmp_path / "case.toml"
    path.write_text(text.replace("[0.0, 1.5, 0.4]", "[0.0, 1e30, 0.4]"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        code, _, err = run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))
    assert "Warning" not in err and code in (0, 2), err
    if code == 2:
        one_error_line(code, err)


def test_mesh_load_and_designer_refuse_special_files(tmp_path, capsys):
    from ruledmesh import io as rio

    with pytest.raises(ParameterError, match="character device"):
        rio.load(_device_link(tmp_path, "zero.obj"))
    assert main(["design", _device_link(tmp_path, "zero.toml"), "--no-browser"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "character device" in err[0]


def _device_link(tmp_path, name):
    """A path with the given extension that is the character device /dev/zero."""
    link = tmp_path / name
    link.symlink_to("/dev/zero")
    return str(link)
