"""Turning a grid of points into a mesh: quads, wrapped directions, poles, members.

Most catalogue constructions produce a grid ``X[i, j]`` whose cells are the
planar faces; this module does the bookkeeping once (vectorised), so each
construction module only computes points.
"""

from __future__ import annotations

import numpy as np

from ..mesh import FaceKind, Mesh, offsets_from_valences

__all__ = ["grid_quads", "grid_mesh", "polyline_members"]


def grid_quads(nu: int, nv: int, wrap_u: bool = False, wrap_v: bool = False) -> np.ndarray:
    """Vertex indices of the cells of an ``nu x nv`` grid (vertex ``i * nv + j``).

    Parameters
    ----------
    nu, nv : int
        Grid size.
    wrap_u, wrap_v : bool
        Close the grid in that direction (row ``nu - 1`` joins row 0).

    Returns
    -------
    quads : (F, 4) int64
        ``[X[i, j], X[i+1, j], X[i+1, j+1], X[i, j+1]]`` per cell, cells in
        row-major order of ``(i, j)``.
    """
    iu = np.arange(nu if wrap_u else nu - 1)
    jv = np.arange(nv if wrap_v else nv - 1)
    gi, gj = np.meshgrid(iu, jv, indexing="ij")
    i, j = gi.ravel(), gj.ravel()
    i1 = (i + 1) % nu
    j1 = (j + 1) % nv
    return np.stack([i * nv + j, i1 * nv + j, i1 * nv + j1, i * nv + j1], axis=1).astype(np.int64)


def grid_mesh(points: np.ndarray, *, wrap_u: bool = False, wrap_v: bool = False,
              cell_mask: np.ndarray | None = None, members: np.ndarray | None = None,
              member_id: np.ndarray | None = None, info: dict | None = None,
              collapse: bool = True) -> Mesh:
    """The mesh of the cells of a point grid, with poles collapsed to triangles.

    Parameters
    ----------
    points : (nu, nv, 3) float64
        The grid ``X[i, j]``.
    wrap_u, wrap_v : bool
        Close the grid in that direction.
    cell_mask : (F,) bool, optional
        Keep only these cells (order of :func:`grid_quads`).
    members : (E, 2) int64, optional
        Straight members as pairs of grid vertex indices ``i * nv + j``.
    member_id : (E,) int64, optional
        Line each member lies on.
    info : dict, optional
        Mesh info.
    collapse : bool
        Merge a grid row whose points all coincide (a pole on an axis) into one
        vertex; its cells become triangles (:attr:`FaceKind.POLYGON`).

    Returns
    -------
    Mesh
        Unused vertices dropped.
    """
    nu, nv, _ = points.shape
    verts = points.reshape(-1, 3)
    quads = grid_quads(nu, nv, wrap_u, wrap_v)
    if cell_mask is not None:
        quads = quads[np.asarray(cell_mask, dtype=bool)]
    remap = np.arange(nu * nv, dtype=np.int64)
    if collapse:
        # A row is a pole when all its points are the same point (exactly: it was
        # computed from a zero radius), so its cells lose one corner.
        rows = points - points[:, :1, :]
        pole_rows = np.flatnonzero(np.all(rows == 0.0, axis=(1, 2)))
        if pole_rows.size and nv > 1:
            remap = remap.reshape(nu, nv)
            remap[pole_rows, :] = remap[pole_rows, :1]
            remap = remap.ravel()
        pole_cols = np.flatnonzero(np.all(points - points[:1, :, :] == 0.0, axis=(0, 2)))
        if pole_cols.size and nu > 1:
            remap = remap.reshape(nu, nv)
            remap[:, pole_cols] = remap[:1, pole_cols]
            remap = remap.ravel()
    q = remap[quads]
    keep = q != np.roll(q, -1, axis=1)
    valence = keep.sum(axis=1)
    good = valence >= 3
    q, keep, valence = q[good], keep[good], valence[good]
    kinds = np.where(valence == 4, FaceKind.QUAD, FaceKind.POLYGON).astype(np.uint8)
    mem = np.zeros((0, 2), np.int64) if members is None else remap[np.asarray(members, np.int64)]
    mid = (np.arange(len(mem), dtype=np.int64) if member_id is None
           else np.asarray(member_id, np.int64))
    real = mem[:, 0] != mem[:, 1]
    mem, mid = mem[real], mid[real]
    mesh = Mesh(verts.copy(), offsets_from_valences(valence), q[keep], kinds, mem, mid, {},
                dict(info or {}))
    return mesh.compact()


def polyline_members(index: np.ndarray) -> np.ndarray:
    """Member segments along rows of vertex indices.

    Parameters
    ----------
    index : (L, k) int64
        Each row is the chain of vertex indices along one straight line.

    Returns
    -------
    (L * (k - 1), 2) int64
    """
    index = np.asarray(index, dtype=np.int64)
    return np.stack([index[:, :-1], index[:, 1:]], axis=-1).reshape(-1, 2)
