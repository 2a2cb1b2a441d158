"""The §4.1 hybrid mesher under its earlier name: it lives in :mod:`ruledmesh.skew.hybrid`.

Kept so that code written against ``ruledmesh.hybrid`` keeps working; new code imports
from :mod:`ruledmesh.skew` (or uses :func:`ruledmesh.hybrid_mesh`).
"""

from __future__ import annotations

from .skew.hybrid import checkerboard_faces, hybrid_grid, hybrid_mesh, orient_generators

__all__ = ["checkerboard_faces", "hybrid_grid", "hybrid_mesh", "orient_generators"]
