"""A JSON Schema (draft 2020-12) of design files, read off the design layer's own readers.

The design layer reads each table through a few calls: ``Fields(table, "surface", [keys])``
and its typed accessors (``f.number("r", lo=0.0, lo_open=True)``, ``f.points(...)``,
``f.choice("style", Style)``), ``check_keys(table, KEYS, "mesh")``, ``mesh_counts(mesh, 4,
None)`` and the ``check_int(value, "mesh.rows", lo=1)`` family.  This module reads those calls
from the source of the design modules (the builders registered for each ``kind``, ``method``
and ``type``) and turns them into the schema, so the schema cannot drift from what the loader
accepts: a key added to a reader appears in the schema with it.

The schema checks what a reader checks locally: the table layout, the keys each ``kind`` /
``type`` / ``method`` allows, value types, simple bounds and choices.  Conditions between
values (``0 < first < second``, a polygon of distinct points) stay the loader's job.

Run ``ruledmesh schema`` (or ``python -m ruledmesh.design.schema``) to print it; point an
editor's TOML extension at the file (see ``docs/design-reference.md``).
"""

from __future__ import annotations

import ast
import enum
import functools
import importlib
import inspect
import sys
from collections.abc import Iterable
from typing import Any

__all__ = ["SCHEMA_DRAFT", "design_schema", "kind_choices", "kind_defaults", "main"]

SCHEMA_DRAFT = "https://json-schema.org/draft/2020-12/schema"

# Modules whose registered builders read the design tables.
_READERS = ("ruledmesh.design.catalogue", "ruledmesh.design.meshers", "ruledmesh.design.pq",
            "ruledmesh.design.transforms")
_DECORATORS = {"surface_kind": "surface", "mesh_method": "mesh", "transform_type": "transform"}
# Fields methods that read a value (``has`` and ``path`` only look).
_ACCESSORS = ("number", "integer", "boolean", "vector", "optional_vector", "points", "floats",
              "choice", "raw")
_NUMBER = {"type": "number"}
_VECTOR = {"type": "array", "items": _NUMBER}
_POINTS = {"type": "array", "items": _VECTOR}


def _constant(node: ast.AST, module: Any, local: dict | None = None) -> Any:
    """The value of a literal, of a literal assigned in the function (``local``) or of a
    module-level name, else ``None``."""
    try:
        return ast.literal_eval(node)
    except (ValueError, TypeError, SyntaxError):
        pass
    if isinstance(node, ast.Name):
        if local and node.id in local:
            return local[node.id]
        return getattr(module, node.id, None)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        v = _constant(node.operand, module)
        return -v if isinstance(v, (int, float)) else None
    return None


def _bounds(call: ast.Call, module: Any, schema: dict) -> dict:
    kw = {k.arg: _constant(k.value, module) for k in call.keywords if k.arg}
    out = dict(schema)
    for key, incl, excl, flag in (("lo", "minimum", "exclusiveMinimum", "lo_open"),
                                  ("hi", "maximum", "exclusiveMaximum", "hi_open")):
        v = kw.get(key)
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            out[excl if kw.get(flag) else incl] = v
    return out


def _value_schema(accessor: str, call: ast.Call, module: Any) -> dict:
    """The schema of one value read by ``accessor`` (a Fields method or a check_* helper),
    with the default a Fields method reads where it is a literal."""
    schema = _value_type(accessor, call, module)
    default = _default(accessor, call, module) if schema else None
    return {**schema, "default": default} if default is not None else schema


