"""The JSON Schema of design files: read off the loader, so schema and loader agree.

Every bundled example validates; designs the loader refuses for a local reason (an unknown
key, a wrong type, a value out of bounds, an unknown choice) are refused by the schema too.
"""

from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path

import jsonschema
import pytest

from ruledmesh.cli import main
from ruledmesh.design import build_design, design_from_tables
from ruledmesh.design.schema import SCHEMA_DRAFT, design_schema
from ruledmesh.errors import DesignError

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))


@pytest.fixture(scope="module")
def validator() -> jsonschema.Draft202012Validator:
    schema = design_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def test_schema_is_draft_2020_12_and_names_every_registered_builder(validator):
    from ruledmesh.registry import MESH_METHODS, SURFACE_KINDS, TRANSFORMS

    schema = validator.schema
    assert schema["$schema"] == SCHEMA_DRAFT
    props = schema["properties"]
    assert set(props["surface"]["properties"]["kind"]["enum"]) == set(SURFACE_KINDS)
    assert set(props["mesh"]["properties"]["method"]["enum"]) == set(MESH_METHODS)
    assert set(props["transform"]["items"]["properties"]["type"]["enum"]) == set(TRANSFORMS)


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_every_example_validates(validator, path):
    errors = [f"{list(e.absolute_path)}: {e.message}"
              for e in validator.iter_errors(tomllib.loads(path.read_text(encoding="utf-8")))]
    assert not errors, errors


def _example(name: str) -> dict:
    return tomllib.loads((ROOT / "examples" / f"{name}.toml").read_text(encoding="utf-8"))


def _changed(name: str, *edits) -> dict:
    data = copy.deepcopy(_example(name))
    for path, value in edits:
        table = data
        for key in path[:-1]:
            table = table[key]
        if value is _DELETE:
            del table[path[-1]]
        else:
            table[path[-1]] = value
    return data


_DELETE = object()

# (example, edits, the field the loader names)
BAD = [
    ("fig5b-torus", [(("colour",), "red")], ""),
    ("fig5b-torus", [(("surface", "radius"), 1.0)], "surface"),
    ("fig5b-torus", [(("surface", "r"), -1.0)], "surface.r"),
    ("fig5b-torus", [(("surface", "r"), "one")], "surface.r"),
    ("fig5b-torus", [(("surface", "kind"), "doughnut")], "surface.kind"),
    ("fig5b-torus", [(("mesh", "rows"), 20)], "mesh"),
    ("fig5b-torus", [(("mesh", "u"), "many")], "mesh.u"),
    ("fig5b-torus", [(("units",), "furlong")], "units"),
    ("fig7b-hyperboloid-circular", [(("surface", "style"), "circle")], "surface.style"),
    ("fig5a-transformed-rotational", [(("transform", 0, "xw"), 1.0)], "transform"),
    ("skew", [(("mesh", "rows"), 0)], "mesh.rows"),
    ("skew", [(("mesh", "extend"), "far")], "mesh.extend"),
    ("skew", [(("mesh", "respace"), "sometimes")], "mesh.respace"),
    ("skew", [(("mesh", "rows_from"), "c3")], "mesh.rows_from"),
    ("skew", [(("mesh", "method"), "quads")], "mesh.method"),
    ("skew", [(("mesh", "divisions"), 4)], "mesh"),
    ("skew", [(("surface",), {"kind": "torus", "R": 3.0, "r": 1.0})], "rulings"),
    ("hybrid-fig9", [(("mesh", "rows"), 4)], "mesh"),
]


@pytest.mark.parametrize("name,edits,field", BAD, ids=[f"{b[0]}-{b[2] or 'top'}-{i}"
                                                     for i, b in enumerate(BAD)])
def test_bad_designs_are_refused_by_schema_and_loader(validator, name, edits, field):
    data = _changed(name, *edits)
    assert list(validator.iter_errors(data)), f"the schema accepts {edits}"
    with pytest.raises(DesignError) as err:
        build_design(design_from_tables(data, f"{name}.toml", base_dir=ROOT / "examples"))
    assert (err.value.field or "").startswith(field), (err.value.field, field)


def test_curve_with_a_key_of_another_type_is_refused(validator):
    data = _example("skew")
    curve = next(iter(data["curves"].values()))
    curve["pitch"] = 1.0  # a helix key on another curve type
    assert list(validator.iter_errors(data))
    with pytest.raises(DesignError):
        build_design(design_from_tables(data, "skew.toml", base_dir=ROOT / "examples"))


@pytest.mark.parametrize("curve,key,value", [
    ("c1", "degree", 7),            # a B-spline of degree 1..5
    ("c1", "points", "abc"),        # points are lists of numbers
    ("c2", "type", "bsplin"),       # an unknown curve type
])
def test_bad_curves_are_refused_by_schema_and_loader(validator, curve, key, value):
    data = _example("skew")
    data["curves"][curve][key] = value
    assert list(validator.iter_errors(data)), f"the schema accepts curves.{curve}.{key} = {value!r}"
    with pytest.raises(DesignError) as err:
        build_design(design_from_tables(data, "skew.toml", base_dir=ROOT / "examples"))
    assert err.value.field == f"curves.{curve}.{key}"


def test_cli_writes_the_schema(tmp_path, capsys):
    out = tmp_path / "design.schema.json"
    assert main(["schema", "-o", str(out)]) == 0
    assert json.loads(out.read_text(encoding="utf-8")) == design_schema()
    assert capsys.readouterr().out == f"wrote {out}\n"
    assert main(["schema"]) == 0
    assert json.loads(capsys.readouterr().out) == design_schema()
