"""Compound surfaces of HP patches joined with C1 continuity (paper §4.2).

A net ``P[i, j]`` of points spans bilinear patches (hyperbolic paraboloids)
``[P[i, j], P[i+1, j], P[i+1, j+1], P[i, j+1]]``.  Two patches sharing the
segment ``d`` have the same tangent planes all along it (C1) if and only if
the edges that leave its two ends on either side satisfy, with one common
``lambda``::

    alpha' = lambda alpha + sigma d,    beta' = lambda beta + tau d

(``alpha``, ``alpha'``: the edges before and after the joint at one end of
``d``; ``beta``, ``beta'`` at the other end).  The tangent plane of a
bilinear patch along an edge is a linear function of the edge parameter, so
the planes agree everywhere iff they agree at both ends with the same factor.
So C1 leaves three numbers per new generator, ``(lambda, sigma, tau)``:
``lambda`` > 0 scales the next strip's width, ``sigma`` and ``tau`` slide its
two end points along the joint's direction (``sigma = tau = 0`` for every
step gives back one single HP).  See :func:`c1_step`.

In both directions (patches joined across both families of generators) the
first row and the first column of patches can be chosen freely, with three
numbers per step each; every other corner ``P[i+1, j+1]`` is then determined:
it must lie on one line from its left neighbour's C1 condition and on one line
from the lower neighbour's, and these two lines always meet (the net is a
discrete asymptotic net whose Lelieuvre normals form a translational net).
:func:`compound_net` builds it and reports the distance between the two
lines (rounding).  That is the "massive restriction" of the paper: a net of
``(I + 1) (J + 1)`` points has only ``3 (I + J) + 6`` free numbers.

Meshed by the checkerboard of the patches' isoline grid (see
:mod:`ruledmesh.skew.hybrid`), every face is a planar quad, including those that
straddle a joint (both halves lie in the common tangent plane at the centre)
and those centred on an interior net point (all four edges through it lie in
its tangent plane).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import check_int, check_points, describe
from ..budget import HYBRID_BYTES_PER_NODE, MAX_COUNT, check_budget
from ..errors import GeometryError, ParameterError
from ..mesh import FaceKind, Mesh

__all__ = ["c1_step", "compound_net", "c1_residual", "compound_mesh", "CompoundSurface",
           "CompoundReference"]


# --------------------------------------------------------------------------- construction
def c1_step(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray, lam, sigma, tau
            ) -> tuple[np.ndarray, np.ndarray]:
    """The next generator of a C1 compound of HP patches.

    Parameters
    ----------
    p0, q0 : (..., 3) float64
        End points of the previous generator.
    p1, q1 : (..., 3) float64
        End points of the joint (the generator shared by the two patches).
    lam, sigma, tau : (...) float
        Width ratio of the new strip to the previous one, and the slides of its
        end points along the joint's direction ``q1 - p1``.

    Returns
    -------
    p2, q2 : (..., 3) float64
        ``p2 = p1 + lam (p1 - p0) + sigma d``, ``q2 = q1 + lam (q1 - q0) + tau d``.
    """
    d = q1 - p1
    lam, sigma, tau = (np.asarray(x, dtype=np.float64)[..., None] for x in (lam, sigma, tau))
    return p1 + lam * (p1 - p0) + sigma * d, q1 + lam * (q1 - q0) + tau * d


def _solve2(x: np.ndarray, p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares ``x = l p + s q`` for rows of (n, 3) arrays."""
    pp, pq_, qq = (np.einsum("ij,ij->i", u, w) for u, w in ((p, p), (p, q), (q, q)))
    xp, xq = np.einsum("ij,ij->i", x, p), np.einsum("ij,ij->i", x, q)
    det = pp * qq - pq_ * pq_
    det = np.where(det == 0, 1.0, det)
    return (xp * qq - xq * pq_) / det, (xq * pp - xp * pq_) / det


def _meet(p1: np.ndarray, d1: np.ndarray, p2: np.ndarray, d2: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray]:
    """Midpoint of the closest points of lines ``p1 + s d1`` and ``p2 + t d2``, and their gap."""
    s, t = _solve2(p2 - p1, d1, -d2)
    x1, x2 = p1 + s[:, None] * d1, p2 + t[:, None] * d2
    return 0.5 * (x1 + x2), np.linalg.norm(x1 - x2, axis=1)


