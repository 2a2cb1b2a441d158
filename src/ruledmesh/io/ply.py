"""Stanford PLY (binary little-endian): polygons kept, kinds and generators too.

Elements written, all of them ones the PLY readers parse::

    comment units <m|cm|mm|in|ft>
    element vertex V      double x, y, z
    element face F        list uchar int vertex_indices     (+ uchar kind, inline)
    element edge E        int vertex1, int vertex2                  (inline)
    element generator E   int id                                    (inline)

``kind`` is the :class:`~ruledmesh.mesh.FaceKind` value of each face (a
comment lists them); the ``edge`` element (the name and properties of the
PLY specification's edge example) holds the members, generator segments,
and the ``generator`` element the generator id of each.  Every header line is short.

Where the kinds and generators go (``extras``):

* ``"file"`` (default): ``NAME.ply`` has only vertices and plain faces, which
  every reader takes (Open3D, MeshLab/pymeshlab, trimesh, meshio, Blender;
  meshio refuses any element but vertex and face and any face property but
  the index list); the companion ``NAME.ruledmesh.ply`` next to it holds the
  same vertices, an element ``face_kind`` (``uchar kind``, one per face) and
  the ``edge`` element (Open3D and trimesh read it as a line set), and
  :func:`ruledmesh.io.load` reads it back;
* ``"inline"``: one file with the ``kind`` face property and the ``edge``
  and ``generator`` elements (Open3D and MeshLab read it; meshio does not);
* ``"omit"``: vertices and faces only.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..mesh import FaceKind, Mesh
from ..units import unit_of

__all__ = ["EXTRAS_MODES", "companion_path", "companions", "dumpb", "loadb"]

EXTRAS_MODES = ("file", "inline", "omit")


def companion_path(path) -> Path:
    """The companion file (kinds and generators) of the PLY file ``path``."""
    path = Path(path)
    return path.with_name(f"{path.stem}.ruledmesh.ply")


def _check_extras(extras: str) -> str:
    if extras not in EXTRAS_MODES:
        raise ParameterError(f'expected "file", "inline" or "omit", got {extras!r}', "extras")
    return extras


def _header(mesh: Mesh, faces: str = "plain", edges: bool = False) -> bytes:
    """Header text; ``faces``: "plain", "kind" (with the kind property) or "separate"."""
    lines = ["ply", "format binary_little_endian 1.0", "comment ruledmesh PLY",
             f"comment units {mesh.units}",
             "comment face kind: " + ", ".join(f"{k.value}={k.label}" for k in FaceKind)]
    construction = str(mesh.info.get("construction", ""))
    if construction and construction.isprintable() and construction.isascii():
        lines.append(f"comment construction {construction[:200]}")
    lines += [f"element vertex {mesh.n_vertices}", "property double x", "property double y",
              "property double z"]
    if faces == "separate":
        lines += [f"element face_kind {mesh.n_faces}", "property uchar kind"]
    else:
        lines += [f"element face {mesh.n_faces}", "property list uchar int vertex_indices"]
        if faces == "kind":
            lines.append("property uchar kind")
    if edges and len(mesh.members):
        # Generator ids in an element of their own: trimesh reads every edge
        # property as a column of the segment array.
        lines += [f"element edge {len(mesh.members)}", "property int vertex1",
                  "property int vertex2", f"element generator {len(mesh.members)}",
                  "property int id"]
    lines.append("end_header")
    return ("\n".join(lines) + "\n").encode("ascii")


def _edge_bytes(mesh: Mesh) -> bytes:
    return mesh.members.astype("<i4").tobytes() + mesh.member_id.astype("<i4").tobytes()


def dumpb(mesh: Mesh, extras: str = "file") -> bytes:
    """The binary PLY bytes of ``mesh``.

    Parameters
    ----------
    mesh : Mesh
    extras : {"file", "inline", "omit"}
        Where the face kinds and members go (see the module notes); with
        ``"file"`` the companion file's bytes come from :func:`companions`.

    Returns
    -------
    bytes
    """
    inline = _check_extras(extras) == "inline"
    val = mesh.valences
    if val.size and val.max() > 255:
        raise ParameterError("PLY faces are limited to 255 vertices", "mesh")
    if mesh.n_vertices >= 2**31:
        raise ParameterError("PLY int indices are limited to 2**31 vertices", "mesh")
    verts = mesh.vertices.astype("<f8").tobytes()
    # Each face record: uchar count, count x int32 (, uchar kind) -- one byte array.
    nbytes = 1 + 4 * val + inline
    rec_off = np.zeros(len(val) + 1, np.int64)
    np.cumsum(nbytes, out=rec_off[1:])
    buf = np.zeros(int(rec_off[-1]), np.uint8)
    buf[rec_off[:-1]] = val.astype(np.uint8)
    if inline:
        buf[rec_off[1:] - 1] = mesh.face_kind
    idx_bytes = mesh.face_indices.astype("<i4").view(np.uint8).reshape(-1, 4)
    corner_face = np.repeat(np.arange(len(val)), val)
    corner_pos = np.arange(mesh.face_indices.size) - mesh.face_offsets[corner_face]
    start = rec_off[corner_face] + 1 + 4 * corner_pos
    buf[start[:, None] + np.arange(4)] = idx_bytes
    edges = _edge_bytes(mesh) if inline and len(mesh.members) else b""
    head = _header(mesh, faces="kind" if inline else "plain", edges=inline)
    return head + verts + buf.tobytes() + edges


def companions(path, mesh: Mesh, extras: str = "file") -> dict:
    """Extra files written with ``path``: ``{companion_path(path): bytes}`` or nothing.

    The companion holds every vertex (so indices are the main file's), the
    ``face_kind`` element and the ``edge`` element.
    """
    if _check_extras(extras) != "file":
        return {}
    data = (_header(mesh, faces="separate", edges=True) + mesh.vertices.astype("<f8").tobytes()
            + mesh.face_kind.astype(np.uint8).tobytes()
            + (_edge_bytes(mesh) if len(mesh.members) else b""))
    return {companion_path(path): data}


def load_companions(path, mesh: Mesh) -> Mesh:
    """``mesh`` with the kinds and members of the companion file of ``path``, if there is one."""
    from dataclasses import replace

    side = companion_path(path)
    if not side.is_file():
        return mesh
    kinds, members, member_id = _parse(side.read_bytes())[1:]
    if kinds is None or kinds.size != mesh.n_faces:
        raise ParameterError(f"{side.name} does not match {Path(path).name} (its face count "
                             "differs): not its companion file", "ply")
    if members is not None and members.size and members.max() >= mesh.n_vertices:
        raise ParameterError(f"{side.name}: member indices beyond the vertices", "ply")
    kw = {"face_kind": kinds}
    if members is not None:
        kw.update(members=members, member_id=member_id)
    return replace(mesh, **kw)


_TYPES = {"char": "i1", "uchar": "u1", "short": "<i2", "ushort": "<u2", "int": "<i4",
          "uint": "<u4", "float": "<f4", "double": "<f8", "int8": "i1", "uint8": "u1",
          "int16": "<i2", "uint16": "<u2", "int32": "<i4", "uint32": "<u4",
          "float32": "<f4", "float64": "<f8"}


def loadb(data: bytes) -> Mesh:
    """Read a binary little-endian PLY with vertex, face and optional edge elements."""
    mesh, kinds, members, member_id = _parse(data)
    if kinds is not None and kinds.size == mesh.n_faces:
        mesh = Mesh.from_arrays(mesh.vertices, mesh.face_offsets, mesh.face_indices, kinds,
                                members=members, member_id=member_id, info=mesh.info)
    elif members is not None:
        mesh = Mesh.from_arrays(mesh.vertices, mesh.face_offsets, mesh.face_indices, mesh.face_kind,
                                members=members, member_id=member_id, info=mesh.info)
    return mesh


def _parse(data: bytes):
    """The plain mesh of a PLY file, and its kinds and members where present."""
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply") or end < 0:
        raise ParameterError("not a PLY file", "ply")
    lines = data[:end].decode("ascii", "replace").splitlines()
    if "format binary_little_endian 1.0" not in lines:
        raise ParameterError("only binary little-endian PLY is read", "ply")
    elements: list[tuple[str, int, list[tuple]]] = []
    runs: list[int] = []
    mem: list[int] = []
    units = None
    for line in lines:
        parts = line.split()
        if parts[:2] == ["comment", "units"] and len(parts) == 3:
            units = parts[2]
        elif parts[:3] == ["comment", "ruledmesh", "kinds"]:  # files of ruledmesh 0.1
            runs.extend(int(x) for x in parts[3:])
        elif parts[:3] == ["comment", "ruledmesh", "members"]:
            mem.extend(int(x) for x in parts[3:])
        elif parts[:1] == ["element"]:
            elements.append((parts[1], int(parts[2]), []))
        elif parts[:1] == ["property"]:
            elements[-1][2].append(tuple(parts[1:]))
    pos = end + len(b"end_header\n")
    out: dict[str, dict[str, Any]] = {}
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
    face: dict[str, Any] = out.get("face", {"__lists__": []})
    faces = face["__lists__"]
    kinds = None
    if "kind" in face and face["kind"].size == len(faces):
        kinds = face["kind"].astype(np.uint8)
    elif "kind" in out.get("face_kind", {}):
        kinds = out["face_kind"]["kind"].astype(np.uint8)
    elif runs:
        pairs = np.array(runs, np.int64).reshape(-1, 2)
        kinds = np.repeat(pairs[:, 0], pairs[:, 1]).astype(np.uint8)
        if kinds.size != len(faces):
            kinds = None
    if kinds is not None and kinds.size and kinds.max() > max(FaceKind):
        raise ParameterError("face kinds out of range", "ply.kind")
    members = member_id = None
    edge = out.get("edge", {})
    if "vertex1" in edge and "vertex2" in edge:
        members = np.column_stack([edge["vertex1"], edge["vertex2"]]).astype(np.int64)
        ids = out.get("generator", {}).get("id")
        member_id = ids.astype(np.int64) if ids is not None and ids.size == len(members) else None
    elif mem:
        triples = np.array(mem, np.int64).reshape(-1, 3)
        members, member_id = triples[:, :2], triples[:, 2]
    info = {} if units is None else {"units": unit_of(units, "ply.units").value}
    mesh = Mesh.from_faces(vertices, faces, None, info=info) if faces else Mesh.from_arrays(
        vertices, [0], [], info=info)
    return mesh, kinds, members, member_id