def _default(accessor: str, call: ast.Call, module: Any) -> Any:
    """The literal default of a ``Fields`` read (``f.number("a", 1.0)``), else None: none given,
    ``Fields.REQUIRED``, or one computed from other values (``f.number("b", a)``)."""
    at = {"number": 1, "integer": 1, "boolean": 1, "choice": 2}.get(accessor)
    if at is None:
        return None
    given = {k.arg: k.value for k in call.keywords if k.arg}
    node = call.args[at] if len(call.args) > at else given.get("default")
    if node is None:
        return None
    literal = isinstance(node, ast.Constant) or (
        isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub) and isinstance(node.operand, ast.Constant)
    ) or (isinstance(node, ast.Name) and node.id.isupper())
    value = _constant(node, module) if literal else None
    if accessor == "choice":
        kind = _constant(call.args[1], module)
        values = [m.value for m in kind] if isinstance(kind, type) and issubclass(kind, enum.Enum) else []
        return value if value in values else None
    if accessor == "boolean":
        return value if isinstance(value, bool) else None
    return value if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _value_type(accessor: str, call: ast.Call, module: Any) -> dict:
    """The type and bounds of one value read by ``accessor``."""
    kw = {k.arg: _constant(k.value, module) for k in call.keywords if k.arg}
    if accessor in ("number", "check_float"):
        return _bounds(call, module, _NUMBER)
    if accessor in ("integer", "check_int"):
        return _bounds(call, module, {"type": "integer"})
    if accessor in ("boolean", "check_bool"):
        return {"type": "boolean"}
    if accessor in ("vector", "optional_vector", "check_vector"):
        dim = kw.get("dim", 3)
        return {**_VECTOR, "minItems": dim, "maxItems": dim}
    if accessor in ("points", "check_points"):
        return _POINTS
    if accessor == "floats":
        count = kw.get("count")
        return {**_VECTOR, "minItems": count, "maxItems": count} if count else _VECTOR
    if accessor in ("choice", "check_choice"):
        kind = _constant(call.args[1], module)
        if isinstance(kind, type) and issubclass(kind, enum.Enum):
            return {"enum": [m.value for m in kind]}
    return {}


def _merge(old: dict | None, new: dict) -> dict:
    """Two readings of one key (two branches): keep what both say, or either when they differ."""
    if old is None or old == new:
        return new
    if not old or not new:
        return {}
    return {"anyOf": [old, new]}


class _Table:
    """Keys and value schemas one reader allows in one table."""

    def __init__(self) -> None:
        self.keys: list[str] = []
        self.values: dict[str, dict] = {}
        self.required: set[str] = set()

    def allow(self, keys: Iterable[str]) -> None:
        self.keys += [k for k in keys if k not in self.keys]

    def value(self, key: str, schema: dict) -> None:
        self.values[key] = _merge(self.values.get(key), schema)

    def schema(self, selector: str | None = None, name: str | None = None) -> dict:
        props: dict[str, Any] = {k: self.values.get(k, {}) for k in self.keys}
        if selector is not None and name is not None:
            props[selector] = {"const": name}
        out: dict[str, Any] = {"type": "object", "properties": props, "additionalProperties": False}
        if self.required - {selector}:
            out["required"] = sorted(self.required - {selector})
        return out


def _functions(tree: ast.Module) -> dict[str, ast.FunctionDef]:
    return {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}


def _bindings(fn: ast.AST, module: Any) -> tuple[dict[str, str], dict[str, Any], dict[str, Any]]:
    """Names in ``fn`` bound to a Fields object (-> its prefix), to a literal, and loop
    variables over a literal list (-> the list)."""
    variables: dict[str, str] = {}
    local: dict[str, Any] = {}
    loops: dict[str, Any] = {}
    for node in ast.walk(fn):
        if isinstance(node, ast.Assign) and len(node.targets) == 1 \
                and isinstance(node.targets[0], ast.Name):
            if isinstance(node.value, ast.Call) and _fields_prefix(node.value, module):
                variables[node.targets[0].id] = _fields_prefix(node.value, module) or ""
            else:
                value = _constant(node.value, module)
                if isinstance(value, (list, tuple, str)):
                    local[node.targets[0].id] = value
        elif isinstance(node, (ast.comprehension, ast.For)) and isinstance(node.target, ast.Name):
            values = _constant(node.iter, module, local)
            if isinstance(values, (list, tuple)):
                loops[node.target.id] = values
    return variables, local, loops