def compound_net(seed: Any, u_steps: Any = (), v_steps: Any = ()) -> tuple[np.ndarray, float]:
    """The corner net of a C1 compound of HP patches, grown from one patch.

    Parameters
    ----------
    seed : (2, 2, 3) array_like
        The first two generators ``[[a0, b0], [a1, b1]]``: the seed patch has
        corners ``P[0, 0] = a0, P[0, 1] = b0, P[1, 0] = a1, P[1, 1] = b1``.
    u_steps : (I - 1, 3) array_like
        ``(lambda, sigma, tau)`` of every further generator across the
        generators (direction ``i``).
    v_steps : (J - 1, 3) array_like
        The same across the seed's other family of generators (the lines
        ``a0 a1`` and ``b0 b1``, direction ``j``): ``sigma`` slides along
        ``P[1, j] - P[0, j]``.  With both given the patches fill an
        ``I x J`` grid.

    Returns
    -------
    P : (I + 1, J + 1, 3) float64
    gap : float
        Largest distance between the two lines that determine an inner
        corner (0 up to rounding; reported as a check).
    """
    seed = np.asarray(check_points(np.asarray(seed, dtype=float).reshape(-1, 3), "seed",
                                   min_count=4)).reshape(-1, 2, 3)
    if seed.shape != (2, 2, 3):
        raise ParameterError(f"expected two generators [[a0, b0], [a1, b1]], got {seed.shape[0]}",
                             "seed")
    us = check_steps(u_steps, "u_steps")
    vs = check_steps(v_steps, "v_steps")
    I, J = len(us) + 1, len(vs) + 1
    P = np.full((I + 1, J + 1, 3), np.nan)
    P[:2, :2] = seed
    for k, (lam, sig, tau) in enumerate(us):          # a loop over generators, not faces
        P[k + 2, 0], P[k + 2, 1] = c1_step(P[k, 0], P[k + 1, 0], P[k, 1], P[k + 1, 1], lam, sig, tau)
    for k, (lam, sig, tau) in enumerate(vs):
        P[0, k + 2], P[1, k + 2] = c1_step(P[0, k], P[0, k + 1], P[1, k], P[1, k + 1], lam, sig, tau)
    gap = 0.0
    # Inner corners, one anti-diagonal at a time (each needs its left and lower neighbours).
    for s in range(2, I + J - 1):
        i = np.arange(1, I)
        i = i[(s - i >= 1) & (s - i <= J - 1)]
        if i.size == 0:
            continue
        j = s - i
        # From the left patch (i-1, j), across the joint P[i, j] P[i, j+1].
        d = P[i, j + 1] - P[i, j]
        lam, _ = _solve2(P[i + 1, j] - P[i, j], P[i, j] - P[i - 1, j], d)
        p1 = P[i, j + 1] + lam[:, None] * (P[i, j + 1] - P[i - 1, j + 1])
        # From the lower patch (i, j-1), across the joint P[i, j] P[i+1, j].
        e = P[i + 1, j] - P[i, j]
        mu, _ = _solve2(P[i, j + 1] - P[i, j], P[i, j] - P[i, j - 1], e)
        p2 = P[i + 1, j] + mu[:, None] * (P[i + 1, j] - P[i + 1, j - 1])
        X, g = _meet(p1, d, p2, e)
        P[i + 1, j + 1] = X
        gap = max(gap, float(g.max()))
    if not np.all(np.isfinite(P)):
        raise GeometryError("compound: the C1 steps give no finite net (a joint of zero length "
                            "or a torsal joint)")
    return P, gap


def check_steps(value: Any, name: str, err: type = ParameterError) -> np.ndarray:
    """``value`` as an (n, 3) array of ``(lambda, sigma, tau)`` with ``lambda > 0``."""
    expected = f"expected a list of [lambda, sigma, tau] triples, got {describe(value)}"
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise err(expected, name) from None
    if arr.size == 0:
        return np.zeros((0, 3))
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise err(expected, name)
    if not np.all(np.isfinite(arr)):
        raise err("expected finite numbers, got NaN or infinity", name)
    bad = np.nonzero(arr[:, 0] <= 0)[0]
    if bad.size:
        raise err(f"expected lambda > 0 (the next strip continues the surface), got "
                  f"{arr[bad[0], 0]:g} in step {int(bad[0])}", name)
    return arr


# --------------------------------------------------------------------------- analysis
def _bilinear(P: np.ndarray, i, j, u, v):
    """Point and partials of patch (i, j) of net ``P`` at local (u, v) (broadcast)."""
    P00, P10, P11, P01 = P[i, j], P[i + 1, j], P[i + 1, j + 1], P[i, j + 1]
    u, v = np.asarray(u)[..., None], np.asarray(v)[..., None]
    X = (1 - u) * (1 - v) * P00 + u * (1 - v) * P10 + u * v * P11 + (1 - u) * v * P01
    Xu = (1 - v) * (P10 - P00) + v * (P11 - P01)
    Xv = (1 - u) * (P01 - P00) + u * (P11 - P10)
    return X, Xu, Xv


