"""Fabrication outputs: flat panels on sheets, schedules, statistics, hot-wire paths.

* :mod:`.unroll` lays every planar panel flat in its own plane, exactly;
* :mod:`.nesting` places the flat panels on sheets (true-shape or shelf packing);
* :mod:`.sheets` writes the sheets as SVG and DXF, labelled;
* :mod:`.schedules` lists nodes, edges (length, dihedral angle) and members;
* :mod:`.panels` counts the panels and their congruence classes;
* :mod:`.hotwire` turns the generators into synchronised paths for a
  4-axis hot-wire cutter (CSV and XYUV G-code);
* :mod:`.output` writes all of it into a folder (``ruledmesh fabricate``).

See ``docs/fabrication.md`` for the conventions (units, sides, kerf).
"""

from __future__ import annotations

import importlib
from typing import Any

# Bound here, not lazily: the submodule has the function's name, and importing the
# submodule later would otherwise replace the function with the module.
from .unroll import Unrolled, unroll

# name -> submodule that defines it, imported on first access (PEP 562): ``import
# ruledmesh`` loads this package (see ruledmesh/__init__.py) and should cost little.
_LAZY = {
    "Layout": "nesting", "layout": "nesting",
    "congruence_classes": "panels", "panel_statistics": "panels", "panel_table": "panels",
    "node_schedule": "schedules", "edge_schedule": "schedules",
    "member_schedule": "schedules", "csv_bytes": "schedules",
}

__all__ = ["Layout", "Unrolled", "congruence_classes", "csv_bytes", "edge_schedule", "layout",
           "member_schedule", "node_schedule", "panel_statistics", "panel_table", "unroll"]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
