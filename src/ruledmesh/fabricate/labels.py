"""Panel labels (see :mod:`ruledmesh.labels`, where the exports read them too)."""

from ..labels import PREFIX, face_of_label, panel_labels

__all__ = ["PREFIX", "face_of_label", "panel_labels"]
