"""The polygon mesh type: float64 vertices, faces of mixed valence, members.

Faces are stored in compressed-row form: one flat ``face_indices`` array and
``face_offsets`` such that face ``f`` is
``face_indices[face_offsets[f]:face_offsets[f + 1]]``.  That keeps quads,
clipped border pentagons and fill triangles in two numpy arrays, with no
Python list per face in any hot path.  Every face carries a :class:`FaceKind`;
the *members* are straight segments between vertices (the generators, which
become beams or cables, paper §6).
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field, replace
from enum import IntEnum
from typing import Any

import numpy as np

from ._arrays import diagonal, extent, ranks, unique
from ._validation import check_points
from .errors import ParameterError
from .tolerances import ROUNDING, TINY

__all__ = ["FaceKind", "Mesh"]


class FaceKind(IntEnum):
    """What a face is, kept per face through every operation and export.

    ``QUAD``: a planar quad of a construction (PQ face).
    ``BORDER``: a face clipped by the patch border (planar polygon, 3-6 sides).
    ``FILL``: a triangle filling a notch or a torsal hole (paper §4.3).
    ``SPLIT``: half of a quad that failed the convexity check, split along its
    generator diagonal instead of being shipped as a bow-tie.
    ``TRIANGLE``: a triangle of a hybrid HP-patch mesh (paper §4.1).
    ``POLYGON``: any other planar polygon (caps, imported faces).
    ``STRIP``: a quad between two consecutive generators that are coplanar (to
    the planarity tolerance), with two vertices on each (paper §3.1).
    """

    QUAD = 0
    BORDER = 1
    FILL = 2
    SPLIT = 3
    TRIANGLE = 4
    POLYGON = 5
    STRIP = 6

    @property
    def label(self) -> str:
        """Lower-case name used in files and reports."""
        return self.name.lower()

    @classmethod
    def from_label(cls, label: str) -> FaceKind:
        """The kind named ``label`` (as written by :attr:`label`)."""
        try:
            return cls[label.upper()]
        except KeyError:
            raise ParameterError(
                f"expected one of {', '.join(k.label for k in cls)}, got \"{label}\"", "kind"
            ) from None


def offsets_from_valences(valences: np.ndarray) -> np.ndarray:
    offsets = np.zeros(len(valences) + 1, dtype=np.int64)
    np.cumsum(valences, out=offsets[1:])
    return offsets


# id(face_offsets) -> (weak reference to that array, arrays derived from it); an entry goes
# when its array does.
_BY_OFFSETS: dict[int, tuple[weakref.ref, dict[str, np.ndarray]]] = {}


def _offsets_cache(offsets: np.ndarray) -> dict[str, np.ndarray]:
    """The cache of arrays derived from ``offsets``, shared by every mesh built on it."""
    key = id(offsets)
    entry = _BY_OFFSETS.get(key)
    if entry is not None and entry[0]() is offsets:
        return entry[1]
    cache: dict[str, np.ndarray] = {}

    def forget(_: weakref.ref) -> None:
        _BY_OFFSETS.pop(key, None)

    _BY_OFFSETS[key] = (weakref.ref(offsets, forget), cache)
    return cache


@dataclass(frozen=True, eq=False)
class Mesh:
    """An immutable polygon mesh with per-face kinds and straight members.

    Parameters
    ----------
    vertices : (V, 3) float64
        Vertex positions.
    face_offsets : (F + 1,) int64
        Start of each face in ``face_indices``; ``face_offsets[0] == 0``.
    face_indices : (face_offsets[-1],) int64
        Vertex indices of all faces, concatenated; each face is a closed
        polygon listed in order around its boundary.
    face_kind : (F,) uint8
        A :class:`FaceKind` per face.
    members : (E, 2) int64
        Vertex index pairs of straight members (generator segments).
    member_id : (E,) int64
        Which generator (or other line) each member segment lies on.
    vertex_data : mapping of str to (V, ...) arrays
        Per-vertex attributes, e.g. ``"t"`` (parameter on the generator) and
        ``"generator"`` (generator index).
    info : mapping
        Free-form metadata: construction name, warnings, counts.

    Notes
    -----
    Build meshes with :meth:`from_faces` or :meth:`from_arrays`; both validate.
    The dataclass constructor trusts its arguments (used by constructions that
    produce consistent arrays already).
    """

    vertices: np.ndarray
    face_offsets: np.ndarray
    face_indices: np.ndarray
    face_kind: np.ndarray
    members: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    member_id: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    vertex_data: Mapping[str, np.ndarray] = field(default_factory=dict)
    info: Mapping[str, Any] = field(default_factory=dict)

    # ------------------------------------------------------------------ build
    @classmethod
    def from_arrays(cls, vertices, face_offsets, face_indices, face_kind=None, *,
                    members=None, member_id=None, vertex_data=None, info=None) -> Mesh:
        """Build a mesh from compressed-row face arrays, validating them.

        Parameters
        ----------
        vertices : (V, 3) array_like
        face_offsets : (F + 1,) array_like of int
        face_indices : (N,) array_like of int
        face_kind : (F,) array_like of int or FaceKind, optional
            Defaults to ``QUAD`` for four-sided faces and ``POLYGON`` otherwise.
        members : (E, 2) array_like of int, optional
        member_id : (E,) array_like of int, optional
        vertex_data : mapping, optional
        info : mapping, optional
        """
        v = check_points(vertices, "vertices", min_count=0)
        off = np.asarray(face_offsets, dtype=np.int64).reshape(-1)
        idx = np.asarray(face_indices, dtype=np.int64).reshape(-1)
        if off.size == 0 or off[0] != 0 or off[-1] != idx.size or np.any(np.diff(off) < 3):
            raise ParameterError("expected increasing offsets from 0 to len(face_indices), "
                                 "every face with at least 3 vertices", "face_offsets")
        if idx.size and (idx.min() < 0 or idx.max() >= len(v)):
            raise ParameterError(f"expected vertex indices in [0, {len(v)}), "
                                 f"got [{idx.min()}, {idx.max()}]", "face_indices")
        nf = off.size - 1
        if face_kind is None:
            val = np.diff(off)
            kind = np.where(val == 4, FaceKind.QUAD, FaceKind.POLYGON).astype(np.uint8)
        else:
            kind = np.asarray(face_kind, dtype=np.uint8).reshape(-1)
            if kind.shape != (nf,):
                raise ParameterError(f"expected {nf} kinds, got {kind.shape[0]}", "face_kind")
            if kind.size and kind.max() > max(FaceKind):
                raise ParameterError("expected FaceKind values", "face_kind")
        mem = np.zeros((0, 2), np.int64) if members is None else np.asarray(members, np.int64)
        if mem.ndim != 2 or mem.shape[1] != 2:
            raise ParameterError(f"expected shape (E, 2), got {mem.shape}", "members")
        if mem.size and (mem.min() < 0 or mem.max() >= len(v)):
            raise ParameterError("expected vertex indices", "members")
        mid = (np.arange(len(mem), dtype=np.int64) if member_id is None
               else np.asarray(member_id, np.int64).reshape(-1))
        if mid.shape != (len(mem),):
            raise ParameterError(f"expected {len(mem)} ids, got {mid.shape[0]}", "member_id")
        vdata = {}
        for key, arr in dict(vertex_data or {}).items():
            arr = np.asarray(arr)
            if arr.shape[:1] != (len(v),):
                raise ParameterError(f"expected {len(v)} rows, got {arr.shape}", f"vertex_data.{key}")
            vdata[key] = arr
        return cls(v, off, idx, kind, mem, mid, vdata, dict(info or {}))

    @classmethod
    def from_faces(cls, vertices, faces, face_kind=None, **kwargs) -> Mesh:
        """Build a mesh from a ``(F, k)`` array or a list of index sequences.

        Parameters
        ----------
        vertices : (V, 3) array_like
        faces : (F, k) array_like of int, or sequence of sequences of int
        face_kind : optional
            As in :meth:`from_arrays`.
        **kwargs
            ``members``, ``member_id``, ``vertex_data``, ``info``.
        """
        if isinstance(faces, np.ndarray) and faces.ndim == 2:
            k = faces.shape[1]
            off = np.arange(faces.shape[0] + 1, dtype=np.int64) * k
            idx = faces.reshape(-1)
        else:
            faces = list(faces)
            val = np.fromiter((len(f) for f in faces), dtype=np.int64, count=len(faces))
            off = offsets_from_valences(val)
            idx = (np.concatenate([np.asarray(f, np.int64) for f in faces])
                   if faces else np.zeros(0, np.int64))
        return cls.from_arrays(vertices, off, idx, face_kind, **kwargs)

    @classmethod
    def concatenate(cls, meshes: Iterable[Mesh], info: Mapping[str, Any] | None = None) -> Mesh:
        """Join meshes into one (vertices are not merged; see :meth:`merge_vertices`)."""
        meshes = list(meshes)
        if not meshes:
            raise ParameterError("expected at least one mesh", "meshes")
        vshift = np.cumsum([0] + [m.n_vertices for m in meshes[:-1]])
        ishift = np.cumsum([0] + [m.face_indices.size for m in meshes[:-1]])
        vertices = np.concatenate([m.vertices for m in meshes])
        idx = np.concatenate([m.face_indices + s for m, s in zip(meshes, vshift)])
        off = np.concatenate([[0]] + [m.face_offsets[1:] + s for m, s in zip(meshes, ishift)])
        kind = np.concatenate([m.face_kind for m in meshes])
        mem = np.concatenate([m.members + s for m, s in zip(meshes, vshift)])
        mid = np.concatenate([m.member_id for m in meshes])
        keys = set.intersection(*(set(m.vertex_data) for m in meshes))
        vdata = {k: np.concatenate([m.vertex_data[k] for m in meshes]) for k in keys}
        return cls(vertices, off.astype(np.int64), idx, kind, mem, mid, vdata,
                   dict(info if info is not None else meshes[0].info))

    # -------------------------------------------------------------- queries
    @property
    def n_vertices(self) -> int:
        """Number of vertices."""
        return int(self.vertices.shape[0])

    @property
    def n_faces(self) -> int:
        """Number of faces."""
        return int(self.face_offsets.shape[0] - 1)

    def __getstate__(self) -> dict[str, Any]:
        # The derived arrays stay behind: a pickled mesh (the designer's worker sends one
        # per edit) carries what it is made of, not what was computed from it.
        state = dict(self.__dict__)
        state.pop("_cache", None)
        return state

    def _derived(self, name: str, make: Callable[[], np.ndarray]) -> np.ndarray:
        """``make()``, computed once per ``face_offsets`` array and kept read-only.

        The mesh is immutable, so arrays derived from its faces hold for its life;
        a build asks for the valences hundreds of times.  They depend on the
        offsets alone, and a pass that changes corners but not the faces' sizes
        keeps the offsets array: the meshes it makes share them.  Read-only, so
        that a caller changing one in place fails at once instead of corrupting
        the next caller's.
        """
        cache = self.__dict__.get("_cache")
        if cache is None:
            cache = _offsets_cache(self.face_offsets)
            object.__setattr__(self, "_cache", cache)
        out = cache.get(name)
        if out is None:
            out = make()
            out.setflags(write=False)
            cache[name] = out
        return out

    @property
    def valences(self) -> np.ndarray:
        """(F,) int64: number of vertices of each face (read-only)."""
        # np.diff's result, without its argument handling (a build asks this hundreds of times).
        off = self.face_offsets
        return self._derived("valences", lambda: np.subtract(off[1:], off[:-1]))

    @property
    def face_of(self) -> np.ndarray:
        """(N,) int64: for each entry of ``face_indices``, the face it belongs to.

        Computed on each call, like :meth:`next_corners`: kept with the mesh, the two
        held 35 MB per mesh of a 1000 x 1000 build (old and new mesh of a pass both
        alive) for no time saved.
        """
        return np.repeat(np.arange(self.n_faces), self.valences)

    @property
    def kinds(self) -> np.ndarray:
        """(F,) uint8: the :class:`FaceKind` of each face."""
        return self.face_kind

    def faces_of_valence(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Faces with exactly ``k`` vertices.

        Returns
        -------
        face_ids : (F_k,) int64
            Their indices among all faces.
        faces : (F_k, k) int64
            Their vertex indices.
        """
        ids = np.flatnonzero(self.valences == k)
        if ids.size == 0:
            return ids, np.zeros((0, k), dtype=np.int64)
        cols = self.face_offsets[ids][:, None] + np.arange(k)
        return ids, self.face_indices[cols]

    def fan_triangles(self) -> tuple[np.ndarray, np.ndarray]:
        """Every face as a fan of triangles from its first corner.

        Returns
        -------
        triangles : (T, 3) int64
            Vertex indices.
        face : (T,) int64
            The face each triangle belongs to.
        """
        off = self.face_offsets
        idx = self.face_indices
        ntri = np.maximum(self.valences - 2, 0)
        face = np.repeat(np.arange(self.n_faces), ntri)
        # j = 1 .. k-2 within each face.
        j = ranks(ntri) + 1
        base = off[:-1][face]
        return np.stack([idx[base], idx[base + j], idx[base + j + 1]], axis=1), face

    def padded_faces(self, fill: int = -1) -> np.ndarray:
        """(F, K) int64: faces padded to the largest valence K with ``fill``."""
        val = self.valences
        width = int(val.max()) if val.size else 0
        out = np.full((self.n_faces, width), fill, dtype=np.int64)
        rows = np.repeat(np.arange(self.n_faces), val)
        cols = np.arange(self.face_indices.size) - np.repeat(self.face_offsets[:-1], val)
        out[rows, cols] = self.face_indices
        return out

    def face_list(self) -> list[list[int]]:
        """Faces as Python lists (for writers and tests; not for hot paths)."""
        return [seg.tolist() for seg in np.split(self.face_indices, self.face_offsets[1:-1])]

    def face(self, f: int) -> np.ndarray:
        """(k,) int64: vertex indices of face ``f``."""
        return self.face_indices[self.face_offsets[f]:self.face_offsets[f + 1]]

    def next_corners(self) -> np.ndarray:
        """(N,) int64: for each entry of ``face_indices``, the position of the next corner of its face."""
        nxt = np.arange(self.face_indices.size) + 1
        nxt[self.face_offsets[1:] - 1] = self.face_offsets[:-1]
        return nxt

    def edge_uses(self) -> tuple[np.ndarray, np.ndarray]:
        """Sorted undirected edge keys ``low * n_vertices + high`` and how many faces use each.

        Returns
        -------
        keys : (E,) int64
        uses : (E,) int64
            1 on the border, 2 inside a manifold, more where faces fold together.
        """
        idx = self.face_indices
        nxt = idx[self.next_corners()]
        return np.unique(np.minimum(idx, nxt) * np.int64(self.n_vertices) + np.maximum(idx, nxt),
                         return_counts=True)

    def edges(self) -> np.ndarray:
        """(E, 2) int64: unique undirected edges, each as (low, high)."""
        nxt = self.next_corners()
        lo = np.minimum(self.face_indices, self.face_indices[nxt])
        hi = np.maximum(self.face_indices, self.face_indices[nxt])
        if lo.size == 0:
            return np.zeros((0, 2), np.int64)
        # One packed int64 key per edge: a 1-D unique is several times faster than axis=0.
        key = unique(lo * np.int64(self.n_vertices) + hi)
        return np.stack([key // self.n_vertices, key % self.n_vertices], axis=1)

    def bounding_box(self) -> np.ndarray:
        """(2, 3) float64: min and max corner."""
        if self.n_vertices == 0:
            return np.zeros((2, 3))
        return np.stack(extent(self.vertices))

    def diagonal(self) -> float:
        """Length of the bounding-box diagonal (the scale of relative measures)."""
        return diagonal(self.vertices) if self.n_vertices else 0.0

    @property
    def units(self) -> str:
        """Length unit of the coordinates (``info["units"]``; ``"m"`` when not stated).

        One of ``"m"``, ``"cm"``, ``"mm"``, ``"in"``, ``"ft"`` (see :mod:`ruledmesh.units`).
        """
        from .units import unit_of

        return unit_of(self.info.get("units"), "info.units").value

    def count_kinds(self) -> dict[str, int]:
        """Number of faces of each kind present, by label."""
        counts = np.bincount(self.face_kind, minlength=len(FaceKind))
        return {FaceKind(k).label: int(c) for k, c in enumerate(counts) if c}

    def euler_characteristic(self, n_edges: int | None = None) -> int:
        """V - E + F over the vertices used by faces (``n_edges`` if already known)."""
        used = np.count_nonzero(np.bincount(self.face_indices, minlength=self.n_vertices))
        return int(used - (len(self.edges()) if n_edges is None else n_edges) + self.n_faces)

    # -------------------------------------------------------------- modify
    def with_vertices(self, vertices: np.ndarray, **info: Any) -> Mesh:
        """The same connectivity with new vertex positions (and updated info)."""
        new_info = {**self.info, **info}
        return replace(self, vertices=np.ascontiguousarray(vertices, dtype=np.float64), info=new_info)

    def with_info(self, **info: Any) -> Mesh:
        """The same mesh with ``info`` updated."""
        return replace(self, info={**self.info, **info})

    def with_units(self, units: str, *, convert: bool = True) -> Mesh:
        """The mesh in ``units``: coordinates scaled from :attr:`units` (or only relabelled).

        Parameters
        ----------
        units : {"m", "cm", "mm", "in", "ft"}
        convert : bool
            Scale the coordinates (default); ``False`` states the unit without
            moving anything (for a mesh read from a file that did not say).
        """
        from .units import conversion_factor, unit_of

        target = unit_of(units).value
        factor = conversion_factor(self.units, target) if convert else 1.0
        if factor == 1.0:
            return self.with_info(units=target)
        return self.with_vertices(self.vertices * factor, units=target)

    def select_faces(self, mask: np.ndarray) -> Mesh:
        """The mesh made of the faces where ``mask`` is true (vertices kept)."""
        mask = np.asarray(mask, dtype=bool)
        val = self.valences[mask]
        keep = np.repeat(mask, self.valences)
        return replace(self, face_offsets=offsets_from_valences(val),
                       face_indices=self.face_indices[keep], face_kind=self.face_kind[mask])

    def compact(self) -> Mesh:
        """Drop vertices used by no face and no member, renumbering the rest."""
        return self._compacted()[0]

    def compact_index(self) -> tuple[Mesh, np.ndarray]:
        """:meth:`compact`, and (V,) int64 the new index of each vertex (-1: dropped)."""
        out, used = self._compacted()
        if used is None:
            return out, np.arange(self.n_vertices)
        return out, np.where(used, np.cumsum(used) - 1, -1)

    def _compacted(self) -> tuple[Mesh, np.ndarray | None]:
        used = np.zeros(self.n_vertices, dtype=bool)
        used[self.face_indices] = True
        used[self.members.reshape(-1)] = True
        if used.all():
            return self, None
        new = np.cumsum(used) - 1
        vdata = {k: v[used] for k, v in self.vertex_data.items()}
        return replace(self, vertices=self.vertices[used], face_indices=new[self.face_indices],
                       members=new[self.members], vertex_data=vdata), used

    def merge_vertices(self, tol: float = ROUNDING) -> Mesh:
        """Merge vertices closer than ``tol`` times the diagonal (exact grid snap).

        Vertices are snapped to a grid of spacing ``tol * diagonal`` and merged
        when they fall in the same cell, so the operation is vectorised; two
        close points straddling a cell border stay apart, which is harmless
        for ruledmesh's constructions (shared vertices are bit-identical).
        """
        if self.n_vertices == 0:
            return self
        scale = max(self.diagonal(), TINY) * tol
        key = np.round((self.vertices - self.vertices.min(axis=0)) / scale).astype(np.int64)
        _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
        inverse = inverse.reshape(-1)
        order = np.argsort(first)
        rank = np.empty_like(order)
        rank[order] = np.arange(order.size)
        remap = rank[inverse]
        keep = first[order]
        vdata = {k: v[keep] for k, v in self.vertex_data.items()}
        return replace(self, vertices=self.vertices[keep], face_indices=remap[self.face_indices],
                       members=remap[self.members], vertex_data=vdata)

    def drop_repeated_corners(self) -> Mesh:
        """Remove corners equal to the next corner of their face; drop faces left with < 3.

        After :meth:`merge_vertices` a face whose corners collapsed loses them
        (a quad with two merged corners becomes a triangle, a triangle with two
        merged corners disappears); members between merged vertices go too.
        """
        idx = self.face_indices
        keep = idx != idx[self.next_corners()]
        if keep.all() and np.all(self.members[:, 0] != self.members[:, 1]):
            return self
        face_of = self.face_of
        val = np.bincount(face_of[keep], minlength=self.n_faces)
        ok_face = val >= 3
        keep &= ok_face[face_of]
        mem_ok = self.members[:, 0] != self.members[:, 1]
        return replace(self, face_offsets=offsets_from_valences(val[ok_face]),
                       face_indices=idx[keep], face_kind=self.face_kind[ok_face],
                       members=self.members[mem_ok], member_id=self.member_id[mem_ok])

    def _repr_html_(self) -> str:
        """The Jupyter view: counts and a small picture (:func:`ruledmesh.notebook.mesh_html`)."""
        from .notebook import mesh_html

        return mesh_html(self)

    def __repr__(self) -> str:
        kinds = ", ".join(f"{k}={c}" for k, c in self.count_kinds().items())
        return f"Mesh(vertices={self.n_vertices}, faces={self.n_faces} [{kinds}], members={len(self.members)})"
