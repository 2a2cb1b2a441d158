"""Moulding surfaces and pipes (paper §2.2, Fig. 4a, 4b).

A (generalised) moulding surface turns its profile polygon step by step:
``c_{k+1}`` is ``c_k`` rotated about a line ``L_k``.  Each strip between
consecutive polygons is a piece of a rotational surface, so its quads are
isosceles trapezoids, circular.  With parallel ``L_k`` this is the classic
moulding surface (a plane profile rolling on a cylinder); the paper's Fig. 4a
drops the parallelism.

A discrete pipe is a moulding whose profile is a circle: circle ``k + 1`` is
circle ``k`` rotated about the line where their planes meet.  The rotation
mapping the centre ``s_k`` to ``s_{k+1}`` and the circle plane along is the
product of two reflections, in the bisector plane of the chord
``s_k s_{k+1}`` and then in the plane through ``s_{k+1}`` normal to the
reflected circle normal (the double-reflection rule), so the circle planes
follow the spine without twist.  The circles' normals approximate the spine's
tangents within the sampling error: the first one is the tangent of the circle
through the first three spine points, so a spine sampled from a circle gives
an exact torus.
"""

from __future__ import annotations

import numpy as np

from .._validation import check_float, check_int, check_points, check_vector
from ..errors import GeometryError, ParameterError
from ..tolerances import DEFAULT, ROUNDING, ROUNDING_SQ, TINY
from ._grid import grid_mesh
from .frames import perpendicular, rotation_matrix

__all__ = ["moulding_mesh", "pipe_mesh"]


def moulding_mesh(profile: np.ndarray, origins: np.ndarray, directions: np.ndarray,
                  angles, *, closed: bool = False):
    """Planar profile polygon rolled by successive rotations about lines of its plane.

    Step ``k`` turns the current polygon ``c_k`` by ``angles[k]`` about the
    axis ``L_k``; the axes are given as lines of the *initial* profile plane
    and move with it, so each axis lies in the plane of the polygon it turns.
    That is what makes every quad an isosceles trapezoid: ``P`` and its image
    are mirror images in the plane through ``L_k`` bisecting the turn, the
    same plane for all points of a plane containing ``L_k``.  Parallel axes
    give the classic moulding surface (a plane rolling on a cylinder),
    non-parallel ones the generalisation of Fig. 4a.

    Parameters
    ----------
    profile : (n, 3) float64
        ``c_0``, a planar polygon (not all on one line).
    origins, directions : (K, 3) float64
        A point and a non-zero direction of each axis, in the plane of ``c_0``.
    angles : (K,) float64
        Rotation angle of each step in degrees.
    closed : bool
        The profile is a closed polygon.

    Returns
    -------
    Mesh
        ``K`` strips of isosceles trapezoids (circular).

    Raises
    ------
    GeometryError
        If the profile is not planar or an axis is not in its plane.
    """
    c = check_points(profile, "profile", min_count=2)
    o = check_points(origins, "origins").copy()
    d = check_points(directions, "directions", min_count=len(o))
    ang = np.radians(np.asarray(angles, dtype=np.float64).reshape(-1))
    if not (len(o) == len(d) == ang.size):
        raise ParameterError(f"expected as many origins, directions and angles, got {len(o)}, "
                             f"{len(d)} and {ang.size}", "angles")
    if np.any(np.linalg.norm(d, axis=1) == 0):
        raise ParameterError("expected non-zero axis directions", "directions")
    d = d / np.linalg.norm(d, axis=1)[:, None]
    normal = _profile_plane(c, o[0], d[0])
    size = max(float(np.ptp(c, axis=0).max()), TINY)
    off = np.abs((o - c[0]) @ normal)
    tilt = np.abs(d @ normal)
    bad = np.flatnonzero((off > DEFAULT.degenerate * size) | (tilt > DEFAULT.degenerate))
    if bad.size:
        raise GeometryError(f"axis {int(bad[0])} is not in the plane of the profile: every "
                            f"quad would be twisted")
    rows = [c]
    for k in range(len(o)):  # one rotation per polygon; later axes ride along
        rot = rotation_matrix(d[k], ang[k])
        rows.append((rows[-1] - o[k]) @ rot.T + o[k])
        o[k + 1:] = (o[k + 1:] - o[k]) @ rot.T + o[k]
        d[k + 1:] = d[k + 1:] @ rot.T
    return grid_mesh(np.stack(rows), wrap_v=closed, collapse=False,
                     info={"construction": "moulding"})


