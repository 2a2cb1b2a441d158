"""Renders: a mesh's faces coloured by a measure, its generators drawn on top.

Every figure in the docs comes from :func:`render`.  Faces are coloured by
planarity (log scale, the measure of :func:`ruledmesh.analysis.planarity`),
by closeness of their centroids to the smooth design surface (relative to the
bounding-box diagonal), or by :class:`~ruledmesh.mesh.FaceKind`; a colour bar
says which.  matplotlib is an optional dependency (extra ``plot``) and runs
headless (the Agg canvas, no pyplot, so no global figure state and no display).
"""

from __future__ import annotations

import io
import os
from enum import Enum
from pathlib import Path
from typing import Any

import numpy as np

from ._validation import check_choice, check_float, check_int
from .analysis import faces as F
from .errors import ExportError, ParameterError
from .mesh import FaceKind, Mesh
from .tolerances import COLLINEAR, DEFAULT, DEPTH_BIAS, PLANARITY_FLOOR, TINY

__all__ = ["FORMATS", "MAX_LABELS", "MIN_FACE_PIXELS", "MIN_GENERATOR_SPACING", "MIN_LABEL_PIXELS",
           "ColorBy", "Switch", "face_values", "render", "save_render", "visible_faces"]

# File types the Agg-based figure can write, by extension.
FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}

_PLANARITY_FLOOR = PLANARITY_FLOOR

# One fixed colour per FaceKind so figures agree with each other.
_KIND_COLORS = {
    FaceKind.QUAD: "#4c78a8",
    FaceKind.BORDER: "#f58518",
    FaceKind.FILL: "#e45756",
    FaceKind.SPLIT: "#b279a2",
    FaceKind.TRIANGLE: "#54a24b",
    FaceKind.POLYGON: "#9d755d",
    FaceKind.STRIP: "#72b7b2",
}


class Switch(str, Enum):
    """Whether to draw edges or generators: always, never, or by the face count."""

    ON = "on"
    OFF = "off"
    AUTO = "auto"


class ColorBy(str, Enum):
    """What the face colours show."""

    PLANARITY = "planarity"
    CLOSENESS = "closeness"
    KIND = "kind"


def face_values(mesh: Mesh, color: ColorBy | str = ColorBy.PLANARITY, reference=None) -> np.ndarray:
    """The per-face value a render colours by.

    Parameters
    ----------
    mesh : Mesh
    color : ColorBy or str
        ``"planarity"``, ``"closeness"`` or ``"kind"``.
    reference : object with ``distance(points)``, optional
        The smooth design surface; required for ``"closeness"``.

    Returns
    -------
    values : (F,) float64
        Planarity (scale-free), centroid distance / bounding-box diagonal, or
        the FaceKind value.
    """
    color = check_choice(color, ColorBy, "color")
    if color is ColorBy.PLANARITY:
        return F.planarity(mesh)
    if color is ColorBy.KIND:
        return mesh.face_kind.astype(np.float64)
    if reference is None:
        raise ParameterError("colouring by closeness needs the design surface; "
                             "give the design file the mesh was built from", "reference")
    diag = mesh.diagonal() or 1.0
    return reference.distance(F.face_centroids(mesh)) / diag


def _pair(value, name: str, check) -> tuple:
    """Two checked numbers from a pair (a tuple, list or array)."""
    if isinstance(value, str) or np.ndim(value) != 1 or len(value) != 2:
        raise ParameterError(f"expected two numbers, got {value!r}", name)
    return check(value[0], name), check(value[1], name)


def _face_polygons(mesh: Mesh) -> np.ndarray:
    """(F, K, 3): faces padded to the largest valence by repeating their last vertex.

    A repeated vertex draws nothing, so one array serves faces of mixed valence.
    """
    padded = mesh.padded_faces(fill=-1)
    last = mesh.face_indices[mesh.face_offsets[1:] - 1]
    padded = np.where(padded < 0, last[:, None], padded)
    return mesh.vertices[padded]


