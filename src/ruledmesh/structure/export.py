"""Solids (beams, thick panels) as OBJ, 3DM and IFC: one object per solid.

* OBJ: one ``o NAME`` object per solid, coordinates with 17 significant
  digits, and the solid's table row as a ``# key=value ...`` comment line
  before its faces (other readers ignore comments);
* 3DM (rhino3dm): one closed Rhino mesh per solid on layer ``LAYER``, named
  after the solid, with every table column as a user string;
* IFC4 (IfcOpenShell): one ``IfcMember`` (beams) or ``IfcPlate`` (panels) per
  solid, whose 'Body' is a closed ``IfcPolygonalFaceSet``, and the table row
  (less the index columns, which are in the name) as a property set
  ``Pset_RuledmeshStructure`` (torsion, bevels, ...).

Lengths are in the mesh's units (IFC: metres, as :mod:`ruledmesh.io.ifc`).
"""

from __future__ import annotations

import os
import tempfile

import numpy as np

from ..errors import ExportError
from ..io import require
from ..triangulate import triangulate
from .beams import Solids

__all__ = ["solids_3dm", "solids_ifc", "solids_obj"]

PSET = "Pset_RuledmeshStructure"
# Index columns are already in the product's name; leaving them out of the
# property sets saves a third of the file and of the writing time.
_NOT_PROPERTIES = frozenset({"edge", "generator", "face", "v0", "v1", "node0", "node1",
                             "face0", "face1", "id"})


def _rows(solids: Solids) -> list[dict[str, float | int]]:
    """The table as one plain dict per solid (NaN kept as NaN)."""
    cols = {k: np.asarray(v).tolist() for k, v in solids.table.items()}
    return [{k: cols[k][s] for k in cols} for s in range(solids.count)]


def _by_solid(solids: Solids) -> tuple[np.ndarray, np.ndarray]:
    """Start and end face of every solid (faces are stored solid after solid)."""
    bounds = np.searchsorted(solids.solid, np.arange(solids.count + 1))
    return bounds[:-1], bounds[1:]


def _face_lines(offsets: np.ndarray, indices: np.ndarray) -> list[str]:
    """One ``f a b c ...`` line per face (1-based), formatted in one C-level call."""
    val = np.diff(offsets)
    templates = {int(k): "f" + " %d" * int(k) for k in np.unique(val)}
    text = "\n".join(templates[int(k)] for k in val.tolist()) % tuple((indices + 1).tolist())
    return text.split("\n")


def solids_obj(solids: Solids) -> bytes:
    """OBJ bytes: one object per solid, its table row as a comment.

    Parameters
    ----------
    solids : Solids

    Returns
    -------
    bytes
    """
    mesh = solids.mesh
    head = (f"# ruledmesh {mesh.info.get('construction', 'solids')}: "
            f"{solids.count} closed solids\n")
    # %-formatting the whole block at once is several times faster than savetxt.
    verts = ("v %.17g %.17g %.17g\n" * mesh.n_vertices) % tuple(mesh.vertices.reshape(-1).tolist())
    lines = _face_lines(mesh.face_offsets, mesh.face_indices)
    keys = list(solids.table)
    row_format = "# " + " ".join(f"{k}=%r" for k in keys)
    cols = [np.asarray(solids.table[k]).tolist() for k in keys]
    first, last = _by_solid(solids)
    body = [f"o {name.replace(' ', '-')}\n{row_format % row}\n" + "\n".join(lines[a:b]) + "\n"
            for name, row, a, b in zip(solids.names, zip(*cols), first.tolist(), last.tolist())]
    return (head + verts + "".join(body)).encode("utf-8")


