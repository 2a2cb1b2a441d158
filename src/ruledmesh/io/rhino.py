"""Rhino 3DM (via rhino3dm): meshes with quads kept, generators as line curves.

Each face kind present becomes one Rhino Mesh object on layer
``ruledmesh-<kind>``.  Rhino meshes hold triangles and quads only: those are
written as they are, and any face with five or more corners (clipped border
faces, caps) is split into triangles without splinters
(:func:`ruledmesh.triangulate.triangulate`).  Each mesh carries the user
string ``ruledmesh.face_of``: the source face id of every Rhino mesh face,
comma separated, so the polygons can be recovered.  Vertices are stored in
double precision.  Members are LineCurve objects on layer ``generators``,
named ``generator <id>`` with the user string ``generator``.  Requires the
optional dependency ``rhino3dm`` (``pip install ruledmesh[rhino]``).
"""

from __future__ import annotations

import os
import tempfile

import numpy as np

from ..errors import ExportError
from ..mesh import FaceKind, Mesh
from ..triangulate import triangulate

__all__ = ["dumpb", "RHINO_VERSION"]

# The 3DM archive version written (Rhino 7 and later read it).
RHINO_VERSION = 7
_LAYER_COLOURS = {FaceKind.QUAD: (200, 205, 215), FaceKind.BORDER: (240, 180, 80),
                  FaceKind.FILL: (90, 165, 240), FaceKind.SPLIT: (230, 80, 80),
                  FaceKind.TRIANGLE: (115, 205, 115), FaceKind.POLYGON: (180, 140, 215),
                  FaceKind.STRIP: (114, 183, 178)}


def _import_rhino3dm():
    from . import require

    return require("rhino3dm", "rhino", "3DM export")


def rhino_faces(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Faces as Rhino stores them: triangles and quads kept, larger faces split.

    Returns
    -------
    faces : (G, 4) int64
        Vertex indices; a triangle repeats its last vertex (Rhino's own
        convention for triangles in a quad list).
    face_of : (G,) int64
        Source face of each row.
    """
    val = mesh.valences
    small = val <= 4
    padded = mesh.padded_faces()
    rows = []
    if padded.shape[1] < 4:
        padded = np.pad(padded, ((0, 0), (0, 4 - padded.shape[1])), constant_values=-1)
    quads = padded[:, :4].copy()
    tri_mask = val == 3
    quads[tri_mask, 3] = quads[tri_mask, 2]
    rows.append((quads[small], np.flatnonzero(small)))
    if not small.all():
        big = mesh.select_faces(~small)
        tri = triangulate(big)
        t = tri.triangles
        rows.append((np.column_stack([t, t[:, 2]]), np.flatnonzero(~small)[tri.face_of]))
    faces = np.concatenate([r[0] for r in rows])
    face_of = np.concatenate([r[1] for r in rows])
    order = np.argsort(face_of, kind="stable")
    return faces[order], face_of[order]


def dumpb(mesh: Mesh) -> bytes:
    """The .3dm bytes of ``mesh``.

    Parameters
    ----------
    mesh : Mesh

    Returns
    -------
    bytes
    """
    r3 = _import_rhino3dm()
    model = r3.File3dm()
    model.ApplicationName = "ruledmesh"
    faces, face_of = rhino_faces(mesh)
    for kind in np.unique(mesh.face_kind).tolist():
        kind = FaceKind(kind)
        layer = r3.Layer()
        layer.Name = f"ruledmesh-{kind.label}"
        layer.Color = (*_LAYER_COLOURS[kind], 255)
        index = model.Layers.Add(layer)
        sel = mesh.face_kind[face_of] == kind
        used, local = np.unique(faces[sel], return_inverse=True)
        local = local.reshape(-1, 4)
        rmesh = r3.Mesh()
        for x, y, z in mesh.vertices[used].tolist():
            rmesh.Vertices.AddPoint3d(x, y, z)  # double precision (Add() is float32)
        for a, b, c, d in local.tolist():
            if c == d:
                rmesh.Faces.AddFace(a, b, c)
            else:
                rmesh.Faces.AddFace(a, b, c, d)
        rmesh.Normals.ComputeNormals()
        rmesh.SetUserString("ruledmesh.face_of", ",".join(map(str, face_of[sel].tolist())))
        attrs = r3.ObjectAttributes()
        attrs.LayerIndex = index
        attrs.Name = kind.label
        model.Objects.AddMesh(rmesh, attrs)
    if len(mesh.members):
        layer = r3.Layer()
        layer.Name = "generators"
        layer.Color = (20, 20, 25, 255)
        index = model.Layers.Add(layer)
        ends = mesh.vertices[mesh.members].tolist()
        for (p, q), gid in zip(ends, mesh.member_id.tolist()):
            attrs = r3.ObjectAttributes()
            attrs.LayerIndex = index
            attrs.Name = f"generator {gid}"
            attrs.SetUserString("generator", str(gid))
            model.Objects.AddCurve(r3.LineCurve(r3.Point3d(*p), r3.Point3d(*q)), attrs)
    # rhino3dm writes to a path only; go through a private temporary file.
    fd, tmp = tempfile.mkstemp(suffix=".3dm")
    os.close(fd)
    try:
        if not model.Write(tmp, RHINO_VERSION):
            raise ExportError("rhino3dm could not write the 3DM file")
        with open(tmp, "rb") as fh:
            return fh.read()
    finally:
        os.unlink(tmp)
