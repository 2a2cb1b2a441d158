"""glTF 2.0 binary (.glb): triangulated for rendering, polygons recoverable.

Layout of the file ruledmesh writes:

* one glTF mesh ``"panels"`` with one triangle primitive per face kind
  present, each with its own material (a colour per kind, double sided);
* every face's corners are written as their own vertices, in the face's
  boundary order, so each vertex belongs to exactly one face and carries
  two application-specific attributes (FLOAT scalars, exact below 2**24):
  ``_FACE_ID`` (index of the face in the source mesh) and ``_VERTEX_ID``
  (index of the source vertex, to weld faces back together);
* the triangles of a face are consecutive in the index accessor, split as
  :func:`ruledmesh.triangulate.triangulate` does (no splinters);
* ``NORMAL`` is the face normal (``shading="flat"``, panels look like the
  flat panels they are) or the area-weighted vertex normal
  (``shading="smooth"``);
* the generators go into a second mesh ``"generators"`` as a LINES
  primitive, one segment per member, with ``_MEMBER_ID``;
* glTF is Y-up and in metres by specification, ruledmesh designs are Z-up
  in their own unit: positions are scaled to metres and turned so the
  design's +Z is glTF's +Y, glTF ``(x, y, z) = s * (x, z, -y)`` of the
  design (a proper rotation about +X; ``s`` the unit in metres), which
  Blender, three.js and every viewer show upright;
* positions are float32 relative to the bounding-box centre, which is the
  nodes' ``translation`` (float64 in the JSON): large site coordinates keep
  their precision (a corner at 2.6e6 m is placed to float64 precision).

To recover the polygons: in each triangle primitive, group vertices by
``_FACE_ID``; within a group the vertices are the polygon in boundary order
(and ``_VERTEX_ID`` welds shared corners).  The mesh's ``extras.ruledmesh``
summarises this.
"""

from __future__ import annotations

import json
import struct
from dataclasses import replace

import numpy as np

from ..analysis.faces import face_normals
from ..errors import ExportError
from ..mesh import FaceKind, Mesh
from ..triangulate import triangulate

__all__ = ["KIND_COLOURS", "Z_UP_TO_Y_UP", "dumpb", "gltf_positions"]

# Linear RGBA base colours per face kind (readable on white and black).
KIND_COLOURS = {
    FaceKind.QUAD: (0.80, 0.82, 0.86, 1.0),
    FaceKind.BORDER: (0.95, 0.70, 0.30, 1.0),
    FaceKind.FILL: (0.35, 0.65, 0.95, 1.0),
    FaceKind.SPLIT: (0.90, 0.30, 0.30, 1.0),
    FaceKind.TRIANGLE: (0.45, 0.80, 0.45, 1.0),
    FaceKind.POLYGON: (0.70, 0.55, 0.85, 1.0),
    FaceKind.STRIP: (0.45, 0.72, 0.70, 1.0),
}
_FLOAT, _UINT = 5126, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_TRIANGLES, _LINES = 4, 1
_EXACT_FLOAT_INT = 2 ** 24  # ids written as float32 must stay exact
# Design (Z-up) to glTF (Y-up): (x, y, z) -> (x, z, -y), a rotation by -90 degrees about +X.
Z_UP_TO_Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


def gltf_positions(vertices: np.ndarray, units: str = "m") -> np.ndarray:
    """(V, 3) float64: design coordinates in ``units`` as glTF coordinates (metres, Y-up)."""
    from ..units import metres_per_unit

    return metres_per_unit(units) * (np.asarray(vertices, dtype=np.float64) @ Z_UP_TO_Y_UP.T)


