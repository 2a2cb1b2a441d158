"""The degenerate-geometry catalogue (docs/robustness.md), through the CLI.

Each case is a design file written in ``tmp_path`` and built with ``ruledmesh
build``; the expected outcome is either a mesh that passes the invariants
(finite, every face planar to 1e-12, every vertex on a generator segment of
the design, read back from the written file) or one line on stderr naming the
file and the problem, exit code 2, and no file written.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

from ruledmesh.analysis import planarity
from ruledmesh.cli import main
from ruledmesh.design import build_file
from ruledmesh.io import load

ROOT = Path(__file__).resolve().parents[1]


# ----------------------------------------------------------------- helpers
def _lines(lines) -> str:
    rows = ",\n  ".join(
        "[[{!r}, {!r}, {!r}], [{!r}, {!r}, {!r}]]".format(*map(float, a), *map(float, b)) for a, b in lines)
    return f"[rulings]\nlines = [\n  {rows}\n]\n"


def build(tmp_path: Path, capsys, text: str, name: str = "case.toml", out: str = "out.obj"):
    """Write ``text`` to ``tmp_path/name``, run ``ruledmesh build --json``; return
    ``(code, report or None, stderr, design path, output path)``."""
    design = tmp_path / name
    design.write_text(text)
    target = tmp_path / out
    # Run from the folder with the name as a user types it: errors quote the path as typed.
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        code = main(["build", name, "-o", out, "--json"])
    finally:
        os.chdir(cwd)
    captured = capsys.readouterr()
    report = json.loads(captured.out) if code == 0 else None
    return code, report, captured.err, design, target


def expect_error(tmp_path, capsys, text: str, pattern: str) -> str:
    """The build fails with one line ``ruledmesh: error: case.toml: ...`` matching ``pattern``."""
    code, _, err, _, target = build(tmp_path, capsys, text)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert lines[0].startswith("ruledmesh: error: case.toml: "), lines[0]
    assert re.search(pattern, lines[0]), lines[0]
    assert not target.exists()
    assert not list(tmp_path.glob(".out.obj*")), "temporary file left behind"
    return lines[0]


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(V, m) distances of points ``p`` from the segments ``a_i b_i``."""
    d = b - a
    rel = p[:, None, :] - a[None, :, :]
    t = np.clip(np.einsum("vmk,mk->vm", rel, d) / np.einsum("mk,mk->m", d, d), 0.0, 1.0)
    return np.linalg.norm(rel - t[..., None] * d[None], axis=2)


def expect_mesh(tmp_path, capsys, text: str, *, on_generators: bool = True,
                kinds: set | None = None, warning: str | None = None):
    """The build succeeds and the written mesh passes the invariants: ``(mesh, report, built)``,
    ``built`` only ``on_generators`` (else None)."""
    code, report, err, design, target = build(tmp_path, capsys, text)
    assert code == 0, err
    assert "Traceback" not in err
    assert report["finite"] and report["planarity"]["max"] <= 1e-12
    assert report["planarity"]["above_tolerance"] == 0
    mesh = load(target)                              # what was written, read back
    assert mesh.n_faces == report["faces"] > 0
    assert np.all(np.isfinite(mesh.vertices))
    assert planarity(mesh).max() <= 1e-12
    assert not list(tmp_path.glob(".out.obj*"))
    # The generators as built (refinement may add some); a second build, so only when asked.
    built = build_file(design) if on_generators else None
    if built is not None:
        r = built.rulings
        dist = _point_segment_distance(mesh.vertices, np.asarray(r.a), np.asarray(r.b))
        assert dist.min(axis=1).max() <= 1e-9 * mesh.diagonal()
    if kinds is not None:
        assert set(report["kinds"]) <= kinds, report["kinds"]
    if warning is not None:
        assert any(warning in w for w in report["warnings"]), report["warnings"]
    return mesh, report, built


def _curve(name: str, body: str) -> str:
    return f"[curves.{name}]\n{body.strip()}\n"


