"""Wavefront OBJ: polygons kept as they are, generators as ``l`` elements.

Face kinds are written as groups (``g quad``, ``g border``, ``g fill`` ...),
switching group only where the kind changes, so the face order is kept and
Rhino and Blender show each kind as its own group.  Members (generator
segments) follow under ``g generators``, one ``l`` line each; the generator
index of each member is kept in a trailing ``# member ids`` comment block that
ruledmesh reads back and other readers ignore.  Coordinates are written with
17 significant digits, so a round trip is exact.  OBJ has no unit field: the
unit is stated in the header comment ``# units: mm`` (read back by
ruledmesh).  OBJ has no up-axis either: Rhino reads it Z-up (as written),
Blender's importer turns Y-up files to its Z-up by default, so import with
"Up Axis: Z" (``forward_axis='Y', up_axis='Z'``) to keep the design upright.
"""

from __future__ import annotations

import io
import itertools

import numpy as np

from ..errors import ParameterError
from ..mesh import FaceKind, Mesh
from ..units import unit_of

__all__ = ["dumpb", "dumps", "loadb", "loads"]


def _runs(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Start indices and values of runs of equal values."""
    if values.size == 0:
        return np.zeros(0, np.int64), values
    starts = np.flatnonzero(np.r_[True, values[1:] != values[:-1]])
    return starts, values[starts]


def dumps(mesh: Mesh) -> str:
    """The OBJ text of ``mesh``.

    Parameters
    ----------
    mesh : Mesh

    Returns
    -------
    str
    """
    out = io.StringIO()
    out.write("# ruledmesh OBJ\n")
    # OBJ has no unit: state it where people and ruledmesh's reader look.
    out.write(f"# units: {mesh.units}\n")
    for key in ("construction", "source"):
        if key in mesh.info:
            out.write(f"# {key}: {mesh.info[key]}\n")
    out.write("o ruledmesh\n")
    np.savetxt(out, mesh.vertices, fmt="v %.17g %.17g %.17g")
    one = mesh.face_indices + 1
    lines = np.char.mod("%d", one)
    # Join each face's indices; np.split keeps this a per-face list only at write time.
    starts, kinds = _runs(mesh.face_kind)
    bounds = np.r_[starts, mesh.n_faces]
    for r, kind in enumerate(kinds):
        out.write(f"g {FaceKind(int(kind)).label}\n")
        f0, f1 = bounds[r], bounds[r + 1]
        offs = mesh.face_offsets[f0:f1 + 1]
        val = np.diff(offs)
        if np.all(val == val[0]):
            block = lines[offs[0]:offs[-1]].reshape(-1, int(val[0]))
            out.write("".join("f " + " ".join(row) + "\n" for row in block.tolist()))
        else:
            segs = np.split(lines[offs[0]:offs[-1]], (offs[1:-1] - offs[0]))
            out.write("".join("f " + " ".join(s.tolist()) + "\n" for s in segs))
    if len(mesh.members):
        out.write("g generators\n")
        np.savetxt(out, mesh.members + 1, fmt="l %d %d")
        out.write("# member ids:")
        out.write("".join(f" {i}" for i in mesh.member_id.tolist()))
        out.write("\n")
    return out.getvalue()


def dumpb(mesh: Mesh) -> bytes:
    """:func:`dumps` encoded as UTF-8."""
    return dumps(mesh).encode("utf-8")


def loads(text: str) -> Mesh:
    """Read OBJ text: ``v``, ``f`` (any valence; ``v/vt/vn`` forms accepted),
    ``l`` (two-point and longer lines become members), and ruledmesh's groups.

    Negative (relative) indices are resolved.  Unknown statements are ignored.
    """
    verts: list[list[float]] = []
    faces: list[list[int]] = []
    kinds: list[int] = []
    members: list[tuple[int, int]] = []
    member_ids: list[int] | None = None
    group_kind = FaceKind.POLYGON
    units = None
    labels = {k.label: k for k in FaceKind}

    def index(tok: str, lineno: int) -> int:
        try:
            i = int(tok.split("/")[0])
        except ValueError:
            raise ParameterError(f"line {lineno}: bad vertex index \"{tok}\"", "obj") from None
        return i - 1 if i > 0 else len(verts) + i

    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("# member ids:"):
            member_ids = [int(x) for x in line.split(":", 1)[1].split()]
            continue
        if line.startswith("# units:"):
            units = unit_of(line.split(":", 1)[1].strip(), f"obj line {lineno}: units").value
            continue
        if line[0] == "#":
            continue
        tag, _, rest = line.partition(" ")
        parts = rest.split()
        if tag == "v":
            try:
                verts.append([float(x) for x in parts[:3]])
            except ValueError:
                raise ParameterError(f"line {lineno}: bad vertex \"{line}\"", "obj") from None
        elif tag == "f":
            face = [index(t, lineno) for t in parts]
            if len(face) < 3:
                raise ParameterError(f"line {lineno}: a face needs 3 vertices", "obj")
            faces.append(face)
            kind = group_kind
            if kind == FaceKind.POLYGON and len(face) == 4:
                kind = FaceKind.QUAD
            kinds.append(int(kind))
        elif tag == "l":
            ids = [index(t, lineno) for t in parts]
            members.extend(itertools.pairwise(ids))
        elif tag == "g":
            group_kind = labels.get(parts[0] if parts else "", FaceKind.POLYGON)
    if member_ids is not None and len(member_ids) != len(members):
        member_ids = None
    return Mesh.from_faces(np.array(verts, dtype=np.float64).reshape(-1, 3), faces,
                           np.array(kinds, dtype=np.uint8),
                           members=np.array(members, dtype=np.int64).reshape(-1, 2),
                           member_id=member_ids, info={} if units is None else {"units": units})


def loadb(data: bytes) -> Mesh:
    """:func:`loads` from UTF-8 bytes."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise ParameterError("not a text OBJ file", "obj") from None
    return loads(text)