def _read_function(fn: ast.FunctionDef | ast.Module, module: Any, tables: dict[str, _Table],
                   functions: dict[str, ast.FunctionDef], seen: set[str]) -> None:
    """Record what ``fn`` (and the module's functions it calls) read, by table prefix."""
    seen = seen | {getattr(fn, "name", "")}
    variables, local, loops = _bindings(fn, module)
    parents = {child: node for node in ast.walk(fn) for child in ast.iter_child_nodes(node)}
    for node in ast.walk(fn):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        name = func.id if isinstance(func, ast.Name) else None
        if name in functions and name not in seen:
            _read_function(functions[name], module, tables, functions, seen)
        prefix = _fields_prefix(node, module)
        if prefix:
            tables.setdefault(prefix, _Table()).allow(_constant(node.args[2], module, local) or ())
        elif name == "check_keys" and len(node.args) >= 3:
            keys, where = _constant(node.args[1], module, local), _constant(node.args[2], module)
            if isinstance(where, str) and keys:
                tables.setdefault(where, _Table()).allow(keys)
        elif name == "mesh_counts":
            defaults = [_constant(a, module) for a in node.args[1:3]]
            mesh = tables.setdefault("mesh", _Table())
            kw = {k.arg: _constant(k.value, module) for k in node.keywords if k.arg}
            for key, default in zip(("u", "v"), defaults):
                if default is not None:
                    mesh.allow([key])
                    mesh.value(key, {"type": "integer", "minimum": kw.get(f"min_{key}", 1), "default": default})
        elif name and name.startswith("check_") and len(node.args) >= 2:
            where = _constant(node.args[1] if name != "check_choice" else node.args[2], module)
            if isinstance(where, str) and "." in where and _direct(node.args[0]):
                table, key = where.rsplit(".", 1)
                schema = _value_schema(name, node, module)
                tables.setdefault(table, _Table()).value(key, _or_words(schema, node, parents))
        elif (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
              and func.value.id in variables and func.attr in _ACCESSORS and node.args):
            arg = node.args[0]
            one = _constant(arg, module, local)
            keys = [one] if isinstance(one, str) else (
                loops.get(arg.id, ()) if isinstance(arg, ast.Name) else ())
            for key in keys:
                target = tables.setdefault(variables[func.value.id], _Table())
                target.value(key, _value_schema(func.attr, node, module))
                if (len(node.args) > 1 and isinstance(node.args[1], ast.Attribute)
                        and node.args[1].attr == "REQUIRED" and not _branched(node, parents)):
                    target.required.add(key)


def _direct(arg: ast.AST) -> bool:
    """Whether a check_* call checks the design value itself (not a reshaped copy of it)."""
    if isinstance(arg, ast.Name | ast.Subscript):
        return True
    return (isinstance(arg, ast.Call) and isinstance(arg.func, ast.Attribute)
            and arg.func.attr == "get")


def _branched(node: ast.AST, parents: dict) -> bool:
    """Whether ``node`` runs only on some paths (inside an ``if``)."""
    while node in parents:
        node = parents[node]
        if isinstance(node, ast.If | ast.IfExp):
            return True
    return False


def _or_words(schema: dict, call: ast.Call, parents: dict) -> dict:
    """``schema`` or the words the surrounding branches accept instead (``"auto"``, ``"middle"``).

    A reader that takes ``extend = "auto"`` or a number checks the number inside
    ``if extend != "auto":``; the word compared with the same variable is the other choice.
    """
    arg = call.args[0]
    if not schema or not isinstance(arg, ast.Name):
        return schema
    words: list[str] = []
    node: ast.AST = call
    while node in parents:
        node = parents[node]
        if isinstance(node, ast.If):
            for sub in ast.walk(node):
                if (isinstance(sub, ast.Compare) and isinstance(sub.left, ast.Name)
                        and sub.left.id == arg.id):
                    words += [c.value for c in sub.comparators
                              if isinstance(c, ast.Constant) and isinstance(c.value, str)]
    return {"anyOf": [schema, {"enum": sorted(set(words))}]} if words else schema


def _fields_prefix(call: ast.Call, module: Any) -> str | None:
    """The table prefix of a ``Fields(table, prefix, keys)`` (or ``_fields``) call, else None."""
    func = call.func
    if isinstance(func, ast.Name) and func.id in ("Fields", "_fields") and len(call.args) >= 3:
        prefix = _constant(call.args[1], module)
        return prefix if isinstance(prefix, str) else "<path>"
    return None


