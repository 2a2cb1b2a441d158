"""Distances to the smooth ruled surface a mesh was built from.

The smooth reference surfaces live in :mod:`ruledmesh.surfaces` (the meshers
build them); this module keeps their analysis-side name.
"""

from ..surfaces import RuledPatch, RuledReference

__all__ = ["RuledPatch", "RuledReference"]
