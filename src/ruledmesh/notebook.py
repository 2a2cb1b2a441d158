"""How a :class:`~ruledmesh.mesh.Mesh` shows in Jupyter: counts and a small SVG picture.

:func:`mesh_html` is what ``Mesh._repr_html_`` returns: a table of the
vertex, face (by kind) and generator counts, and an axonometric SVG of the
faces coloured by kind, drawn for meshes of up to :data:`MAX_DRAWN_FACES`
faces (larger ones get the table only).  Plain HTML, no JavaScript, no
dependency.
"""

from __future__ import annotations

import html

import numpy as np

from .mesh import FaceKind, Mesh

__all__ = ["MAX_DRAWN_FACES", "mesh_html", "mesh_svg"]

MAX_DRAWN_FACES = 20_000
_COLOURS = {FaceKind.QUAD: "#c8cdd7", FaceKind.BORDER: "#f0b450", FaceKind.FILL: "#5aa5f0",
            FaceKind.SPLIT: "#e65050", FaceKind.TRIANGLE: "#73cd73", FaceKind.POLYGON: "#b48cd7",
            FaceKind.STRIP: "#72b7b2"}


def _project(vertices: np.ndarray) -> np.ndarray:
    """Axonometric view from (1, -1, 1): x to the right, z up, in a 300-unit box."""
    right = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    up = np.array([-1.0, 1.0, 2.0]) / np.sqrt(6)
    p = np.stack([vertices @ right, -(vertices @ up)], axis=1)
    p -= p.min(axis=0)
    size = float(p.max()) or 1.0
    return p * (300.0 / size) + 5.0


def mesh_svg(mesh: Mesh) -> str:
    """An SVG of the faces of ``mesh``, coloured by kind, drawn far to near."""
    if mesh.n_faces == 0 or not np.all(np.isfinite(mesh.vertices)):
        return ""
    xy = _project(mesh.vertices)
    depth = mesh.vertices @ np.array([1.0, -1.0, 1.0])
    padded = mesh.padded_faces()
    valid = padded >= 0
    centre = np.where(valid, depth[np.maximum(padded, 0)], 0).sum(1) / valid.sum(1)
    order = np.argsort(-centre)
    # One path element per face: a display of at most MAX_DRAWN_FACES faces, not a hot path.
    parts = []
    for f in order.tolist():
        pts = xy[padded[f][valid[f]]]
        d = "M" + "L".join(f"{x:.1f} {y:.1f}" for x, y in pts.tolist()) + "Z"
        parts.append(f'<path d="{d}" fill="{_COLOURS[FaceKind(int(mesh.face_kind[f]))]}"/>')
    w, h = (xy.max(axis=0) + 5.0).tolist()
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0f}" height="{h:.0f}" '
            f'stroke="#333" stroke-width="0.3" stroke-linejoin="round">{"".join(parts)}</svg>')


def mesh_html(mesh: Mesh) -> str:
    """The Jupyter view of ``mesh``: counts, and the picture when it is small enough.

    >>> from ruledmesh import Mesh
    >>> square = Mesh.from_faces([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]])
    >>> "<svg" in mesh_html(square) and "1 quad" in mesh_html(square)
    True
    """
    kinds = ", ".join(f"{c} {k}" for k, c in mesh.count_kinds().items()) or "none"
    units = html.escape(str(mesh.info.get("units", "")))
    rows = [("vertices", str(mesh.n_vertices)), ("faces", f"{mesh.n_faces} ({kinds})"),
            ("generator segments", str(len(mesh.members))),
            ("bounding-box diagonal", f"{mesh.diagonal():.6g} {units}".strip())]
    table = "".join(f"<tr><th style='text-align:left'>{k}</th><td>{html.escape(v)}</td></tr>"
                    for k, v in rows)
    picture = mesh_svg(mesh) if mesh.n_faces <= MAX_DRAWN_FACES else (
        f"<p>({mesh.n_faces} faces: not drawn; ruledmesh render draws any size)</p>")
    return f"<div><b>ruledmesh Mesh</b><table>{table}</table>{picture}</div>"