def _registered(module_name: str) -> list[tuple[str, str, dict[str, _Table]]]:
    """(registry, name, tables read) for every builder a design module registers."""
    module = importlib.import_module(module_name)
    tree = ast.parse(inspect.getsource(module))
    functions = _functions(tree)
    out = []
    for fn in functions.values():
        for deco in fn.decorator_list:
            if (isinstance(deco, ast.Call) and isinstance(deco.func, ast.Name)
                    and deco.func.id in _DECORATORS and deco.args):
                tables: dict[str, _Table] = {}
                _read_function(fn, module, tables, functions, set())
                out.append((_DECORATORS[deco.func.id], _constant(deco.args[0], module), tables))
    return out


def _profile_schema() -> dict:
    """``{type = "arc", ...}`` tables of :func:`ruledmesh.design.profiles.profile_from_spec`."""
    module = importlib.import_module("ruledmesh.design.profiles")
    fn = _functions(ast.parse(inspect.getsource(module)))["profile_from_spec"]
    branches = []
    for node in ast.walk(fn):
        if (isinstance(node, ast.If) and isinstance(node.test, ast.Compare)
                and isinstance(node.test.comparators[0], ast.Constant)):
            kind = node.test.comparators[0].value
            tables: dict[str, _Table] = {}
            branch = ast.Module(body=node.body, type_ignores=[])
            _read_function(branch, module, tables, {}, {"profile_from_spec"})
            table = tables.get("<path>", _Table())
            branches.append(_conditional("type", str(kind), table, default=kind == "polyline"))
    # A bare list of points is a polyline too.
    return {"anyOf": [_POINTS, {"type": "object", "properties": {"type": {"enum": [
        b["if"]["properties"]["type"]["const"] for b in branches]}}, "allOf": branches}]}


def _conditional(selector: str, name: str, table: _Table, *, default: bool = False) -> dict:
    """``if selector == name then`` the keys and values of ``table``."""
    cond: dict[str, Any] = {"properties": {selector: {"const": name}}}
    if not default:
        cond["required"] = [selector]
    then = table.schema(selector, name)
    then.pop("type")
    return {"if": cond, "then": then}


def _curve_values(reader: Any, table: _Table) -> None:
    """Value schemas of one ``[curves.NAME]`` reader (``_line(t)``, ``_helix(t)``, ...).

    Its table ``t`` reads ``t.points(key)``, ``t.vector(key)``, ``t.number(key, default=...)``
    (all required unless given a default or read on one branch only) and
    ``check_int(t.spec.get(key, ...), t.field(key), ...)``.
    """
    module = inspect.getmodule(reader)
    fn = ast.parse(inspect.getsource(reader)).body[0]
    if not isinstance(fn, ast.FunctionDef):
        raise TypeError(f"curve reader {reader!r} is not a plain function: its schema cannot be read")
    t = fn.args.args[0].arg
    parents = {child: node for node in ast.walk(fn) for child in ast.iter_child_nodes(node)}
    for node in ast.walk(fn):
        if not (isinstance(node, ast.Call) and node.args):
            continue
        func = node.func
        if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
                and func.value.id == t and func.attr in ("points", "vector", "number")):
            key = _constant(node.args[0], module)
            if isinstance(key, str):
                table.value(key, _value_schema(func.attr, node, module))
                if not (_branched(node, parents) or _after_early_return(node, fn, parents)
                        or any(k.arg == "default" for k in node.keywords)):
                    table.required.add(key)
        elif (isinstance(func, ast.Name) and func.id.startswith("check_") and len(node.args) >= 2
              and isinstance(node.args[1], ast.Call) and node.args[1].args):
            key = _constant(node.args[1].args[0], module)
            if isinstance(key, str):
                table.value(key, _value_schema(func.id, node, module))


def _after_early_return(node: ast.AST, fn: ast.FunctionDef, parents: dict) -> bool:
    """Whether ``node`` runs only when an earlier ``if ...: return`` of ``fn`` did not return."""
    while parents.get(node) is not fn:
        node = parents[node]
    earlier = fn.body[:fn.body.index(node)]
    return any(isinstance(st, ast.If) and any(isinstance(n, ast.Return) for n in ast.walk(st))
               for st in earlier)


