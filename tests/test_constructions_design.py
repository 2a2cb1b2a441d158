"""Catalogue kinds through design files and the CLI, read back with meshio.

Each example is built with ``ruledmesh build`` to OBJ and read by meshio (an
independent reader); the invariants of its kind are checked on what meshio
returns.  The names the design reference fixes (helicoid, hyperboloid styles,
hyperbolic-paraboloid styles, ellipsoid axes, torus R/r, [mesh] u/v,
inversion) are built exactly as written there, with Hypothesis over the values.
"""

from __future__ import annotations

import json
import pathlib

import _catalogue_checks as chk  # a helper module of tests/ (see conftest.py)
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

meshio = pytest.importorskip("meshio")

from ruledmesh.cli import main  # noqa: E402
from ruledmesh.design import build_design, parse_design  # noqa: E402
from ruledmesh.errors import DesignError  # noqa: E402

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"
FAST = settings(max_examples=10, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture])

CIRCULAR = {"fig4a-generalised-moulding", "fig4b-pipe", "fig4c-canal", "fig5b-torus",
            "fig5c-torus-inversion", "fig5c-dupin-cyclide", "fig7b-hyperboloid-circular",
            "fig7c-hyperboloid-generators", "sec2-rotational"}
PARALLELOGRAMS = {"fig3b-strips-congruent", "fig6a-prism", "fig7a-hp-parabolas",
                  "fig7c-hp-generators", "fig8-helicoid", "sec2-translational"}