# --------------------------------------------------------- torsal generators
def test_torsal_pair_pq_fills_the_strip_with_triangles(tmp_path, capsys):
    # generators 2 and 3 cross at a point (coplanar pair): a torsal generator
    # between them; the other pairs are skew with one twist sign on each side.
    lines = [((0, 0, 0), (0, 4, 1)), ((1, 0, 0.5), (1, 4, 0)), ((2, 0, 0), (2, 4, 1)),
             ((2.5, 0, 0.5), (1.5, 4, 0.5)), ((3.5, 0, 0), (3.5, 4, 1)),
             ((4.5, 0, 0.5), (4.5, 4, 0)), ((5.5, 0, 0), (5.5, 4, 1))]
    _mesh, report, _ = expect_mesh(tmp_path, capsys, _lines(lines) + "[mesh]\nrows = 6\n",
                                  warning="torsal strips")
    assert report["kinds"].get("fill", 0) > 0


def test_torsal_lines_hybrid_mesh_is_planar_and_conforming(tmp_path, capsys):
    text = (ROOT / "examples" / "hybrid-torsal-lines.toml").read_text()
    _mesh, report, _ = expect_mesh(tmp_path, capsys, text, on_generators=False)
    assert set(report["kinds"]) <= {"quad", "triangle"}


def test_cli_build_of_folded_lines_returns(tmp_path):
    # a real process: the build (and its report) must end, with exit code 0
    import subprocess
    import sys

    out = tmp_path / "h.obj"
    try:
        proc = subprocess.run([sys.executable, "-m", "ruledmesh.cli", "build",
                               str(ROOT / "examples" / "hybrid-torsal-lines.toml"), "-o", str(out)],
                              capture_output=True, text=True, timeout=30)
    except subprocess.TimeoutExpired:
        pytest.fail("ruledmesh build did not finish in 30 s")
    assert proc.returncode == 0 and out.exists(), proc.stderr


# ------------------------------------------------------- all-parallel (cylinder)
CYLINDER = (_curve("c1", 'type = "arc"\ncenter = [0, 0, 0]\nradius = 2\nnormal = [0, 0, 1]\n'
                   "start_angle = 0\nend_angle = 180")
            + _curve("c2", 'type = "arc"\ncenter = [0, 0, 5]\nradius = 2\nnormal = [0, 0, 1]\n'
                     "start_angle = 0\nend_angle = 180")
            + '[rulings]\nbetween = ["c1", "c2"]\ncount = 9\n')


def test_cylinder_pq_every_strip_is_a_prism_of_strip_quads(tmp_path, capsys):
    _mesh, report, _ = expect_mesh(tmp_path, capsys, CYLINDER, kinds={"strip"},
                                  warning="8 torsal strips")
    # each strip a planar rectangle between generators, divided like the rows (20 / 2)
    assert report["faces"] == 8 * 10
    assert abs(report["coverage"]["ratio"] - 1) < 0.02   # the polygonal cylinder vs the arc


def test_cylinder_hybrid(tmp_path, capsys):
    expect_mesh(tmp_path, capsys, CYLINDER + '[mesh]\nmethod = "hybrid"\ndivisions = 4\n',
                on_generators=False)


# ------------------------------------------------------ all through one point
CONE_AT_END = _lines([((0, 0, 0), (np.cos(p), np.sin(p), 1.0))
                      for p in np.linspace(0, np.pi, 6)])
CONE_THROUGH = _lines([((-np.cos(p), -np.sin(p), -1.0), (np.cos(p), np.sin(p), 1.0))
                       for p in np.linspace(0, np.pi * 0.9, 6)])


def test_cone_apex_at_the_ends_merges_the_apex(tmp_path, capsys):
    # Every strip is flat: its triangles pair into exactly planar strip quads where they fit.
    mesh, _report, _ = expect_mesh(tmp_path, capsys, CONE_AT_END, kinds={"fill", "strip"},
                                  warning="torsal strips")
    apex = np.flatnonzero(np.linalg.norm(mesh.vertices, axis=1) < 1e-12)
    assert len(apex) == 1                          # one apex vertex, no zero-area faces
    from ruledmesh.analysis import face_areas
    assert face_areas(mesh).min() > 0


def test_cone_apex_inside_every_generator(tmp_path, capsys):
    mesh, _report, _ = expect_mesh(tmp_path, capsys, CONE_THROUGH, kinds={"fill", "strip"},
                                  warning="torsal strips")
    from ruledmesh.analysis import face_areas
    assert face_areas(mesh).min() > 0