def _curve_schema() -> dict:
    from ..curves import CurveType
    from .curves import _KEYS, _READERS

    branches = []
    for kind, keys in _KEYS.items():
        table = _Table()
        table.allow(keys)
        _curve_values(_READERS[kind], table)
        branches.append(_conditional("type", kind.value, table))
    return {"type": "object", "required": ["type"],
            "properties": {"type": {"enum": [t.value for t in CurveType]}}, "allOf": branches}


def _rulings_schema() -> dict:
    from .rulings import _RULINGS_KEYS

    table = _Table()
    table.allow(_RULINGS_KEYS)
    return table.schema()


def _found() -> dict[str, dict[str, dict[str, _Table]]]:
    """What each registered builder reads: registry -> name -> table prefix -> :class:`_Table`."""
    from ..registry import MESH_METHODS, SURFACE_KINDS, TRANSFORMS, load_plugins

    load_plugins()
    found: dict[str, dict[str, dict[str, _Table]]] = {"surface": {}, "mesh": {}, "transform": {}}
    for name in _READERS:
        for registry, key, tables in _registered(name):
            found[registry][key] = tables
    missing = [(r, k) for r, names in (("surface", SURFACE_KINDS), ("mesh", MESH_METHODS),
                                       ("transform", TRANSFORMS)) for k in names if k not in found[r]]
    if missing:  # a builder registered from a module not listed in _READERS
        raise RuntimeError(f"no reader found for {missing}; add its module to _READERS")
    return found


def _surface_branches(found: dict, mesh_keys: _Table) -> tuple[list[dict], list[dict]]:
    """Per surface kind: the ``[surface]`` keys, and the ``[mesh]`` keys it allows."""
    surface, mesh_branches = [], []
    for kind, tables in sorted(found["surface"].items()):
        table = tables.get("surface", _Table())
        for key, sub in tables.items():  # nested tables read with their own Fields
            if key.startswith("surface.") and key.count(".") == 1:
                table.value(key.split(".")[1], sub.schema())
        for key in table.keys:  # raw values handed to profile_from_spec
            if not table.values.get(key) and _reads_profile(kind, key):
                table.value(key, {"$ref": "#/$defs/profile"})
        surface.append(_conditional("kind", kind, table))
        mesh = tables.get("mesh", _Table())
        mesh_keys.allow(mesh.keys)
        mesh_branches.append({"if": {"required": ["surface"], "properties": {
            "surface": {"required": ["kind"], "properties": {"kind": {"const": kind}}}}},
            "then": {"properties": {"mesh": mesh.schema()}}})
    return surface, mesh_branches


def _method_branches(found: dict, mesh_keys: _Table) -> list[dict]:
    """Per mesh method of a ``[rulings]`` design: the ``[mesh]`` keys it allows."""
    branches = []
    for method, tables in sorted(found["mesh"].items()):
        mesh = tables.get("mesh", _Table())
        mesh_keys.allow(mesh.keys)
        # A [rulings] design without [mesh] method is meshed by "pq".
        which: dict[str, Any] = {"properties": {"method": {"const": method}}}
        if method != "pq":
            which["required"] = ["method"]
        branches.append({"if": {"required": ["rulings"], "properties": {"mesh": which}},
                         "then": {"properties": {"mesh": mesh.schema()}}})
    return branches


