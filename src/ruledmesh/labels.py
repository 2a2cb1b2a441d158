"""Panel labels: one name per face, the same on sheets, schedules and 3-D models.

Face ``f`` is labelled ``"P<f>"`` (``P0``, ``P1``, ...): the label written at
the panel's centre on the cutting sheets, in the ``label`` column of
``panels.csv``, as the name of the panel's ``IfcPlate`` in IFC and of its
mesh object in 3DM, so a panel picked in BIM or CAD is found on the sheet.
"""

from __future__ import annotations

import numpy as np

__all__ = ["PREFIX", "face_of_label", "panel_labels"]

PREFIX = "P"


def panel_labels(n_faces: int) -> np.ndarray:
    """(F,) str: the labels of faces ``0 .. n_faces - 1``.

    >>> panel_labels(3).tolist()
    ['P0', 'P1', 'P2']
    """
    return np.char.add(PREFIX, np.arange(n_faces).astype(str)) if n_faces else np.zeros(0, "<U1")


def face_of_label(label: str) -> int:
    """The face index a label names (inverse of :func:`panel_labels`).

    >>> face_of_label("P12")
    12
    """
    from .errors import ParameterError

    if not (label.startswith(PREFIX) and label[len(PREFIX):].isdigit()):
        raise ParameterError(f'expected a panel label like "{PREFIX}12", got {label!r}', "label")
    return int(label[len(PREFIX):])
