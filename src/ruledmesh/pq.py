"""The §4.3 PQ mesher under its earlier name: it lives in :mod:`ruledmesh.skew.pq`.

``ruledmesh.pq.pq_mesh`` is the documented entry point of the mesher (and the
one benchmarks and scripts call), so it keeps working; the mesher's modules
(row maps, runs, trimming, assembly, pairing, flips) are in
:mod:`ruledmesh.skew.pq` beside the other meshers of the paper's §4.
"""

from __future__ import annotations

from .skew.pq import MAX_GRID_POINTS, RowsFrom, pq_mesh, row_maps

__all__ = ["MAX_GRID_POINTS", "RowsFrom", "pq_mesh", "row_maps"]
