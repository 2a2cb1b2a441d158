"""The Hops wire format: component metadata and solve payloads, as plain JSON.

Grasshopper's Hops component asks a server for a component's description
with ``GET /<name>`` and solves it with ``POST /<name>`` (or ``POST /solve``
with ``"pointer": "/<name>"``).  Both carry JSON; every value travels as
``{"type": <.NET type>, "data": <JSON text>}`` inside a data tree
``{"ParamName": ..., "InnerTree": {"{0}": [values...]}}``.  This module
turns component definitions into that metadata and payloads into Python
values; it knows nothing about geometry (see :mod:`.geometry`).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..errors import ParameterError

__all__ = ["Component", "Param", "metadata", "output_tree", "read_inputs", "value_item"]

# Hops parameter type -> the .NET type of its values in a payload.
RESULT_TYPES = {
    "Integer": "System.Int32",
    "Number": "System.Double",
    "Text": "System.String",
    "Boolean": "System.Boolean",
    "Curve": "Rhino.Geometry.Curve",
    "Line": "Rhino.Geometry.Line",
    "Mesh": "Rhino.Geometry.Mesh",
}
_MAX_INT32 = 2**31 - 1


@dataclass(frozen=True)
class Param:
    """One input or output of a Hops component.

    Parameters
    ----------
    name : str
        Shown on the component; the key of the value in payloads.
    kind : str
        Hops parameter type (a key of ``RESULT_TYPES``).
    description : str
    nickname : str
    many : bool
        A list (Grasshopper "list access") instead of one item.
    default : object, optional
        Value used when the input is left empty; ``None``: required.
    """

    name: str
    kind: str
    description: str
    nickname: str = ""
    many: bool = False
    default: Any = None

    def encode(self) -> dict[str, Any]:
        """The parameter's metadata, as Hops reads it."""
        out: dict[str, Any] = {
            "Name": self.name,
            "Nickname": self.nickname or self.name[:1],
            "Description": self.description,
            "ParamType": self.kind,
            "ResultType": RESULT_TYPES[self.kind],
            "AtLeast": 1,
            "AtMost": _MAX_INT32 if self.many else 1,
        }
        if self.default is not None:
            out["Default"] = self.default
        return out


@dataclass(frozen=True)
class Component:
    """A Hops component: its route, parameters and the function that solves it.

    ``solve(inputs) -> (outputs, warnings)`` takes the decoded inputs by
    name and returns the outputs by name (already encoded as value items,
    see :func:`value_item`) and a list of warnings for the Hops component.
    """

    name: str
    description: str
    inputs: tuple[Param, ...]
    outputs: tuple[Param, ...]
    solve: Callable[[dict[str, Any]], tuple[dict[str, list[dict[str, str]]], list[str]]]
    category: str = "ruledmesh"
    subcategory: str = "PQ meshes"
    decode: Mapping[str, Callable[[str, Any], Any]] = field(default_factory=dict)

    @property
    def uri(self) -> str:
        return f"/{self.name}"


def metadata(component: Component) -> dict[str, Any]:
    """What ``GET /<name>`` returns for ``component``."""
    return {
        "Uri": component.uri,
        "Name": component.name,
        "Nickname": component.name,
        "Description": component.description,
        "Category": component.category,
        "Subcategory": component.subcategory,
        "Inputs": [p.encode() for p in component.inputs],
        "Outputs": [p.encode() for p in component.outputs],
    }


def _scalar(param: Param, item: Any) -> Any:
    """One decoded value of a Text/Integer/Number/Boolean input."""
    if not isinstance(item, Mapping) or "data" not in item:
        raise ParameterError("expected {\"type\": ..., \"data\": ...} items", param.name)
    data = item["data"]
    try:
        value = json.loads(data) if isinstance(data, str) else data
    except json.JSONDecodeError:
        value = data  # a bare string
    if param.kind == "Text":
        return str(value)
    if param.kind == "Boolean":
        if isinstance(value, bool):
            return value
        if str(value).lower() in ("true", "false"):
            return str(value).lower() == "true"
        raise ParameterError(f"expected true or false, got {str(value)[:40]!r}", param.name)
    if param.kind == "Integer":
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or float(value) != int(value):
            raise ParameterError(f"expected an integer, got {str(value)[:40]!r}", param.name)
        return int(value)
    if param.kind == "Number":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(f"expected a number, got {str(value)[:40]!r}", param.name)
        return float(value)
    return item  # geometry: decoded by the component's own decoder


def read_inputs(component: Component, payload: Mapping[str, Any],
                max_items: int) -> dict[str, Any]:
    """The inputs of ``component`` from a solve payload, by parameter name.

    Parameters
    ----------
    component : Component
    payload : mapping
        The decoded JSON of the request (``values`` holds the data trees).
    max_items : int
        Refuse an input with more values than this (bounds the work).

    Raises
    ------
    ParameterError
        Naming the input: missing, malformed, or too many values.
    """
    values = payload.get("values")
    if not isinstance(values, list):
        raise ParameterError("expected a list of input trees", "values")
    trees = {v.get("ParamName"): v.get("InnerTree") for v in values if isinstance(v, Mapping)}
    out: dict[str, Any] = {}
    for param in component.inputs:
        tree = trees.get(param.name)
        items: list[Any] = []
        if isinstance(tree, Mapping):
            for key in sorted(tree):  # a list input flattens its branches in path order
                branch = tree[key]
                if isinstance(branch, list):
                    items.extend(branch)
        if len(items) > max_items:
            raise ParameterError(f"at most {max_items} values, got {len(items)}", param.name)
        if not items:
            if param.default is None:
                raise ParameterError("missing (connect a value)", param.name)
            out[param.name] = [param.default] if param.many else param.default
            continue
        if param.kind in component.decode:
            decoded = [component.decode[param.kind](param.name, item) for item in items]
        else:
            decoded = [_scalar(param, item) for item in items]
        out[param.name] = decoded if param.many else decoded[0]
    return out


def value_item(kind: str, data: Any) -> dict[str, str]:
    """One value of an output of type ``kind``; ``data`` is JSON-serialisable."""
    return {"type": RESULT_TYPES[kind], "data": json.dumps(data)}


def output_tree(name: str, items: list[dict[str, str]]) -> dict[str, Any]:
    """The data tree of one output: one branch ``{0}``."""
    return {"ParamName": name, "InnerTree": {"{0}": items}}
