"""A picture of a support structure: mesh, node axes, offset layer, beams.

The mesh's edges are coloured by torsion (the colour bar reaches at least one
degree, so a torsion-free structure shows uniformly dark instead of
stretching rounding noise), the node axes are drawn from the mesh to the
offset layer, the offset layer is a light translucent copy and the beams,
when given, are grey solids.  Headless matplotlib (Agg, no pyplot), as
:mod:`ruledmesh.render`.
"""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from ..errors import ExportError
from ..mesh import Mesh
from ..tolerances import DEFAULT
from .beams import Solids
from .support import SupportStructure

__all__ = ["render_structure"]


def _polygons(mesh: Mesh) -> np.ndarray:
    padded = mesh.padded_faces(fill=-1)
    last = mesh.face_indices[mesh.face_offsets[1:] - 1]
    return mesh.vertices[np.where(padded < 0, last[:, None], padded)]


def render_structure(structure: SupportStructure, *, beams: Solids | None = None,
                     panels: Solids | None = None,
                     view: tuple[float, float] = (25.0, -60.0), size: tuple[int, int] = (1000, 800),
                     dpi: int = 100, title: str | None = None, fmt: str = "png") -> bytes:
    """The picture of ``structure`` as image bytes.

    Parameters
    ----------
    structure : SupportStructure
    beams : Solids, optional
        Beams to draw (e.g. :func:`~ruledmesh.structure.beams.edge_beams`).
    panels : Solids, optional
        Thick panels to draw (:func:`~ruledmesh.structure.beams.thick_panels`),
        translucent blue instead of the mesh's faces.
    view : (elevation, azimuth) in degrees
    size : (width, height) in pixels
    dpi : int
    title : str, optional
        Default: the method, exactness and largest torsion.
    fmt : {"png", "svg", "pdf"}

    Returns
    -------
    bytes
    """
    try:
        from matplotlib import colors
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.cm import ScalarMappable
        from matplotlib.figure import Figure
        from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection
    except ImportError:
        raise ExportError("rendering needs matplotlib: pip install 'ruledmesh[plot]'") from None
    mesh = structure.mesh
    v, w = mesh.vertices, structure.offset
    fig = Figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    FigureCanvasAgg(fig)
    ax: Any = fig.add_axes((-0.02, -0.05, 0.88, 1.1), projection="3d", computed_zorder=False)  # an untyped Axes3D
    shown = mesh if panels is None else panels.mesh
    ax.add_collection3d(Poly3DCollection(_polygons(shown), facecolors="#9ecae1", alpha=0.55,
                                         edgecolors="none" if panels is None else "#3182bd40",
                                         linewidths=0.2))
    ax.add_collection3d(Poly3DCollection(_polygons(mesh.with_vertices(w)), facecolors="#d9d9d9",
                                         alpha=0.3, edgecolors="#80808060", linewidths=0.2))
    if beams is not None:
        ax.add_collection3d(Poly3DCollection(_polygons(beams.mesh), facecolors="#8c8c8c",
                                             alpha=0.8, edgecolors="#40404040", linewidths=0.1))
    ax.add_collection3d(Line3DCollection(np.stack([v, w], axis=1), colors="#e6550d",
                                         linewidths=0.6))
    torsion = structure.torsion
    norm = colors.Normalize(0.0, max(float(torsion.max(initial=0.0)), 1.0))
    segs = v[structure.edges]
    ax.add_collection3d(Line3DCollection(segs, array=torsion, cmap="viridis", norm=norm,
                                         linewidths=1.2))
    pts = np.concatenate([v, w])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = np.maximum(hi - lo, DEFAULT.degenerate * max(float(np.max(hi - lo)), 1.0))
    ax.set_xlim(lo[0], lo[0] + span[0])
    ax.set_ylim(lo[1], lo[1] + span[1])
    ax.set_zlim(lo[2], lo[2] + span[2])
    ax.set_box_aspect(tuple(np.maximum(span / span.max(), 0.02)), zoom=0.9)
    ax.view_init(elev=view[0], azim=view[1])
    ax.set_axis_off()
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap="viridis"),
                       cax=fig.add_axes((0.88, 0.2, 0.025, 0.6)))
    bar.set_label("edge torsion (degrees)")
    if title is None:
        title = (f"{structure.method.value} axes, "
                 f"{'torsion-free' if structure.exact else 'not torsion-free'}, "
                 f"largest torsion {float(torsion.max(initial=0.0)):.3g} deg")
    fig.suptitle(title)
    buf = io.BytesIO()
    fig.savefig(buf, format=fmt, dpi=dpi)
    return buf.getvalue()
