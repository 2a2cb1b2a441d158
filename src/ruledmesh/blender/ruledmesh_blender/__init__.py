"""ruledmesh for Blender: import a design file as a PQ mesh, rebuild it from the sidebar.

File > Import > ruledmesh design (.toml) builds the design with the ruledmesh
package installed in Blender's Python and adds

* a mesh object with the faces as built: planar quads stay quads, border
  faces stay n-gons; the face attribute ``ruledmesh_kind`` (integer, see
  ``ruledmesh.FaceKind``) and one material slot per face kind;
* an edge-only object ``<name> generators`` with the generator segments.

Coordinates are converted from the design's length unit (``units``, metres
when not stated) to the scene's units (Scene > Units > Unit Scale).  The
sidebar (N) tab "ruledmesh" shows the rows, generator count and option of
the selected design object; Rebuild builds it again with them.

Written by ``ruledmesh blender-addon -o ruledmesh_blender.zip``.
"""

from __future__ import annotations

import json
import os
import sys
import tomllib

import bpy
import numpy as np
from bpy.props import EnumProperty, IntProperty, PointerProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

bl_info = {
    "name": "ruledmesh",
    "author": "ruledmesh",
    "version": (0, 0, 0),  # set from ruledmesh.__version__ when the zip is written
    "blender": (4, 2, 0),
    "location": "File > Import > ruledmesh design (.toml); View3D > Sidebar > ruledmesh",
    "description": "Planar quad meshes of ruled surfaces from ruledmesh design files",
    "category": "Import-Export",
}

# Metres per design unit.
UNIT_METRES = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "ft": 0.3048}
KIND_NAMES = ("quad", "border", "fill", "split", "triangle", "polygon", "strip")
KIND_COLOURS = ((0.78, 0.80, 0.84), (0.94, 0.71, 0.31), (0.35, 0.65, 0.94),
                (0.90, 0.31, 0.31), (0.45, 0.80, 0.45), (0.71, 0.55, 0.84), (0.45, 0.72, 0.70))
_UNIT_ITEMS = [("AUTO", "From the design", "the design's units key (metres when not stated)")] + [
    (u.upper(), u, f"coordinates in {u}") for u in UNIT_METRES]


def _ruledmesh():
    """The installed ruledmesh package; the path recorded when the add-on was made as a fallback."""
    try:
        import ruledmesh
        return ruledmesh
    except ImportError:
        pass
    config = os.path.join(os.path.dirname(__file__), "config.json")
    path = ""
    if os.path.isfile(config):
        with open(config, encoding="utf-8") as fh:
            path = json.load(fh).get("ruledmesh_path", "")
    if path and os.path.isdir(path) and path not in sys.path:
        sys.path.append(path)  # after Blender's own packages: its numpy stays first
    try:
        import ruledmesh
        return ruledmesh
    except ImportError:
        raise RuntimeError("ruledmesh is not installed in Blender's Python: run "
                           f"'{sys.executable} -m pip install ruledmesh'") from None


def _expected_errors() -> tuple[type[BaseException], ...]:
    """Errors that are the design's fault (reported), not the add-on's (raised)."""
    found: tuple[type[BaseException], ...] = (OSError, ValueError, RuntimeError)
    try:
        return (_ruledmesh().RuledMeshError, *found)
    except RuntimeError:
        return found


class RuledmeshSettings(bpy.types.PropertyGroup):
    """What an imported design object remembers, for Rebuild."""

    design: StringProperty(name="Design", subtype="FILE_PATH",
                           description="design file the object was built from")
    rows: IntProperty(name="Rows", min=0, default=0,
                      description="divisions of the primary generator (0: as in the design)")
    count: IntProperty(name="Generators", min=0, default=0,
                       description="number of generators (0: as in the design)")
    option: IntProperty(name="Option", min=-1, max=1, default=-1,
                        description="checkerboard option 0 or 1 (-1: as in the design)")
    units: EnumProperty(name="Units", items=_UNIT_ITEMS, default="AUTO")
    generators: StringProperty(name="Generators object")


def _design_data(path: str, rows: int, count: int, option: int) -> dict:
    with open(path, "rb") as fh:
        data = tomllib.load(fh)
    mesh = data.setdefault("mesh", {})
    if rows > 0:
        mesh["rows"] = rows
    if option >= 0:
        mesh["option"] = option
    if count > 0 and isinstance(data.get("rulings"), dict) and "count" in data["rulings"]:
        data["rulings"]["count"] = count
    return data


def _scale(mesh, units: str, scene) -> float:
    """Blender units per design unit."""
    unit = mesh.info.get("units", "m") if units == "AUTO" else units.lower()
    metres = UNIT_METRES.get(str(unit), 1.0)
    return metres / (scene.unit_settings.scale_length or 1.0)


def _materials() -> list:
    mats = []
    for name, colour in zip(KIND_NAMES, KIND_COLOURS):
        mat = bpy.data.materials.get(f"ruledmesh {name}") or bpy.data.materials.new(f"ruledmesh {name}")
        mat.diffuse_color = (*colour, 1.0)
        mats.append(mat)
    return mats


