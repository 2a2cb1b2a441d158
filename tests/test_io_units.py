"""Units, up-axis, site coordinates and per-panel identity, read back by each
format's own library (ifcopenshell, rhino3dm, ezdxf, trimesh, pygltflib,
numpy-stl, Open3D, pymeshlab, meshio)."""

from __future__ import annotations

import csv
import io
import warnings
from pathlib import Path

import export_meshes as E  # a helper module of tests/ (see conftest.py)
import numpy as np
import pytest

from ruledmesh.cli import main
from ruledmesh.design import build_design, parse_design
from ruledmesh.errors import DesignError, ParameterError, RuledMeshWarning
from ruledmesh.fabricate.output import fabricate
from ruledmesh.io import load, save
from ruledmesh.mesh import FaceKind
from ruledmesh.triangulate import triangulate
from ruledmesh.units import Unit, conversion_factor

UNITS = ["m", "mm", "cm", "in", "ft"]
SITE = np.array([2.6e6, 1.2e6, 35.0])


def mixed(units="m"):
    return E.mixed().with_units(units, convert=False)


# ------------------------------------------------------------- the unit itself
def test_design_units_key_reaches_the_mesh():
    text = (Path(__file__).parents[1] / "examples" / "fig7a-hp-parabolas.toml").read_text()
    plain = build_design(parse_design(text)).mesh
    assert plain.units == "m"
    mm = build_design(parse_design('units = "mm"\n' + text)).mesh
    assert mm.units == "mm"
    np.testing.assert_array_equal(mm.vertices, plain.vertices)


def test_design_bad_units_names_the_key():
    with pytest.raises(DesignError, match=r'units: expected one of "m" \| "cm" \| "mm" \| "in" \| "ft"'):
        build_design(parse_design('units = "mtr"\n[surface]\nkind = "x"\n'))


def test_with_units_converts_and_relabels():
    m = mixed("ft")
    inch = m.with_units("in")
    np.testing.assert_allclose(inch.vertices, m.vertices * 12.0, rtol=1e-15)
    assert inch.units == "in"
    same = m.with_units("mm", convert=False)
    assert same.units == "mm" and same.vertices is m.vertices
    assert conversion_factor("mm", "m") == 0.001
    with pytest.raises(ParameterError, match="units"):
        m.with_units("yd")


# ------------------------------------------------------------- per format
@pytest.mark.parametrize("units", UNITS)
def test_ifc_unit_read_by_ifcopenshell(tmp_path, units):
    pytest.importorskip("ifcopenshell")
    import ifcopenshell
    import ifcopenshell.util.unit

    save(tmp_path / "m.ifc", mixed(units))
    model = ifcopenshell.open(str(tmp_path / "m.ifc"))
    assert ifcopenshell.util.unit.calculate_unit_scale(model) == pytest.approx(Unit(units).metres,
                                                                               rel=1e-12)
    (assignment,) = model.by_type("IfcUnitAssignment")
    (length,) = [u for u in assignment.Units if u.UnitType == "LENGTHUNIT"]
    if Unit(units).metric:
        assert length.is_a("IfcSIUnit") and length.Name == "METRE"
        assert length.Prefix == {"m": None, "cm": "CENTI", "mm": "MILLI"}[units]
    else:
        assert length.is_a("IfcConversionBasedUnit")


def test_ifc_metres_regression_not_milli(tmp_path):
    """IFC files said MILLI METRE while the coordinates were metres (1000x too small)."""
    pytest.importorskip("ifcopenshell")
    import ifcopenshell
    import ifcopenshell.util.unit

    save(tmp_path / "m.ifc", mixed())
    model = ifcopenshell.open(str(tmp_path / "m.ifc"))
    assert ifcopenshell.util.unit.calculate_unit_scale(model) == 1.0


@pytest.mark.parametrize("units", UNITS)
def test_3dm_unit_read_by_rhino3dm(tmp_path, units):
    r3 = pytest.importorskip("rhino3dm")
    save(tmp_path / "m.3dm", mixed(units))
    model = r3.File3dm.Read(str(tmp_path / "m.3dm"))
    want = {"m": r3.UnitSystem.Meters, "cm": r3.UnitSystem.Centimeters,
            "mm": r3.UnitSystem.Millimeters, "in": r3.UnitSystem.Inches,
            "ft": r3.UnitSystem.Feet}[units]
    assert model.Settings.ModelUnitSystem == want


