"""DXF (via ezdxf): faces as MESH entities, generators as LINEs, a layer per kind.

Each face kind present becomes one MESH entity (n-gon faces kept: quads stay
quads, pentagons stay pentagons) on layer ``ruledmesh-<kind>`` (e.g.
``ruledmesh-quad``, ``ruledmesh-border``), holding only the vertices its faces
use.  Each member (generator segment) is a LINE on layer ``generators`` whose
XDATA (application ``RULEDMESH``, group 1071) is the generator id.  The file
is DXF R2010 (MESH needs R2000 or later); coordinates are written at full
double precision.  Requires the optional dependency ``ezdxf``
(``pip install ruledmesh[dxf]``).
"""

from __future__ import annotations

import io

import numpy as np

from ..mesh import FaceKind, Mesh

__all__ = ["dumpb", "LAYER_COLOURS", "APPID"]

APPID = "RULEDMESH"
# AutoCAD colour index per face kind.
LAYER_COLOURS = {FaceKind.QUAD: 8, FaceKind.BORDER: 30, FaceKind.FILL: 5, FaceKind.SPLIT: 1,
                 FaceKind.TRIANGLE: 3, FaceKind.POLYGON: 6, FaceKind.STRIP: 4}


def layer_name(kind: FaceKind) -> str:
    """The DXF layer of faces of ``kind``."""
    return f"ruledmesh-{kind.label}"


def _import_ezdxf():
    from . import require

    return require("ezdxf", "dxf", "DXF export")


def dumpb(mesh: Mesh) -> bytes:
    """The DXF bytes (UTF-8 text) of ``mesh``.

    Parameters
    ----------
    mesh : Mesh

    Returns
    -------
    bytes
    """
    ezdxf = _import_ezdxf()
    doc = ezdxf.new("R2010", units=0)
    doc.appids.add(APPID)
    msp = doc.modelspace()
    for kind in np.unique(mesh.face_kind).tolist():
        kind = FaceKind(kind)
        doc.layers.add(layer_name(kind), color=LAYER_COLOURS[kind])
        sub = mesh.select_faces(mesh.face_kind == kind)
        used, local = np.unique(sub.face_indices, return_inverse=True)
        offs = sub.face_offsets
        faces = np.split(local.reshape(-1), offs[1:-1])
        entity = msp.add_mesh(dxfattribs={"layer": layer_name(kind)})
        with entity.edit_data() as data:
            data.vertices = [tuple(p) for p in mesh.vertices[used].tolist()]
            data.faces = [f.tolist() for f in faces]
    if len(mesh.members):
        doc.layers.add("generators", color=7)
        ends = mesh.vertices[mesh.members].tolist()
        for (p, q), gid in zip(ends, mesh.member_id.tolist()):
            line = msp.add_line(p, q, dxfattribs={"layer": "generators"})
            line.set_xdata(APPID, [(1071, int(gid))])
    out = io.StringIO()
    doc.write(out)
    return out.getvalue().encode("utf-8")