@pytest.mark.parametrize("shape", ["cylinder", "cone"])
def test_developables_hybrid(tmp_path, capsys, shape):
    text = CONE_THROUGH if shape == "cone" else CYLINDER
    expect_mesh(tmp_path, capsys, text + '[mesh]\nmethod = "hybrid"\n', on_generators=False)


# ------------------------------------------ coincident curves, zero-length lines
def test_coincident_director_curves(tmp_path, capsys):
    body = 'type = "polyline"\npoints = [[0, 0, 0], [1, 1, 0], [2, 0, 1]]'
    expect_error(tmp_path, capsys, _curve("c1", body) + _curve("c2", body)
                 + '[rulings]\nbetween = ["c1", "c2"]\ncount = 10\n',
                 r"generator 0 has zero length")


def test_curves_touching_at_one_end(tmp_path, capsys):
    expect_error(tmp_path, capsys,
                 _curve("c1", 'type = "line"\npoints = [[0, 0, 0], [4, 0, 0]]')
                 + _curve("c2", 'type = "line"\npoints = [[0, 0, 0], [4, 3, 2]]')
                 + '[rulings]\nbetween = ["c1", "c2"]\ncount = 5\n',
                 r"generator 0 has zero length: its ends coincide")


def test_zero_length_generator_in_lines(tmp_path, capsys):
    expect_error(tmp_path, capsys,
                 _lines([((0, 0, 0), (0, 1, 0)), ((1, 0, 0), (1, 0, 0)), ((2, 0, 0), (2, 1, 3))]),
                 r"generator 1 has zero length")


def test_repeated_line(tmp_path, capsys):
    expect_error(tmp_path, capsys,
                 _lines([((0, 0, 0), (0, 1, 0)), ((0, 0, 0), (0, 1, 0)), ((2, 0, 0), (2, 1, 3))]),
                 r"generators 0 and 1 are the same line")


# ------------------------------------------------ self-intersecting, closed
def test_self_intersecting_director_curve(tmp_path, capsys):
    text = (_curve("c1", 'type = "polyline"\npoints = [[0, 0, 0], [2, 2, 0], [2, 0, 0], [0, 2, 0]]')
            + _curve("c2", 'type = "line"\npoints = [[0, 0, 3], [2, 1, 4]]')
            + '[rulings]\nbetween = ["c1", "c2"]\ncount = 13\n[mesh]\nrows = 8\n')
    expect_mesh(tmp_path, capsys, text)


def test_closed_director_curves(tmp_path, capsys):
    # both polylines closed: the first and the last generator are the same line
    text = (_curve("c1", 'type = "polyline"\npoints = [[1, 0, 0], [0, 1, 0], [-1, 0, 0], '
                   "[0, -1, 0], [1, 0, 0]]")
            + _curve("c2", 'type = "polyline"\npoints = [[0, 1, 2], [-1, 0, 2], [0, -1, 2], '
                     "[1, 0, 2], [0, 1, 2]]")
            + '[rulings]\nbetween = ["c1", "c2"]\ncount = 17\n[mesh]\nrows = 8\n')
    _mesh, _report, built = expect_mesh(tmp_path, capsys, text)
    assert np.allclose(built.rulings.a[0], built.rulings.a[-1])


def test_closed_bspline_hybrid(tmp_path, capsys):
    ring = [[float(np.cos(p)), float(np.sin(p)), 0.0] for p in np.linspace(0, 2 * np.pi, 9)]
    top = [[x, y, 2.0 + 0.3 * x] for x, y, _ in ring]
    text = (_curve("c1", f'type = "bspline"\ndegree = 2\npoints = {ring}')
            + _curve("c2", f'type = "bspline"\ndegree = 2\npoints = {top}')
            + '[rulings]\nbetween = ["c1", "c2"]\ncount = 13\n[mesh]\nmethod = "hybrid"\n')
    expect_mesh(tmp_path, capsys, text, on_generators=False)


# ----------------------------------------- director plane, linear directrix
TWO_LINES = (_curve("c1", 'type = "line"\npoints = [[0, 0, 0], [10, 0, 0]]')
             + _curve("c2", 'type = "line"\npoints = [[0, 2, 4], [10, 3, 5]]'))