class _Builder:
    """Accumulates the BIN chunk, buffer views and accessors."""

    def __init__(self):
        self.chunks: list[bytes] = []
        self.size = 0
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def add(self, array: np.ndarray, kind: str, target: int, minmax: bool = False) -> int:
        data = np.ascontiguousarray(array).tobytes()
        view = {"buffer": 0, "byteOffset": self.size, "byteLength": len(data), "target": target}
        self.views.append(view)
        pad = (-len(data)) % 4
        self.chunks.append(data + b"\0" * pad)
        self.size += len(data) + pad
        acc = {"bufferView": len(self.views) - 1,
               "componentType": _UINT if array.dtype == np.uint32 else _FLOAT,
               "count": int(array.shape[0]), "type": kind}
        if minmax:
            acc["min"] = array.min(axis=0).astype(float).tolist()
            acc["max"] = array.max(axis=0).astype(float).tolist()
        self.accessors.append(acc)
        return len(self.accessors) - 1


def _vertex_normals(mesh: Mesh, normals: np.ndarray, areas: np.ndarray) -> np.ndarray:
    """Area-weighted average of the normals of the faces around each vertex."""
    acc = np.zeros((mesh.n_vertices, 3))
    np.add.at(acc, mesh.face_indices, np.repeat(normals * areas[:, None], mesh.valences, axis=0))
    return acc


def _unit(v: np.ndarray) -> np.ndarray:
    """Unit float32 vectors; a zero vector (degenerate face) becomes +z."""
    v = np.asarray(v, dtype=np.float64)
    n = np.linalg.norm(v, axis=1)
    out = np.where(n[:, None] > 0, v / np.where(n > 0, n, 1.0)[:, None], [0.0, 0.0, 1.0])
    return out.astype(np.float32)


def _add_generators(b: _Builder, mesh: Mesh, centre: np.ndarray, materials: list, meshes: list,
                    nodes: list) -> None:
    """The generators as a second mesh of line segments (``_MEMBER_ID`` per end point)."""
    pos = (mesh.vertices[mesh.members.reshape(-1)] - centre).astype(np.float32)
    attrs = {"POSITION": b.add(pos, "VEC3", _ARRAY_BUFFER, minmax=True),
             "_MEMBER_ID": b.add(np.repeat(mesh.member_id, 2).astype(np.float32),
                                 "SCALAR", _ARRAY_BUFFER)}
    materials.append({"name": "generators",
                      "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.1, 0.12, 1.0],
                                               "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    meshes.append({"name": "generators",
                   "primitives": [{"attributes": attrs, "mode": _LINES,
                                   "material": len(materials) - 1}]})
    nodes.append({"name": "generators", "mesh": 1, "translation": centre.tolist()})


def _glb(doc: dict, b: _Builder) -> bytes:
    """The binary container: header, the JSON chunk (space-padded) and the BIN chunk."""
    js = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    js += b" " * ((-len(js)) % 4)
    binary = b"".join(b.chunks)
    total = 12 + 8 + len(js) + 8 + len(binary)
    return b"".join([
        struct.pack("<4sII", b"glTF", 2, total),
        struct.pack("<I4s", len(js), b"JSON"), js,
        struct.pack("<I4s", len(binary), b"BIN\0"), binary,
    ])


