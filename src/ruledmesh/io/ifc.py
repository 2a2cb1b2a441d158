"""IFC4 (via IfcOpenShell): panels as IfcPlate with an IfcPolygonalFaceSet.

IFC's tessellated geometry (``IfcIndexedPolygonalFace``) requires planar
faces, which is exactly what a PQ mesh provides: every quad, border pentagon
and fill triangle is written as one polygonal face, none split.  Layout:
``IfcProject`` > ``IfcSite`` containing one ``IfcPlate`` (predefined type
``CURTAIN_PANEL``) per face kind, named ``ruledmesh <kind>``, whose 'Body'
representation is an ``IfcPolygonalFaceSet`` (open, ``Closed = .F.``) over an
``IfcCartesianPointList3D``; and one ``IfcMember`` named ``generators``
whose 'Axis' representation is an ``IfcGeometricCurveSet`` of two-point
``IfcPolyline`` s, one per member.  Lengths are metres (the mesh's units are
taken as metres).  Requires the optional dependency ``ifcopenshell``
(``pip install ruledmesh[ifc]``).
"""

from __future__ import annotations

import numpy as np

from ..mesh import FaceKind, Mesh

__all__ = ["dumpb"]


def _import_ifcopenshell():
    from . import require

    for sub in ("ifcopenshell.api", "ifcopenshell.guid"):
        require(sub, "ifc", "IFC export")
    return require("ifcopenshell", "ifc", "IFC export")


def dumpb(mesh: Mesh) -> bytes:
    """The IFC4 (STEP physical file) bytes of ``mesh``.

    Parameters
    ----------
    mesh : Mesh

    Returns
    -------
    bytes
    """
    ifcopenshell = _import_ifcopenshell()
    run = ifcopenshell.api.run
    f = run("project.create_file", version="IFC4")
    name = str(mesh.info.get("construction", "ruledmesh"))
    project = run("root.create_entity", f, ifc_class="IfcProject", name=name)
    run("unit.assign_unit", f)
    model = run("context.add_context", f, context_type="Model")
    body = run("context.add_context", f, context_type="Model", context_identifier="Body",
               target_view="MODEL_VIEW", parent=model)
    axis = run("context.add_context", f, context_type="Model", context_identifier="Axis",
               target_view="GRAPH_VIEW", parent=model)
    site = run("root.create_entity", f, ifc_class="IfcSite", name="site")
    run("aggregate.assign_object", f, products=[site], relating_object=project)
    origin = f.createIfcLocalPlacement(None, f.createIfcAxis2Placement3D(
        f.createIfcCartesianPoint((0.0, 0.0, 0.0)), None, None))
    site.ObjectPlacement = origin
    products = []
    for kind in np.unique(mesh.face_kind).tolist():
        kind = FaceKind(kind)
        sub = mesh.select_faces(mesh.face_kind == kind)
        used, local = np.unique(sub.face_indices, return_inverse=True)
        points = f.createIfcCartesianPointList3D(mesh.vertices[used].tolist())
        one_based = np.split(local.reshape(-1) + 1, sub.face_offsets[1:-1])
        faces = [f.createIfcIndexedPolygonalFace(face.tolist()) for face in one_based]
        faceset = f.createIfcPolygonalFaceSet(points, False, faces, None)
        rep = f.createIfcShapeRepresentation(body, "Body", "Tessellation", [faceset])
        plate = run("root.create_entity", f, ifc_class="IfcPlate", name=f"ruledmesh {kind.label}",
                    predefined_type="CURTAIN_PANEL")
        plate.ObjectPlacement = f.createIfcLocalPlacement(origin, f.createIfcAxis2Placement3D(
            f.createIfcCartesianPoint((0.0, 0.0, 0.0)), None, None))
        plate.Representation = f.createIfcProductDefinitionShape(None, None, [rep])
        products.append(plate)
    if len(mesh.members):
        ends = mesh.vertices[mesh.members].tolist()
        lines = [f.createIfcPolyline([f.createIfcCartesianPoint(p), f.createIfcCartesianPoint(q)])
                 for p, q in ends]
        curves = f.createIfcGeometricCurveSet(lines)
        rep = f.createIfcShapeRepresentation(axis, "Axis", "GeometricCurveSet", [curves])
        member = run("root.create_entity", f, ifc_class="IfcMember", name="generators")
        member.ObjectPlacement = f.createIfcLocalPlacement(origin, f.createIfcAxis2Placement3D(
            f.createIfcCartesianPoint((0.0, 0.0, 0.0)), None, None))
        member.Representation = f.createIfcProductDefinitionShape(None, None, [rep])
        products.append(member)
    run("spatial.assign_container", f, products=products, relating_structure=site)
    return f.to_string().encode("utf-8")
