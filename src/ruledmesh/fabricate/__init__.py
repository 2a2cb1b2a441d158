"""Fabrication outputs: flat panels on sheets, schedules, statistics, hot-wire paths.

* :mod:`.unroll` lays every planar panel flat in its own plane, exactly;
* :mod:`.nesting` places the flat panels on sheets (shelf packing);
* :mod:`.sheets` writes the sheets as SVG and DXF, labelled;
* :mod:`.schedules` lists nodes, edges (length, dihedral angle) and members;
* :mod:`.panels` counts the panels and their congruence classes;
* :mod:`.hotwire` turns the generators into synchronised paths for a
  4-axis hot-wire cutter (CSV and XYUV G-code);
* :mod:`.output` writes all of it into a folder (``ruledmesh fabricate``).

See ``docs/fabrication.md`` for the conventions (units, sides, kerf).
"""

from .nesting import Layout, layout
from .panels import congruence_classes, panel_statistics, panel_table
from .schedules import csv_bytes, edge_schedule, member_schedule, node_schedule
from .unroll import Unrolled, unroll

__all__ = [
    "Unrolled", "unroll", "Layout", "layout",
    "congruence_classes", "panel_statistics", "panel_table",
    "node_schedule", "edge_schedule", "member_schedule", "csv_bytes",
]
