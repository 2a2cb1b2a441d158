"""Panel statistics and congruence classes: how many different panels to make.

Two flat panels are congruent (equal up to a rotation, a translation and a
mirror image: a panel can be turned over) exactly when their cyclic
sequences of edge lengths and interior angles agree up to a cyclic shift and
a reversal.  With tolerances, a face joins a class when some shift or
reversal of its sequence is within ``length_tol`` on every edge and within
``angle_tol`` on every angle of another member; the classes are the connected
components of that relation (so a chain of near misses can join two panels
that differ by more than the tolerance; keep the tolerance below the
fabrication accuracy).  Interior angles come from the unrolled polygons, so a
reflex corner is told from a convex one.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import check_float
from ..mesh import FaceKind, Mesh
from ..tolerances import CONGRUENCE_ANGLE_DEG, DEFAULT
from .labels import panel_labels
from .unroll import Unrolled, interior_angles, polygon_edges, unroll

__all__ = ["congruence_classes", "panel_table", "panel_statistics"]


def _signatures(lengths: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """(n, 2k, 2k) float64: every cyclic shift and reversal of each face's sequence.

    Row ``r`` of face ``i`` is ``[lengths..., angles...]`` read from corner
    ``r`` forwards (``r < k``) or backwards (``r >= k``).
    """
    _n, k = lengths.shape
    shift = (np.arange(k)[:, None] + np.arange(k)[None, :]) % k          # (k, k)
    fwd_l = lengths[:, shift]
    fwd_a = angles[:, shift]
    # Backwards from corner r: corners r, r-1, ...; the edge between corners
    # j and j-1 is edge j-1 (edges leave their corner forwards).
    back_c = (np.arange(k)[:, None] - np.arange(k)[None, :]) % k
    back_l = lengths[:, (back_c - 1) % k]
    back_a = angles[:, back_c]
    fwd = np.concatenate([fwd_l, fwd_a], axis=2)
    back = np.concatenate([back_l, back_a], axis=2)
    return np.concatenate([fwd, back], axis=1)


def congruence_classes(mesh: Mesh, *, length_tol: float | None = None, angle_tol: float = CONGRUENCE_ANGLE_DEG,
                       unrolled: Unrolled | None = None) -> np.ndarray:
    """(F,) int64: a class number per face, equal for congruent panels.

    Parameters
    ----------
    mesh : Mesh
    length_tol : float, optional
        Largest difference of corresponding edge lengths, in mesh units; by
        default ``1e-9`` times the bounding-box diagonal.
    angle_tol : float
        Largest difference of corresponding interior angles, in degrees.
    unrolled : Unrolled, optional
        :func:`~ruledmesh.fabricate.unroll.unroll` of ``mesh``, if already computed.

    Returns
    -------
    classes : (F,) int64
        Numbered 0, 1, ... in order of each class's first face.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    if length_tol is None:
        length_tol = DEFAULT.degenerate * (mesh.diagonal() or 1.0)
    length_tol = check_float(length_tol, "length_tol", lo=0.0, lo_open=True)
    angle_tol = check_float(angle_tol, "angle_tol", lo=0.0, lo_open=True)
    if unrolled is None:
        unrolled = unroll(mesh, require_planar=False)
    off = mesh.face_offsets
    lengths = polygon_edges(unrolled.points, off) / length_tol
    angles = np.degrees(interior_angles(unrolled.points, off)) / angle_tol
    nf = mesh.n_faces
    rows, cols = [], []
    val = mesh.valences
    for k in np.unique(val):                     # one pass per valence (a handful)
        ids = np.flatnonzero(val == k)
        cidx = off[ids][:, None] + np.arange(k)
        sig = _signatures(lengths[cidx], angles[cidx])            # (n, 2k, 2k)
        base = cKDTree(sig[:, 0])
        variants = cKDTree(sig.reshape(-1, 2 * k))
        # Chebyshev radius 1 in units of the tolerances: every entry within its tolerance.
        pairs = base.sparse_distance_matrix(variants, 1.0, p=np.inf, output_type="ndarray")
        rows.append(ids[pairs["i"]])
        cols.append(ids[pairs["j"] // (2 * k)])
    r = np.concatenate(rows + [np.arange(nf)])
    c = np.concatenate(cols + [np.arange(nf)])
    graph = coo_matrix((np.ones(r.size, dtype=np.int8), (r, c)), shape=(nf, nf))
    _, label = connected_components(graph, directed=False)
    # Renumber by first appearance so class 0 holds face 0.
    _, first = np.unique(label, return_index=True)
    return np.argsort(np.argsort(first))[label]


def panel_table(mesh: Mesh, *, unrolled: Unrolled | None = None, classes: np.ndarray | None = None,
                **tolerances: Any) -> dict[str, np.ndarray]:
    """One row per panel: kind, valence, area, perimeter, angle range, class.

    Parameters
    ----------
    mesh : Mesh
    unrolled : Unrolled, optional
    classes : (F,) int64, optional
        From :func:`congruence_classes` (computed with ``**tolerances`` if omitted).
    """
    if unrolled is None:
        unrolled = unroll(mesh, require_planar=False)
    if classes is None:
        classes = congruence_classes(mesh, unrolled=unrolled, **tolerances)
    off = mesh.face_offsets
    p = unrolled.points
    lengths = polygon_edges(p, off)
    angles = np.degrees(interior_angles(p, off))
    nxt = np.r_[np.arange(1, p.shape[0]), 0]
    nxt[off[1:] - 1] = off[:-1]
    shoelace = p[:, 0] * p[nxt, 1] - p[nxt, 0] * p[:, 1]
    return {
        "id": np.arange(mesh.n_faces),
        "label": panel_labels(mesh.n_faces),
        "kind": np.array([FaceKind(int(k)).label for k in mesh.face_kind]),
        "valence": mesh.valences,
        "area": 0.5 * np.add.reduceat(shoelace, off[:-1]),
        "perimeter": np.add.reduceat(lengths, off[:-1]),
        "min_edge": np.minimum.reduceat(lengths, off[:-1]),
        "max_edge": np.maximum.reduceat(lengths, off[:-1]),
        "min_angle_deg": np.minimum.reduceat(angles, off[:-1]),
        "max_angle_deg": np.maximum.reduceat(angles, off[:-1]),
        "class": classes,
    }


def panel_statistics(mesh: Mesh, *, table: dict[str, np.ndarray] | None = None,
                     **tolerances: Any) -> dict[str, Any]:
    """Counts and ranges of the panels, and the number of distinct panels.

    Returns
    -------
    dict (JSON-serialisable)
        ``count``, ``kinds``, ``area`` (min, max, total), ``edge_length``
        (min, max), ``angle_deg`` (min, max), ``distinct_panels`` (number of
        congruence classes), ``largest_class``, ``tolerances``.
    """
    if table is None:
        table = panel_table(mesh, **tolerances)
    if mesh.n_faces == 0:
        return {"count": 0, "distinct_panels": 0}
    classes = table["class"]
    sizes = np.bincount(classes)
    return {
        "count": mesh.n_faces,
        "kinds": mesh.count_kinds(),
        "area": {"min": float(table["area"].min()), "max": float(table["area"].max()),
                 "total": float(table["area"].sum())},
        "edge_length": {"min": float(table["min_edge"].min()), "max": float(table["max_edge"].max())},
        "angle_deg": {"min": float(table["min_angle_deg"].min()),
                      "max": float(table["max_angle_deg"].max())},
        "distinct_panels": int(sizes.size),
        "largest_class": int(sizes.max()),
        "tolerances": {"length": tolerances.get("length_tol", DEFAULT.degenerate * (mesh.diagonal() or 1.0)),
                       "angle_deg": tolerances.get("angle_tol", CONGRUENCE_ANGLE_DEG)},
    }
