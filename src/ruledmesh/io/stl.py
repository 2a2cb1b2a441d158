"""Binary STL: the mesh triangulated without splinters, for printing.

Faces are split by :func:`ruledmesh.triangulate.triangulate` (quads along the
shorter diagonal, polygons by the max-min-angle split).  Each triangle's
normal is its *face's* normal, so the halves of a planar panel carry the same
normal.  The 2-byte attribute of each triangle holds the face kind
(:class:`~ruledmesh.mesh.FaceKind` value); STL has no faces, members or
double precision, so coordinates are float32 and generators are dropped.
The polygon structure is recoverable from the triangle order: face ``f``
gives ``valence(f) - 2`` consecutive triangles (see ``docs/exports.md``).

STL has no unit field: the 80-byte header states it (``units=mm``).  Float32
keeps about 7 digits, so a mesh far from the origin (site coordinates) is
rounded by centimetres or more: ``origin`` subtracts a point first (recorded
in the header as ``origin=x,y,z``), and without it a
:class:`~ruledmesh.errors.RuledMeshWarning` says how much is lost.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._validation import check_vector
from ..analysis.faces import face_normals
from ..errors import RuledMeshWarning
from ..mesh import Mesh
from ..tolerances import FLOAT32_WARNING
from ..triangulate import triangulate

__all__ = ["RECORD", "dumpb", "float32_error"]

# One STL triangle record: normal, three corners (float32), attribute word.
RECORD = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attr", "<u2")])
# Warn when float32 rounding moves corners by more than this fraction of the mesh size.
PRECISION_WARNING = FLOAT32_WARNING


def float32_error(vertices: np.ndarray) -> float:
    """Largest rounding error of ``vertices`` stored as float32 (half an ulp at the largest)."""
    if vertices.size == 0:
        return 0.0
    return float(np.spacing(np.float32(np.abs(vertices).max()))) / 2


def _origin(mesh: Mesh, origin) -> np.ndarray:
    if origin is None:
        return np.zeros(3)
    if isinstance(origin, str):
        if origin != "auto":
            raise ValueError  # caught by check_vector's message below
        # Whole units: short in the 80-byte header, and easy to type back in CAD.
        return np.floor(mesh.bounding_box()[0]) if mesh.n_vertices else np.zeros(3)
    return check_vector(origin, "origin")


def dumpb(mesh: Mesh, quads: str = "shorter", origin=None) -> bytes:
    """The binary STL bytes of ``mesh`` triangulated.

    Parameters
    ----------
    mesh : Mesh
    quads : {"shorter", "best"}
        Quad split rule, see :class:`ruledmesh.triangulate.QuadSplit`.
    origin : (3,) float or "auto", optional
        Subtracted from every vertex before rounding to float32 (``"auto"``:
        the bounding box's minimum corner rounded down to whole units);
        written into the header.

    Returns
    -------
    bytes
        80-byte header, uint32 triangle count, 50-byte records.

    Warns
    -----
    RuledMeshWarning
        When the coordinates written lose more than 1e-5 of the mesh size.
    """
    try:
        o = _origin(mesh, origin)
    except ValueError:
        from ..errors import ParameterError

        raise ParameterError(f'expected a point (x, y, z) or "auto", got {origin!r}', "origin") from None
    local = mesh.vertices - o
    err = float32_error(local)
    if err > PRECISION_WARNING * (mesh.diagonal() or 1.0):
        warnings.warn(f"STL stores float32: coordinates this far from the origin are rounded by "
                      f"up to {err:.3g} {mesh.units}; give an origin (--origin auto) to keep them",
                      RuledMeshWarning, stacklevel=2)
    tri = triangulate(mesh, quads)
    # Newell sums of absolute positions lose digits far from the origin
    # (site coordinates); the normals of the centred mesh are the same vectors.
    normals, _ = face_normals(mesh.with_vertices(mesh.vertices - mesh.bounding_box().mean(axis=0)))
    rec = np.zeros(tri.n_triangles, dtype=RECORD)
    rec["normal"] = normals[tri.face_of]
    rec["corners"] = local[tri.triangles]
    rec["attr"] = mesh.face_kind[tri.face_of]
    name = str(mesh.info.get("construction", "mesh"))
    text = f"ruledmesh STL units={mesh.units} attr=kind"
    if origin is not None:
        text += " origin=" + ",".join(f"{x:.17g}" for x in o.tolist())
    # A header starting with "solid" makes some readers try ASCII STL.
    header = f"{text} {name}".encode("ascii", "replace")[:80].ljust(80, b" ")
    return header + np.uint32(tri.n_triangles).tobytes() + rec.tobytes()