def solids_3dm(solids: Solids, layer: str = "structure") -> bytes:
    """3DM bytes: one closed Rhino mesh per solid, table columns as user strings.

    Faces with more than four corners are split into triangles (Rhino meshes
    hold triangles and quads only); the solid stays closed.
    """
    r3 = require("rhino3dm", "rhino", "3DM export")
    mesh = solids.mesh
    tri = triangulate(mesh.select_faces(mesh.valences > 4)) if np.any(mesh.valences > 4) else None
    big = np.flatnonzero(mesh.valences > 4)
    model = r3.File3dm()
    model.ApplicationName = "ruledmesh"
    lay = r3.Layer()
    lay.Name = layer
    index = model.Layers.Add(lay)
    first, last = _by_solid(solids)
    for name, row, a, b in zip(solids.names, _rows(solids), first.tolist(), last.tolist()):
        corners: list[list[int]] = []
        for f in range(a, b):
            face = mesh.face(f).tolist()
            if len(face) <= 4 or tri is None:
                corners.append(face)
            else:
                corners.extend(tri.triangles[tri.face_of == np.searchsorted(big, f)].tolist())
        used, local = np.unique(np.concatenate([np.asarray(c) for c in corners]),
                                return_inverse=True)
        rmesh = r3.Mesh()
        for x, y, z in mesh.vertices[used].tolist():
            rmesh.Vertices.AddPoint3d(x, y, z)  # double precision (Add() is float32)
        pos = 0
        for c in corners:
            rmesh.Faces.AddFace(*local[pos:pos + len(c)].tolist())
            pos += len(c)
        rmesh.Normals.ComputeNormals()
        attrs = r3.ObjectAttributes()
        attrs.LayerIndex = index
        attrs.Name = name
        for k, v in row.items():
            attrs.SetUserString(k, repr(v))
        model.Objects.AddMesh(rmesh, attrs)
    fd, tmp = tempfile.mkstemp(suffix=".3dm")
    os.close(fd)
    try:
        if not model.Write(tmp, 7):
            raise ExportError("rhino3dm could not write the 3DM file")
        with open(tmp, "rb") as fh:
            return fh.read()
    finally:
        os.unlink(tmp)


def _ifc_value(f, v):
    if isinstance(v, bool):
        return f.createIfcBoolean(v)
    if isinstance(v, int):
        return f.createIfcInteger(v)
    return f.createIfcReal(float(v))


def solids_ifc(solids: Solids, *, ifc_class: str = "IfcMember",
               predefined_type: str = "MULLION", name: str = "ruledmesh structure") -> bytes:
    """IFC4 bytes: one product per solid with a closed polygonal face set and a property set.

    Parameters
    ----------
    solids : Solids
    ifc_class : {"IfcMember", "IfcPlate"}
    predefined_type : str
        The product's predefined type (``MULLION`` for frame members,
        ``CURTAIN_PANEL`` for panels, ``MEMBER`` for generator beams).
    name : str
        Project name.
    """
    ifcopenshell = require("ifcopenshell", "ifc", "IFC export")
    for sub in ("ifcopenshell.api", "ifcopenshell.guid"):
        require(sub, "ifc", "IFC export")
    run = ifcopenshell.api.run
    new_guid = ifcopenshell.guid.new
    f = run("project.create_file", version="IFC4")
    project = run("root.create_entity", f, ifc_class="IfcProject", name=name)
    run("unit.assign_unit", f)
    model = run("context.add_context", f, context_type="Model")
    body = run("context.add_context", f, context_type="Model", context_identifier="Body",
               target_view="MODEL_VIEW", parent=model)
    site = run("root.create_entity", f, ifc_class="IfcSite", name="site")
    run("aggregate.assign_object", f, products=[site], relating_object=project)
    origin = f.createIfcAxis2Placement3D(f.createIfcCartesianPoint((0.0, 0.0, 0.0)), None, None)
    site_place = f.createIfcLocalPlacement(None, origin)
    site.ObjectPlacement = site_place
    mesh = solids.mesh
    first, last = _by_solid(solids)
    products = []
    for label, row, a, b in zip(solids.names, _rows(solids), first.tolist(), last.tolist()):
        lo, hi = int(mesh.face_offsets[a]), int(mesh.face_offsets[b])
        used, local = np.unique(mesh.face_indices[lo:hi], return_inverse=True)
        points = f.createIfcCartesianPointList3D(mesh.vertices[used].tolist())
        offs = mesh.face_offsets[a:b + 1] - lo
        faces = [f.createIfcIndexedPolygonalFace(seg.tolist())
                 for seg in np.split(local.reshape(-1) + 1, offs[1:-1])]
        faceset = f.createIfcPolygonalFaceSet(points, True, faces, None)
        rep = f.createIfcShapeRepresentation(body, "Body", "Tessellation", [faceset])
        product = f.create_entity(ifc_class, GlobalId=new_guid(), Name=label,
                                  PredefinedType=predefined_type)
        product.ObjectPlacement = f.createIfcLocalPlacement(site_place, origin)
        product.Representation = f.createIfcProductDefinitionShape(None, None, [rep])
        props = [f.createIfcPropertySingleValue(k, None, _ifc_value(f, v), None)
                 for k, v in row.items()
                 if k not in _NOT_PROPERTIES and not (isinstance(v, float) and np.isnan(v))]
        pset = f.createIfcPropertySet(new_guid(), None, PSET, None, props)
        f.createIfcRelDefinesByProperties(new_guid(), None, None, None, [product], pset)
        products.append(product)
    # One containment relation made directly: the API call re-derives every
    # product's placement, seconds for a few thousand beams.
    f.createIfcRelContainedInSpatialStructure(new_guid(), None, "site contents", None,
                                              products, site)
    return f.to_string().encode("utf-8")
