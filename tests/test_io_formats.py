"""Every export format read back by a reader someone else wrote: face counts
and vertex positions match the source within the format's precision."""

from __future__ import annotations

import json

import export_meshes as E  # a helper module of tests/ (see conftest.py)
import numpy as np
import pytest

from ruledmesh.cli import main
from ruledmesh.errors import ExportError, RuledMeshWarning
from ruledmesh.io import READERS, WRITERS, formats, load, save
from ruledmesh.mesh import FaceKind
from ruledmesh.triangulate import recover_polygons, triangulate

MESHES = E.all_meshes()
NAMES = list(MESHES)


def f32_tol(mesh):
    """Absolute float32 rounding bound for absolute coordinates of ``mesh``."""
    return 2.0 ** -23 * float(np.abs(mesh.vertices).max()) * 2


def test_registry_lists_every_format():
    assert {".obj", ".ply", ".stl", ".glb", ".dxf", ".3dm", ".ifc", ".json"} <= set(formats())
    assert ".json" in READERS
    for ext in WRITERS:
        assert ext.startswith(".")


# ---------------------------------------------------------------- STL
@pytest.mark.parametrize("name", NAMES)
def test_stl_numpy_stl_and_meshio(tmp_path, name):
    stl_mesh = pytest.importorskip("stl.mesh")
    meshio = pytest.importorskip("meshio")
    mesh = MESHES[name]
    if name == "far":  # STL's float32 rounds these coordinates: the writer says so
        with pytest.warns(RuledMeshWarning, match="STL stores float32"):
            save(tmp_path / "m.stl", mesh)
    else:
        save(tmp_path / "m.stl", mesh)
    tri = triangulate(mesh)
    # calculate_normals=False: keep the normals stored in the file.
    got = stl_mesh.Mesh.from_file(str(tmp_path / "m.stl"), calculate_normals=False)
    assert len(got.vectors) == tri.n_triangles
    np.testing.assert_allclose(got.vectors, mesh.vertices[tri.triangles], rtol=0, atol=f32_tol(mesh))
    np.testing.assert_array_equal(got.attr.reshape(-1), mesh.face_kind[tri.face_of])
    # Stored normals are the faces' unit normals, turning like the triangles.
    n = got.normals.astype(np.float64)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-6)
    if f32_tol(mesh) < 1e-6 * mesh.diagonal():
        # (Far from the origin float32 rounds small faces flat: STL's limit.)
        v = got.vectors.astype(np.float64)
        cross = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
        assert np.all(np.einsum("ij,ij->i", cross, n) > 0)
    m2 = meshio.read(tmp_path / "m.stl")
    assert sum(len(c.data) for c in m2.cells if c.type == "triangle") == tri.n_triangles


def test_stl_polygons_recoverable_from_triangle_order(tmp_path):
    """Face f gives valence(f) - 2 consecutive triangles: with the valences the
    polygons come back from the STL alone."""
    stl_mesh = pytest.importorskip("stl.mesh")
    mesh = MESHES["mixed"]
    save(tmp_path / "m.stl", mesh)
    tris = stl_mesh.Mesh.from_file(str(tmp_path / "m.stl")).vectors.reshape(-1, 3)
    _, index = np.unique(tris, axis=0, return_inverse=True)
    face_of = np.repeat(np.arange(mesh.n_faces), mesh.valences - 2)
    off, idx = recover_polygons(index.reshape(-1, 3), face_of)
    np.testing.assert_array_equal(off, mesh.face_offsets)
    uniq = np.unique(tris, axis=0)
    for f in range(mesh.n_faces):
        got = uniq[idx[off[f]:off[f + 1]]]
        want = mesh.vertices[mesh.face(f)].astype(np.float32)
        shift = int(np.flatnonzero((want == got[0]).all(axis=1))[0])
        np.testing.assert_array_equal(np.roll(want, -shift, axis=0), got)


# ---------------------------------------------------------------- OBJ / PLY via meshio
@pytest.mark.parametrize("name", NAMES)
def test_obj_read_by_meshio(tmp_path, name):
    meshio = pytest.importorskip("meshio")
    mesh = MESHES[name]
    save(tmp_path / "m.obj", mesh)
    got = meshio.read(tmp_path / "m.obj")
    np.testing.assert_array_equal(got.points, mesh.vertices)
    faces = [row for c in got.cells if c.type != "line" for row in c.data.tolist()]
    assert faces == mesh.face_list()
    # meshio 5.3 skips OBJ ``l`` statements; the members are checked in the text.
    text = (tmp_path / "m.obj").read_text()
    lines = [list(map(int, ln.split()[1:])) for ln in text.splitlines() if ln.startswith("l ")]
    np.testing.assert_array_equal(np.array(lines) - 1, mesh.members)