def test_director_plane_parallel_to_a_curve(tmp_path, capsys):
    expect_error(tmp_path, capsys, TWO_LINES + '[rulings]\nbetween = ["c1", "c2"]\n'
                 'distribution = "director-plane"\ndirector_plane = [0, 0, 1]\ncount = 10\n',
                 r"director-plane: c1 lies in a plane parallel to the director plane")


def test_director_plane_without_common_range(tmp_path, capsys):
    expect_error(tmp_path, capsys, TWO_LINES.replace("[0, 2, 4], [10, 3, 5]", "[20, 2, 4], [30, 3, 5]")
                 + '[rulings]\nbetween = ["c1", "c2"]\ndistribution = "director-plane"\n'
                 'director_plane = [1, 0, 0]\ncount = 10\n',
                 r"no plane n \. x = s meets both curves")


def test_linear_directrix_missing_a_curve(tmp_path, capsys):
    expect_error(tmp_path, capsys, TWO_LINES + '[rulings]\nbetween = ["c1", "c2"]\n'
                 'distribution = "linear-directrix"\n'
                 'directrix = [[100, 100, 100], [101, 100, 100]]\ncount = 10\n',
                 r"linear-directrix: the plane through the directrix d and a_0 \(generator 0\) "
                 r"does not meet c2")


def test_linear_directrix_through_c1(tmp_path, capsys):
    expect_error(tmp_path, capsys, TWO_LINES + '[rulings]\nbetween = ["c1", "c2"]\n'
                 'distribution = "linear-directrix"\n'
                 'directrix = [[5, 0, 0], [5, 1, 7]]\ncount = 10\n',
                 r"linear-directrix: ")


def test_linear_directrix_that_works(tmp_path, capsys):
    expect_mesh(tmp_path, capsys, TWO_LINES + '[rulings]\nbetween = ["c1", "c2"]\n'
                'distribution = "linear-directrix"\n'
                'directrix = [[5, 10, 0], [5, 10, 1]]\ncount = 9\n[mesh]\nrows = 6\n')


# ------------------------------------------------ several roots per plane
ZIGZAG = (_curve("c1", 'type = "polyline"\npoints = [[0, 0, 0], [4, 1, 0], [2, 2, 0.5], '
                 "[6, 3, 0]]")
          + _curve("c2", 'type = "line"\npoints = [[0, 0, 4], [6, 3, 5]]'))


def test_director_plane_with_several_roots_turns_back(tmp_path, capsys):
    # the planes x = s meet c1 up to three times for 2 < s < 4: the branch
    # followed from c1(0) turns back at x = 4 before the last plane
    expect_error(tmp_path, capsys, ZIGZAG + '[rulings]\nbetween = ["c1", "c2"]\n'
                 'distribution = "director-plane"\ndirector_plane = [1, 0, 0]\ncount = 10\n',
                 r"director-plane: the branch on c1 turns back .*generators? \d+( and \d+)? of 10")


def test_linear_directrix_with_several_roots_picks_one_branch(tmp_path, capsys):
    # a helix c2 around the directrix's direction: each plane through d cuts it
    # once per turn; the branch nearest c2(0) is followed
    text = (_curve("c1", 'type = "line"\npoints = [[-3, -1, 0], [-3, 1, 3]]')
            + _curve("c2", 'type = "helix"\ncenter = [0, 0, 0]\naxis = [0, 0, 1]\nradius = 1\n'
                     "pitch = 1\nturns = 2.5")
            + '[rulings]\nbetween = ["c1", "c2"]\ndistribution = "linear-directrix"\n'
            "directrix = [[0, 0, 0], [0, 0, 1]]\ncount = 9\n[mesh]\nrows = 6\n")
    code, _report, err, _design, _target = build(tmp_path, capsys, text)
    if code == 0:
        expect_mesh(tmp_path, capsys, text)
    else:
        assert code == 2 and len(err.strip().splitlines()) == 1 and "case.toml: " in err


