"""Stanford PLY (binary little-endian): polygons kept, kinds and generators too.

Layout, kept to the two elements every PLY reader knows (meshio, Blender,
MeshLab, Open3D)::

    element vertex V      double x, y, z
    element face F        list uchar int vertex_indices

The face kinds and the members (generator segments) travel in ``comment``
lines that other readers skip: ``comment ruledmesh kinds K N K N ...`` gives
run lengths of :class:`~ruledmesh.mesh.FaceKind` values in face order, and
``comment ruledmesh members i j g i j g ...`` (several lines) the members'
vertex pairs and generator ids.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..mesh import FaceKind, Mesh

__all__ = ["dumpb", "loadb"]


def _comment_lines(tag: str, values: np.ndarray, per_line: int) -> list[str]:
    values = values.astype(np.int64)
    return [f"comment ruledmesh {tag} " + " ".join(map(str, values[i:i + per_line].tolist()))
            for i in range(0, len(values), per_line)]


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
    kinds = mesh.face_kind
    starts = np.flatnonzero(np.r_[True, kinds[1:] != kinds[:-1]]) if kinds.size else np.zeros(0, int)
    runs = np.column_stack([kinds[starts], np.diff(np.r_[starts, kinds.size])]).reshape(-1)
    header = ["ply", "format binary_little_endian 1.0",
              "comment ruledmesh PLY; face kinds: " + ", ".join(f"{k.value}={k.label}" for k in FaceKind)]
    header += _comment_lines("kinds", runs, 400)
    if len(mesh.members):
        header += _comment_lines("members", np.column_stack([mesh.members, mesh.member_id]).reshape(-1), 600)
    header += [f"element vertex {mesh.n_vertices}", "property double x", "property double y",
               "property double z", f"element face {mesh.n_faces}",
               "property list uchar int vertex_indices", "end_header"]
    head = ("\n".join(header) + "\n").encode("ascii")
    verts = mesh.vertices.astype("<f8").tobytes()
    # Each face record: uchar count, then count x int32 -- built as one byte array.
    nbytes = 1 + 4 * val
    rec_off = np.zeros(len(val) + 1, np.int64)
    np.cumsum(nbytes, out=rec_off[1:])
    buf = np.zeros(int(rec_off[-1]), np.uint8)
    buf[rec_off[:-1]] = val.astype(np.uint8)
    idx_bytes = mesh.face_indices.astype("<i4").view(np.uint8).reshape(-1, 4)
    corner_face = np.repeat(np.arange(len(val)), val)
    corner_pos = np.arange(mesh.face_indices.size) - mesh.face_offsets[corner_face]
    start = rec_off[corner_face] + 1 + 4 * corner_pos
    buf[start[:, None] + np.arange(4)] = idx_bytes
    return head + verts + buf.tobytes()


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
    runs: list[int] = []
    mem: list[int] = []
    for line in lines:
        parts = line.split()
        if parts[:3] == ["comment", "ruledmesh", "kinds"]:
            runs.extend(int(x) for x in parts[3:])
        elif parts[:3] == ["comment", "ruledmesh", "members"]:
            mem.extend(int(x) for x in parts[3:])
        elif parts[:1] == ["element"]:
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
    faces = out.get("face", {"__lists__": []})["__lists__"]
    kinds = None
    if runs:
        pairs = np.array(runs, np.int64).reshape(-1, 2)
        kinds = np.repeat(pairs[:, 0], pairs[:, 1]).astype(np.uint8)
        if kinds.size != len(faces):
            kinds = None
    members = member_id = None
    if mem:
        triples = np.array(mem, np.int64).reshape(-1, 3)
        members, member_id = triples[:, :2], triples[:, 2]
    return Mesh.from_faces(vertices, faces, kinds, members=members, member_id=member_id)