def _colouring(values: np.ndarray, color: ColorBy):
    """Colormap, norm, colour-bar label and ticks for ``values``."""
    from matplotlib import colors

    if color is ColorBy.KIND:
        kinds = list(FaceKind)
        cmap = colors.ListedColormap([_KIND_COLORS[k] for k in kinds])
        norm = colors.BoundaryNorm(np.arange(len(kinds) + 1) - 0.5, len(kinds))
        return cmap, norm, "face kind", (np.arange(len(kinds)), [k.label for k in kinds])
    if color is ColorBy.PLANARITY:
        v = np.maximum(values, _PLANARITY_FLOOR)
        lo = float(v.min()) if v.size else _PLANARITY_FLOOR
        # The bar reaches at least the planarity tolerance, so an exact mesh shows as
        # uniformly low instead of stretching rounding noise over the whole colour map.
        hi = max(float(v.max()) if v.size else lo, DEFAULT.planarity, lo * 10.0)
        return ("viridis", colors.LogNorm(lo, hi),
                "planarity (diagonal gap / diagonal length)", None)
    hi = float(values.max()) if values.size else 0.0
    return "magma_r", colors.Normalize(0.0, hi if hi > 0 else 1.0), \
        "closeness (centroid distance / bounding-box diagonal)", None


# Share of the canvas the mesh covers, roughly (the colour bar and margins take the rest).
_MESH_SHARE = 0.5

# ``edges="auto"`` outlines faces while each covers at least this many pixels on average.
MIN_FACE_PIXELS = 60.0

# ``generators="auto"`` keeps generators at least this many pixels apart on average.
MIN_GENERATOR_SPACING = 8.0


def _switch(value: bool | str, name: str, auto: bool) -> bool:
    """``True``/``"on"``, ``False``/``"off"``, or ``"auto"`` (then ``auto``)."""
    if isinstance(value, bool):
        return value
    choice = check_choice(value, Switch, name)
    return auto if choice is Switch.AUTO else choice is Switch.ON


def _edge_width(face_pixels: float) -> float:
    """Outline width in points: thinner as faces get smaller."""
    return float(np.clip(0.3 * np.sqrt(face_pixels / 400.0), 0.1, 0.4))


def _generator_subset(mesh: Mesh, generators: bool | str, width: int) -> np.ndarray:
    """(E', 2) member segments to draw: all, none, or every k-th generator ("auto")."""
    if not len(mesh.members):
        return mesh.members
    ids, index = np.unique(mesh.member_id, return_inverse=True)
    room = max(int(width * 0.8 / MIN_GENERATOR_SPACING), 1)
    if not _switch(generators, "generators", True):
        return mesh.members[:0]
    if isinstance(generators, bool) or Switch(generators) is Switch.ON or len(ids) <= room:
        return mesh.members
    step = int(np.ceil(len(ids) / room))
    return mesh.members[index % step == 0]


# ``labels="auto"`` writes panel labels while a face covers at least this many pixels on
# average (a label needs room to be read) ...
MIN_LABEL_PIXELS = 1500.0
# ... and at most this many, drawn or asked for: every label is a text object of its own.
MAX_LABELS = 5000


def _projected(ax, points: np.ndarray) -> np.ndarray:
    """(..., 3) screen x, y and depth (smaller is nearer) of 3-D points in ``ax``'s camera."""
    m = ax.get_proj()
    h = points @ m[:3, :3].T + m[:3, 3]
    w = points @ m[3, :3] + m[3, 3]
    return h / w[..., None]


