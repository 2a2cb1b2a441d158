"""glTF 2.0 (.glb) export: the Khronos validator finds no error and no warning,
and the polygons come back from _FACE_ID as documented."""

from __future__ import annotations

import json
import shutil
import struct
import subprocess
from pathlib import Path

import export_meshes as E  # a helper module of tests/ (see conftest.py)
import numpy as np
import pytest

from ruledmesh.io import save
from ruledmesh.io.gltf import dumpb, gltf_positions
from ruledmesh.triangulate import triangulate

JS = Path(__file__).with_name("js")


def validate(paths: list[Path]) -> list[dict]:
    """Reports of the Khronos glTF validator (npm gltf-validator) for ``paths``."""
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed: cannot run the Khronos glTF validator")
    if not (JS / "node_modules" / "gltf-validator").is_dir():
        pytest.fail("gltf-validator is not installed: run `npm ci --prefix tests/js`")
    out = subprocess.run([node, str(JS / "validate_gltf.js"), *map(str, paths)],
                         capture_output=True, text=True, timeout=120, check=True)
    return json.loads(out.stdout)


def read_glb(data: bytes) -> tuple[dict, bytes]:
    magic, version, length = struct.unpack_from("<4sII", data)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    jlen, jtype = struct.unpack_from("<I4s", data, 12)
    doc = json.loads(data[20:20 + jlen])
    blen, btype = struct.unpack_from("<I4s", data, 20 + jlen)
    assert (jtype, btype) == (b"JSON", b"BIN\0")
    return doc, data[28 + jlen:28 + jlen + blen]


def accessor(doc: dict, binary: bytes, index: int) -> np.ndarray:
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    dtype = {5126: "<f4", 5125: "<u4"}[acc["componentType"]]
    width = {"SCALAR": 1, "VEC3": 3}[acc["type"]]
    arr = np.frombuffer(binary, dtype=dtype, count=acc["count"] * width,
                        offset=view["byteOffset"] + acc.get("byteOffset", 0))
    return arr.reshape(acc["count"], width) if width > 1 else arr


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    folder = tmp_path_factory.mktemp("glb")
    files = {}
    for name, mesh in E.all_meshes().items():
        for shading in ("flat", "smooth"):
            path = folder / f"{name}-{shading}.glb"
            save(path, mesh, shading=shading)
            files[path] = mesh
    return files


def test_khronos_validator_no_errors_no_warnings(written):
    reports = validate(list(written))
    assert len(reports) == len(written)
    for (path, mesh), report in zip(written.items(), reports):
        issues = report["issues"]
        messages = [(m["code"], m["message"]) for m in issues["messages"]]
        assert issues["numErrors"] == 0, (path.name, messages)
        assert issues["numWarnings"] == 0, (path.name, messages)
        assert report["info"]["totalTriangleCount"] == int((mesh.valences - 2).sum())


def test_validator_catches_a_broken_file(tmp_path):
    # The harness is not vacuous: a wrong asset version is an error.
    data = dumpb(E.hp_translational()).replace(b'"version":"2.0"', b'"version":"3.0"')
    (tmp_path / "bad.glb").write_bytes(data)
    assert validate([tmp_path / "bad.glb"])[0]["issues"]["numErrors"] > 0


@pytest.mark.parametrize("name", ["hp", "mixed", "far"])
def test_polygons_and_positions_recovered(name):
    source = E.all_meshes()[name]
    doc, binary = read_glb(dumpb(source))
    # glTF is metres and Y-up: compare with the design turned the same way.
    mesh = source.with_vertices(gltf_positions(source.vertices, source.units))
    origin = np.array(doc["nodes"][0]["translation"])
    faces: dict[int, list[int]] = {}
    n_tri = 0
    for prim in doc["meshes"][0]["primitives"]:
        attrs = prim["attributes"]
        pos = accessor(doc, binary, attrs["POSITION"]).astype(np.float64) + origin
        fid = accessor(doc, binary, attrs["_FACE_ID"]).astype(np.int64)
        vid = accessor(doc, binary, attrs["_VERTEX_ID"]).astype(np.int64)
        normal = accessor(doc, binary, attrs["NORMAL"])
        np.testing.assert_allclose(np.linalg.norm(normal, axis=1), 1.0, atol=1e-6)
        # float32 offsets from the centre: error below 2**-23 of the extent.
        tol = 2.0 ** -22 * np.abs(pos - origin).max() + 1e-12
        np.testing.assert_allclose(pos, mesh.vertices[vid], rtol=0, atol=tol)
        for f in np.unique(fid).tolist():
            faces[f] = vid[fid == f].tolist()
        idx = accessor(doc, binary, prim["indices"]).reshape(-1, 3)
        n_tri += len(idx)
        # Each triangle stays within one face.
        assert np.all(fid[idx] == fid[idx[:, :1]])
    assert sorted(faces) == list(range(mesh.n_faces))
    assert all(faces[f] == mesh.face(f).tolist() for f in range(mesh.n_faces))
    assert n_tri == triangulate(mesh).n_triangles
    gens = doc["meshes"][1]["primitives"][0]
    seg = accessor(doc, binary, gens["attributes"]["POSITION"]).astype(np.float64) + origin
    np.testing.assert_allclose(seg.reshape(-1, 2, 3), mesh.vertices[mesh.members],
                               atol=2.0 ** -22 * mesh.diagonal() * 4)
    np.testing.assert_array_equal(
        accessor(doc, binary, gens["attributes"]["_MEMBER_ID"])[::2], mesh.member_id)
