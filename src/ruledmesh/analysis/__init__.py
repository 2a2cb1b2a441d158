"""Mesh analysis: the numbers a designer judges a panel mesh by.

Per-face measures live in :mod:`.faces`; distances to the smooth design
surface in :mod:`.surface`; :func:`.report.analyze` gathers everything.
"""

from .faces import (
                    convexity,
                    corner_angles,
                    edge_lengths,
                    face_areas,
                    face_centroids,
                    face_normals,
                    planarity,
                    polygon_planarity,
                    quad_diagonal_crossing,
                    quad_planarity,
)

__all__ = [
    "convexity",
    "corner_angles",
    "edge_lengths",
    "face_areas",
    "face_centroids",
    "face_normals",
    "planarity",
    "polygon_planarity",
    "quad_diagonal_crossing",
    "quad_planarity",
]