# The PLY file keeps to the vertex and face elements every reader knows; face kinds
# and members travel in the companion file, so meshio reads faces and vertices exactly.
def test_ply_read_by_meshio(tmp_path):
    meshio = pytest.importorskip("meshio")
    mesh = MESHES["mixed"]
    save(tmp_path / "m.ply", mesh)
    got = meshio.read(tmp_path / "m.ply")
    np.testing.assert_array_equal(got.points, mesh.vertices)
    assert sum(len(c.data) for c in got.cells) == mesh.n_faces
    faces = sorted(tuple(f) for c in got.cells for f in c.data.tolist())
    assert faces == sorted(tuple(f) for f in mesh.face_list())


def test_ply_keeps_kinds_and_members_for_ruledmesh(tmp_path):
    mesh = MESHES["mixed"]
    save(tmp_path / "m.ply", mesh)
    back = load(tmp_path / "m.ply")
    np.testing.assert_array_equal(back.face_kind, mesh.face_kind)
    np.testing.assert_array_equal(back.members, mesh.members)
    np.testing.assert_array_equal(back.member_id, mesh.member_id)


# ---------------------------------------------------------------- DXF
@pytest.mark.parametrize("name", NAMES)
def test_dxf_audit_and_read_back_with_ezdxf(tmp_path, name):
    ezdxf = pytest.importorskip("ezdxf")
    mesh = MESHES[name]
    save(tmp_path / "m.dxf", mesh)
    doc = ezdxf.readfile(tmp_path / "m.dxf")
    auditor = doc.audit()
    assert not auditor.has_errors, [e.message for e in auditor.errors]
    msp = doc.modelspace()
    for kind in np.unique(mesh.face_kind).tolist():
        kind = FaceKind(kind)
        (entity,) = msp.query(f'MESH[layer=="ruledmesh-{kind.label}"]')
        sub = mesh.select_faces(mesh.face_kind == kind)
        verts = np.array(entity.vertices)
        got = [verts[list(f)] for f in entity.faces]
        want = [mesh.vertices[f] for f in sub.face_list()]
        assert len(got) == len(want)
        for g, w in zip(got, want):
            np.testing.assert_array_equal(g, w)  # DXF keeps full double precision
    lines = msp.query('LINE[layer=="generators"]')
    assert len(lines) == len(mesh.members)
    ends = np.array([[ln.dxf.start, ln.dxf.end] for ln in lines])
    np.testing.assert_array_equal(ends, mesh.vertices[mesh.members])
    ids = [ln.get_xdata("RULEDMESH")[0].value for ln in lines]
    assert ids == mesh.member_id.tolist()


# ---------------------------------------------------------------- 3DM
@pytest.mark.parametrize("name", NAMES)
def test_3dm_read_back_with_rhino3dm(tmp_path, name):
    r3 = pytest.importorskip("rhino3dm")
    mesh = MESHES[name]
    save(tmp_path / "m.3dm", mesh, panels="joined")
    model = r3.File3dm.Read(str(tmp_path / "m.3dm"))
    layers = [layer.Name for layer in model.Layers]
    meshes = {}
    curves = []
    for obj in model.Objects:
        geo = obj.Geometry
        layer = layers[obj.Attributes.LayerIndex]
        if isinstance(geo, r3.Mesh):
            meshes[layer] = geo
        else:
            curves.append((geo, obj.Attributes.GetUserString("generator")))
    for kind in np.unique(mesh.face_kind).tolist():
        kind = FaceKind(kind)
        geo = meshes[f"ruledmesh-{kind.label}"]
        sub_ids = np.flatnonzero(mesh.face_kind == kind)
        val = mesh.valences[sub_ids]
        # Quads are kept as quads; triangles stay; bigger faces are split.
        assert geo.Faces.QuadCount == int(np.count_nonzero(val == 4))
        assert geo.Faces.TriangleCount == int((val[val != 4] - 2).sum())
        face_of = np.array(geo.GetUserString("ruledmesh.face_of").split(","), dtype=np.int64)
        assert sorted(set(face_of.tolist())) == sub_ids.tolist()
        pts = np.array([[p.X, p.Y, p.Z] for p in
                        (geo.Vertices.Point3dAt(i) for i in range(len(geo.Vertices)))])
        for g in range(len(geo.Faces)):
            a, b, c, d = geo.Faces[g]
            corners = pts[[a, b, c] if c == d else [a, b, c, d]]
            face = mesh.vertices[mesh.face(int(face_of[g]))]
            # Every Rhino face corner is a corner of its source face, exactly (doubles).
            assert all(np.any(np.all(face == p, axis=1)) for p in corners)
            if c != d:
                np.testing.assert_array_equal(corners, face)
    assert len(curves) == len(mesh.members)
    ends = np.array([[[c.PointAtStart.X, c.PointAtStart.Y, c.PointAtStart.Z],
                      [c.PointAtEnd.X, c.PointAtEnd.Y, c.PointAtEnd.Z]] for c, _ in curves])
    np.testing.assert_array_equal(ends, mesh.vertices[mesh.members])
    assert [int(g) for _, g in curves] == mesh.member_id.tolist()