def c1_residual(P: np.ndarray, samples: int = 9) -> dict[str, float]:
    """How far the patches of net ``P`` are from sharing tangent planes along their joints.

    Parameters
    ----------
    P : (I + 1, J + 1, 3) float64
    samples : int
        Points per joint.

    Returns
    -------
    dict
        ``max``: the largest sine of the angle between the two tangent planes at
        a joint point (0 for C1; rounding is ~1e-15), ``joints``: how many joints
        were checked.
    """
    I, J = P.shape[0] - 1, P.shape[1] - 1
    s = np.linspace(0.0, 1.0, samples)
    worst, count = 0.0, 0

    def sine(n1, n2):
        n1 = n1 / np.linalg.norm(n1, axis=-1, keepdims=True)
        n2 = n2 / np.linalg.norm(n2, axis=-1, keepdims=True)
        return np.linalg.norm(np.cross(n1, n2), axis=-1)

    if I >= 2:   # joints x = i, between patches (i-1, j) and (i, j)
        i, j = np.meshgrid(np.arange(1, I), np.arange(J), indexing="ij")
        i, j = i.ravel()[:, None], j.ravel()[:, None]
        _, u1, v1 = _bilinear(P, i - 1, j, 1.0, s)
        _, u2, v2 = _bilinear(P, i, j, 0.0, s)
        worst = max(worst, float(sine(np.cross(u1, v1), np.cross(u2, v2)).max()))
        count += i.size
    if J >= 2:   # joints y = j, between patches (i, j-1) and (i, j)
        i, j = np.meshgrid(np.arange(I), np.arange(1, J), indexing="ij")
        i, j = i.ravel()[:, None], j.ravel()[:, None]
        _, u1, v1 = _bilinear(P, i, j - 1, s, 1.0)
        _, u2, v2 = _bilinear(P, i, j, s, 0.0)
        worst = max(worst, float(sine(np.cross(u1, v1), np.cross(u2, v2)).max()))
        count += i.size
    return {"max": worst, "joints": int(count)}


@dataclass(frozen=True, eq=False)
class CompoundSurface:
    """The piecewise-bilinear surface of net ``P`` on ``[0, 1]^2`` (for closeness, coverage).

    ``point(u, t)`` / ``partials(u, t)`` as a :class:`~ruledmesh.rulings.RuledSurface`:
    ``u`` across the generators, ``t`` along them.
    """

    P: np.ndarray

    def _locate(self, u, t):
        I, J = self.P.shape[0] - 1, self.P.shape[1] - 1
        x, y = np.asarray(u, float) * I, np.asarray(t, float) * J
        i = np.clip(np.floor(x).astype(int), 0, I - 1)
        j = np.clip(np.floor(y).astype(int), 0, J - 1)
        return i, j, x - i, y - j, I, J

    def point(self, u, t) -> np.ndarray:
        i, j, lu, lv, _, _ = self._locate(u, t)
        return _bilinear(self.P, i, j, lu, lv)[0]

    def partials(self, u, t) -> tuple[np.ndarray, np.ndarray]:
        i, j, lu, lv, I, J = self._locate(u, t)
        _, Xu, Xv = _bilinear(self.P, i, j, lu, lv)
        return Xu * I, Xv * J

    def area(self, n: int = 16) -> float:
        """Sum of the patch areas (Gauss-Legendre, ``n`` points per direction)."""
        x, w = np.polynomial.legendre.leggauss(n)
        x, w = 0.5 * (x + 1), 0.5 * w
        I, J = self.P.shape[0] - 1, self.P.shape[1] - 1
        i, j, a, b = np.meshgrid(np.arange(I), np.arange(J), np.arange(n), np.arange(n),
                                 indexing="ij")
        _, Xu, Xv = _bilinear(self.P, i, j, x[a], x[b])
        return float((np.linalg.norm(np.cross(Xu, Xv), axis=-1) * w[a] * w[b]).sum())


