"""The §4.2 compound mesher under its earlier name: it lives in :mod:`ruledmesh.skew.compound`.

Kept so that code written against ``ruledmesh.compound`` keeps working; new code imports
from :mod:`ruledmesh.skew`.
"""

from __future__ import annotations

from .skew.compound import (
    CompoundReference,
    CompoundSurface,
    c1_residual,
    c1_step,
    compound_mesh,
    compound_net,
)

__all__ = ["CompoundReference", "CompoundSurface", "c1_residual", "c1_step", "compound_mesh",
           "compound_net"]