# ------------------------------------------------------------ hops to infinity
def test_rows_through_infinity_are_dropped_not_emitted(tmp_path, capsys):
    # hyperbolic paraboloid z = x y: all generators parallel to the plane x = 0,
    # so the hops of a far-extended division run off towards infinity.  One mesh, not the
    # six of the checkerboard choice: each takes about 6 s (the passes on 44k faces).
    lines = [((x, 0.0, 0.0), (x, 1.0, x)) for x in np.linspace(-1, 1, 9)]
    mesh, _report, _ = expect_mesh(tmp_path, capsys,
                                   _lines(lines) + "[mesh]\nrows = 6\nextend = 500\n"
                                   "max_extend = 1000\ntrim = false\nrefine = false\n",
                                   on_generators=False)
    a = np.array([p for p, _ in lines])               # explicit lines are built as given
    b = np.array([q for _, q in lines])
    patch = np.linalg.norm(np.ptp(np.concatenate([a, b]), axis=0))
    assert np.abs(mesh.vertices).max() <= 1e3 * patch * 2


def test_hops_to_infinity_trimmed(tmp_path, capsys):
    # strongly varying twist: some rows pass through infinity between generators
    phi = np.concatenate([np.linspace(0, 1.2, 5), np.linspace(1.25, 3.0, 4)])
    lines = [((np.cos(p) - np.sin(p), np.sin(p) + np.cos(p), -1.0),
              (np.cos(p) + np.sin(p), np.sin(p) - np.cos(p), 1.0)) for p in phi]
    mesh, _report, _ = expect_mesh(tmp_path, capsys, _lines(lines)
                                  + "[mesh]\nrows = 10\nmax_extend = 1000\n")
    v = mesh.vertices                               # on the hyperboloid x^2 + y^2 - z^2 = 1
    assert np.abs(v[:, 0] ** 2 + v[:, 1] ** 2 - v[:, 2] ** 2 - 1).max() < 1e-9


# ------------------------------------------------------------------- scaling
def _scaled_skew(s: float, mesh: str = "rows = 10") -> str:
    pts1 = np.array([[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]], float) * s
    pts2 = np.array([[0, 2, 4], [3, 4, 5], [6, 3, 3], [10, 3, 4]], float) * s
    return (_curve("c1", f'type = "bspline"\ndegree = 3\npoints = {pts1.tolist()}')
            + _curve("c2", f'type = "polyline"\npoints = {pts2.tolist()}')
            + f'[rulings]\nbetween = ["c1", "c2"]\ncount = 15\n[mesh]\n{mesh}\n')


@pytest.mark.parametrize("method", ["pq", "hybrid"])
def test_results_scale_from_1e_minus_6_to_1e6(tmp_path, capsys, method):
    """Scaling by a power of two is exact in floating point, and every
    tolerance is relative: the mesh must be the same mesh, scaled, to the bit
    (through the OBJ file, which keeps 17 digits).  At 1e-6 and 1e6 exactly
    the inputs differ by rounding; the invariants and the relative figures
    must hold the same way."""
    table = "rows = 10" if method == "pq" else 'method = "hybrid"'
    results = {}
    for s in (2.0 ** -20, 1e-6, 1.0, 1e6, 2.0 ** 20):
        sub = tmp_path / f"s{s:g}"
        sub.mkdir()
        results[s] = expect_mesh(sub, capsys, _scaled_skew(s, table),
                                 on_generators=(method == "pq"))[:2]
    base, rep1 = results[1.0]
    for s in (2.0 ** -20, 2.0 ** 20):
        mesh, rep = results[s]
        assert rep["kinds"] == rep1["kinds"]
        assert np.array_equal(mesh.face_indices, base.face_indices)
        assert np.array_equal(mesh.vertices / s, base.vertices)
        assert rep["planarity"]["max"] == rep1["planarity"]["max"]
    for s in (1e-6, 1e6):
        mesh, rep = results[s]
        assert rep["planarity"]["max"] <= 1e-12        # relative: the same bound at every scale
        assert rep["coverage"]["ratio"] == pytest.approx(rep1["coverage"]["ratio"], abs=0.01)
        assert rep["closeness"]["vertices_max"] == pytest.approx(
            rep1["closeness"]["vertices_max"], abs=1e-9)
        assert mesh.diagonal() == pytest.approx(base.diagonal() * s, rel=1e-12)
        assert abs(mesh.n_faces - base.n_faces) <= 0.05 * base.n_faces


