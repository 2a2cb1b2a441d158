"""PQ meshes of skew surfaces from a discrete set of generators (paper §4.3).

Divide a primary generator ``g_p``; from each division point hop across the
next generator to the next-but-one (chain *a*, generators of the primary's
parity), and from the first crossing hop likewise (chain *b*, the other
parity).  The grid point ``X[i, r]`` is the vertex of row ``r`` on ``g_i``.
The two options of the paper are the two colours of a checkerboard on that
grid: a face is centred on every grid point of the other colour,

    [X[i-1, r], X[i, r-1], X[i+1, r], X[i, r+1]],

with one diagonal on the generator ``g_i`` and the other on a hop line that
crosses ``g_i``: two intersecting lines, so every face is planar by
construction, up to rounding that does not accumulate.

- :mod:`~ruledmesh.skew.pq.maps`: the rows as Moebius maps of the line parameter,
  propagated hop by hop; the drift between the two chains.
- :mod:`~ruledmesh.skew.pq.runs`: one run's grid; chain *b* rooted where its faces
  stay convex; matched divisions for runs that meet on a generator; rows through the
  generators' end points on a director curve (``rows_from``).
- :mod:`~ruledmesh.skew.pq.grading`: the primary's division graded for faces of even shape
  on every generator the rows reach (``division = "graded"``).
- :mod:`~ruledmesh.skew.pq.mesher`: torsal generators, restarts, the whole mesh.
- :mod:`~ruledmesh.skew.pq.strips` and :mod:`~ruledmesh.skew.pq.assemble`: trimming to
  the patch with every vertex on a generator, closing the strips.
"""

from __future__ import annotations

from .maps import row_maps
from .mesher import PrimaryDivision, RowsFrom, pq_mesh
from .runs import MAX_GRID_POINTS

__all__ = ["MAX_GRID_POINTS", "PrimaryDivision", "RowsFrom", "pq_mesh", "row_maps"]