def design_schema() -> dict:
    """The JSON Schema (draft 2020-12) of a design file, as a dict ready for :func:`json.dumps`.

    Returns
    -------
    dict
    """
    from .. import __version__
    from ..units import Unit
    from . import TOP_LEVEL

    found = _found()
    mesh_keys = _Table()
    surface_branches, mesh_branches = _surface_branches(found, mesh_keys)
    mesh_branches += _method_branches(found, mesh_keys)
    mesh_schema = mesh_keys.schema()
    mesh_schema["properties"]["method"] = {"enum": sorted(found["mesh"])}
    transform_branches = [_conditional("type", t, tables.get("<path>", _Table()))
                          for t, tables in sorted(found["transform"].items())]
    properties: dict[str, Any] = {
        "name": {"type": "string"},
        "description": {"type": "string"},
        "units": {"enum": [u.value for u in Unit]},
        "curves": {"type": "object", "additionalProperties": {"$ref": "#/$defs/curve"}},
        "rulings": _rulings_schema(),
        "mesh": mesh_schema,
        "surface": {"type": "object", "required": ["kind"],
                    "properties": {"kind": {"enum": sorted(found["surface"])}},
                    "allOf": surface_branches},
        "transform": {"type": "array", "items": {
            "type": "object", "required": ["type"],
            "properties": {"type": {"enum": sorted(found["transform"])}},
            "allOf": transform_branches}},
    }
    unknown = set(properties) ^ set(TOP_LEVEL)
    if unknown:
        raise RuntimeError(f"top-level tables out of step with the loader: {sorted(unknown)}")
    return {
        "$schema": SCHEMA_DRAFT,
        "$id": f"urn:ruledmesh:design:{__version__}",
        "title": "ruledmesh design file",
        "description": "A ruledmesh design: [surface] (a catalogue kind) or [curves.*] with "
                       "[rulings], then [mesh] and [[transform]]. Generated by `ruledmesh schema`.",
        "type": "object",
        "properties": properties,
        "additionalProperties": False,
        "not": {"required": ["surface", "rulings"]},
        "allOf": mesh_branches,
        "$defs": {"curve": _curve_schema(), "profile": _profile_schema()},
    }


def kind_defaults() -> dict[str, dict[str, dict[str, Any]]]:
    """The defaults of each catalogue kind's numeric, boolean and choice fields, as its builder
    reads them: ``{kind: {"surface": {key: default}, "mesh": {key: default}}}``.

    Only literal defaults: a key whose default follows from another value (the hyperboloid's
    ``b``, ``a`` unless given) or that the design must give is not listed.  The designer
    shows these as grey fields, so that a kind built from its defaults can be edited.
    """
    return _kind_fields()[0]


def kind_choices() -> dict[str, dict[str, list[str]]]:
    """The words each catalogue kind's ``[surface]`` choice fields take, as its builder reads
    them: ``{kind: {key: [word, ...]}}`` (the hyperboloid's ``style``); the designer's menus."""
    return _kind_fields()[1]


@functools.cache
def _kind_fields() -> tuple[dict[str, dict[str, dict[str, Any]]], dict[str, dict[str, list[str]]]]:
    """:func:`kind_defaults` and :func:`kind_choices`, from one reading of the builders (about
    half a second: a designer session reads them when it starts, see :mod:`ruledmesh.web.session`)."""
    defaults: dict[str, dict[str, dict[str, Any]]] = {}
    choices: dict[str, dict[str, list[str]]] = {}
    for kind, tables in sorted(_found()["surface"].items()):
        defaults[kind] = {
            table: {key: value["default"] for key, value in tables[table].values.items()
                    if "default" in value and isinstance(value["default"], (bool, int, float, str))}
            for table in ("surface", "mesh") if table in tables}
        values = tables["surface"].values if "surface" in tables else {}
        choices[kind] = {key: list(value["enum"]) for key, value in values.items()
                         if isinstance(value.get("enum"), list) and all(isinstance(w, str) for w in value["enum"])}
    return defaults, choices


def _reads_profile(kind: str, key: str) -> bool:
    """Whether the builder of ``kind`` hands ``surface.key`` to ``profile_from_spec``."""
    module = importlib.import_module("ruledmesh.design.catalogue")
    for fn in _functions(ast.parse(inspect.getsource(module))).values():
        if not any(isinstance(d, ast.Call) and d.args and _constant(d.args[0], module) == kind
                   for d in fn.decorator_list):
            continue
        for node in ast.walk(fn):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id == "profile_from_spec" and node.args):
                arg = node.args[0]
                if (isinstance(arg, ast.Call) and arg.args
                        and _constant(arg.args[0], module) == key):
                    return True
    return False


def main(argv: list[str] | None = None) -> int:
    """Print the schema (``python -m ruledmesh.design.schema [OUT.json]``); 0 on success."""
    import json

    args = sys.argv[1:] if argv is None else list(argv)
    text = json.dumps(design_schema(), indent=2) + "\n"
    if args:
        from ..io import write_atomic

        write_atomic(args[0], text.encode("utf-8"))
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