def test_pq_combinatorics_do_not_depend_on_rounding():
    # Regression: quad/fill decisions at the border flipped with rounding-level changes
    # of the generators (skew example x 3 or x 1e6: 37 vs 38 quads).
    from ruledmesh.design import build_design, parse_design
    from ruledmesh.pq import pq_mesh

    # The generators of the even division's refinement, as when this was found (the graded
    # division's rounds add others: 93 instead of 45, where one pair of border triangles
    # between four points of the polyline c2 is planar to 5e-13 at this scale and 1e-12 at
    # 1e6, either side of the exact pairing bar).
    r = build_design(parse_design(_scaled_skew(1.0, 'rows = 10\ndivision = "even"'))).rulings
    base = pq_mesh(r.a, r.b, rows=10)
    for s in (3.0, 1e6):
        assert pq_mesh(r.a * s, r.b * s, rows=10).count_kinds() == base.count_kinds()


# -------------------------------------------------------------- huge requests
TWO_SKEW = (_curve("c1", 'type = "line"\npoints = [[0, 0, 0], [10, 0, 0]]')
            + _curve("c2", 'type = "line"\npoints = [[0, 2, 4], [10, 3, 5]]'))


def test_a_million_generators_is_refused_up_front_with_the_memory(tmp_path, capsys):
    line = expect_error(tmp_path, capsys, TWO_SKEW + '[rulings]\nbetween = ["c1", "c2"]\n'
                        "count = 1000000\n",
                        r"rulings\.count: expected at most 100000 generators, got 1000000: "
                        r"meshing them would need about [\d.]+ GiB")
    gib = float(re.search(r"about ([\d.]+) GiB", line).group(1))
    assert 10 < gib < 40


def test_a_million_lines_from_a_file_are_refused(tmp_path, capsys):
    rows = np.zeros((100_001, 6))
    rows[:, 0] = rows[:, 3] = np.arange(len(rows))
    rows[:, 4] = 1
    rows[:, 5] = np.sin(np.arange(len(rows)))
    np.savetxt(tmp_path / "many.csv", rows, delimiter=",", fmt="%.6g")
    expect_error(tmp_path, capsys, '[rulings]\nfile = "many.csv"\n',
                 r"rulings\.file: expected at most 100000 lines \(rows\), got 100001")


def test_a_huge_grid_is_refused_before_it_is_built(tmp_path, capsys):
    expect_error(tmp_path, capsys, TWO_SKEW + '[rulings]\nbetween = ["c1", "c2"]\n'
                 "count = 500\n[mesh]\nrows = 100000\n",
                 r"mesh\.rows: 500 generators x 100001 rows would need about [\d.]+ GiB")


def test_json_report_of_a_cone_is_strict_json(tmp_path, capsys):
    # degenerate triangles at the apex must not put NaN or Infinity in the report
    design = tmp_path / "case.toml"
    design.write_text(CONE_AT_END)
    assert main(["build", str(design), "-o", str(tmp_path / "out.obj"), "--json"]) == 0

    def refuse(name):
        raise ValueError(f"{name} in the JSON report")

    json.loads(capsys.readouterr().out, parse_constant=refuse)


# Catalogue bugs found by tests/test_fuzz.py, fixed: each spine now meshes or is refused.
CANAL_BUGS = {
    "zero-length-arc-spine": '{type = "arc", center = [0, 0, 0], radius = 1, start = 1e-121, '
                             'end = 0, plane = "xy"}',
    "right-angle-spine": "[[0, 0, 1], [0, 0, 0], [0, 1, 0]]",
    "spine-doubling-back": "[[0, 0, 1], [0, 0, 0], [0, 0, 1]]",
}


