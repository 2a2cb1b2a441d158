"""Cutting sheets as SVG and DXF: panel outlines to cut, labels to engrave.

One file per sheet.  Both formats carry the same three layers: ``SHEET``
(the sheet's border, for reference only), ``CUT`` (each panel's closed
outline) and ``LABEL`` (the panel's face id at its centre, and the 3-D length
of every edge written along that edge, just inside it).  Coordinates are mesh
units; ``unit`` only names them in the files (SVG ``width``/``height``, DXF
``$INSUNITS``).  SVG has y pointing down, so its y is ``height - y``; the
panels are not mirrored.  Panels are seen from the side their face normal
points to.
"""

from __future__ import annotations

import io
from dataclasses import dataclass

import numpy as np

from ..errors import ExportError, ParameterError
from ..tolerances import TINY
from .labels import panel_labels as panel_labels_of
from .nesting import Layout
from .unroll import corner_structure

__all__ = ["Labels", "panel_labels", "sheet_svg", "sheet_dxf", "UNITS"]

# unit name -> DXF $INSUNITS code; "" leaves the unit unnamed.
UNITS = {"": 0, "in": 1, "ft": 2, "mm": 4, "cm": 5, "m": 6}


@dataclass(frozen=True, eq=False)
class Labels:
    """Text placed on the sheets: per face, its id, then one length per edge.

    Attributes
    ----------
    text : list of str
    position : (L, 2) float64
        Centre of each text on its sheet.
    angle : (L,) float64
        Direction of the text's baseline, degrees counter-clockwise (kept readable).
    size : (L,) float64
        Text height in mesh units.
    offsets : (F + 1,) int64
        The labels of face ``f`` are ``offsets[f]:offsets[f + 1]``.
    """

    text: list
    position: np.ndarray
    angle: np.ndarray
    size: np.ndarray
    offsets: np.ndarray

    def of_face(self, f: int):
        """Iterate ``(text, (x, y), angle, size)`` for face ``f``."""
        for i in range(self.offsets[f], self.offsets[f + 1]):
            yield self.text[i], self.position[i], float(self.angle[i]), float(self.size[i])


def panel_labels(layout: Layout, *, decimals: int = 3) -> Labels:
    """Panel labels (:mod:`.labels`) at the panels' centres and edge lengths along their edges.

    The lengths are those of the placed (= unrolled = 3-D) edges, written with
    ``decimals`` decimals, inside the panel (panels run counter-clockwise, so
    inside is to the left of each edge) and scaled to fit the edge.
    """
    off = layout.unrolled.face_offsets
    nf = layout.unrolled.n_faces
    face, nxt, _ = corner_structure(off)
    p = layout.points
    d = p[nxt] - p
    length = np.hypot(d[:, 0], d[:, 1])
    val = np.diff(off)
    # Area centroid (shoelace), where the id goes.
    cross = p[:, 0] * p[nxt, 1] - p[nxt, 0] * p[:, 1]
    area2 = np.add.reduceat(cross, off[:-1]) if nf else np.zeros(0)
    cx = np.add.reduceat((p[:, 0] + p[nxt, 0]) * cross, off[:-1]) / (3 * area2) if nf else area2
    cy = np.add.reduceat((p[:, 1] + p[nxt, 1]) * cross, off[:-1]) / (3 * area2) if nf else area2
    face_size = 0.15 * np.minimum(layout.box[:, 0], layout.box[:, 1])
    texts = [f"{x:.{decimals}f}" for x in length.tolist()]
    chars = np.fromiter((len(t) for t in texts), dtype=np.float64, count=len(texts))
    edge_size = np.minimum(0.5 * face_size[face], 0.8 * length / (0.6 * chars + 1.0))
    angle = np.degrees(np.arctan2(d[:, 1], d[:, 0]))
    angle = np.where(angle > 90.0, angle - 180.0, np.where(angle <= -90.0, angle + 180.0, angle))
    inward = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.maximum(length, TINY)[:, None]
    pos = 0.5 * (p + p[nxt]) + inward * (0.9 * edge_size)[:, None]
    # Interleave: face f's labels are its id, then its edges in corner order.
    slot = np.arange(off[-1]) + face + 1
    id_slot = off[:-1] + np.arange(nf)
    total = int(off[-1]) + nf
    position = np.zeros((total, 2))
    ang = np.zeros(total)
    size = np.zeros(total)
    text = [""] * total
    position[slot], ang[slot], size[slot] = pos, angle, edge_size
    position[id_slot] = np.stack([cx, cy], axis=1) if nf else np.zeros((0, 2))
    size[id_slot] = face_size
    for i, t in zip(slot.tolist(), texts):
        text[i] = t
    for i, name in zip(id_slot.tolist(), panel_labels_of(nf).tolist()):
        text[i] = name
    return Labels(text, position, ang, size, np.r_[0, np.cumsum(val + 1)].astype(np.int64))


