"""The top-level API (ruledmesh.build/load/save/analyze/fabricate), python -m, --version."""

import importlib.metadata
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ruledmesh
from ruledmesh.cli import main

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def skew(skew_path):
    return ruledmesh.build(skew_path)


@pytest.mark.parametrize("ext", [".obj", ".ply", ".json"])
def test_round_trip_build_save_load_analyze(skew, tmp_path, ext, skew_path):
    path = ruledmesh.save(tmp_path / f"skew{ext}", skew)
    back = ruledmesh.load(path)
    assert back.count_kinds() == skew.count_kinds()
    np.testing.assert_allclose(back.vertices, skew.vertices, rtol=0, atol=1e-12 * skew.diagonal())
    assert np.array_equal(back.face_indices, skew.face_indices)
    report = ruledmesh.analyze(back, design=skew_path)
    assert report["planarity"]["max"] <= 1e-12
    assert report["closeness"]["vertices_max"] <= 1e-9
    assert abs(report["coverage"]["ratio"] - 1) < 0.02


def test_analyze_is_the_cli_json(skew, tmp_path, capsys, skew_path):
    obj = ruledmesh.save(tmp_path / "skew.obj", skew)
    assert main(["analyze", str(obj), "--design", str(skew_path), "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    cli.pop("file")
    api = ruledmesh.analyze(obj, design=str(skew_path))
    assert json.loads(json.dumps(api)) == cli
    assert main(["analyze", str(skew_path), "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    cli.pop("file")
    assert json.loads(json.dumps(ruledmesh.analyze(skew_path))) == cli
    # Without a design there is nothing to measure closeness against.
    assert "closeness" not in ruledmesh.analyze(skew)


def test_build_takes_path_text_and_dict_alike(skew, skew_path):
    import tomllib

    text = skew_path.read_text()
    for design in (str(skew_path), text, tomllib.loads(text), "examples/skew.toml"):
        mesh = ruledmesh.build(design)
        assert np.array_equal(mesh.vertices, skew.vertices)
        assert np.array_equal(mesh.face_kind, skew.face_kind)


def test_build_relative_file_of_text_resolves_against_base_dir():
    text = (ROOT / "examples" / "lines-file.toml").read_text()
    with pytest.raises(ruledmesh.DesignError):
        ruledmesh.build(text, base_dir=ROOT / "tests")  # the CSV is not there
    mesh = ruledmesh.build(text, base_dir=ROOT / "examples")
    assert mesh.count_kinds()["quad"] > 0


@pytest.mark.parametrize("design, field", [
    (42, "design"),
    ({"curvez": {}}, "curvez"),
    ("[rulings]\ncount = 'forty'\n", "rulings"),
    ("not toml = = 1\n", "TOML"),
])
def test_bad_designs_fail_with_one_clear_error(design, field):
    with pytest.raises(ruledmesh.RuledMeshError) as info:
        ruledmesh.build(design)
    assert field in str(info.value) and "\n" not in str(info.value)


def test_fabricate_from_a_design(tmp_path, skew, skew_path):
    summary = ruledmesh.fabricate(skew_path, tmp_path / "fab", dxf=False)
    assert summary["panels"]["count"] == skew.n_faces
    assert (tmp_path / "fab" / "summary.json").is_file()


@pytest.mark.parametrize("first", ["import ruledmesh.fabricate.output",
                                   "from ruledmesh.fabricate.output import fabricate",
                                   "import ruledmesh.fabricate"])
def test_fabricate_stays_the_function_after_importing_the_subpackage(first):
    # Regression: importing ruledmesh.fabricate.output replaced ruledmesh.fabricate (the
    # function) with the subpackage, and ruledmesh.fabricate(...) raised "module not callable".
    code = (f"{first}\nimport ruledmesh, ruledmesh.fabricate.unroll\n"
            "from ruledmesh.fabricate import unroll\n"
            "assert callable(ruledmesh.fabricate) and ruledmesh.fabricate is ruledmesh.api.fabricate\n"
            "assert callable(unroll)\n")
    run = subprocess.run([sys.executable, "-c", code], check=False, capture_output=True,
                         text=True, timeout=60)
    assert run.returncode == 0, run.stderr


def test_pq_and_hybrid_mesh_at_the_top_level():
    phi = np.linspace(0, 2, 13)
    a = np.stack([np.cos(phi) - np.sin(phi), np.sin(phi) + np.cos(phi), -np.ones(13)], 1)
    b = np.stack([np.cos(phi) + np.sin(phi), np.sin(phi) - np.cos(phi), np.ones(13)], 1)
    mesh = ruledmesh.pq_mesh(a, b, rows=8)
    from ruledmesh.pq import pq_mesh

    assert ruledmesh.pq_mesh is pq_mesh
    x, y, z = mesh.vertices.T
    assert np.abs(x**2 + y**2 - z**2 - 1).max() < 1e-12
    assert ruledmesh.planarity(mesh).max() < 1e-12
    hybrid = ruledmesh.hybrid_mesh(a, b, divisions=4)
    assert hybrid.count_kinds()["quad"] > 0
    with pytest.raises(AttributeError):
        ruledmesh.no_such_name  # noqa: B018
    assert set(ruledmesh.__all__) <= set(dir(ruledmesh))


def test_version_in_one_place(capsys):
    assert ruledmesh.__version__ == importlib.metadata.version("ruledmesh")
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.strip() == f"ruledmesh {ruledmesh.__version__}"


def test_python_m_ruledmesh_is_the_cli(tmp_path):
    run = subprocess.run([sys.executable, "-m", "ruledmesh", "--help"], check=False, capture_output=True,
                         text=True, cwd=tmp_path, timeout=60)
    assert run.returncode == 0 and "ruledmesh build examples/skew.toml" in run.stdout
    run = subprocess.run([sys.executable, "-m", "ruledmesh", "--version"], check=False, capture_output=True,
                         text=True, cwd=tmp_path, timeout=60)
    assert run.returncode == 0 and run.stdout.strip() == f"ruledmesh {ruledmesh.__version__}"
    run = subprocess.run([sys.executable, "-m", "ruledmesh", "build", "nothing.toml", "-o", "x.obj"],
                         check=False, capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert run.returncode == 2 and "Traceback" not in run.stderr and not (tmp_path / "x.obj").exists()


def test_jupyter_view_is_wellformed_html_with_one_path_per_face(skew):
    import xml.etree.ElementTree as ET

    from ruledmesh.notebook import MAX_DRAWN_FACES

    view = ET.fromstring(skew._repr_html_())  # well-formed: parses as XML
    svg = view.find("{http://www.w3.org/2000/svg}svg")
    paths = svg.findall("{http://www.w3.org/2000/svg}path")
    assert len(paths) == skew.n_faces
    assert f"{skew.count_kinds()['quad']} quad" in "".join(view.itertext())
    phi = np.linspace(0, 2, 201)
    a = np.stack([np.cos(phi) - np.sin(phi), np.sin(phi) + np.cos(phi), -np.ones(201)], 1)
    b = np.stack([np.cos(phi) + np.sin(phi), np.sin(phi) - np.cos(phi), np.ones(201)], 1)
    big = ruledmesh.pq_mesh(a, b, rows=250)
    assert big.n_faces > MAX_DRAWN_FACES
    assert "<svg" not in big._repr_html_() and "not drawn" in big._repr_html_()