@pytest.mark.parametrize("case", sorted(CANAL_BUGS))
def test_canal_degenerate_spines_mesh_or_refuse_cleanly(case):
    import warnings

    from ruledmesh.design import build_design, parse_design
    from ruledmesh.errors import RuledMeshError

    text = (f'[surface]\nkind = "canal"\nspine = {CANAL_BUGS[case]}\nradius = 1\n'
            "[mesh]\nu = 2\nv = 3\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            built = build_design(parse_design(text, "canal.toml"))
        except RuledMeshError:
            return
    assert np.all(np.isfinite(built.mesh.vertices))
    assert planarity(built.mesh).max() <= 1e-12


def test_pq_repeated_generator_does_not_warn():
    import warnings

    from ruledmesh.pq import pq_mesh

    a = np.array([[1, 0, 0], [0, 0, 1], [1, 0, 0]], float)
    b = np.array([[1, 1, 0], [0, 0, 0], [1, 1, 0]], float)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        mesh = pq_mesh(a, b, rows=1)
    assert np.all(np.isfinite(mesh.vertices))


def test_spline_with_a_cusp_meshes_without_warnings():
    # Regression (fuzz, CI): a degree-2 spline doubling back has zero speed at its cusp; the
    # arc-length correspondence divided by that speed.
    import warnings

    from ruledmesh.design import build_design, parse_design

    text = ('[curves.c1]\ntype = "line"\npoints = [[0, 0, 0], [0, 0, 1]]\n'
            '[curves.c2]\ntype = "bspline"\ndegree = 2\npoints = [[1, 0, 0], [0, 0, 0], [1, 0, 0]]\n'
            '[rulings]\nbetween = ["c1", "c2"]\ncount = 3\ndistribution = "arc-length"\n'
            '[mesh]\nmethod = "hybrid"\nmidpoints = 0\ndivisions = 1\n')
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        built = build_design(parse_design(text, "cusp.toml"))
    assert np.all(np.isfinite(built.mesh.vertices))
    assert planarity(built.mesh).max() <= 1e-12


def test_helicoid_with_a_vanishing_pitch_is_refused():
    # Regression (fuzz): pitch 2.2e-308 underflowed k^2 and gave 0 * inf = NaN in the area.
    from ruledmesh.design import build_design, parse_design
    from ruledmesh.errors import RuledMeshError

    text = ('[surface]\nkind = "helicoid"\nradius = 1.0\npitch = 2.2250738585072014e-308\n'
            'turns = 1.0\n[mesh]\nu = 3\nv = 3\n')
    # The design layer refuses such a number before the construction sees it.
    with pytest.raises(RuledMeshError, match=r"surface\.pitch: expected 0 or a number of magnitude"):
        build_design(parse_design(text, "helicoid.toml"))


def test_pq_border_snap_that_would_leave_no_face_is_not_taken():
    # Found by the fuzz at 10x its examples: five micrometre generators, 2 rows, no extension.
    # The snap of a corner onto the border removed every face around the end point, and its
    # measure indexed a vertex the merged mesh no longer had (IndexError).
    from ruledmesh.analysis.faces import convexity
    from ruledmesh.pq import pq_mesh

    a = np.array([[1e-6, 0, 0], [1e-6, 0, 2.5e-7], [1e-6, 0, 5e-7], [1e-6, 0, 7.5e-7], [1e-6, 0, 1e-6]])
    b = np.array([[1e-6, 1e-6, 1e-6], [1e-6, 1e-6, 1.25e-6], [1.075e-6, 1.5e-6, -5e-7],
                  [1.16875e-6, 1.75e-6, -1.25e-6], [1.3e-6, 2e-6, -2e-6]])
    mesh = pq_mesh(a, b, rows=2, option=0, trim=False, primary="middle", extend=0.0)
    assert mesh.n_faces > 0 and np.all(np.isfinite(mesh.vertices))
    assert planarity(mesh).max() <= 1e-12 and convexity(mesh).all()


def test_linear_directrix_with_a_flat_stretch_of_its_twist_builds():
    # Found by the fuzz at 10x its examples: the root search of a torsal band's partner met two
    # equal values of the twist and divided by zero in its inverse quadratic step (scipy's C
    # code gets inf there and bisects, as ours does now).
    import ruledmesh

    design = {"curves": {"c1": {"type": "line", "points": [[1.585402155435423, 1.7762939584031822e-236,
                                                              -3.3216671699380305], [7.0, 0.0, 0.0]]},
                         "c2": {"type": "line", "points": [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]}},
              "rulings": {"between": ["c1", "c2"], "count": 7, "distribution": "linear-directrix",
                          "directrix": [[0.0, 0.0, 0.0], [1.0, 0.0, 1.0]]},
              "mesh": {"method": "pq", "rows": 1, "option": 0, "trim": True}}
    mesh = ruledmesh.build(design)
    assert mesh.n_faces > 0 and planarity(mesh).max() <= 1e-12
