"""What BIM and CAD writers attach to each panel: label, kind, area, planarity."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..analysis.faces import face_normals
from ..analysis.planar import face_planarity
from ..errors import ParameterError
from ..labels import panel_labels
from ..mesh import FaceKind, Mesh

__all__ = ["PANEL_MODES", "PanelData", "panel_data"]

# ``panels`` option of the IFC and 3DM writers: one object per face, or one per face kind.
PANEL_MODES = ("each", "joined")


@dataclass(frozen=True, eq=False)
class PanelData:
    """Per-face data written with every panel.

    Attributes
    ----------
    label : (F,) str
        :func:`ruledmesh.labels.panel_labels`, as on the sheets.
    kind : (F,) str
        :class:`~ruledmesh.mesh.FaceKind` labels.
    area : (F,) float64
        Face areas in the mesh unit squared.
    planarity : (F,) float64
        The planarity ``ruledmesh analyze`` reports
        (:func:`ruledmesh.analysis.planar.face_planarity`: quads by their
        diagonals, larger polygons by the best-fit plane, triangles 0).
    """

    label: np.ndarray
    kind: np.ndarray
    area: np.ndarray
    planarity: np.ndarray


def check_panels(panels: str) -> str:
    """Validate the ``panels`` option of a writer."""
    if panels not in PANEL_MODES:
        raise ParameterError(f'expected "each" or "joined", got {panels!r}', "panels")
    return panels


def panel_data(mesh: Mesh) -> PanelData:
    """The :class:`PanelData` of every face of ``mesh``."""
    centre = mesh.bounding_box().mean(axis=0)
    # Areas of the centred mesh: Newell sums far from the origin lose digits.
    _, area = face_normals(mesh.with_vertices(mesh.vertices - centre))
    labels = np.array([k.label for k in FaceKind])
    return PanelData(panel_labels(mesh.n_faces), labels[mesh.face_kind], area,
                     face_planarity(mesh))