def _profile_plane(c: np.ndarray, o: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Unit normal of the plane of a planar profile (with the first axis if it is a line)."""
    rel = c - c[0]
    size = max(float(np.abs(rel).max()), TINY)
    _, sv, vt = np.linalg.svd(rel, full_matrices=False)
    if len(sv) < 2 or sv[1] <= ROUNDING * size:
        n = np.cross(vt[0], np.where(np.abs(d @ vt[0]) < 1 - ROUNDING, d, o - c[0]))
        if np.linalg.norm(n) <= ROUNDING:
            raise GeometryError("profile and first axis are collinear: no plane to roll")
        return n / np.linalg.norm(n)
    if len(sv) > 2 and sv[2] > ROUNDING * size * max(1, np.sqrt(len(c))):
        raise GeometryError("the moulding profile must be planar")
    return vt[2] if len(vt) > 2 else np.cross(vt[0], vt[1])


def _reflect(points: np.ndarray, origin: np.ndarray, normal: np.ndarray) -> np.ndarray:
    n = normal / np.linalg.norm(normal)
    return points - 2.0 * ((points - origin) @ n)[..., None] * n


def _first_tangent(spine: np.ndarray) -> np.ndarray:
    """Tangent at ``spine[0]`` of the circle through the first three points (or the chord)."""
    d = spine[1] - spine[0]
    if len(spine) < 3:
        return d / np.linalg.norm(d)
    u, w = spine[1] - spine[0], spine[2] - spine[0]
    n = np.cross(u, w)
    nn = n @ n
    if nn <= ROUNDING_SQ * (u @ u) * (w @ w):
        return d / np.linalg.norm(d)
    center = spine[0] + (np.cross(n, u) * (w @ w) + np.cross(w, n) * (u @ u)) / (2 * nn)
    t = np.cross(n, spine[0] - center)
    t /= np.linalg.norm(t)
    return t if t @ d > 0 else -t


def pipe_mesh(spine: np.ndarray, radius: float, segments: int, *, normal=None):
    """Discrete pipe: congruent circles along a spine polygon, each strip a moulding strip.

    Parameters
    ----------
    spine : (m, 3) float64
        Centres of the circles.
    radius : float
    segments : int
        Points per circle.
    normal : (3,) float64, optional
        Normal of the first circle (default: see module doc).

    Returns
    -------
    Mesh
        Closed tube of isosceles trapezoids (circular).
    """
    s = check_points(spine, "spine", min_count=2)
    radius = check_float(radius, "radius", lo=0.0, lo_open=True)
    segments = check_int(segments, "segments", lo=3)
    chords = np.diff(s, axis=0)
    if np.any(np.linalg.norm(chords, axis=1) <= ROUNDING * np.abs(s).max()):
        raise GeometryError("spine has coincident consecutive points")
    n = _first_tangent(s) if normal is None else check_vector(normal, "normal", nonzero=True)
    n = n / np.linalg.norm(n)
    e1 = perpendicular(n)
    e2 = np.cross(n, e1)
    a = 2 * np.pi * np.arange(segments) / segments
    circle = s[0] + radius * (np.cos(a)[:, None] * e1 + np.sin(a)[:, None] * e2)
    rows = [circle]
    for k in range(len(s) - 1):  # two reflections per circle, vectorised over its points
        mid = 0.5 * (s[k] + s[k + 1])
        chord = s[k + 1] - s[k]
        if abs(n @ chord) <= DEFAULT.degenerate * np.linalg.norm(chord):
            raise GeometryError(f"spine turns by 90 degrees or more at point {k}: the circle "
                                f"plane contains the next chord")
        pts = _reflect(rows[-1], mid, chord)
        r = n - 2 * (n @ chord) / (chord @ chord) * chord
        pts = _reflect(pts, s[k + 1], r)
        n = -r / np.linalg.norm(r)
        rows.append(pts)
    return grid_mesh(np.stack(rows), wrap_v=True, info={"construction": "pipe"})
