"""Binary STL: the mesh triangulated without splinters, for printing.

Faces are split by :func:`ruledmesh.triangulate.triangulate` (quads along the
shorter diagonal, polygons by the max-min-angle split).  Each triangle's
normal is its *face's* normal, so the halves of a planar panel carry the same
normal.  The 2-byte attribute of each triangle holds the face kind
(:class:`~ruledmesh.mesh.FaceKind` value); STL has no faces, members or
double precision, so coordinates are float32 and generators are dropped.
The polygon structure is recoverable from the triangle order: face ``f``
gives ``valence(f) - 2`` consecutive triangles (see ``docs/exports.md``).
"""

from __future__ import annotations

import numpy as np

from ..analysis.faces import face_normals
from ..mesh import Mesh
from ..triangulate import triangulate

__all__ = ["dumpb", "RECORD"]

# One STL triangle record: normal, three corners (float32), attribute word.
RECORD = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attr", "<u2")])


def dumpb(mesh: Mesh, quads: str = "shorter") -> bytes:
    """The binary STL bytes of ``mesh`` triangulated.

    Parameters
    ----------
    mesh : Mesh
    quads : {"shorter", "best"}
        Quad split rule, see :class:`ruledmesh.triangulate.QuadSplit`.

    Returns
    -------
    bytes
        80-byte header, uint32 triangle count, 50-byte records.
    """
    tri = triangulate(mesh, quads)
    # Newell sums of absolute positions lose digits far from the origin
    # (site coordinates); the normals of the centred mesh are the same vectors.
    normals, _ = face_normals(mesh.with_vertices(mesh.vertices - mesh.bounding_box().mean(axis=0)))
    rec = np.zeros(tri.n_triangles, dtype=RECORD)
    rec["normal"] = normals[tri.face_of]
    rec["corners"] = mesh.vertices[tri.triangles]
    rec["attr"] = mesh.face_kind[tri.face_of]
    name = str(mesh.info.get("construction", "mesh"))
    header = f"ruledmesh binary STL: {name}; attr = face kind".encode("ascii", "replace")[:80]
    # A header starting with "solid" makes some readers try ASCII STL.
    header = header.ljust(80, b" ")
    return header + np.uint32(tri.n_triangles).tobytes() + rec.tobytes()
