"""IFC4 (via IfcOpenShell): one ``IfcPlate`` per panel, in a spatial structure.

IFC's tessellated geometry (``IfcIndexedPolygonalFace``) requires planar
faces, which is exactly what a PQ mesh provides: every quad, border pentagon
and fill triangle is one polygonal face, none split.  Layout::

    IfcProject (units: the mesh's, IfcSIUnit or IfcConversionBasedUnit for in/ft)
      IfcSite "site" > IfcBuilding "building" > IfcBuildingStorey "level 0"
        IfcElementAssembly "ruledmesh <kind>"   one per face kind present
          IfcPlate "P<f>"                        one per face (panels="each")
        IfcMember "generators"                   the members, 'Axis' curves

Each plate (predefined type ``CURTAIN_PANEL``) has Name and Tag equal to the
panel label of the fabrication sheets and schedules (``P0``, ``P1``, ...), a
'Body' representation that is one ``IfcPolygonalFaceSet`` face, and the
property set ``ruledmesh_Panel`` with ``Label``, ``Kind``, ``Area`` (area
unit of the project), ``Planarity`` (corner distance from the best-fit
plane over the panel diameter) and ``FaceIndex``.  ``panels="joined"``
writes one plate per face kind instead (all its faces in one face set), for
meshes too large to be handled panel by panel.  Members become one
``IfcMember`` whose 'Axis' representation is an ``IfcGeometricCurveSet`` of
two-point polylines.  Requires ``ifcopenshell`` (``pip install ruledmesh[ifc]``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..mesh import FaceKind, Mesh
from ..units import Unit, unit_of
from ._panels import check_panels, panel_data

__all__ = ["PSET", "dumpb"]

PSET = "ruledmesh_Panel"
# SI prefix of each metric unit, and IfcOpenShell's names of the imperial ones.
_SI_PREFIX = {Unit.M: None, Unit.CM: "CENTI", Unit.MM: "MILLI"}
_IMPERIAL = {Unit.IN: ("inch", "square inch"), Unit.FT: ("foot", "square foot")}


def _import_ifcopenshell():
    from . import require

    for sub in ("ifcopenshell.api", "ifcopenshell.guid"):
        require(sub, "ifc", "IFC export")
    return require("ifcopenshell", "ifc", "IFC export")


def _assign_units(f, run, unit: Unit) -> None:
    """Project length and area units of ``unit``; angles in radians."""
    if unit in _IMPERIAL:
        length_name, area_name = _IMPERIAL[unit]
        length = run("unit.add_conversion_based_unit", f, name=length_name)
        area = run("unit.add_conversion_based_unit", f, name=area_name)
    else:
        length = run("unit.add_si_unit", f, unit_type="LENGTHUNIT", prefix=_SI_PREFIX[unit])
        area = run("unit.add_si_unit", f, unit_type="AREAUNIT", prefix=_SI_PREFIX[unit])
    angle = run("unit.add_si_unit", f, unit_type="PLANEANGLEUNIT")
    run("unit.assign_unit", f, units=[length, area, angle])


class _Writer:
    """The IFC file under construction and the shared entities."""

    def __init__(self, mesh: Mesh):
        self.ifc = _import_ifcopenshell()
        self.run = self.ifc.api.run
        f = self.f = self.run("project.create_file", version="IFC4")
        self.mesh = mesh
        name = str(mesh.info.get("construction", "ruledmesh"))
        project = self.run("root.create_entity", f, ifc_class="IfcProject", name=name)
        _assign_units(f, self.run, unit_of(mesh.units))
        model = self.run("context.add_context", f, context_type="Model")
        self.body = self.run("context.add_context", f, context_type="Model",
                             context_identifier="Body", target_view="MODEL_VIEW", parent=model)
        self.axis = self.run("context.add_context", f, context_type="Model",
                             context_identifier="Axis", target_view="GRAPH_VIEW", parent=model)
        parent, placement = project, None
        for ifc_class, label in (("IfcSite", "site"), ("IfcBuilding", "building"),
                                 ("IfcBuildingStorey", "level 0")):
            spatial = self.run("root.create_entity", f, ifc_class=ifc_class, name=label)
            self.run("aggregate.assign_object", f, products=[spatial], relating_object=parent)
            placement = spatial.ObjectPlacement = self.placement(placement)
            parent = spatial
        self.storey, self.origin = parent, placement

    def placement(self, relative_to=None):
        """An identity placement relative to ``relative_to``."""
        f = self.f
        return f.createIfcLocalPlacement(relative_to, f.createIfcAxis2Placement3D(
            f.createIfcCartesianPoint((0.0, 0.0, 0.0)), None, None))

    def entity(self, ifc_class: str, name: str | None, **attrs: Any):
        """A rooted entity with a fresh GlobalId (faster than the API's root.create_entity)."""
        return self.f.create_entity(ifc_class, GlobalId=self.ifc.guid.new(), Name=name, **attrs)

    def faceset_shape(self, points: list, faces: list):
        """An IfcProductDefinitionShape: one polygonal face set.

        ``points`` are (x, y, z) lists, ``faces`` lists of 1-based indices into them.
        """
        f = self.f
        faceset = f.createIfcPolygonalFaceSet(
            f.createIfcCartesianPointList3D(points), False,
            [f.createIfcIndexedPolygonalFace(face) for face in faces], None)
        rep = f.createIfcShapeRepresentation(self.body, "Body", "Tessellation", [faceset])
        return f.createIfcProductDefinitionShape(None, None, [rep])

    def shapes(self, ids: np.ndarray, panels: str) -> list:
        """The shapes of faces ``ids``: one per face, or one of all of them."""
        mesh = self.mesh
        if panels == "each":
            corners = np.split(mesh.vertices[mesh.face_indices], mesh.face_offsets[1:-1])
            return [self.faceset_shape(corners[i].tolist(), [list(range(1, len(corners[i]) + 1))])
                    for i in ids.tolist()]
        sub = mesh.select_faces(np.isin(np.arange(mesh.n_faces), ids))
        used, local = np.unique(sub.face_indices, return_inverse=True)
        faces = [x.tolist() for x in np.split(local.reshape(-1) + 1, sub.face_offsets[1:-1])]
        return [self.faceset_shape(mesh.vertices[used].tolist(), faces)]

    def pset(self, product, values: list) -> None:
        """Attach the ``ruledmesh_Panel`` property set ``values`` to ``product``."""
        f = self.f
        props = [f.createIfcPropertySingleValue(key, None, f.create_entity(kind, value), None)
                 for key, kind, value in values]
        pset = self.entity("IfcPropertySet", PSET, HasProperties=props)
        self.entity("IfcRelDefinesByProperties", None, RelatedObjects=[product],
                    RelatingPropertyDefinition=pset)

    def plates(self, panels: str) -> list:
        """The assemblies of plates, one assembly per face kind."""
        mesh = self.mesh
        data = panel_data(mesh)
        assemblies = []
        for kind in np.unique(mesh.face_kind).tolist():
            kind = FaceKind(kind)
            ids = np.flatnonzero(mesh.face_kind == kind)
            assembly = self.entity("IfcElementAssembly", f"ruledmesh {kind.label}",
                                   ObjectPlacement=self.placement(self.origin),
                                   PredefinedType="USERDEFINED", ObjectType="panels")
            groups = ([np.array([i]) for i in ids.tolist()] if panels == "each" else [ids])
            parts = []
            for group, shape in zip(groups, self.shapes(ids, panels)):
                one = panels == "each"
                name = str(data.label[group[0]]) if one else f"ruledmesh {kind.label}"
                plate = self.entity("IfcPlate", name, Tag=name if one else None,
                                    ObjectPlacement=self.placement(assembly.ObjectPlacement),
                                    Representation=shape,
                                    PredefinedType="CURTAIN_PANEL")
                i = int(group[0])
                values = ([("Label", "IfcLabel", name), ("Kind", "IfcLabel", kind.label),
                           ("Area", "IfcAreaMeasure", float(data.area[i])),
                           ("Planarity", "IfcRatioMeasure", float(data.planarity[i])),
                           ("FaceIndex", "IfcInteger", i)] if one else
                          [("Kind", "IfcLabel", kind.label),
                           ("Area", "IfcAreaMeasure", float(data.area[group].sum())),
                           ("Planarity", "IfcRatioMeasure", float(data.planarity[group].max())),
                           ("Faces", "IfcInteger", int(group.size))])
                self.pset(plate, values)
                parts.append(plate)
            self.entity("IfcRelAggregates", None, RelatingObject=assembly, RelatedObjects=parts)
            assemblies.append(assembly)
        return assemblies

    def members(self) -> list:
        """The generators as one IfcMember (empty when the mesh has none)."""
        mesh, f = self.mesh, self.f
        if not len(mesh.members):
            return []
        ends = mesh.vertices[mesh.members].tolist()
        lines = [f.createIfcPolyline([f.createIfcCartesianPoint(p), f.createIfcCartesianPoint(q)])
                 for p, q in ends]
        curves = f.createIfcGeometricCurveSet(lines)
        rep = f.createIfcShapeRepresentation(self.axis, "Axis", "GeometricCurveSet", [curves])
        member = self.entity("IfcMember", "generators", ObjectPlacement=self.placement(self.origin),
                             Representation=f.createIfcProductDefinitionShape(None, None, [rep]),
                             PredefinedType="USERDEFINED", ObjectType="generators")
        return [member]


def dumpb(mesh: Mesh, panels: str = "each") -> bytes:
    """The IFC4 (STEP physical file) bytes of ``mesh``.

    Parameters
    ----------
    mesh : Mesh
        Its :attr:`~ruledmesh.mesh.Mesh.units` become the project units.
    panels : {"each", "joined"}
        One ``IfcPlate`` per face (default), or one per face kind.

    Returns
    -------
    bytes
    """
    panels = check_panels(panels)
    w = _Writer(mesh)
    products = w.plates(panels) + w.members()
    w.entity("IfcRelContainedInSpatialStructure", "panels", RelatedElements=products,
             RelatingStructure=w.storey)
    return w.f.to_string().encode("utf-8")