CATALOGUE = sorted(p for p in EXAMPLES.glob("*.toml")
                   if p.name.startswith(("fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "sec2-")))


def read_back(path):
    m = meshio.read(path)
    faces = [list(row) for block in m.cells for row in block.data
             if block.type in ("triangle", "quad", "polygon") or block.type.startswith("polygon")]
    return m.points, faces


def build_cli(tmp_path, text_or_path, name="design"):
    if isinstance(text_or_path, pathlib.Path):
        design = text_or_path
    else:
        design = tmp_path / f"{name}.toml"
        design.write_text(text_or_path)
    out = tmp_path / f"{design.stem}.obj"
    assert main(["build", str(design), "-o", str(out), "-q"]) == 0
    return read_back(out)


def check_planar(points, faces):
    q = chk.quads_of(points, faces)
    assert len(q) + sum(len(f) != 4 for f in faces) == len(faces) > 0
    if len(q):
        assert chk.planarity(q).max() <= 1e-12
    for p in chk.polygons_of(points, faces):
        assert chk.polygon_planarity(p) <= 1e-12


@pytest.mark.parametrize("path", CATALOGUE, ids=lambda p: p.stem)
def test_example_builds_and_keeps_its_invariant(tmp_path, path):
    points, faces = build_cli(tmp_path, path)
    check_planar(points, faces)
    q = chk.quads_of(points, faces)
    if path.stem in CIRCULAR:
        assert chk.circularity(q).max() <= 1e-10
    if path.stem in PARALLELOGRAMS:
        assert chk.parallelogram(q).max() <= 1e-12


@pytest.mark.parametrize("path", CATALOGUE, ids=lambda p: p.stem)
def test_example_analysis_reports_closeness_where_analytic(path, capsys):
    assert main(["analyze", str(path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["planarity"]["above_tolerance"] == 0
    if "closeness" in report and path.stem not in ("fig4b-pipe",):
        assert report["closeness"]["vertices_max"] <= 1e-10
    if path.stem in CIRCULAR:
        assert report["circularity"]["circular"] is True
    if path.stem in PARALLELOGRAMS:
        assert report["parallelogram"]["all_quads"] is True


ANALYTIC = {
    "helicoid", "hyperboloid", "hyperbolic-paraboloid", "ellipsoid", "torus", "rotational",
    "translational", "hyperboloid-two-sheets", "elliptic-paraboloid", "dupin-cyclide", "pipe",
}


def test_every_analytic_example_has_a_reference():
    for path in CATALOGUE:
        built = build_design(parse_design(path.read_text(), path.name))
        kind = parse_design(path.read_text()).data["surface"]["kind"]
        if kind in ANALYTIC and "transform" not in parse_design(path.read_text()).data:
            assert built.reference is not None, path.name


# ----------------------------- the names the design reference fixes, via the CLI
@FAST
@given(radius=st.floats(0.5, 4), pitch=st.floats(0.5, 6), turns=st.floats(0.5, 2),
       u=st.integers(8, 40), v=st.integers(8, 40))
def test_helicoid_design(tmp_path, radius, pitch, turns, u, v):
    points, faces = build_cli(tmp_path, f"""
[surface]
kind = "helicoid"
radius = {radius!r}
pitch = {pitch!r}
turns = {turns!r}
[mesh]
u = {u}
v = {v}
""")
    check_planar(points, faces)
    assert chk.parallelogram(chk.quads_of(points, faces)).max() <= 1e-12
    k = pitch / (2 * np.pi)
    x, y, z = points.T
    f = x * np.sin(z / k) - y * np.cos(z / k)
    grad = np.sqrt(1 + ((x * np.cos(z / k) + y * np.sin(z / k)) / k) ** 2)
    assert (np.abs(f) / grad).max() <= 1e-10 * chk.diagonal(points)
    assert np.hypot(x, y).max() <= radius * (1 + 1e-12)


@FAST
@given(a=st.floats(0.5, 3), c=st.floats(0.5, 3), height=st.floats(0.5, 4),
       style=st.sampled_from(["circular", "generators"]), u=st.integers(8, 48),
       v=st.integers(2, 20))
def test_hyperboloid_design(tmp_path, a, c, height, style, u, v):
    text = f"""
[surface]
kind = "hyperboloid"
a = {a!r}
c = {c!r}
height = {height!r}
style = "{style}"
[mesh]
u = {u}
v = {v}
"""
    if style == "generators" and c * np.tan(2 * np.pi / u) > height:
        with pytest.raises(DesignError, match="height"):
            build_design(parse_design(text))
        return
    points, faces = build_cli(tmp_path, text)
    check_planar(points, faces)
    q = chk.quads_of(points, faces)
    assert chk.circularity(q).max() <= 1e-10
    x, y, z = points.T
    f = (x * x + y * y) / a ** 2 - z * z / c ** 2 - 1
    grad = 2 * np.sqrt((x * x + y * y) / a ** 4 + z * z / c ** 4)
    assert (np.abs(f) / grad).max() <= 1e-10 * chk.diagonal(points)
    assert np.abs(z).max() <= height * (1 + 1e-12)


@FAST
@given(a=st.floats(0.5, 3), b=st.floats(0.5, 3), size=st.floats(0.5, 4),
       style=st.sampled_from(["parabolas", "generators"]), u=st.integers(3, 20),
       v=st.integers(3, 20))
def test_hyperbolic_paraboloid_design(tmp_path, a, b, size, style, u, v):
    points, faces = build_cli(tmp_path, f"""
[surface]
kind = "hyperbolic-paraboloid"
a = {a!r}
b = {b!r}
size = {size!r}
style = "{style}"
[mesh]
u = {u}
v = {v}
""")
    check_planar(points, faces)
    assert chk.parallelogram(chk.quads_of(points, faces)).max() <= 1e-12
    x, y, z = points.T
    f = x * x / a ** 2 - y * y / b ** 2 - z
    grad = np.sqrt(1 + 4 * x * x / a ** 4 + 4 * y * y / b ** 4)
    assert (np.abs(f) / grad).max() <= 1e-10 * chk.diagonal(points)
    assert np.abs(points[:, :2]).max() <= size * (1 + 1e-12)


@FAST
@given(axes=st.tuples(st.floats(0.5, 4), st.floats(0.5, 4), st.floats(0.5, 4)),
       u=st.integers(3, 40), v=st.integers(2, 20))
def test_ellipsoid_design(tmp_path, axes, u, v):
    a, b, c = axes
    points, faces = build_cli(tmp_path, f"""
[surface]
kind = "ellipsoid"
axes = [{a!r}, {b!r}, {c!r}]
[mesh]
u = {u}
v = {v}
""")
    check_planar(points, faces)
    w = np.array([1 / a ** 2, 1 / b ** 2, 1 / c ** 2])
    f = (points ** 2) @ w - 1
    grad = 2 * np.linalg.norm(points * w, axis=1)
    assert (np.abs(f) / grad).max() <= 1e-10 * chk.diagonal(points)


@FAST
@given(R=st.floats(2, 5), frac=st.floats(0.1, 0.8), u=st.integers(3, 40), v=st.integers(3, 30),
       center=st.tuples(st.floats(-2, 2), st.floats(-2, 2), st.floats(2.5, 6)),
       radius=st.floats(1, 8), invert=st.booleans())
def test_torus_design_and_inversion(tmp_path, R, frac, u, v, center, radius, invert):
    r = frac * R
    text = f"""
[surface]
kind = "torus"
R = {R!r}
r = {r!r}
[mesh]
u = {u}
v = {v}
"""
    if invert:
        text += f"""
[[transform]]
type = "inversion"
center = [{center[0]!r}, {center[1]!r}, {center[2]!r}]
radius = {radius!r}
"""
    points, faces = build_cli(tmp_path, text)
    check_planar(points, faces)
    assert chk.circularity(chk.quads_of(points, faces)).max() <= 1e-10
    if invert:
        c = np.asarray(center)
        rel = points - c
        points = c + radius ** 2 * rel / np.einsum("ij,ij->i", rel, rel)[:, None]
    rho = np.hypot(points[:, 0], points[:, 1])
    assert np.abs(np.hypot(rho - R, points[:, 2]) - r).max() <= 1e-10 * chk.diagonal(points)


def test_inversion_of_a_non_circular_mesh_is_refused(tmp_path, capsys):
    design = tmp_path / "hp.toml"
    design.write_text("""
[surface]
kind = "hyperbolic-paraboloid"
a = 1.0
b = 1.5
size = 2.0
style = "parabolas"

[[transform]]
type = "inversion"
center = [0.5, 0.3, 4.0]
radius = 5.0
""")
    out = tmp_path / "hp.obj"
    assert main(["build", str(design), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "transform[0]" in err and "circular" in err
    assert not out.exists()


@pytest.mark.parametrize("text, field", [
    ('[surface]\nkind = "torus"\nR = 1.0\nr = 2.0\n', "surface.r"),
    ('[surface]\nkind = "ellipsoid"\naxes = [1.0, 2.0]\n', "surface.axes"),
    ('[surface]\nkind = "hyperboloid"\nstyle = "generator"\n', "surface.style"),
    ('[surface]\nkind = "helicoid"\nradius = 1.0\nradis = 2.0\n', "surface.radis"),
    ('[surface]\nkind = "torus"\nR = 3.0\nr = 1.0\n[mesh]\nu = 2\n', "mesh.u"),
    ('[surface]\nkind = "torus"\nR = 3.0\nr = 1.0\n[mesh]\nw = 2\n', "mesh.w"),
    ('[surface]\nkind = "torus"\nR = 3.0\nr = 1.0\n[[transform]]\ntype = "inversion"\n'
     'center = [0, 0]\nradius = 1.0\n', "transform[0].center"),
])
def test_design_errors_name_the_field(text, field):
    with pytest.raises(DesignError) as info:
        build_design(parse_design(text, "bad.toml"))
    assert f"bad.toml: {field}:" in str(info.value)
