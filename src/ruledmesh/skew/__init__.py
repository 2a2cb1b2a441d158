"""Discretisation of general skew surfaces: the meshers of the paper's §4.

A skew ruled surface given by any set of generators has no exact PQ mesh in
general; §4 of the paper gives three ways to mesh it, and this package holds
them the way §2-§3's constructions are held in :mod:`ruledmesh.constructions`:

* §4.1 *Local approximation* -- :mod:`ruledmesh.skew.hybrid`: one discrete
  hyperbolic paraboloid per strip between consecutive generators; quads inside
  the strips, triangle pairs along the generators (:func:`hybrid_mesh`).
* §4.2 *Compound surfaces from HP patches* -- :mod:`ruledmesh.skew.compound`:
  HP patches joined with C1 continuity, so every face is a planar quad
  (:func:`compound_net`, :func:`compound_mesh`).
* §4.3 *General algorithm for PQ meshes on skew surfaces* -- :mod:`ruledmesh.skew.pq`:
  the hop from generator to generator (:func:`pq_mesh`, also :func:`ruledmesh.pq.pq_mesh`).
"""

from __future__ import annotations

from .compound import (
    CompoundReference,
    CompoundSurface,
    c1_residual,
    c1_step,
    compound_mesh,
    compound_net,
)
from .hybrid import checkerboard_faces, hybrid_grid, hybrid_mesh, orient_generators
from .pq import MAX_GRID_POINTS, RowsFrom, pq_mesh, row_maps

__all__ = ["MAX_GRID_POINTS", "CompoundReference", "RowsFrom", "CompoundSurface", "c1_residual", "c1_step",
           "checkerboard_faces", "compound_mesh", "compound_net", "hybrid_grid", "hybrid_mesh",
           "orient_generators", "pq_mesh", "row_maps"]