def visible_faces(ax, mesh: Mesh, faces: np.ndarray) -> np.ndarray:
    """(k,) bool: whether the centroid of each face in ``faces`` is seen by ``ax``'s camera.

    A centroid is hidden when another face covers it on the screen and lies
    nearer to the camera there (faces fanned into triangles, depth
    interpolated across each triangle).

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
        Axes whose camera and limits are set.
    mesh : Mesh
    faces : (k,) int64
    """
    c = _projected(ax, F.face_centroids(mesh)[faces])
    poly = _projected(ax, _face_polygons(mesh))
    k = poly.shape[1]
    tri = np.stack([np.repeat(poly[:, :1], k - 2, axis=1), poly[:, 1:-1], poly[:, 2:]], axis=2)
    owner = np.repeat(np.arange(mesh.n_faces), k - 2)
    tri = tri.reshape(-1, 3, 3)
    e1, e2 = tri[:, 1, :2] - tri[:, 0, :2], tri[:, 2, :2] - tri[:, 0, :2]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    keep = np.abs(det) > COLLINEAR * (np.abs(e1).sum(axis=1) * np.abs(e2).sum(axis=1) + TINY)
    tri, e1, e2, det, owner = tri[keep], e1[keep], e2[keep], det[keep], owner[keep]
    depth = float(np.ptp(poly[..., 2])) or 1.0
    seen = np.ones(len(faces), dtype=bool)
    # Label-by-triangle tests in blocks that keep the temporaries to a few million entries.
    block = max(1, 2_000_000 // max(len(tri), 1))
    for s in range(0, len(faces), block):
        d = c[s:s + block, None, :2] - tri[None, :, 0, :2]
        u = (d[..., 0] * e2[:, 1] - d[..., 1] * e2[:, 0]) / det
        v = (e1[:, 0] * d[..., 1] - e1[:, 1] * d[..., 0]) / det
        inside = (u >= 0) & (v >= 0) & (u + v <= 1)
        z = tri[:, 0, 2] + u * (tri[:, 1, 2] - tri[:, 0, 2]) + v * (tri[:, 2, 2] - tri[:, 0, 2])
        nearer = z < c[s:s + block, None, 2] - DEPTH_BIAS * depth
        other = owner[None, :] != faces[s:s + block, None]
        seen[s:s + block] = ~np.any(inside & nearer & other, axis=1)
    return seen


def _draw_labels(ax, mesh: Mesh, labels: bool | str, pixels: float) -> int:
    """Write the panel labels of the fabrication schedules at the visible face centroids.

    Returns the number of labels drawn.
    """
    from .fabricate.labels import panel_labels

    per_face = pixels / mesh.n_faces
    auto = per_face >= MIN_LABEL_PIXELS and mesh.n_faces <= MAX_LABELS
    if not _switch(labels, "labels", auto):
        return 0
    if mesh.n_faces > MAX_LABELS:
        raise ParameterError(f"{mesh.n_faces} faces are too many to label (at most {MAX_LABELS}); "
                             "render a part of the mesh", "labels")
    faces = np.arange(mesh.n_faces)
    faces = faces[visible_faces(ax, mesh, faces)]
    names = panel_labels(mesh.n_faces)[faces]
    at = F.face_centroids(mesh)[faces]
    size = float(np.clip(0.12 * np.sqrt(per_face), 4.0, 10.0))
    for (x, y, z), name in zip(at.tolist(), names.tolist(), strict=True):
        ax.text(x, y, z, name, fontsize=size, ha="center", va="center", zorder=4,
                color="#111111", gid=f"label-{name}")
    return len(faces)


def _frame(ax, mesh: Mesh, elev: float, azim: float) -> None:
    """Axis limits around the mesh at equal scale, the camera, no axes drawn."""
    lo, hi = mesh.bounding_box()
    span = np.maximum(hi - lo, DEFAULT.degenerate * max(float(np.max(hi - lo)), 1.0))
    ax.set_xlim(lo[0], lo[0] + span[0])
    ax.set_ylim(lo[1], lo[1] + span[1])
    ax.set_zlim(lo[2], lo[2] + span[2])
    # Equal scale on the three axes: a flat-looking panel must look flat.
    ax.set_box_aspect(tuple(np.maximum(span / span.max(), 0.02)), zoom=0.9)
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()


def render(mesh: Mesh, *, color: ColorBy | str = ColorBy.PLANARITY, reference=None,
           view: tuple[float, float] = (25.0, -60.0), size: tuple[int, int] = (1000, 800),
           dpi: int = 100, generators: bool | str = "auto", edges: bool | str = "auto",
           labels: bool | str = "off", title: str | None = None, fmt: str = "png") -> bytes:
    """The picture of ``mesh`` as image bytes.

    Parameters
    ----------
    mesh : Mesh
    color : ColorBy or str
        ``"planarity"`` (log colour scale), ``"closeness"`` (needs
        ``reference``) or ``"kind"``.
    reference : object with ``distance(points)``, optional
        The smooth design surface, for ``"closeness"``.
    view : (elevation, azimuth) in degrees
        The camera direction (matplotlib's ``view_init``).
    size : (width, height) in pixels
        The image size (exact for raster formats).
    dpi : int
    generators : bool or {"on", "off", "auto"}
        Draw the members (generator segments) as dark lines.  ``"auto"``
        draws every generator while they are at least
        :data:`MIN_GENERATOR_SPACING` pixels apart on average, and an evenly
        spaced subset of them beyond that (so the faces stay visible).
    edges : bool or {"on", "off", "auto"}
        Outline the faces.  ``"auto"`` outlines them while a face covers at
        least :data:`MIN_FACE_PIXELS` pixels on average and drops the outlines
        beyond (a million outlined faces would paint the picture black).
    labels : bool or {"on", "off", "auto"}
        Write each panel's label (``P0``, ``P1``, ...: the labels of the
        cutting sheets, ``panels.csv`` and the IFC/3DM objects, see
        :mod:`ruledmesh.fabricate.labels`) at its centroid, for the faces
        whose centroid the camera sees (see :func:`visible_faces`).
        ``"auto"`` labels while a face covers at least
        :data:`MIN_LABEL_PIXELS` pixels on average; at most
        :data:`MAX_LABELS` faces can be labelled.
    title : str, optional
    fmt : {"png", "svg", "pdf"}

    Returns
    -------
    bytes
        The encoded image.
    """
    if not isinstance(mesh, Mesh):
        raise ParameterError(f"expected a Mesh, got {type(mesh).__name__}", "mesh")
    color = check_choice(color, ColorBy, "color")
    if fmt not in FORMATS.values():
        raise ParameterError(f"expected one of {', '.join(FORMATS.values())}, got \"{fmt}\"", "fmt")
    elev, azim = _pair(view, "view", check_float)
    width, height = _pair(size, "size", lambda x, n: check_int(x, n, lo=16, hi=20000))
    dpi = check_int(dpi, "dpi", lo=10, hi=1200)
    if mesh.n_faces == 0:
        raise ParameterError("the mesh has no faces to render", "mesh")
    if not np.all(np.isfinite(mesh.vertices)):
        raise ParameterError("the mesh has NaN or infinite coordinates", "mesh")
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection
    except ImportError:
        raise ExportError("rendering needs matplotlib: pip install 'ruledmesh[plot]'") from None

    values = face_values(mesh, color, reference)
    cmap, norm, label, ticks = _colouring(values, color)
    pixels = width * height * _MESH_SHARE
    draw_edges = _switch(edges, "edges", pixels / mesh.n_faces >= MIN_FACE_PIXELS)
    members = _generator_subset(mesh, generators, width)

    fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi)
    FigureCanvasAgg(fig)
    # The 3-D axes reserve wide empty margins; most of the canvas goes to the mesh.
    # A title gets its own band at the top, inside the canvas.
    top = 1.1 if not title else 1.0
    ax: Any = fig.add_axes((-0.02, -0.05, 0.88, top), projection="3d", computed_zorder=False)  # an untyped Axes3D
    # Without outlines, antialiased neighbours leave light seams between sub-pixel faces.
    polys = Poly3DCollection(_face_polygons(mesh), cmap=cmap, norm=norm,
                             edgecolors="#20202080" if draw_edges else "none",
                             linewidths=_edge_width(pixels / mesh.n_faces) if draw_edges else 0.0,
                             antialiased=draw_edges)
    polys.set_array(values if color is not ColorBy.PLANARITY
                    else np.maximum(values, _PLANARITY_FLOOR))
    ax.add_collection3d(polys)
    if len(members):
        segs = mesh.vertices[members]
        thinned = len(members) < len(mesh.members)
        ax.add_collection3d(Line3DCollection(segs, colors="#111111", zorder=3,
                                             linewidths=0.5 if thinned else 0.8))

    _frame(ax, mesh, elev, azim)
    _draw_labels(ax, mesh, labels, pixels)
    bar = fig.colorbar(polys, cax=fig.add_axes((0.88, 0.2, 0.025, 0.6)))
    bar.set_label(label)
    if ticks is not None:
        bar.set_ticks(ticks[0], labels=ticks[1])
    if title:
        fig.text(0.43, 0.985, title, ha="center", va="top", fontsize=max(8.0, min(16.0, height / 50)))
    buf = io.BytesIO()
    fig.savefig(buf, format=fmt, dpi=dpi)
    return buf.getvalue()


def save_render(path: str | os.PathLike, mesh: Mesh, **options) -> Path:
    """Render ``mesh`` to ``path`` (format by extension: .png, .svg, .pdf), atomically.

    Parameters
    ----------
    path : path-like
    mesh : Mesh
    **options
        As in :func:`render`.

    Returns
    -------
    Path
    """
    from .io import write_atomic

    path = Path(path)
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise ParameterError(f"cannot render to \"{path.suffix or '(no extension)'}\" files; "
                             f"known: {', '.join(FORMATS)}", "path")
    return write_atomic(path, render(mesh, fmt=fmt, **options))