def dumpb(mesh: Mesh, shading: str = "flat", quads: str = "shorter") -> bytes:
    """The .glb bytes of ``mesh`` (see the module docstring for the layout).

    Parameters
    ----------
    mesh : Mesh
    shading : {"flat", "smooth"}
        Face normals, or area-weighted vertex normals.
    quads : {"shorter", "best"}
        Quad split rule, see :class:`ruledmesh.triangulate.QuadSplit`.

    Returns
    -------
    bytes
    """
    if shading not in ("flat", "smooth"):
        raise ExportError(f'shading: expected "flat" or "smooth", got "{shading}"')
    if mesh.n_faces >= _EXACT_FLOAT_INT or mesh.n_vertices >= _EXACT_FLOAT_INT:
        raise ExportError("glTF export is limited to 2**24 faces and vertices (float32 ids)")
    if mesh.n_faces == 0:
        raise ExportError("the mesh has no faces; a glTF file needs at least one triangle")
    source_units = mesh.units
    mesh = mesh.with_vertices(gltf_positions(mesh.vertices, source_units))
    centre = mesh.bounding_box().mean(axis=0)
    # Newell sums lose digits far from the origin: take normals of the centred mesh.
    normals, areas = face_normals(mesh.with_vertices(mesh.vertices - centre))
    corner_face = mesh.face_of
    if shading == "flat":
        corner_normal = normals[corner_face]
    else:
        corner_normal = _vertex_normals(mesh, normals, areas)[mesh.face_indices]
    # Triangulate the "corner mesh" (every face with its own copy of its
    # corners) so the triangles index the duplicated vertices directly.
    n_corners = mesh.face_indices.size
    corners = replace(mesh, vertices=mesh.vertices[mesh.face_indices],
                      face_indices=np.arange(n_corners, dtype=np.int64))
    tri = triangulate(corners, quads)
    kind_of_tri = mesh.face_kind[tri.face_of]

    b = _Builder()
    primitives, materials = [], []
    for kind in np.unique(mesh.face_kind).tolist():
        faces = np.flatnonzero(mesh.face_kind == kind)
        cmask = np.repeat(mesh.face_kind == kind, mesh.valences)
        cids = np.flatnonzero(cmask)
        remap = np.full(n_corners, -1, dtype=np.int64)
        remap[cids] = np.arange(cids.size)
        tris = remap[tri.triangles[kind_of_tri == kind]]
        pos = (mesh.vertices[mesh.face_indices[cids]] - centre).astype(np.float32)
        attrs = {
            "POSITION": b.add(pos, "VEC3", _ARRAY_BUFFER, minmax=True),
            "NORMAL": b.add(_unit(corner_normal[cids]), "VEC3", _ARRAY_BUFFER),
            "_FACE_ID": b.add(corner_face[cids].astype(np.float32), "SCALAR", _ARRAY_BUFFER),
            "_VERTEX_ID": b.add(mesh.face_indices[cids].astype(np.float32), "SCALAR", _ARRAY_BUFFER),
        }
        index = b.add(tris.reshape(-1).astype(np.uint32), "SCALAR", _ELEMENT_ARRAY_BUFFER)
        materials.append({
            "name": FaceKind(kind).label,
            "pbrMetallicRoughness": {"baseColorFactor": list(KIND_COLOURS[FaceKind(kind)]),
                                     "metallicFactor": 0.0, "roughnessFactor": 0.8},
            "doubleSided": True,
        })
        primitives.append({"attributes": attrs, "indices": index, "mode": _TRIANGLES,
                           "material": len(materials) - 1,
                           "extras": {"kind": FaceKind(kind).label, "faces": int(faces.size)}})
    meshes = [{"name": "panels", "primitives": primitives,
               "extras": {"ruledmesh": {
                   "faces": mesh.n_faces, "vertices": mesh.n_vertices,
                   "kinds": mesh.count_kinds(),
                   "face_id_attribute": "_FACE_ID", "vertex_id_attribute": "_VERTEX_ID",
                   "polygons": "per primitive, vertices grouped by _FACE_ID are the polygon "
                               "in boundary order; triangles are consecutive per face",
                   "shading": shading, "source_units": source_units,
                   "axes": "glTF (x, y, z) in metres = design (x, z, -y) times the unit"}}}]
    nodes = [{"name": "panels", "mesh": 0, "translation": centre.tolist()}]
    if len(mesh.members):
        _add_generators(b, mesh, centre, materials, meshes, nodes)
    doc = {
        "asset": {"version": "2.0", "generator": "ruledmesh"},
        "scene": 0,
        "scenes": [{"name": str(mesh.info.get("construction", "ruledmesh")),
                    "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": b.size}],
    }
    return _glb(doc, b)
