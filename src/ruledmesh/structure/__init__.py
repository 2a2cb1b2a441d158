"""Support structures behind a PQ mesh: node axes, offset layers, beams, panels.

A PQ mesh is the glass; the frame behind it needs a *node axis* at every
vertex such that the axes at the two ends of every edge are coplanar with it
(a *torsion-free support structure*).  Then every beam is a planar slab
through its edge and both axes, and moving the vertices along their axes
gives an *offset layer* whose faces are planar and parallel to the mesh's
(Pottmann et al. 2007, see docs/structure.md).

=============================  ===============================================
:mod:`.parallel`               the linear space of parallel meshes (sparse)
:mod:`.circular`               exact vertex offsets of circular meshes
:mod:`.support`                node axes and offset layer, method selection
:mod:`.measures`               torsion and exactness, from the two layers
:mod:`.beams`                  beams along edges and generators, thick panels
:mod:`.output`                 the files of ``ruledmesh structure``
=============================  ===============================================
"""

from .measures import edge_torsion
from .parallel import closest_parallel_offset, parallel_constraints
from .support import AxisMethod, SupportStructure, measure_structure, support_structure

__all__ = [
           "AxisMethod",
           "SupportStructure",
           "closest_parallel_offset",
           "edge_torsion",
           "measure_structure",
           "parallel_constraints",
           "support_structure",
]
