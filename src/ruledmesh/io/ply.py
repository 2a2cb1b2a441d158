"""Stanford PLY (binary little-endian): polygons kept, kinds and generators too.

Layout::

    element vertex V      float64 x, y, z
    element face F        list uchar int vertex_indices, uchar kind
    element edge E        int vertex1, int vertex2, int generator

``kind`` is the :class:`~ruledmesh.mesh.FaceKind` value; ``edge`` elements
(the convention of several PLY tools) carry the members.  Readers that do not
know ``kind`` or ``edge`` skip them.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..mesh import Mesh

__all__ = ["dumpb", "loadb"]


def dumpb(mesh: Mesh) -> bytes:
    """The binary PLY bytes of ``mesh``.

    Parameters
    ----------
    mesh : Mesh

    Returns
    -------
    bytes
    """
    val = mesh.valences
    if val.size and val.max() > 255:
        raise ParameterError("PLY faces are limited to 255 vertices", "mesh")
    header = [
        "ply",
        "format binary_little_endian 1.0",
        "comment ruledmesh PLY; face kind: " + ", ".join(
            f"{k.value}={k.label}" for k in __import__("ruledmesh.mesh", fromlist=["FaceKind"]).FaceKind),
        f"element vertex {mesh.n_vertices}",
        "property double x",
        "property double y",
        "property double z",
        f"element face {mesh.n_faces}",
        "property list uchar int vertex_indices",
        "property uchar kind",
    ]
    if len(mesh.members):
        header += [f"element edge {len(mesh.members)}", "property int vertex1",
                   "property int vertex2", "property int generator"]
    header.append("end_header")
    head = ("\n".join(header) + "\n").encode("ascii")
    verts = mesh.vertices.astype("<f8").tobytes()
    # Each face record: uchar count, count x int32, uchar kind -- built as one byte array.
    nbytes = 1 + 4 * val + 1
    rec_off = np.zeros(len(val) + 1, np.int64)
    np.cumsum(nbytes, out=rec_off[1:])
    buf = np.zeros(int(rec_off[-1]), np.uint8)
    buf[rec_off[:-1]] = val.astype(np.uint8)
    buf[rec_off[1:] - 1] = mesh.face_kind
    idx_bytes = mesh.face_indices.astype("<i4").view(np.uint8).reshape(-1, 4)
    corner_face = np.repeat(np.arange(len(val)), val)
    corner_pos = np.arange(mesh.face_indices.size) - mesh.face_offsets[corner_face]
    start = rec_off[corner_face] + 1 + 4 * corner_pos
    buf[start[:, None] + np.arange(4)] = idx_bytes
    parts = [head, verts, buf.tobytes()]
    if len(mesh.members):
        edges = np.column_stack([mesh.members, mesh.member_id]).astype("<i4")
        parts.append(edges.tobytes())
    return b"".join(parts)


_TYPES = {"char": "i1", "uchar": "u1", "short": "<i2", "ushort": "<u2", "int": "<i4",
          "uint": "<u4", "float": "<f4", "double": "<f8", "int8": "i1", "uint8": "u1",
          "int16": "<i2", "uint16": "<u2", "int32": "<i4", "uint32": "<u4",
          "float32": "<f4", "float64": "<f8"}


def loadb(data: bytes) -> Mesh:
    """Read a binary little-endian PLY with vertex, face and optional edge elements."""
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply") or end < 0:
        raise ParameterError("not a PLY file", "ply")
    lines = data[:end].decode("ascii", "replace").splitlines()
    if "format binary_little_endian 1.0" not in lines:
        raise ParameterError("only binary little-endian PLY is read", "ply")
    elements: list[tuple[str, int, list[tuple]]] = []
    for line in lines:
        parts = line.split()
        if parts[:1] == ["element"]:
            elements.append((parts[1], int(parts[2]), []))
        elif parts[:1] == ["property"]:
            elements[-1][2].append(tuple(parts[1:]))
    pos = end + len(b"end_header\n")
    out: dict[str, dict[str, np.ndarray]] = {}
    for name, count, props in elements:
        if all(p[0] != "list" for p in props):
            dtype = np.dtype([(p[1], _TYPES[p[0]]) for p in props])
            arr = np.frombuffer(data, dtype=dtype, count=count, offset=pos)
            pos += dtype.itemsize * count
            out[name] = {p[1]: arr[p[1]] for p in props}
            continue
        # Faces: one list property (vertex indices) plus optional scalars; parse
        # record by record only over the counts, vectorised per valence.
        values: dict[str, list] = {p[-1]: [] for p in props}
        lists = []
        raw = np.frombuffer(data, np.uint8, offset=pos)
        p = 0
        for _ in range(count):
            for prop in props:
                if prop[0] == "list":
                    ct = np.dtype(_TYPES[prop[1]])
                    it = np.dtype(_TYPES[prop[2]])
                    n = int(raw[p:p + ct.itemsize].view(ct)[0])
                    p += ct.itemsize
                    lists.append(raw[p:p + n * it.itemsize].view(it).astype(np.int64))
                    p += n * it.itemsize
                else:
                    dt = np.dtype(_TYPES[prop[0]])
                    values[prop[1]].append(raw[p:p + dt.itemsize].view(dt)[0])
                    p += dt.itemsize
        pos += p
        out[name] = {k: np.array(v) for k, v in values.items() if v}
        out[name]["__lists__"] = lists
    vert = out.get("vertex", {})
    vertices = np.column_stack([vert["x"], vert["y"], vert["z"]]).astype(np.float64)
    face = out.get("face", {"__lists__": []})
    faces = face["__lists__"]
    kinds = face.get("kind")
    edge = out.get("edge")
    members = member_id = None
    if edge is not None:
        members = np.column_stack([edge["vertex1"], edge["vertex2"]]).astype(np.int64)
        member_id = edge["generator"].astype(np.int64) if "generator" in edge else None
    return Mesh.from_faces(vertices, faces, kinds, members=members, member_id=member_id)