@pytest.mark.parametrize("units", UNITS)
def test_dxf_unit_read_by_ezdxf(tmp_path, units):
    ezdxf = pytest.importorskip("ezdxf")
    save(tmp_path / "m.dxf", mixed(units))
    doc = ezdxf.readfile(tmp_path / "m.dxf")
    assert doc.header["$INSUNITS"] == {"m": 6, "cm": 5, "mm": 4, "in": 1, "ft": 2}[units]
    assert ezdxf.units.conversion_factor(doc.units, ezdxf.units.M) == pytest.approx(
        Unit(units).metres, rel=1e-9)
    assert doc.header["$MEASUREMENT"] == (1 if Unit(units).metric else 0)


@pytest.mark.parametrize("units", ["m", "mm", "ft"])
def test_text_formats_state_and_read_back_the_unit(tmp_path, units):
    mesh = mixed(units)
    for ext in (".obj", ".ply", ".json"):
        save(tmp_path / f"m{ext}", mesh)
        assert load(tmp_path / f"m{ext}").units == units
    assert f"# units: {units}\n" in (tmp_path / "m.obj").read_text()
    assert f"comment units {units}\n".encode() in (tmp_path / "m.ply").read_bytes()[:400]
    save(tmp_path / "m.stl", mesh)
    assert f"units={units}".encode() in (tmp_path / "m.stl").read_bytes()[:80]


@pytest.mark.parametrize("units", ["m", "mm", "in"])
def test_gltf_is_metres_by_trimesh(tmp_path, units):
    trimesh = pytest.importorskip("trimesh")
    mesh = mixed(units)
    save(tmp_path / "m.glb", mesh)
    scene = trimesh.load(tmp_path / "m.glb", force="scene")
    got = scene.to_mesh() if hasattr(scene, "to_mesh") else scene.dump(concatenate=True)
    extent = mesh.vertices.max(axis=0) - mesh.vertices.min(axis=0)
    want = Unit(units).metres * extent[[0, 2, 1]]  # Y-up: design z is glTF y
    np.testing.assert_allclose(got.extents, want, rtol=1e-6)


def test_cli_export_units_converts(tmp_path, capsys):
    pytest.importorskip("ifcopenshell")
    import ifcopenshell
    import ifcopenshell.util.unit

    save(tmp_path / "m.obj", mixed())
    assert main(["export", str(tmp_path / "m.obj"), "-o", str(tmp_path / "mm.obj"),
                 "--units", "mm"]) == 0
    back = load(tmp_path / "mm.obj")
    assert back.units == "mm"
    np.testing.assert_allclose(back.vertices, mixed().vertices * 1000.0, rtol=1e-15)
    assert main(["export", str(tmp_path / "mm.obj"), "-o", str(tmp_path / "m.ifc")]) == 0
    model = ifcopenshell.open(str(tmp_path / "m.ifc"))
    assert ifcopenshell.util.unit.calculate_unit_scale(model) == 0.001
    assert "units mm" in capsys.readouterr().out


# ------------------------------------------------------------- glTF up-axis, site
def test_gltf_y_up_read_by_pygltflib(tmp_path):
    pygltflib = pytest.importorskip("pygltflib")
    mesh = mixed()
    save(tmp_path / "m.glb", mesh)
    gltf = pygltflib.GLTF2().load(str(tmp_path / "m.glb"))
    acc = gltf.accessors[gltf.meshes[0].primitives[0].attributes.POSITION]
    t = np.array(gltf.nodes[0].translation)
    lo, hi = np.array(acc.min) + t, np.array(acc.max) + t
    quads = mesh.select_faces(mesh.face_kind == mesh.face_kind[0]).compact()
    vlo, vhi = quads.vertices.min(axis=0), quads.vertices.max(axis=0)
    # glTF +Y is the design's +Z, glTF +Z is the design's -Y.
    np.testing.assert_allclose(lo, [vlo[0], vlo[2], -vhi[1]], atol=1e-6)
    np.testing.assert_allclose(hi, [vhi[0], vhi[2], -vlo[1]], atol=1e-6)


