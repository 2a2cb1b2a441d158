"""Hyperbolic paraboloid ``z = x^2/a^2 - y^2/b^2`` (paper §3.2, Fig. 7).

``style = "parabolas"`` (Fig. 7a): the HP is the translational surface of the
parabolas ``p(x) = (x, 0, x^2/a^2)`` and ``q(y) = (0, y, -y^2/b^2)``; the grid
``p(x_i) + q(y_j)`` on ``|x|, |y| <= size`` is a parallelogram mesh with every
vertex on the surface.

``style = "generators"`` (Fig. 7b, c): the checkerboard of the two reguli
``x/a + y/b = lambda`` and ``x/a - y/b = mu``.  They cross at
``(a (lambda + mu)/2, b (lambda - mu)/2, lambda mu)``; every other crossing is
a vertex and each face has two generator segments as diagonals, which bisect
each other (uniform steps), so the faces are parallelograms.  The patch is
bounded by generators, ``|lambda|, |mu| <= size / max(a, b)`` (the largest
such patch with ``|x|, |y| <= size``); notches along its border are filled
with triangles (``fill = false`` leaves them).  In plan the reguli meet at the
angle ``2 atan(b / a)``: choosing it (key ``angle``) is the affine map of the
paper that turns the orthogonal grid of a right HP into any other.
"""

from __future__ import annotations

from enum import Enum

import numpy as np

from .._validation import check_bool, check_choice, check_float, check_int
from ..errors import GeometryError
from ..mesh import FaceKind, Mesh, offsets_from_valences
from ..surfaces import ImplicitSurface, parametric_area
from ._grid import grid_mesh

__all__ = ["HPStyle", "hyperbolic_paraboloid_mesh", "hyperbolic_paraboloid"]


class HPStyle(str, Enum):
    """How the hyperbolic paraboloid is meshed."""

    PARABOLAS = "parabolas"
    GENERATORS = "generators"


def hyperbolic_paraboloid(a: float, b: float, partials=None, u_range=None,
                          v_range=None) -> ImplicitSurface:
    """Reference ``z = x^2/a^2 - y^2/b^2``; area of the patch given by ``partials``."""
    area = None if partials is None else parametric_area(partials, u_range, v_range)
    return ImplicitSurface(
        "hyperbolic paraboloid",
        lambda p: p[:, 0] ** 2 / a ** 2 - p[:, 1] ** 2 / b ** 2 - p[:, 2],
        lambda p: np.stack([2 * p[:, 0] / a ** 2, -2 * p[:, 1] / b ** 2, -np.ones(len(p))],
                           axis=1),
        area)


def _crossing(lam: np.ndarray, mu: np.ndarray, a: float, b: float) -> np.ndarray:
    return np.stack([0.5 * a * (lam + mu), 0.5 * b * (lam - mu), lam * mu], axis=-1)


def hyperbolic_paraboloid_mesh(a: float, b: float, size: float, u: int, v: int,
                               style: HPStyle | str = "parabolas", *, fill: bool = True) -> Mesh:
    """Mesh of ``z = x^2/a^2 - y^2/b^2`` (see the module doc for the two styles).

    Parameters
    ----------
    a, b : float
        > 0.
    size : float
        ``|x|, |y| <= size``.
    u, v : int
        Steps in x and y (``"parabolas"``), or generators of each regulus
        minus one (``"generators"``, >= 2 each).
    style : {"parabolas", "generators"}
    fill : bool
        Fill the border notches of the generator checkerboard with triangles.

    Returns
    -------
    Mesh
    """
    a = check_float(a, "a", lo=0.0, lo_open=True)
    b = check_float(b, "b", lo=0.0, lo_open=True)
    size = check_float(size, "size", lo=0.0, lo_open=True)
    style = check_choice(style, HPStyle, "style")
    fill = check_bool(fill, "fill")
    if style is HPStyle.PARABOLAS:
        u, v = check_int(u, "u", lo=1), check_int(v, "v", lo=1)
        x = np.linspace(-size, size, u + 1)
        y = np.linspace(-size, size, v + 1)
        p = np.stack([x, 0 * x, x * x / a ** 2], axis=1)
        q = np.stack([0 * y, y, -y * y / b ** 2], axis=1)
        return grid_mesh(p[:, None, :] + q[None, :, :], collapse=False,
                         info={"construction": "hyperbolic paraboloid (parabolas)"})
    u, v = check_int(u, "u", lo=2), check_int(v, "v", lo=2)
    L = size / max(a, b)
    lam = np.linspace(-L, L, u + 1)
    mu = np.linspace(-L, L, v + 1)
    X = _crossing(lam[:, None], mu[None, :], a, b).reshape(-1, 3)
    I, J = np.meshgrid(np.arange(u + 1), np.arange(v + 1), indexing="ij")
    vid = I * (v + 1) + J
    even = (I + J) % 2 == 0
    # Faces centred at odd crossings inside: [X(i-1,j), X(i,j-1), X(i+1,j), X(i,j+1)].
    ci, cj = np.nonzero(~even[1:-1, 1:-1])
    ci, cj = ci + 1, cj + 1
    quads = np.stack([vid[ci - 1, cj], vid[ci, cj - 1], vid[ci + 1, cj], vid[ci, cj + 1]], axis=1)
    faces = [quads]
    kinds = [np.full(len(quads), FaceKind.QUAD, np.uint8)]
    used = even.copy()
    if fill:
        tris = []
        # Notches on the four border generators: odd crossings there get a triangle of their
        # three neighbours; an odd corner becomes a vertex itself.
        for i, j in zip(*np.nonzero(~even)):
            border = i in (0, u) or j in (0, v)
            if not border:
                continue
            nb = [(i + di, j + dj) for di, dj in ((-1, 0), (0, -1), (1, 0), (0, 1))
                  if 0 <= i + di <= u and 0 <= j + dj <= v]
            if len(nb) == 3:
                tris.append([vid[n] for n in nb])
            elif len(nb) == 2:
                tris.append([vid[nb[0]], vid[i, j], vid[nb[1]]])
                used[i, j] = True
        if tris:
            faces.append(np.array(tris, dtype=np.int64))
            kinds.append(np.full(len(tris), FaceKind.FILL, np.uint8))
    # Generators as members: consecutive vertices along each line.
    members, mid = [], []
    for i in range(u + 1):
        js = np.flatnonzero(used[i])
        members.append(np.stack([vid[i, js[:-1]], vid[i, js[1:]]], axis=1))
        mid.append(np.full(len(js) - 1, i))
    for j in range(v + 1):
        is_ = np.flatnonzero(used[:, j])
        members.append(np.stack([vid[is_[:-1], j], vid[is_[1:], j]], axis=1))
        mid.append(np.full(len(is_) - 1, u + 1 + j))
    if sum(len(f) for f in faces) == 0:
        raise GeometryError(f"u = {u}, v = {v} without fill leave no face: raise u or v")
    val = np.concatenate([np.full(len(f), f.shape[1]) for f in faces])
    mesh = Mesh(X, offsets_from_valences(val), np.concatenate([f.ravel() for f in faces]),
                np.concatenate(kinds), np.concatenate(members).astype(np.int64),
                np.concatenate(mid).astype(np.int64), {},
                {"construction": "hyperbolic paraboloid (generators)"})
    return mesh.compact()
