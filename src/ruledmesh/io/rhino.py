"""Rhino 3DM (via rhino3dm): one mesh object per panel, generators as line curves.

Each face becomes one Rhino Mesh object named by its panel label (``P0``,
``P1``, ... as on the fabrication sheets and schedules), on the layer of its
kind, ``ruledmesh-<kind>``, with the user strings ``ruledmesh.label``,
``ruledmesh.kind``, ``ruledmesh.area`` (mesh unit squared),
``ruledmesh.planarity`` (the planarity `ruledmesh analyze` reports: quads by their diagonals,
others by the best-fit plane, triangles 0) and ``ruledmesh.face`` (face index).  With ``panels="joined"``
each face kind is one mesh object instead, with the user string
``ruledmesh.face_of``: the source face of every Rhino mesh face, comma
separated, so the polygons can be recovered.  The model unit system is the
mesh's unit.  Rhino meshes hold triangles and quads only: those are
written as they are, and any face with five or more corners (clipped border
faces, caps) is split into triangles without splinters
(:func:`ruledmesh.triangulate.triangulate`).  Vertices are stored in
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
from ..units import Unit, unit_of
from ._panels import check_panels, panel_data

__all__ = ["RHINO_VERSION", "UNIT_SYSTEMS", "dumpb"]

# The 3DM archive version written (Rhino 7 and later read it).
RHINO_VERSION = 7
# rhino3dm.UnitSystem member of each mesh unit.
UNIT_SYSTEMS = {Unit.M: "Meters", Unit.CM: "Centimeters", Unit.MM: "Millimeters",
                Unit.IN: "Inches", Unit.FT: "Feet"}
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


def _rhino_mesh(r3, points: np.ndarray, quads: np.ndarray):
    """A Rhino mesh of ``points`` (double precision) and (G, 4) faces (triangles: c == d)."""
    rmesh = r3.Mesh()
    for x, y, z in points.tolist():
        rmesh.Vertices.AddPoint3d(x, y, z)  # double precision (Add() is float32)
    for a, b, c, d in quads.tolist():
        if c == d:
            rmesh.Faces.AddFace(a, b, c)
        else:
            rmesh.Faces.AddFace(a, b, c, d)
    rmesh.Normals.ComputeNormals()
    return rmesh


def _add_panels(r3, model, mesh: Mesh, panels: str, layer_of: dict) -> None:
    """One mesh object per face (``"each"``) or per face kind (``"joined"``)."""
    faces, face_of = rhino_faces(mesh)
    data = panel_data(mesh)
    if panels == "joined":
        for kind, index in layer_of.items():
            sel = mesh.face_kind[face_of] == kind
            used, local = np.unique(faces[sel], return_inverse=True)
            rmesh = _rhino_mesh(r3, mesh.vertices[used], local.reshape(-1, 4))
            rmesh.SetUserString("ruledmesh.face_of", ",".join(map(str, face_of[sel].tolist())))
            attrs = r3.ObjectAttributes()
            attrs.LayerIndex = index
            attrs.Name = kind.label
            model.Objects.AddMesh(rmesh, attrs)
        return
    bounds = np.searchsorted(face_of, np.arange(mesh.n_faces + 1))
    for f in range(mesh.n_faces):
        rows = faces[bounds[f]:bounds[f + 1]]
        corners = mesh.face(f)
        # Local indices: position of each row entry among the face's own corners.
        local = np.argmax(rows[..., None] == corners, axis=-1)
        rmesh = _rhino_mesh(r3, mesh.vertices[corners], local)
        attrs = r3.ObjectAttributes()
        attrs.LayerIndex = layer_of[FaceKind(int(mesh.face_kind[f]))]
        attrs.Name = str(data.label[f])
        for key, value in (("label", data.label[f]), ("kind", data.kind[f]),
                           ("area", repr(float(data.area[f]))),
                           ("planarity", repr(float(data.planarity[f]))), ("face", str(f))):
            attrs.SetUserString(f"ruledmesh.{key}", str(value))
        model.Objects.AddMesh(rmesh, attrs)


def dumpb(mesh: Mesh, panels: str = "each") -> bytes:
    """The .3dm bytes of ``mesh``.

    Parameters
    ----------
    mesh : Mesh
        Its :attr:`~ruledmesh.mesh.Mesh.units` become the model unit system.
    panels : {"each", "joined"}
        One mesh object per face, named by its panel label (default), or one
        per face kind.

    Returns
    -------
    bytes
    """
    panels = check_panels(panels)
    r3 = _import_rhino3dm()
    model = r3.File3dm()
    model.ApplicationName = "ruledmesh"
    model.Settings.ModelUnitSystem = getattr(r3.UnitSystem, UNIT_SYSTEMS[unit_of(mesh.units)])
    layer_of = {}
    for kind in np.unique(mesh.face_kind).tolist():
        kind = FaceKind(kind)
        layer = r3.Layer()
        layer.Name = f"ruledmesh-{kind.label}"
        layer.Color = (*_LAYER_COLOURS[kind], 255)
        layer_of[kind] = model.Layers.Add(layer)
    _add_panels(r3, model, mesh, panels, layer_of)
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