def test_gltf_site_coordinates_within_a_millimetre(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    mesh = E.mixed()
    mesh = mesh.with_vertices(mesh.vertices - mesh.vertices.min(axis=0) + SITE)
    save(tmp_path / "site.glb", mesh)
    scene = trimesh.load(tmp_path / "site.glb", force="scene")
    # trimesh applies the node transforms (float64 translation) to the float32 positions.
    got = scene.to_mesh() if hasattr(scene, "to_mesh") else scene.dump(concatenate=True)
    from scipy.spatial import cKDTree

    want = np.stack([mesh.vertices[:, 0], mesh.vertices[:, 2], -mesh.vertices[:, 1]], axis=1)
    # Every vertex read (site corner included) lies within 1 mm of its design position.
    dist, _ = cKDTree(want).query(np.asarray(got.vertices, np.float64))
    assert dist.max() < 1e-3
    dist, _ = cKDTree(np.asarray(got.vertices, np.float64)).query(want)
    assert dist.max() < 1e-3


# ------------------------------------------------------------- STL origin
def test_stl_warns_at_site_coordinates_and_origin_keeps_them(tmp_path):
    stl_mesh = pytest.importorskip("stl.mesh")
    mesh = E.mixed()
    mesh = mesh.with_vertices(mesh.vertices + SITE)
    with pytest.warns(RuledMeshWarning, match="origin"):
        save(tmp_path / "lossy.stl", mesh)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuledMeshWarning)
        save(tmp_path / "site.stl", mesh, origin="auto")
    head = (tmp_path / "site.stl").read_bytes()[:80].decode()
    origin = np.array(head.split("origin=")[1].split()[0].split(","), dtype=float)
    got = stl_mesh.Mesh.from_file(str(tmp_path / "site.stl"))
    tri = triangulate(mesh)
    np.testing.assert_allclose(got.vectors.astype(np.float64) + origin,
                               mesh.vertices[tri.triangles], rtol=0, atol=1e-5)


def test_cli_stl_origin(tmp_path, capsys):
    mesh = E.mixed()
    save(tmp_path / "site.obj", mesh.with_vertices(mesh.vertices + SITE))
    assert main(["export", str(tmp_path / "site.obj"), "-o", str(tmp_path / "a.stl")]) == 0
    assert "warning: STL stores float32" in capsys.readouterr().err
    assert main(["export", str(tmp_path / "site.obj"), "-o", str(tmp_path / "b.stl"),
                 "--origin", "2600000,1200000,0"]) == 0
    assert "warning" not in capsys.readouterr().err
    assert main(["export", str(tmp_path / "site.obj"), "-o", str(tmp_path / "c.stl"),
                 "--origin", "1,2"]) == 2
    assert "--origin" in capsys.readouterr().err


# ------------------------------------------------------------- PLY readers
def _skew():
    from ruledmesh.design import build_file

    return build_file(Path(__file__).parents[1] / "examples" / "skew.toml").mesh


@pytest.fixture(scope="module")
def skew():
    return _skew()


def test_ply_header_lines_are_short(tmp_path, skew):
    for extras in ("file", "inline"):
        save(tmp_path / "m.ply", skew, extras=extras)
        for name in ("m.ply", "m.ruledmesh.ply"):
            data = (tmp_path / name).read_bytes() if (tmp_path / name).exists() else b"ply\nend_header\n"
            head = data[:data.index(b"end_header")]
            assert max(len(line) for line in head.split(b"\n")) < 200


@pytest.mark.parametrize("extras", ["file", "inline"])
def test_ply_read_by_open3d(tmp_path, skew, extras):
    o3d = pytest.importorskip("open3d")
    save(tmp_path / "m.ply", skew, extras=extras)
    tri = o3d.io.read_triangle_mesh(str(tmp_path / "m.ply"))
    np.testing.assert_array_equal(np.asarray(tri.vertices), skew.vertices)
    assert len(tri.triangles) == triangulate(skew).n_triangles
    lines_file = tmp_path / ("m.ply" if extras == "inline" else "m.ruledmesh.ply")
    lines = o3d.io.read_line_set(str(lines_file))
    np.testing.assert_array_equal(np.asarray(lines.lines), skew.members)
    np.testing.assert_array_equal(np.asarray(lines.points), skew.vertices)


@pytest.mark.parametrize("extras", ["file", "inline"])
def test_ply_read_by_pymeshlab(tmp_path, skew, extras):
    pymeshlab = pytest.importorskip("pymeshlab")
    save(tmp_path / "m.ply", skew, extras=extras)
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "m.ply"))
    got = ms.current_mesh()
    np.testing.assert_array_equal(got.vertex_matrix(), skew.vertices)
    assert got.face_number() == triangulate(skew).n_triangles
    assert got.edge_number() == (len(skew.members) if extras == "inline" else 0)


def test_ply_read_by_trimesh_and_meshio(tmp_path, skew):
    trimesh = pytest.importorskip("trimesh")
    meshio = pytest.importorskip("meshio")
    save(tmp_path / "m.ply", skew)
    got = meshio.read(tmp_path / "m.ply")
    assert sum(len(c.data) for c in got.cells) == skew.n_faces
    # trimesh's binary PLY reader takes one list length per file: an all-quad mesh.
    hp = E.hp_translational()
    save(tmp_path / "hp.ply", hp)
    t = trimesh.load(tmp_path / "hp.ply", process=False)
    np.testing.assert_array_equal(t.vertices, hp.vertices)
    assert len(t.faces) == 2 * hp.n_faces
    lines = trimesh.load(tmp_path / "hp.ruledmesh.ply", process=False)
    assert len(lines.vertices) == hp.n_vertices