# --------------------------------------------------------------------------- mesh
def compound_mesh(P: Any, midpoints: int = 1, divisions: int = 8, border: str = "notched") -> Mesh:
    """Checkerboard PQ mesh of a compound of HP patches.

    Parameters
    ----------
    P : (I + 1, J + 1, 3) array_like
        Corner net (see :func:`compound_net`); C1 along the joints for the
        faces that straddle them to be planar.
    midpoints : int, >= 0
        Generators inserted in every patch (``midpoints + 1`` columns per patch).
    divisions : int, >= 1
        Rows per patch along the generators.
    border : {"notched", "triangles"}
        ``"notched"``: only whole quads (the border is a zig-zag touching the
        patch border at every other node); ``"triangles"``: also the half
        faces along the border, as triangles, so the mesh reaches the border
        (notched covers about three quarters of the patch at the default counts).

    Returns
    -------
    Mesh
        ``QUAD`` faces (and ``TRIANGLE`` border halves); members along every
        net column (``member_id`` = column ``i``), vertex data ``u``, ``t``
        (net coordinates, patch units).
    """
    P = np.asarray(P, dtype=np.float64)
    if P.ndim != 3 or P.shape[2] != 3 or P.shape[0] < 2 or P.shape[1] < 2:
        raise ParameterError(f"expected an (I + 1, J + 1, 3) net, got {describe(P)}", "P")
    nu = check_int(midpoints, "midpoints", lo=0, hi=10_000) + 1
    nv = check_int(divisions, "divisions", lo=1, hi=MAX_COUNT)
    if border not in ("notched", "triangles"):
        raise ParameterError(f'expected "notched" or "triangles", got {describe(border)}', "border")
    I, J = P.shape[0] - 1, P.shape[1] - 1
    CX, CY = I * nu, J * nv
    check_budget(float(CX + 1) * (CY + 1), HYBRID_BYTES_PER_NODE,
                 f"{I} x {J} patches x {nu} columns x {nv} divisions",
                 "reduce the midpoints or the divisions", "divisions", ParameterError)
    x, y = np.meshgrid(np.arange(CX + 1), np.arange(CY + 1), indexing="ij")
    i, j = np.minimum(x // nu, I - 1), np.minimum(y // nv, J - 1)
    X = _bilinear(P, i, j, (x - i * nu) / nu, (y - j * nv) / nv)[0].reshape(-1, 3)
    K = CY + 1
    c, r = np.nonzero((x + y) % 2 == 1)
    node = c * K + r
    L, R, B, T = node - K, node + K, node - 1, node + 1
    hL, hR, hB, hT = c > 0, c < CX, r > 0, r < CY
    full = hL & hR & hB & hT
    quads = np.stack([L, B, R, T], axis=1)[full]
    tris = np.zeros((0, 3), np.int64)
    if border == "triangles":
        tris = np.concatenate([
            np.stack([L, R, T], 1)[hL & hR & ~hB], np.stack([L, B, R], 1)[hL & hR & ~hT],
            np.stack([B, R, T], 1)[~hL & hB & hT], np.stack([L, B, T], 1)[~hR & hB & hT],
            np.stack([L, node, T], 1)[~hR & ~hB & hL & hT],
            np.stack([B, R, node], 1)[~hL & ~hT & hR & hB],
            np.stack([L, B, node], 1)[~hR & ~hT & hL & hB]])
    # Members: consecutive vertices along every net column (the joints and the two ends).
    xs = np.arange(0, CX + 1, nu)
    cx, cy = np.meshgrid(xs, np.arange(CY + 1), indexing="ij")
    on = (cx + cy) % 2 == 0
    ci, cj = np.nonzero(on)
    same = ci[1:] == ci[:-1]
    mnodes = cx[ci, cj] * K + cj
    members = np.stack([mnodes[:-1][same], mnodes[1:][same]], axis=1)
    member_id = ci[:-1][same]
    if len(quads) + len(tris) == 0:
        raise ParameterError(f"expected a finer division: {I} x {J} patches with "
                             f"{nu - 1} midpoints and {nv} divisions leave no whole face",
                             "divisions")
    used = np.zeros(len(X), dtype=bool)
    used[quads.ravel()] = True
    used[tris.ravel()] = True
    keep = used[members].all(axis=1)
    members, member_id = members[keep], member_id[keep]
    faces = np.concatenate([quads.ravel(), tris.ravel()]).astype(np.int64)
    offsets = np.r_[np.arange(len(quads) + 1) * 4,
                    4 * len(quads) + np.arange(1, len(tris) + 1) * 3].astype(np.int64)
    kinds = np.r_[np.full(len(quads), FaceKind.QUAD),
                  np.full(len(tris), FaceKind.TRIANGLE)].astype(np.uint8)
    info = {"construction": "compound-hp", "patches": [I, J], "midpoints": nu - 1,
            "divisions": nv, "border": border, "warnings": []}
    mesh = Mesh(X, offsets, faces, kinds, members.astype(np.int64), member_id.astype(np.int64),
                {"u": (x / nu).ravel(), "t": (y / nv).ravel()}, info)
    return mesh.compact()


class CompoundReference:
    """Closeness and area of the compound (the :class:`~ruledmesh.registry.Reference` protocol).

    Deliberately without a ``surface`` attribute: the tessellation comparison of
    the analysis fits one smooth B-spline surface, which a compound with kinks in
    its curvature is not.
    """

    def __init__(self, P: np.ndarray):
        from ..surfaces import RuledReference

        self._ref = RuledReference(CompoundSurface(np.asarray(P, dtype=np.float64)))

    def distance(self, points: np.ndarray) -> np.ndarray:
        """(n,) float64: distance of each point from the compound."""
        return self._ref.distance(points)

    def area(self) -> float:
        """Area of the compound (sum of its patches)."""
        return self._ref.area()