def _check_unit(unit: str) -> str:
    if unit not in UNITS:
        raise ParameterError(f"expected one of {', '.join(repr(u) for u in UNITS)}, got {unit!r}",
                             "unit")
    return unit


def _fmt(x: float) -> str:
    return f"{x:.15g}"


def sheet_svg(layout: Layout, s: int, *, labels: Labels | None = None, unit: str = "",
              decimals: int = 3) -> str:
    """The SVG text of sheet ``s``.

    Parameters
    ----------
    layout : Layout
    s : int
        Sheet index (0-based).
    labels : Labels, optional
        Precomputed :func:`panel_labels` (computed here when omitted).
    unit : str
        ``""``, ``"mm"``, ``"cm"``, ``"m"``, ``"in"`` or ``"ft"``.
    decimals : int
        Decimals of the edge-length labels.
    """
    unit = _check_unit(unit)
    if labels is None:
        labels = panel_labels(layout, decimals=decimals)
    w, h = (float(x) for x in layout.sheet_size)
    svg_unit = unit if unit in ("mm", "cm", "in") else ""
    scale_unit = {"m": 100.0, "ft": 12.0}.get(unit)
    if scale_unit:  # SVG has no metre or foot: state the size in cm / in.
        size = (f"{_fmt(w * scale_unit)}{'cm' if unit == 'm' else 'in'}",
                f"{_fmt(h * scale_unit)}{'cm' if unit == 'm' else 'in'}")
    else:
        size = (f"{_fmt(w)}{svg_unit}", f"{_fmt(h)}{svg_unit}")
    stroke = _fmt(max(w, h) * 5e-4)
    out = io.StringIO()
    out.write('<?xml version="1.0" encoding="UTF-8"?>\n')
    out.write(f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{size[0]}" '
              f'height="{size[1]}" viewBox="0 0 {_fmt(w)} {_fmt(h)}">\n')
    out.write(f"<title>ruledmesh sheet {s + 1} of {layout.n_sheets}</title>\n")
    out.write(f'<g id="SHEET" fill="none" stroke="#0000ff" stroke-width="{stroke}">'
              f'<rect x="0" y="0" width="{_fmt(w)}" height="{_fmt(h)}"/></g>\n')
    out.write(f'<g id="CUT" fill="none" stroke="#ff0000" stroke-width="{stroke}">\n')
    faces = layout.panels_on(s)
    for f in faces:
        pts = layout.polygon(int(f))
        coords = " ".join(f"{_fmt(x)},{_fmt(h - y)}" for x, y in pts)
        out.write(f'<polygon id="panel-{int(f)}" points="{coords}"/>\n')
    out.write("</g>\n")
    out.write('<g id="LABEL" fill="#000000" font-family="sans-serif" text-anchor="middle" '
              'dominant-baseline="middle">\n')
    for f in faces:
        for text, (x, y), angle, size_ in labels.of_face(int(f)):
            # SVG rotates clockwise with y down: the same visual angle is -angle.
            out.write(f'<text x="{_fmt(x)}" y="{_fmt(h - y)}" font-size="{_fmt(size_)}" '
                      f'transform="rotate({_fmt(-angle)} {_fmt(x)} {_fmt(h - y)})">'
                      f"{text}</text>\n")
    out.write("</g>\n</svg>\n")
    return out.getvalue()


def sheet_dxf(layout: Layout, s: int, *, labels: Labels | None = None, unit: str = "",
              decimals: int = 3) -> bytes:
    """The DXF (R2010) bytes of sheet ``s``; needs ``ezdxf`` (extra ``dxf``).

    Parameters are as for :func:`sheet_svg`.
    """
    unit = _check_unit(unit)
    try:
        import ezdxf
        from ezdxf.enums import TextEntityAlignment
    except ImportError:
        raise ExportError("DXF sheets need ezdxf: pip install 'ruledmesh[dxf]'") from None
    if labels is None:
        labels = panel_labels(layout, decimals=decimals)
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = UNITS[unit]
    doc.layers.add("SHEET", color=5)
    doc.layers.add("CUT", color=1)
    doc.layers.add("LABEL", color=7)
    msp = doc.modelspace()
    w, h = (float(x) for x in layout.sheet_size)
    msp.add_lwpolyline([(0, 0), (w, 0), (w, h), (0, h)], close=True, dxfattribs={"layer": "SHEET"})
    for f in layout.panels_on(s):
        f = int(f)
        msp.add_lwpolyline(layout.polygon(f).tolist(), close=True,
                           dxfattribs={"layer": "CUT"})
        for text, (x, y), angle, size_ in labels.of_face(f):
            msp.add_text(text, height=size_, rotation=angle, dxfattribs={"layer": "LABEL"}) \
               .set_placement((x, y), align=TextEntityAlignment.MIDDLE_CENTER)
    stream = io.StringIO()
    doc.write(stream)
    return stream.getvalue().encode(doc.output_encoding)