def _face_mesh(name: str, mesh, scale: float):
    """A Blender mesh of the faces, set through foreach_set (no loop over vertices)."""
    me = bpy.data.meshes.new(name)
    me.vertices.add(mesh.n_vertices)
    me.vertices.foreach_set("co", (mesh.vertices * scale).astype(np.float32).ravel())
    me.loops.add(len(mesh.face_indices))
    me.loops.foreach_set("vertex_index", mesh.face_indices.astype(np.int32))
    me.polygons.add(mesh.n_faces)
    me.polygons.foreach_set("loop_start", mesh.face_offsets[:-1].astype(np.int32))
    kinds = mesh.face_kind.astype(np.int32)
    for mat in _materials():
        me.materials.append(mat)
    me.polygons.foreach_set("material_index", kinds)
    attr = me.attributes.new(name="ruledmesh_kind", type="INT", domain="FACE")
    attr.data.foreach_set("value", kinds)
    me.update()
    me.validate()
    return me


def _edge_mesh(name: str, mesh, scale: float):
    """A Blender mesh of the generator segments only."""
    used, local = np.unique(mesh.members, return_inverse=True)
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(used))
    me.vertices.foreach_set("co", (mesh.vertices[used] * scale).astype(np.float32).ravel())
    me.edges.add(len(mesh.members))
    me.edges.foreach_set("vertices", local.astype(np.int32).ravel())
    attr = me.attributes.new(name="ruledmesh_generator", type="INT", domain="EDGE")
    attr.data.foreach_set("value", mesh.member_id.astype(np.int32))
    me.update()
    return me


def _build(context, obj, settings) -> list[str]:
    """(Re)build ``obj`` and its generators object from ``settings``; returns the warnings."""
    rm = _ruledmesh()
    path = bpy.path.abspath(settings.design)
    data = _design_data(path, settings.rows, settings.count, settings.option)
    built = rm.build_full(data, base_dir=os.path.dirname(path))
    mesh = built.mesh
    scale = _scale(mesh, settings.units, context.scene)
    old = obj.data
    obj.data = _face_mesh(obj.name, mesh, scale)
    if old is not None and old.users == 0:
        bpy.data.meshes.remove(old)
    gens = bpy.data.objects.get(settings.generators)
    if len(mesh.members):
        edges = _edge_mesh(f"{obj.name} generators", mesh, scale)
        if gens is None:
            gens = bpy.data.objects.new(f"{obj.name} generators", edges)
            for collection in obj.users_collection:
                collection.objects.link(gens)
            gens.parent = obj
            settings.generators = gens.name
        else:
            previous, gens.data = gens.data, edges
            if previous.users == 0:
                bpy.data.meshes.remove(previous)
    obj["ruledmesh_faces"] = mesh.count_kinds()
    return list(mesh.info.get("warnings", []))


class RULEDMESH_OT_import_design(bpy.types.Operator, ImportHelper):
    """Build a ruledmesh design file and add its mesh and generators"""

    bl_idname = "ruledmesh.import_design"
    bl_label = "Import ruledmesh design"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender reads a plain set)
    filename_ext = ".toml"
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})
    units: EnumProperty(name="Units", items=_UNIT_ITEMS, default="AUTO",
                        description="length unit of the design's coordinates")

    def execute(self, context):
        name = os.path.splitext(os.path.basename(self.filepath))[0]
        obj = bpy.data.objects.new(name, bpy.data.meshes.new(name))
        context.collection.objects.link(obj)
        obj.ruledmesh.design = self.filepath
        obj.ruledmesh.units = self.units
        try:
            warnings = _build(context, obj, obj.ruledmesh)
        except _expected_errors() as exc:  # one line naming the field, for the status bar
            bpy.data.objects.remove(obj)
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        for warning in warnings:
            self.report({"WARNING"}, warning)
        for other in context.view_layer.objects:
            other.select_set(False)
        context.view_layer.objects.active = obj
        obj.select_set(True)
        return {"FINISHED"}


class RULEDMESH_OT_rebuild(bpy.types.Operator):
    """Build the selected design object again with the sidebar's rows, generators and option"""

    bl_idname = "ruledmesh.rebuild"
    bl_label = "Rebuild"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender reads a plain set)

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type == "MESH" and bool(obj.ruledmesh.design)

    def execute(self, context):
        obj = context.active_object
        try:
            warnings = _build(context, obj, obj.ruledmesh)
        except _expected_errors() as exc:  # keep the old mesh, say why
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        for warning in warnings:
            self.report({"WARNING"}, warning)
        return {"FINISHED"}


class RULEDMESH_PT_design(bpy.types.Panel):
    bl_label = "ruledmesh"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "ruledmesh"

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type == "MESH" and bool(obj.ruledmesh.design)

    def draw(self, context):
        settings = context.active_object.ruledmesh
        layout = self.layout
        layout.prop(settings, "design")
        layout.prop(settings, "rows")
        layout.prop(settings, "count")
        layout.prop(settings, "option")
        layout.prop(settings, "units")
        layout.operator(RULEDMESH_OT_rebuild.bl_idname)
        faces = context.active_object.get("ruledmesh_faces")
        if faces:
            layout.label(text=", ".join(f"{v} {k}" for k, v in faces.items()))


def _menu(self, context):
    self.layout.operator(RULEDMESH_OT_import_design.bl_idname, text="ruledmesh design (.toml)")


CLASSES = (RuledmeshSettings, RULEDMESH_OT_import_design, RULEDMESH_OT_rebuild, RULEDMESH_PT_design)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Object.ruledmesh = PointerProperty(type=RuledmeshSettings)
    bpy.types.TOPBAR_MT_file_import.append(_menu)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(_menu)
    del bpy.types.Object.ruledmesh
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
