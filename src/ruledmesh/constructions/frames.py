"""Rotations about lines and orthonormal frames (shared by the sweep constructions)."""

from __future__ import annotations

import numpy as np

from ..tolerances import ULPS

__all__ = ["rotation_matrix", "rotate_about_line", "perpendicular", "axis_frame"]


def rotation_matrix(axis: np.ndarray, angle: float) -> np.ndarray:
    """(3, 3) rotation by ``angle`` (radians, right-handed) about the unit vector ``axis``."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


def rotate_about_line(points: np.ndarray, origin: np.ndarray, axis: np.ndarray,
                      angle: float) -> np.ndarray:
    """(n, 3) ``points`` turned by ``angle`` about the line through ``origin`` along ``axis``."""
    rot = rotation_matrix(axis, angle)
    return (points - origin) @ rot.T + origin


def perpendicular(v: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to the non-zero vector ``v``."""
    v = np.asarray(v, dtype=np.float64)
    helper = np.eye(3)[np.argmin(np.abs(v))]
    w = np.cross(v, helper)
    return w / np.linalg.norm(w)


def axis_frame(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Right-handed orthonormal ``(e1, e2, a)`` with ``a`` along ``direction``.

    For the z direction this is the standard basis (so angles are measured
    from the x axis, as in the formulas of the paper).
    """
    a = np.asarray(direction, dtype=np.float64)
    a = a / np.linalg.norm(a)
    if abs(a[2]) > 1 - ULPS and a[0] == 0 and a[1] == 0:
        e1 = np.array([1.0, 0.0, 0.0])
    else:
        e1 = perpendicular(a)
    e2 = np.cross(a, e1)
    return e1, e2, a
