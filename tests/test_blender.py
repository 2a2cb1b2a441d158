"""The Blender add-on: the zip, and the add-on installed and run in headless Blender (bpy).

bpy from PyPI pins numpy < 2, so it usually lives in its own environment: set
RULEDMESH_BPY_PYTHON to a Python that has bpy and ruledmesh (.ci/run makes one);
without it the Blender tests run when bpy imports here and are skipped otherwise.
"""

import ast
import importlib.util
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import ruledmesh
from ruledmesh.cli import main

ROOT = Path(__file__).resolve().parents[1]
SKEW = ROOT / "examples" / "skew.toml"

SCRIPT = r'''
import json, sys
import bpy
import numpy as np

zip_path, design, bad = sys.argv[1:4]
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="ruledmesh_blender")
# File > Import lists the operator: the menu's draw functions include the add-on's.
draw = bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()
out = {"menu": any(getattr(f, "__module__", "") == "ruledmesh_blender" for f in draw)}


def summary(obj):
    me = obj.data
    n = len(me.polygons)
    totals = np.zeros(n, dtype=np.int32)
    me.polygons.foreach_get("loop_total", totals)
    kinds = np.zeros(n, dtype=np.int32)
    me.attributes["ruledmesh_kind"].data.foreach_get("value", kinds)
    mats = np.zeros(n, dtype=np.int32)
    me.polygons.foreach_get("material_index", mats)
    co = np.zeros(3 * len(me.vertices), dtype=np.float64)
    me.vertices.foreach_get("co", co)
    gens = bpy.data.objects[obj.ruledmesh.generators]
    return {"faces": n, "quads": int((totals == 4).sum()), "vertices": len(me.vertices),
            "kind_quads": int((kinds == 0).sum()), "kinds_are_materials": bool((kinds == mats).all()),
            "materials": [m.name for m in me.materials], "extent": float(np.ptp(co)),
            "generator_edges": len(gens.data.edges), "generator_faces": len(gens.data.polygons),
            "generators_parent": gens.parent == obj}


assert bpy.ops.ruledmesh.import_design(filepath=design) == {"FINISHED"}
obj = bpy.context.active_object
out["first"] = summary(obj)
out["panel"] = hasattr(bpy.types, "RULEDMESH_PT_design")
obj.ruledmesh.rows = 10
obj.ruledmesh.count = 21
assert bpy.ops.ruledmesh.rebuild() == {"FINISHED"}
out["rebuilt"] = summary(obj)
assert bpy.ops.ruledmesh.import_design(filepath=design, units="MM") == {"FINISHED"}
out["mm"] = summary(bpy.context.active_object)
bpy.context.scene.unit_settings.scale_length = 0.001  # scene in millimetres
assert bpy.ops.ruledmesh.import_design(filepath=design) == {"FINISHED"}
out["scene_mm"] = summary(bpy.context.active_object)
objects = len(bpy.data.objects)
try:
    bpy.ops.ruledmesh.import_design(filepath=bad)
    out["bad"] = "no error"
except RuntimeError as exc:
    out["bad"] = str(exc)
out["objects_added_by_bad"] = len(bpy.data.objects) - objects
print("RESULT " + json.dumps(out))
'''


def _bpy_python() -> str | None:
    given = os.environ.get("RULEDMESH_BPY_PYTHON")
    if given:
        return given
    if importlib.util.find_spec("bpy") is not None:
        return sys.executable
    return None


@pytest.fixture
def addon_zip(tmp_path, capsys):
    path = tmp_path / "ruledmesh_blender.zip"
    assert main(["blender-addon", "-o", str(path)]) == 0
    assert str(path) in capsys.readouterr().out
    return path


def test_zip_is_an_installable_addon(addon_zip):
    with zipfile.ZipFile(addon_zip) as zf:
        names = zf.namelist()
        source = zf.read("ruledmesh_blender/__init__.py").decode()
        config = json.loads(zf.read("ruledmesh_blender/config.json"))
    assert sorted(names) == ["ruledmesh_blender/__init__.py", "ruledmesh_blender/config.json"]
    tree = ast.parse(source)
    info = next(node.value for node in tree.body if isinstance(node, ast.Assign)
                and getattr(node.targets[0], "id", "") == "bl_info")
    bl_info = ast.literal_eval(info)
    version = tuple(int(p) for p in ruledmesh.__version__.split(".")[:3])
    assert bl_info["version"] == version and bl_info["category"] == "Import-Export"
    assert {"register", "unregister"} <= {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    assert config["ruledmesh_version"] == ruledmesh.__version__
    assert (Path(config["ruledmesh_path"]) / "ruledmesh" / "__init__.py").is_file()


def _obj_quads(path: Path) -> int:
    return sum(1 for line in path.read_text().splitlines()
               if line.startswith("f ") and len(line.split()) == 5)


def test_addon_in_headless_blender(addon_zip, tmp_path):
    python = _bpy_python()
    if python is None:
        pytest.skip("bpy is not installed here (bpy from PyPI pins numpy < 2): set "
                    "RULEDMESH_BPY_PYTHON to a Python with bpy and ruledmesh, as .ci/run does")
    obj = tmp_path / "skew.obj"
    assert main(["build", str(SKEW), "-o", str(obj), "-q"]) == 0
    bad = tmp_path / "bad.toml"
    bad.write_text(SKEW.read_text().replace("count = 41", 'count = "forty"'))
    script = tmp_path / "run.py"
    script.write_text(SCRIPT)
    env = {**os.environ, "BLENDER_USER_RESOURCES": str(tmp_path / "blender")}
    run = subprocess.run([python, str(script), str(addon_zip), str(SKEW), str(bad)],
                         check=False, capture_output=True, text=True, env=env, timeout=600,
                         cwd=tmp_path)
    lines = [line for line in run.stdout.splitlines() if line.startswith("RESULT ")]
    assert run.returncode == 0 and lines, run.stdout[-3000:] + run.stderr[-3000:]
    out = json.loads(lines[-1][len("RESULT "):])
    first = out["first"]
    mesh = ruledmesh.build(SKEW)
    # Quads kept: the same count as the OBJ of the same design.
    assert first["quads"] == _obj_quads(obj) == int(np.count_nonzero(mesh.valences == 4)) > 0
    assert first["faces"] == mesh.n_faces and first["vertices"] == mesh.n_vertices
    assert first["kind_quads"] == mesh.count_kinds()["quad"] and first["kinds_are_materials"]
    assert first["materials"][:2] == ["ruledmesh quad", "ruledmesh border"]
    assert first["generator_edges"] == len(mesh.members) and first["generator_faces"] == 0
    assert first["generators_parent"] and out["panel"] and out["menu"]
    # The sidebar's rows and generator count rebuild the object in place.
    design = {**ruledmesh.api._design(SKEW, None).data}
    design["mesh"] = {**design["mesh"], "rows": 10}
    design["rulings"] = {**design["rulings"], "count": 21}
    again = ruledmesh.build(design)
    assert out["rebuilt"]["quads"] == int(np.count_nonzero(again.valences == 4)) != first["quads"]
    assert out["rebuilt"]["generator_edges"] == len(again.members)
    # Units: metres to millimetres and a millimetre scene both scale the coordinates.
    assert out["mm"]["extent"] == pytest.approx(first["extent"] * 0.001, rel=1e-6)
    assert out["scene_mm"]["extent"] == pytest.approx(first["extent"] * 1000, rel=1e-6)
    assert "rulings.count" in out["bad"] and out["objects_added_by_bad"] == 0
