"""A small TOML writer for design files (the subset :mod:`tomllib` reads back).

Design dictionaries hold strings, integers, floats, booleans, lists and
tables; :func:`dumps` writes top-level scalars first, then one ``[table]``
per nested table (``[curves.c1]``), and arrays of tables (``[[transform]]``)
last.  Lists and tables inside lists are written inline.  Comments of the
original file are not kept (TOML parsers drop them).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from typing import Any

from ..errors import ParameterError

__all__ = ["dumps"]

_BARE = re.compile(r"[A-Za-z0-9_-]+")


_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n",
            "\f": "\\f", "\r": "\\r"}


def _string(text: str) -> str:
    """A TOML basic string: quotes, backslashes and every control character escaped."""
    out = []
    for ch in text:
        if ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:  # TOML refuses raw control characters
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _key(key: Any) -> str:
    if not isinstance(key, str):
        raise ParameterError(f"expected string keys, got {key!r}", "design")
    return key if _BARE.fullmatch(key) else _string(key)


def _value(value: Any, path: str) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)  # repr always has "." or "e": a TOML float, exact round trip
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, Mapping):
        inner = ", ".join(f"{_key(k)} = {_value(v, f'{path}.{k}')}" for k, v in value.items())
        return "{ " + inner + " }" if inner else "{}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v, f"{path}[{i}]") for i, v in enumerate(value)) + "]"
    # numpy scalars and the like
    if hasattr(value, "item"):
        return _value(value.item(), path)
    raise ParameterError(f"cannot write {type(value).__name__} to TOML", path or "design")


def _is_table_array(value: Any) -> bool:
    return (isinstance(value, (list, tuple)) and len(value) > 0
            and all(isinstance(v, Mapping) for v in value))


def _table(lines: list[str], table: Mapping, prefix: str) -> None:
    subtables = []
    arrays = []
    for k, v in table.items():
        if isinstance(v, Mapping):
            subtables.append((k, v))
        elif _is_table_array(v):
            arrays.append((k, v))
        else:
            lines.append(f"{_key(k)} = {_value(v, f'{prefix}{k}')}")
    for k, v in subtables:
        name = f"{prefix}{_key(k)}"
        scalars = [x for x in v.values() if not isinstance(x, Mapping) and not _is_table_array(x)]
        # A table that only holds tables needs no header of its own.
        if scalars or not v:
            lines.append("")
            lines.append(f"[{name}]")
        _table(lines, v, f"{name}.")
    for k, items in arrays:
        name = f"{prefix}{_key(k)}"
        for item in items:
            lines.append("")
            lines.append(f"[[{name}]]")
            _table(lines, item, f"{name}.")


def dumps(data: Mapping[str, Any]) -> str:
    """Write ``data`` as TOML text that :func:`tomllib.loads` reads back equal.

    Parameters
    ----------
    data : mapping
        Tables, strings, ints, floats, bools and lists.

    Returns
    -------
    str

    Examples
    --------
    >>> print(dumps({"name": "x", "mesh": {"rows": 4}}), end="")
    name = "x"
    <BLANKLINE>
    [mesh]
    rows = 4
    """
    if not isinstance(data, Mapping):
        raise ParameterError(f"expected a table, got {type(data).__name__}", "design")
    lines: list[str] = []
    _table(lines, data, "")
    while lines and not lines[0]:
        lines.pop(0)
    return "\n".join(lines) + "\n"
