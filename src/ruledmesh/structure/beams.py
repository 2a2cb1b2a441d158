"""Beams along the edges and generators, and panels with thickness.

Every solid here is bounded by planar faces:

* an *edge beam* is a slab of width ``w`` centred on the plane through its
  edge and the two node axes, reaching from the mesh layer to the offset layer
  (or to ``depth`` along the axes).  Its two long sides are parallel to that
  plane, its ends contain lines parallel to the node axes (set back from the
  node so neighbouring beams do not overlap), its top lies in the mesh edge
  and its bottom in the offset edge.  On a torsion-free structure the plane
  holds both axes exactly; elsewhere the axes are projected into the plane of
  best fit and the twist left out is the edge's torsion (in the tables);
* a *generator beam* is the same slab along one whole generator (a §4.3
  diagonal member), in the plane through the generator and the mean of its end
  axes;
* a *thick panel* is the prism between a face and its copy moved by the
  thickness ``t`` along the node axes, away from the offset layer: the
  copy lies in the face plane shifted by exactly ``t``, and the sides lie in
  the edge planes, so panels and beams meet along planes.

Solids are returned as one :class:`~ruledmesh.mesh.Mesh` of closed, outward
oriented polyhedra that share no vertices, with the solid of every face and a
table of what a fabricator needs per solid.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validation import check_float
from ..errors import GeometryError, ParameterError
from ..fabricate.schedules import edge_schedule, member_schedule
from ..mesh import FaceKind, Mesh
from ..tolerances import MIN_HALF_ANGLE
from ..tolerances import TINY as _TINY
from .normals import face_edges
from .support import SupportStructure

__all__ = ["Solids", "edge_beams", "edge_setbacks", "edge_table", "generator_beams", "thick_panels"]

# Corner (in the cross-section of the box) order of the six faces of a slab whose
# eight corners are [P0, P1, Q1, Q0] + w/2 m and the same - w/2 m.
_BOX_FACES = np.array([[0, 1, 2, 3], [7, 6, 5, 4], [0, 4, 5, 1],
                       [1, 5, 6, 2], [2, 6, 7, 3], [3, 7, 4, 0]], dtype=np.int64)
# A panel side may lean at most this far from its axis: beyond it the thick copy runs away.
_MIN_AXIS_COS = 0.1


@dataclass(frozen=True, eq=False)
class Solids:
    """Closed polyhedra (beams or panels) in one mesh.

    Attributes
    ----------
    mesh : Mesh
        Every solid's faces, solid after solid; no vertex is shared between
        solids, and every solid is closed and oriented outwards.
    solid : (F,) int64
        The solid each face belongs to.
    names : list of str
        One name per solid (``beam 12``, ``panel 3``, ``generator 5``).
    table : dict of (S,) arrays
        Per-solid columns (see the functions that make them).
    skipped : (K,) int64
        Edges, generators or faces that got no solid, because it would
        not be a valid solid there (see ``skip_reason``).
    skip_reason : str
        Why, for the notes of ``structure.json``; empty when nothing was skipped.
    """

    mesh: Mesh
    solid: np.ndarray
    names: list[str]
    table: dict[str, np.ndarray]
    skipped: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    skip_reason: str = ""

    @property
    def count(self) -> int:
        """Number of solids."""
        return len(self.names)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1), _TINY)[..., None]


def _newell(vertices: np.ndarray, offsets: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """(F, 3): Newell area vectors of CSR faces."""
    nxt = np.arange(indices.size) + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    origin = vertices[indices[np.repeat(offsets[:-1], np.diff(offsets))]]
    cr = np.cross(vertices[indices] - origin, vertices[indices[nxt]] - origin)
    return 0.5 * np.add.reduceat(cr, offsets[:-1], axis=0)


def _orient_outwards(vertices, offsets, indices, solid, n_solids) -> np.ndarray:
    """Face indices with every solid of negative signed volume turned inside out."""
    area = _newell(vertices, offsets, indices)
    centroid = np.add.reduceat(vertices[indices], offsets[:-1], axis=0) / np.diff(offsets)[:, None]
    volume = np.bincount(solid, np.einsum("ij,ij->i", area, centroid) / 3.0, minlength=n_solids)
    flip = (volume < 0.0)[solid]
    val = np.diff(offsets)
    start = np.repeat(offsets[:-1], val)
    pos = np.arange(indices.size) - start
    mirrored = start + np.repeat(val, val) - 1 - pos
    out = indices.copy()
    sel = np.repeat(flip, val)
    out[sel] = indices[mirrored[sel]]
    return out


def _slabs(p0, p1, q0, q1, normal, width) -> tuple[np.ndarray, np.ndarray]:
    """Boxes over planar quads ``p0 p1 q1 q0`` thickened by ``width`` along ``normal``.

    Returns
    -------
    vertices : (8 S, 3) float64
    faces : (6 S, 4) int64
    """
    half = 0.5 * width * normal
    mid = np.stack([p0, p1, q1, q0], axis=1)                     # (S, 4, 3)
    corners = np.concatenate([mid + half[:, None], mid - half[:, None]], axis=1)
    s = len(p0)
    faces = (_BOX_FACES[None] + 8 * np.arange(s)[:, None, None]).reshape(-1, 4)
    return corners.reshape(-1, 3), faces


def _box_solids(vertices, faces, names, table, info, keep: np.ndarray, reason: str) -> Solids:
    """The boxes whose ``keep`` is true, as Solids (the others listed as skipped)."""
    vertices = vertices.reshape(-1, 8, 3)[keep].reshape(-1, 3)
    faces = faces.reshape(-1, 6, 4)[keep]
    faces = (faces - faces[:, :1, :1] + 8 * np.arange(len(faces))[:, None, None]).reshape(-1, 4)
    s = int(np.count_nonzero(keep))
    solid = np.repeat(np.arange(s), 6)
    offsets = np.arange(len(faces) + 1, dtype=np.int64) * 4
    idx = _orient_outwards(vertices, offsets, faces.reshape(-1), solid, s)
    mesh = Mesh(vertices, offsets, idx, np.full(len(faces), FaceKind.QUAD, np.uint8), info=info)
    skipped = np.flatnonzero(~keep)
    return Solids(mesh, solid, [n for n, k in zip(names, keep.tolist()) if k],
                  {k: np.asarray(v)[keep] for k, v in table.items()}, skipped,
                  reason if skipped.size else "")


def edge_setbacks(structure: SupportStructure, width: float) -> np.ndarray:
    """Setbacks that keep edge beams of ``width`` apart at the nodes.

    Two beams meeting at a node at the angle ``theta`` (measured across the
    node axis) overlap within ``(w / 2) / tan(theta / 2)`` of the node; each
    beam end is set back by the largest such distance over its neighbours
    around the node, capped at 45 % of the beam's length.

    Returns
    -------
    (E, 2) float64
        Setback at the ``edges[:, 0]`` and ``edges[:, 1]`` ends.
    """
    mesh = structure.mesh
    edges, corner_edge, nxt = face_edges(mesh)
    idx = mesh.face_indices
    prv = np.empty_like(nxt)
    prv[nxt] = np.arange(nxt.size)
    v = mesh.vertices
    axes = structure.axes[idx]
    # The two edges leaving each corner, seen along the node axis.
    d1 = v[idx[nxt]] - v[idx]
    d2 = v[idx[prv]] - v[idx]
    d1 -= np.einsum("ij,ij->i", d1, axes)[:, None] * axes
    d2 -= np.einsum("ij,ij->i", d2, axes)[:, None] * axes
    theta = np.arctan2(np.linalg.norm(np.cross(d1, d2), axis=1), np.einsum("ij,ij->i", d1, d2))
    need = 0.5 * width / np.tan(np.maximum(0.5 * theta, MIN_HALF_ANGLE))
    out = np.zeros((len(edges), 2))
    for e, at_vertex in ((corner_edge, idx), (corner_edge[prv], idx)):
        end = (edges[e, 1] == at_vertex).astype(np.int64)
        np.maximum.at(out, (e, end), need)
    length = np.linalg.norm(v[edges[:, 1]] - v[edges[:, 0]], axis=1)
    return np.minimum(out, 0.45 * length[:, None])


def _bottoms(structure: SupportStructure, ends: np.ndarray, depth: float | None) -> np.ndarray:
    """(n, 3): where the axes at ``ends`` reach the beam depth (offset layer by default)."""
    if depth is None:
        return structure.offset[ends]
    return structure.mesh.vertices[ends] + depth * structure.axes[ends]


def _planes(direction, a0, a1) -> np.ndarray:
    """Unit normals of the planes through ``direction`` and the mean of the two axes.

    On a torsion-free edge both axes lie in that plane; otherwise it splits the
    twist between the two ends.
    """
    return _unit(np.cross(direction, _unit(a0) + _unit(a1)))


def edge_beams(structure: SupportStructure, width: float, *, depth: float | None = None,
               setback: float | str = "auto") -> Solids:
    """One planar-sided beam per face edge.

    Parameters
    ----------
    structure : SupportStructure
    width : float
        Beam width (across the edge plane), > 0.
    depth : float, optional
        Beam depth along the node axes; default: down to the offset layer.
    setback : float or "auto"
        Distance from the node axis to the beam end, along the edge; ``"auto"``
        uses :func:`edge_setbacks`.

    Returns
    -------
    Solids
        Table columns: those of :func:`edge_table`, then ``width``,
        ``setback0``, ``setback1`` (node axis to beam end, along the edge),
        ``depth0``, ``depth1`` (along the ends, in the beam plane).
    """
    width = check_float(width, "width", lo=0.0, lo_open=True)
    if depth is not None:
        depth = check_float(depth, "depth", lo=0.0, lo_open=True)
    mesh, edges = structure.mesh, structure.edges
    v = mesh.vertices
    i, j = edges[:, 0], edges[:, 1]
    if isinstance(setback, str):
        if setback != "auto":
            raise ParameterError(f'expected a number or "auto", got "{setback}"', "setback")
        back = edge_setbacks(structure, width)
    else:
        back = np.full((len(edges), 2), check_float(setback, "setback", lo=0.0))
    e = v[j] - v[i]
    length = np.linalg.norm(e, axis=1)
    eu = e / length[:, None]
    b0, b1 = _bottoms(structure, i, depth), _bottoms(structure, j, depth)
    m = _planes(eu, b0 - v[i], b1 - v[j])
    # Project the bottoms into the beam plane: exact already where torsion-free.
    b0 = b0 - np.einsum("ij,ij->i", b0 - v[i], m)[:, None] * m
    b1 = b1 - np.einsum("ij,ij->i", b1 - v[j], m)[:, None] * m
    bottom = np.einsum("ij,ij->i", b1 - b0, eu)
    keep = bottom > 0.0
    back = _fit_setbacks(back, length, np.where(keep, bottom, length))
    p0 = v[i] + back[:, :1] * eu
    p1 = v[j] - back[:, 1:] * eu
    q0 = b0 + back[:, :1] * eu
    q1 = b1 - back[:, 1:] * eu
    verts, faces = _slabs(p0, p1, q0, q1, m, width)
    table = {**edge_table(structure), "width": np.full(len(edges), width),
             "setback0": back[:, 0], "setback1": back[:, 1],
             "depth0": np.linalg.norm(b0 - v[i], axis=1), "depth1": np.linalg.norm(b1 - v[j], axis=1)}
    names = [f"beam {k}" for k in range(len(edges))]
    return _box_solids(verts, faces, names, table, {"construction": "edge beams", "width": width},
                       keep, "their offset edge runs backwards (the offset or depth is larger "
                             "than the radius of curvature there)")


def _fit_setbacks(back: np.ndarray, top: np.ndarray, bottom: np.ndarray) -> np.ndarray:
    """Setbacks scaled down where they would leave less than 10 % of a beam's top or bottom."""
    room = 0.9 * np.minimum(top, bottom)
    total = back.sum(axis=1)
    scale = np.where(total > room, room / np.maximum(total, _TINY), 1.0)
    return back * scale[:, None]