def test_ply_round_trip_both_layouts(tmp_path, skew):
    for extras in ("file", "inline"):
        save(tmp_path / f"{extras}.ply", skew, extras=extras)
        back = load(tmp_path / f"{extras}.ply")
        np.testing.assert_array_equal(back.face_kind, skew.face_kind)
        np.testing.assert_array_equal(back.members, skew.members)
        np.testing.assert_array_equal(back.member_id, skew.member_id)


# ------------------------------------------------------------- per-panel identity
def _panel_labels(tmp_path, mesh):
    fabricate(mesh, tmp_path / "fab", dxf=False, hotwire=False, nesting="shelf")
    rows = list(csv.DictReader(io.StringIO((tmp_path / "fab" / "panels.csv").read_text())))
    return [r["label"] for r in rows], rows


def test_ifc_one_plate_per_panel(tmp_path):
    pytest.importorskip("ifcopenshell")
    import ifcopenshell
    import ifcopenshell.util.element as ue
    import ifcopenshell.validate

    mesh = E.mixed()
    save(tmp_path / "m.ifc", mesh)
    model = ifcopenshell.open(str(tmp_path / "m.ifc"))
    log = ifcopenshell.validate.json_logger()
    ifcopenshell.validate.validate(model, log, express_rules=True)
    assert log.statements == []
    plates = model.by_type("IfcPlate")
    assert len(plates) == mesh.n_faces
    labels, rows = _panel_labels(tmp_path, mesh)
    by_name = {p.Name: p for p in plates}
    assert sorted(by_name) == sorted(labels)
    for row in rows:
        plate = by_name[row["label"]]
        pset = ue.get_psets(plate)["ruledmesh_Panel"]
        f = pset["FaceIndex"]
        assert plate.Tag == row["label"] and pset["Kind"] == row["kind"]
        assert pset["Area"] == pytest.approx(float(row["area"]), rel=1e-9)
        assert pset["Planarity"] < 1e-9
        (faceset,) = plate.Representation.Representations[0].Items
        np.testing.assert_array_equal(np.array(faceset.Coordinates.CoordList),
                                      mesh.vertices[mesh.face(f)])
        assembly = ue.get_aggregate(plate)
        assert assembly.is_a("IfcElementAssembly") and assembly.Name == f"ruledmesh {row['kind']}"
        storey = ue.get_container(assembly)
        assert storey.is_a("IfcBuildingStorey")
        building = ue.get_aggregate(storey)
        site = ue.get_aggregate(building)
        assert building.is_a("IfcBuilding") and site.is_a("IfcSite")
        assert ue.get_aggregate(site).is_a("IfcProject")
    assert len(model.by_type("IfcElementAssembly")) == len(mesh.count_kinds())


def test_3dm_one_object_per_panel(tmp_path):
    r3 = pytest.importorskip("rhino3dm")
    mesh = E.mixed()
    save(tmp_path / "m.3dm", mesh)
    model = r3.File3dm.Read(str(tmp_path / "m.3dm"))
    layers = [layer.Name for layer in model.Layers]
    labels, rows = _panel_labels(tmp_path, mesh)
    objs = {o.Attributes.Name: o for o in model.Objects if isinstance(o.Geometry, r3.Mesh)}
    assert sorted(objs) == sorted(labels)
    for row in rows:
        obj = objs[row["label"]]
        f = int(obj.Attributes.GetUserString("ruledmesh.face"))
        assert layers[obj.Attributes.LayerIndex] == f"ruledmesh-{row['kind']}"
        assert float(obj.Attributes.GetUserString("ruledmesh.area")) == pytest.approx(
            float(row["area"]), rel=1e-9)
        assert float(obj.Attributes.GetUserString("ruledmesh.planarity")) < 1e-9
        geo = obj.Geometry
        pts = np.array([[p.X, p.Y, p.Z] for p in
                        (geo.Vertices.Point3dAt(i) for i in range(len(geo.Vertices)))])
        np.testing.assert_array_equal(pts, mesh.vertices[mesh.face(f)])
        assert len(geo.Faces) == (1 if mesh.valences[f] <= 4 else mesh.valences[f] - 2)
        assert FaceKind.from_label(row["kind"]) == FaceKind(int(mesh.face_kind[f]))


def test_panels_option_validated(tmp_path):
    pytest.importorskip("ifcopenshell")
    with pytest.raises(ParameterError, match="panels"):
        save(tmp_path / "m.ifc", E.mixed(), panels="some")
