"""JSON of the mesh (and of the design it was built from).

Schema (``"format": "ruledmesh.mesh"``, ``"version": 1``; documented with a
JSON Schema in ``docs/exports.md``)::

    {
      "format": "ruledmesh.mesh", "version": 1,
      "vertices":   [[x, y, z], ...],          # float64, written exactly (repr)
      "faces":      [[i, j, k, ...], ...],     # 0-based, boundary order
      "kinds":      ["quad", "border", ...],   # one FaceKind label per face
      "members":    [[i, j], ...],             # generator segments
      "member_ids": [g, ...],                  # generator of each member
      "vertex_data": {"t": [...], ...},        # optional per-vertex arrays
      "info": {...},                           # optional metadata
      "design": {...}                          # optional: the design tables
    }

Python's ``json`` writes floats as their shortest round-trip repr, so a
round trip through this format is bit-exact.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from enum import Enum
from pathlib import PurePath
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..mesh import FaceKind, Mesh

__all__ = [
    "DESIGN_FORMAT",
    "FORMAT",
    "SCHEMA",
    "VERSION",
    "dump_design",
    "dumpb",
    "from_dict",
    "loadb",
    "to_dict",
]

FORMAT = "ruledmesh.mesh"
DESIGN_FORMAT = "ruledmesh.design"
VERSION = 1

_INDEX = {"type": "integer", "minimum": 0}
SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "ruledmesh mesh",
    "type": "object",
    "required": ["format", "version", "vertices", "faces", "kinds", "members", "member_ids"],
    "properties": {
        "format": {"const": FORMAT},
        "version": {"const": VERSION},
        "vertices": {"type": "array",
                     "items": {"type": "array", "items": {"type": "number"},
                               "minItems": 3, "maxItems": 3}},
        "faces": {"type": "array", "items": {"type": "array", "items": _INDEX, "minItems": 3}},
        "kinds": {"type": "array",
                  "items": {"enum": [k.label for k in FaceKind]}},
        "members": {"type": "array",
                    "items": {"type": "array", "items": _INDEX, "minItems": 2, "maxItems": 2}},
        "member_ids": {"type": "array", "items": {"type": "integer"}},
        "vertex_data": {"type": "object", "additionalProperties": {"type": "array"}},
        "info": {"type": "object"},
        "design": {"type": "object"},
    },
    "additionalProperties": False,
}
"""JSON Schema (draft 2020-12) of the mesh document; counts that must agree
(one kind per face, one id per member, indices below the vertex count) are
checked by :func:`from_dict`."""


def _jsonable(value: Any) -> Any:
    """``json`` fallback: numpy values as lists/numbers, anything else as text."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, (PurePath, set, frozenset, tuple)):
        return list(value) if not isinstance(value, PurePath) else str(value)
    return str(value)


def to_dict(mesh: Mesh, design: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The JSON document of ``mesh`` as a dictionary.

    Parameters
    ----------
    mesh : Mesh
    design : mapping, optional
        The design tables (as parsed from TOML) to embed under ``"design"``.

    Returns
    -------
    dict
    """
    labels = np.array([k.label for k in FaceKind])
    doc: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "vertices": mesh.vertices.tolist(),
        "faces": mesh.face_list(),
        "kinds": labels[mesh.face_kind].tolist(),
        "members": mesh.members.tolist(),
        "member_ids": mesh.member_id.tolist(),
    }
    if mesh.vertex_data:
        doc["vertex_data"] = {k: np.asarray(v).tolist() for k, v in mesh.vertex_data.items()}
    if mesh.info:
        doc["info"] = dict(mesh.info)
    if design is not None:
        doc["design"] = dict(design)
    return doc


def dumpb(mesh: Mesh, design: Mapping[str, Any] | None = None, indent: int | None = None) -> bytes:
    """The UTF-8 JSON bytes of ``mesh`` (see the module docstring for the schema).

    Parameters
    ----------
    mesh : Mesh
    design : mapping, optional
        Design tables to embed.
    indent : int, optional
        Pretty-print with this indent (default: compact).
    """
    text = json.dumps(to_dict(mesh, design), indent=indent, default=_jsonable, allow_nan=False)
    return text.encode("utf-8")


def dump_design(design: Mapping[str, Any], source: str | None = None,
                indent: int | None = 2) -> bytes:
    """JSON of a design's tables (``"format": "ruledmesh.design"``).

    Parameters
    ----------
    design : mapping
        The parsed design file (``Design.data``).
    source : str, optional
        File name the design came from.
    indent : int, optional
    """
    doc = {"format": DESIGN_FORMAT, "version": VERSION, "design": dict(design)}
    if source:
        doc["source"] = source
    return json.dumps(doc, indent=indent, default=_jsonable, allow_nan=False).encode("utf-8")


def _array(doc: Mapping, key: str, shape_tail: tuple, dtype, required: bool = True) -> np.ndarray:
    if key not in doc:
        if required:
            raise ParameterError("missing", f"json.{key}")
        return np.zeros((0,) + shape_tail, dtype=dtype)
    try:
        arr = np.asarray(doc[key], dtype=dtype)
    except (TypeError, ValueError):
        raise ParameterError("expected an array of numbers", f"json.{key}") from None
    if arr.size == 0:
        arr = arr.reshape((0,) + shape_tail)
    if arr.shape[1:] != shape_tail:
        raise ParameterError(f"expected rows of {shape_tail[0] if shape_tail else 1} numbers, "
                             f"got shape {arr.shape}", f"json.{key}")
    return arr


def from_dict(doc: Mapping[str, Any]) -> Mesh:
    """The :class:`Mesh` of a JSON document (inverse of :func:`to_dict`)."""
    if not isinstance(doc, Mapping) or doc.get("format") != FORMAT:
        raise ParameterError(f'expected "format": "{FORMAT}"', "json.format")
    if doc.get("version") != VERSION:
        raise ParameterError(f"expected version {VERSION}, got {doc.get('version')!r}", "json.version")
    vertices = _array(doc, "vertices", (3,), np.float64)
    faces = doc.get("faces")
    if not isinstance(faces, list) or not all(isinstance(f, list) for f in faces):
        raise ParameterError("expected a list of index lists", "json.faces")
    kinds_raw = doc.get("kinds")
    if kinds_raw is None:
        kinds = None
    elif isinstance(kinds_raw, list) and len(kinds_raw) == len(faces):
        try:
            kinds = np.array([FaceKind.from_label(str(k)) for k in kinds_raw], dtype=np.uint8)
        except ParameterError as exc:
            raise ParameterError(exc.detail, "json.kinds") from None
    else:
        raise ParameterError(f"expected {len(faces)} kind labels", "json.kinds")
    members = _array(doc, "members", (2,), np.int64, required=False)
    member_ids = doc.get("member_ids")
    vdata = {k: np.asarray(v) for k, v in dict(doc.get("vertex_data", {})).items()}
    info = dict(doc.get("info", {}))
    if "design" in doc:
        info["design"] = doc["design"]
    return Mesh.from_faces(vertices, faces, kinds, members=members,
                           member_id=None if member_ids is None else np.asarray(member_ids, np.int64),
                           vertex_data=vdata, info=info)


def loadb(data: bytes) -> Mesh:
    """Read a ruledmesh mesh JSON document."""
    try:
        doc = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ParameterError(f"not JSON: {exc}", "json") from None
    return from_dict(doc)