def _angle(a, b) -> np.ndarray:
    """Angle in degrees between unit vectors, folded into [0, 90] (lines, not rays)."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1),
                                 np.abs(np.einsum("ij,ij->i", a, b))))


def edge_table(structure: SupportStructure) -> dict[str, np.ndarray]:
    """The edge schedule of a structure: panels, torsion and cut angles per edge.

    The beam plane of an edge holds the edge and the mean of its two node
    axes (both axes, where torsion-free).

    Returns
    -------
    dict of (E,) arrays
        ``edge``, ``v0``, ``v1``, ``length``, ``face0``, ``face1`` (-1 on the
        border), ``dihedral_deg`` (between the two panels, 180 = flat),
        ``torsion_deg``, ``edge_planarity`` (of the quad edge + offset edge),
        ``panel0_deg``, ``panel1_deg`` (angle between the beam plane and each
        panel, 90 = square), ``bevel0_deg``, ``bevel1_deg`` (end cuts along
        the node axes, 0 = square to the beam).
    """
    from ..analysis.faces import face_normals

    mesh, edges = structure.mesh, structure.edges
    sched = edge_schedule(mesh)
    if not np.array_equal(np.stack([sched["v0"], sched["v1"]], 1), edges):
        raise RuntimeError("edge schedule and structure edges disagree")  # a bug, not bad input
    v = mesh.vertices
    eu = _unit(v[edges[:, 1]] - v[edges[:, 0]])
    a0, a1 = structure.axes[edges[:, 0]], structure.axes[edges[:, 1]]
    m = _planes(eu, a0, a1)
    normals, _ = face_normals(mesh)
    f0, f1 = sched["face0"], sched["face1"]
    # Angle between the beam plane and each panel (the angle between their normals).
    panel0 = _angle(m, normals[f0])
    panel1 = np.where(f1 >= 0, _angle(m, normals[np.maximum(f1, 0)]), np.nan)
    # An end face holds the (projected) axis and the plane normal; its normal
    # against the beam direction is the bevel: 0 = square cut.
    bevel0 = _angle(_unit(np.cross(a0, m)), eu)
    bevel1 = _angle(_unit(np.cross(a1, m)), eu)
    return {"edge": np.arange(len(edges)), "v0": sched["v0"], "v1": sched["v1"],
            "length": sched["length"], "face0": f0, "face1": f1,
            "dihedral_deg": sched["dihedral_deg"], "torsion_deg": structure.torsion,
            "edge_planarity": structure.measures["edge_planarity"],
            "panel0_deg": panel0, "panel1_deg": panel1, "bevel0_deg": bevel0,
            "bevel1_deg": bevel1}


def generator_beams(structure: SupportStructure, width: float, *,
                    depth: float | None = None) -> Solids:
    """One planar-sided beam per generator (the mesh's members, joined by ``member_id``).

    Parameters
    ----------
    structure : SupportStructure
    width : float
        Beam width, > 0.
    depth : float, optional
        Depth along the node axes at the ends; default: down to the offset layer.

    Returns
    -------
    Solids
        Table columns: ``generator``, ``node0``, ``node1``, ``length``,
        ``axis_misfit_deg`` (how far the end axes leave the beam plane: 0 when
        they are coplanar with the generator), ``bevel0_deg``, ``bevel1_deg``,
        ``depth0``, ``depth1``.
    """
    width = check_float(width, "width", lo=0.0, lo_open=True)
    if depth is not None:
        depth = check_float(depth, "depth", lo=0.0, lo_open=True)
    sched = member_schedule(structure.mesh)
    n0, n1 = sched["node0"], sched["node1"]
    if n0.size == 0:
        raise GeometryError("the mesh has no generators (members) to put beams on")
    v = structure.mesh.vertices
    g = _unit(v[n1] - v[n0])
    b0, b1 = _bottoms(structure, n0, depth), _bottoms(structure, n1, depth)
    m = _planes(g, b0 - v[n0], b1 - v[n1])
    misfit = np.maximum(90.0 - _angle(m, _unit(b0 - v[n0])), 90.0 - _angle(m, _unit(b1 - v[n1])))
    b0 = b0 - np.einsum("ij,ij->i", b0 - v[n0], m)[:, None] * m
    b1 = b1 - np.einsum("ij,ij->i", b1 - v[n1], m)[:, None] * m
    keep = np.einsum("ij,ij->i", b0 - v[n0], b1 - v[n1]) > 0.0
    verts, faces = _slabs(v[n0], v[n1], b0, b1, m, width)
    table = {"generator": sched["generator"], "node0": n0, "node1": n1, "length": sched["length"],
             "axis_misfit_deg": misfit,
             "bevel0_deg": _angle(_unit(np.cross(b0 - v[n0], m)), g),
             "bevel1_deg": _angle(_unit(np.cross(b1 - v[n1], m)), g),
             "depth0": np.linalg.norm(b0 - v[n0], axis=1),
             "depth1": np.linalg.norm(b1 - v[n1], axis=1)}
    names = [f"generator {k}" for k in sched["generator"].tolist()]
    return _box_solids(verts, faces, names, table,
                       {"construction": "generator beams", "width": width}, keep,
                       "the axes at their two ends point to opposite sides of the generator")


def _panel_faces(offsets: np.ndarray, nxt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """CSR faces of the prisms over CSR faces: top, reversed bottom, one quad per edge.

    Corner ``p`` of the input is vertex ``p`` (top) and ``N + p`` (bottom).

    Returns
    -------
    offsets, indices : CSR arrays, faces grouped solid after solid
    solid : (G,) int64
    """
    n = int(offsets[-1])
    f = len(offsets) - 1
    val = np.diff(offsets)
    pos = np.arange(n)
    start = np.repeat(offsets[:-1], val)
    top = pos
    bottom = n + start + np.repeat(val, val) - 1 - (pos - start)
    sides = np.stack([nxt, pos, n + pos, n + nxt], axis=1)
    # Per solid: top (val), bottom (val), then val side quads; lay them out in that order.
    per = 2 * val + 4 * val
    sol_start = np.r_[0, np.cumsum(per)[:-1]]
    face_of = np.repeat(np.arange(f), val)
    local = pos - start
    indices = np.empty(int(per.sum()), dtype=np.int64)
    indices[sol_start[face_of] + local] = top
    indices[sol_start[face_of] + np.repeat(val, val) + local] = bottom
    side_pos = (sol_start[face_of] + 2 * np.repeat(val, val) + 4 * local)[:, None] + np.arange(4)
    indices[side_pos] = sides
    counts = 2 + val
    lengths = np.zeros(int(counts.sum()), dtype=np.int64)
    first = np.r_[0, np.cumsum(counts)[:-1]]
    lengths[first] = val
    lengths[first + 1] = val
    rest = np.ones(int(counts.sum()), dtype=bool)
    rest[first] = False
    rest[first + 1] = False
    lengths[rest] = 4
    face_offsets = np.r_[0, np.cumsum(lengths)].astype(np.int64)
    return face_offsets, indices, np.repeat(np.arange(f), counts)


def thick_panels(structure: SupportStructure, thickness: float, *, side: str = "outer") -> Solids:
    """Every face as a solid panel of constant thickness, its sides in the edge planes.

    Parameters
    ----------
    structure : SupportStructure
    thickness : float
        Panel thickness, > 0: the distance between the panel's two faces.
    side : {"outer", "inner"}
        ``"outer"``: the panels lie on the side away from the offset layer
        (glass on the frame); ``"inner"``: towards it.

    Returns
    -------
    Solids
        Table columns: ``face``, ``kind`` (FaceKind value), ``sides``,
        ``thickness``, ``side_planarity_max`` (0 on a torsion-free structure;
        otherwise the twist of the panel's sides), ``area``.
    """
    from ..analysis.faces import face_normals, quad_planarity

    thickness = check_float(thickness, "thickness", lo=0.0, lo_open=True)
    if side not in ("outer", "inner"):
        raise ParameterError(f'expected "outer" or "inner", got "{side}"', "side")
    full = structure.mesh
    normals, area = face_normals(full)
    sign = -1.0 if side == "outer" else 1.0
    face_of = full.face_of
    cos = np.einsum("ij,ij->i", sign * structure.axes[full.face_indices], normals[face_of])
    first = np.repeat(full.face_offsets[:-1], full.valences)
    # A panel needs every corner's axis well out of its plane, all on one side.
    bad_corner = (np.abs(cos) < _MIN_AXIS_COS) | (np.sign(cos) != np.sign(cos[first]))
    good = np.bincount(face_of, bad_corner, minlength=full.n_faces) == 0
    mesh = full.select_faces(good)
    keep_corner = good[face_of]
    cos, face_ids = cos[keep_corner], np.flatnonzero(good)
    _, _, nxt = face_edges(mesh)
    idx = mesh.face_indices
    local_face = mesh.face_of
    top = mesh.vertices[idx]
    bottom = top + (thickness / np.abs(cos))[:, None] * (sign * structure.axes[idx])
    verts = np.concatenate([top, bottom])
    offsets, indices, solid = _panel_faces(mesh.face_offsets, nxt)
    indices = _orient_outwards(verts, offsets, indices, solid, mesh.n_faces)
    sides = np.stack([top[nxt], top, bottom, bottom[nxt]], axis=1)
    side_plan = np.zeros(mesh.n_faces)
    np.maximum.at(side_plan, local_face, quad_planarity(sides))
    out = Mesh(verts, offsets, indices, np.full(len(offsets) - 1, FaceKind.POLYGON, np.uint8),
               info={"construction": "thick panels", "thickness": thickness})
    table: dict[str, Any] = {"face": face_ids, "kind": mesh.face_kind.astype(np.int64),
                             "sides": mesh.valences, "thickness": np.full(mesh.n_faces, thickness),
                             "side_planarity_max": side_plan, "area": area[good]}
    skipped = np.flatnonzero(~good)
    return Solids(out, solid, [f"panel {k}" for k in face_ids.tolist()], table, skipped,
                  "their node axes lie almost in their plane (more than 84 degrees from the "
                  "normal) or on both sides of it" if skipped.size else "")