# ---------------------------------------------------------------- IFC
@pytest.mark.parametrize("name", ["mixed", "far"])
def test_ifc_read_back_and_valid(tmp_path, name):
    pytest.importorskip("ifcopenshell")
    import ifcopenshell.validate

    mesh = MESHES[name]
    save(tmp_path / "m.ifc", mesh, panels="joined")
    model = ifcopenshell.open(str(tmp_path / "m.ifc"))
    assert model.schema == "IFC4"
    log = ifcopenshell.validate.json_logger()
    ifcopenshell.validate.validate(model, log, express_rules=True)
    assert log.statements == []
    plates = {p.Name: p for p in model.by_type("IfcPlate")}
    for kind in np.unique(mesh.face_kind).tolist():
        kind = FaceKind(kind)
        (rep,) = plates[f"ruledmesh {kind.label}"].Representation.Representations
        (faceset,) = rep.Items
        coords = np.array(faceset.Coordinates.CoordList)
        sub = mesh.select_faces(mesh.face_kind == kind)
        got = [coords[np.array(f.CoordIndex) - 1] for f in faceset.Faces]
        want = [mesh.vertices[f] for f in sub.face_list()]
        assert len(got) == len(want)
        for g, w in zip(got, want):
            np.testing.assert_allclose(g, w, rtol=1e-15, atol=0)
    (member,) = model.by_type("IfcMember")
    (rep,) = member.Representation.Representations
    lines = rep.Items[0].Elements
    ends = np.array([[p.Coordinates for p in ln.Points] for ln in lines])
    np.testing.assert_allclose(ends, mesh.vertices[mesh.members], rtol=1e-15, atol=0)


# ---------------------------------------------------------------- JSON
@pytest.mark.parametrize("name", NAMES)
def test_json_schema_and_exact_round_trip(tmp_path, name):
    jsonschema = pytest.importorskip("jsonschema")
    from ruledmesh.io.json_mesh import SCHEMA

    mesh = MESHES[name]
    save(tmp_path / "m.json", mesh)
    doc = json.loads((tmp_path / "m.json").read_text())
    jsonschema.validate(doc, SCHEMA)
    assert doc["faces"] == mesh.face_list()
    np.testing.assert_array_equal(np.array(doc["vertices"]), mesh.vertices)  # exact
    assert doc["kinds"] == [FaceKind(k).label for k in mesh.face_kind.tolist()]
    back = load(tmp_path / "m.json")
    np.testing.assert_array_equal(back.vertices, mesh.vertices)
    np.testing.assert_array_equal(back.face_offsets, mesh.face_offsets)
    np.testing.assert_array_equal(back.face_indices, mesh.face_indices)
    np.testing.assert_array_equal(back.face_kind, mesh.face_kind)
    np.testing.assert_array_equal(back.members, mesh.members)
    np.testing.assert_array_equal(back.member_id, mesh.member_id)


def test_json_reader_names_the_bad_field(tmp_path):
    from ruledmesh.errors import ParameterError

    doc = json.loads((save(tmp_path / "m.json", MESHES["hp"])).read_text())
    doc["kinds"][3] = "hexagon"
    (tmp_path / "bad.json").write_text(json.dumps(doc))
    with pytest.raises(ParameterError, match=r"json\.kinds"):
        load(tmp_path / "bad.json")


def test_design_json():
    from ruledmesh.io.json_mesh import DESIGN_FORMAT, dump_design

    design = {"name": "tower", "surface": {"kind": "hyperboloid", "a": 1.0}, "mesh": {"m": 24}}
    doc = json.loads(dump_design(design, source="tower.toml"))
    assert doc["format"] == DESIGN_FORMAT and doc["design"] == design


# ---------------------------------------------------------------- save / CLI
def test_refuses_nan_and_leaves_no_file(tmp_path):
    bad = MESHES["hp"].with_vertices(np.where(np.arange(42)[:, None] == 5, np.nan,
                                              MESHES["hp"].vertices))
    for ext in (".stl", ".glb", ".json"):
        with pytest.raises(ExportError):
            save(tmp_path / f"m{ext}", bad)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("ext", [".stl", ".glb", ".dxf", ".3dm", ".ifc", ".json", ".ply", ".obj"])
def test_cli_export(tmp_path, ext, capsys):
    save(tmp_path / "m.json", MESHES["mixed"])
    out = tmp_path / f"out{ext}"
    assert main(["export", str(tmp_path / "m.json"), "-o", str(out)]) == 0
    assert out.stat().st_size > 0
    assert "35 faces" in capsys.readouterr().out


def test_cli_export_unknown_extension(tmp_path, capsys):
    save(tmp_path / "m.json", MESHES["hp"])
    assert main(["export", str(tmp_path / "m.json"), "-o", str(tmp_path / "m.xyz")]) == 2
    err = capsys.readouterr().err
    assert ".xyz" in err and ".glb" in err
