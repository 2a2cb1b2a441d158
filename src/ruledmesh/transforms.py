"""Transforms that keep a PQ mesh planar (paper §2.3).

* Affine maps (``affine``, ``translate``, ``rotate``, ``scale``, ``shear``) and
  projective maps (``projective``) send planes to planes: every planar face
  stays planar and straight members stay straight.  A projective map that
  sends a vertex to infinity, or separates the vertices by the plane it sends
  to infinity (so that a face would pass through infinity), is refused.
* Inversion in a sphere sends circles to circles, so it keeps a *circular*
  mesh circular and planar, and nothing else: a mesh with a face that is not
  inscribed in a circle (to :attr:`~ruledmesh.tolerances.Tolerances.circularity`)
  is refused.  Straight members are dropped (lines become circles).

Orientation-reversing maps also reverse each face's vertex order, so face
normals keep pointing to the same side of the surface.

The design surface travels with the mesh (``[[transform]]`` in a design file):
after a similarity (rotation, translation, uniform scale, reflection) the
reference is exact (distances scale, areas scale by the square).  After any
other map, a catalogue (implicit) reference becomes the implicit surface
``F(T^-1 q) = 0``, whose distance is computed by Newton steps (exact on the
surface, second order near it); its area is no longer known, so coverage is
dropped.  References without an implicit form (for example the smooth ruled
patch of a ``[rulings]`` design, or an exact polyline-revolution distance) are
dropped after a non-similar map, and the report says so.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ._validation import check_float, check_vector, describe
from .analysis.circularity import circularity
from .errors import GeometryError, ParameterError
from .mesh import Mesh
from .registry import Built
from .surfaces import ImplicitSurface
from .tolerances import DEFAULT, ROUNDING, ULPS, Tolerances

__all__ = [
    "affine",
    "translate",
    "rotate",
    "scale",
    "shear",
    "projective",
    "inversion",
    "affine_matrix",
    "rotation_matrix",
    "shear_matrix",
    "transform_built",
]


# --------------------------------------------------------------------- helpers
def _reverse_faces(mesh: Mesh) -> Mesh:
    """The same mesh with every face's vertex order reversed (vectorised)."""
    val = mesh.valences
    start = np.repeat(mesh.face_offsets[:-1], val)
    pos = np.arange(mesh.face_indices.size)
    src = 2 * start + np.repeat(val, val) - 1 - pos
    return replace(mesh, face_indices=mesh.face_indices[src])


def _append_transform(mesh: Mesh, name: str) -> dict:
    return {"transforms": [*mesh.info.get("transforms", []), name]}


def rotation_matrix(axis, angle: float) -> np.ndarray:
    """(3, 3) rotation by ``angle`` degrees (right-handed) about ``axis``."""
    a = check_vector(axis, "axis", nonzero=True)
    a = a / np.linalg.norm(a)
    t = np.radians(check_float(angle, "angle"))
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(t) * k + (1 - np.cos(t)) * (k @ k)


def shear_matrix(xy: float = 0.0, xz: float = 0.0, yx: float = 0.0, yz: float = 0.0,
                 zx: float = 0.0, zy: float = 0.0) -> np.ndarray:
    """(3, 3) shear: ``x' = x + xy y + xz z``, ``y' = yx x + y + yz z``, ``z' = zx x + zy y + z``."""
    return np.array([[1.0, xy, xz], [yx, 1.0, yz], [zx, zy, 1.0]])


def affine_matrix(matrix, offset=None, *, name: str = "matrix") -> tuple[np.ndarray, np.ndarray]:
    """Split an affine map into ``(A, t)`` with ``p -> A p + t``.

    ``matrix`` is (3, 3) (with ``offset``), or (3, 4) / (4, 4) homogeneous
    (last row ``0 0 0 1``).
    """
    m = np.asarray(matrix, dtype=np.float64) if not isinstance(matrix, str) else None
    if m is None or m.shape not in ((3, 3), (3, 4), (4, 4)) or not np.all(np.isfinite(m)):
        raise ParameterError(f"expected a 3x3, 3x4 or 4x4 matrix of finite numbers, got "
                             f"{describe(matrix)}", name)
    if m.shape == (4, 4) and not np.allclose(m[3], [0, 0, 0, 1], rtol=0, atol=ULPS):
        raise ParameterError("expected last row 0 0 0 1 for an affine map (use a projective "
                             "map for anything else)", name)
    A = m[:3, :3].copy()
    t = np.zeros(3) if m.shape == (3, 3) else m[:3, 3].copy()
    if offset is not None:
        t = t + check_vector(offset, "offset")
    return A, t


def _similarity_scale(A: np.ndarray) -> float | None:
    """``s`` if ``A`` is ``s`` times an orthogonal matrix, else ``None``."""
    g = A.T @ A
    s2 = np.trace(g) / 3.0
    if s2 > 0 and np.abs(g - s2 * np.eye(3)).max() <= ROUNDING * s2:
        return float(np.sqrt(s2))
    return None


# ------------------------------------------------------------------ reference
@dataclass(frozen=True, eq=False)
class _ScaledReference:
    """A foreign reference moved by a similarity ``q = s R p + t``."""

    base: Any
    inverse: Callable[[np.ndarray], np.ndarray]
    factor: float

    def distance(self, points):
        return self.factor * self.base.distance(self.inverse(np.asarray(points, float)))

    def area(self):
        a = self.base.area()
        return None if a is None else a * self.factor ** 2


def _moved_reference(ref, inverse: Callable, pullback: Callable, similarity: float | None):
    """The reference after a map, and a note when it could not follow exactly.

    Parameters
    ----------
    ref : Reference or None
    inverse : callable
        ``q -> p = T^-1(q)``, (n, 3) -> (n, 3).
    pullback : callable
        ``(q, grad_p) -> grad_q``: the gradient of ``F o T^-1`` from that of ``F``.
    similarity : float or None
        The scale factor if ``T`` is a similarity.
    """
    if ref is None:
        return None, None
    if isinstance(ref, ImplicitSurface):
        value = gradient = None
        f_value, f_gradient, f_exact = ref.value, ref.gradient, ref.exact
        if f_value is not None and f_gradient is not None:
            value = lambda q: f_value(inverse(q))
            gradient = lambda q: pullback(q, f_gradient(inverse(q)))
        if similarity is not None:
            exact = (None if f_exact is None
                     else (lambda q: similarity * f_exact(inverse(q))))
            if exact is None and value is None:
                return None, "reference dropped (no distance after the transform)"
            area = None if ref.patch_area is None else ref.patch_area * similarity ** 2
            return ImplicitSurface(ref.name, value, gradient, area, exact), None
        if value is None:
            return None, (f"closeness dropped: the {ref.name} reference has no implicit form "
                          f"that follows a non-similar map")
        return (ImplicitSurface(f"transformed {ref.name}", value, gradient, None, None),
                "closeness after the transform is the distance to the transformed implicit "
                "surface (Newton steps); coverage dropped (area unknown)")
    if similarity is not None:
        return _ScaledReference(ref, inverse, similarity), None
    return None, "closeness dropped: the reference surface cannot follow a non-similar map"


# ------------------------------------------------------------------ the maps
def affine(mesh: Mesh, matrix, offset=None) -> Mesh:
    """Apply ``p -> A p + t`` to a mesh.

    Parameters
    ----------
    mesh : Mesh
    matrix : (3, 3), (3, 4) or (4, 4) array_like
    offset : (3,) array_like, optional

    Returns
    -------
    Mesh
        Planar faces stay planar; faces reversed if ``det A < 0``.

    Raises
    ------
    ParameterError
        For a singular matrix (it would flatten the mesh).
    """
    A, t = affine_matrix(matrix, offset)
    _check_regular(A, "matrix")
    out = mesh.with_vertices(mesh.vertices @ A.T + t, **_append_transform(mesh, "affine"))
    return _reverse_faces(out) if np.linalg.det(A) < 0 else out


def _check_regular(A: np.ndarray, name: str) -> None:
    n = A.shape[0]
    det = np.linalg.det(A)
    if not abs(det) > ROUNDING * np.linalg.norm(A) ** n:
        raise ParameterError(f"expected an invertible matrix, got determinant {det:.3g}", name)


def translate(mesh: Mesh, vector) -> Mesh:
    """Translate by ``vector`` (3,)."""
    return affine(mesh, np.eye(3), check_vector(vector, "vector"))


def rotate(mesh: Mesh, axis, angle: float, center=(0.0, 0.0, 0.0)) -> Mesh:
    """Rotate by ``angle`` degrees about the line through ``center`` along ``axis``."""
    R = rotation_matrix(axis, angle)
    c = check_vector(center, "center")
    return affine(mesh, R, c - R @ c)


def scale(mesh: Mesh, factors, center=(0.0, 0.0, 0.0)) -> Mesh:
    """Scale by a number or three per-axis factors (non-zero) about ``center``."""
    f = np.broadcast_to(np.asarray(factors, dtype=np.float64), (3,))
    if not np.all(np.isfinite(f)) or np.any(f == 0):
        raise ParameterError(f"expected non-zero finite factors, got {describe(factors)}", "factors")
    c = check_vector(center, "center")
    return affine(mesh, np.diag(f), c - f * c)


def shear(mesh: Mesh, **factors: float) -> Mesh:
    """Shear (keys ``xy, xz, yx, yz, zx, zy``; see :func:`shear_matrix`)."""
    return affine(mesh, shear_matrix(**factors))


def _projective_parts(matrix, vertices: np.ndarray, tol: Tolerances, name: str = "matrix"):
    m = np.asarray(matrix, dtype=np.float64) if not isinstance(matrix, str) else None
    if m is None or m.shape != (4, 4) or not np.all(np.isfinite(m)):
        raise ParameterError(f"expected a 4x4 matrix of finite numbers, got {describe(matrix)}",
                             name)
    _check_regular(m, name)
    w = vertices @ m[3, :3] + m[3, 3]
    size = np.linalg.norm(m[3, :3]) * np.abs(vertices).max(initial=0.0) + abs(m[3, 3])
    small = np.abs(w) <= tol.degenerate * size
    if np.any(small):
        k = int(np.flatnonzero(small)[0])
        raise GeometryError(f"the projective map sends vertex {k} {vertices[k].tolist()} to "
                            f"infinity")
    if np.any(w > 0) and np.any(w < 0):
        raise GeometryError(f"the projective map sends part of the mesh across infinity: "
                            f"{int(np.count_nonzero(w < 0))} of {len(w)} vertices lie on the other "
                            f"side of the plane it sends to infinity")
    return m, w


def projective(mesh: Mesh, matrix, tol: Tolerances = DEFAULT) -> Mesh:
    """Apply the projective map with homogeneous (4, 4) ``matrix``.

    Raises
    ------
    GeometryError
        If a vertex goes to infinity or the mesh straddles the plane sent to infinity.
    """
    m, w = _projective_parts(matrix, mesh.vertices, tol)
    h = mesh.vertices @ m[:3, :3].T + m[:3, 3]
    out = mesh.with_vertices(h / w[:, None], **_append_transform(mesh, "projective"))
    return _reverse_faces(out) if np.linalg.det(m) < 0 else out


def _invert_points(points: np.ndarray, center: np.ndarray, radius: float) -> np.ndarray:
    r = points - center
    return center + (radius * radius) * r / np.einsum("ij,ij->i", r, r)[:, None]


def inversion(mesh: Mesh, center, radius: float, tol: Tolerances = DEFAULT) -> Mesh:
    """Invert a circular mesh in the sphere ``(center, radius)``.

    Parameters
    ----------
    mesh : Mesh
        Every face inscribed in a circle (triangles always are).
    center : (3,) array_like
    radius : float
        > 0.
    tol : Tolerances
        ``tol.circularity`` decides which faces count as circular.

    Returns
    -------
    Mesh
        Circular, faces reversed (inversion reverses orientation), members
        dropped (straight lines become circles).

    Raises
    ------
    GeometryError
        If a face is not circular (the image would not be planar), or the
        centre is at a vertex (it would go to infinity).
    """
    c = check_vector(center, "center")
    radius = check_float(radius, "radius", lo=0.0, lo_open=True)
    circ = circularity(mesh)
    bad = circ > tol.circularity
    if np.any(bad):
        worst = int(np.argmax(circ))
        raise GeometryError(
            f"inversion needs a circular mesh (every face on a circle), otherwise the faces "
            f"would not stay planar: {int(np.count_nonzero(bad))} of {mesh.n_faces} faces are "
            f"not circular (worst {circ[worst]:.3g} at face {worst}, tolerance "
            f"{tol.circularity:g}); rotational, torus, pipe, canal and moulding meshes are circular")
    dist = np.linalg.norm(mesh.vertices - c, axis=1)
    near = dist <= tol.degenerate * max(mesh.diagonal(), radius)
    if np.any(near):
        k = int(np.flatnonzero(near)[0])
        raise GeometryError(f"the inversion centre is at vertex {k}: it would go to infinity")
    info = _append_transform(mesh, "inversion")
    warnings = list(mesh.info.get("warnings", []))
    if len(mesh.members):
        warnings.append("members dropped: inversion maps straight lines to circles")
        info["warnings"] = warnings
    out = replace(mesh.with_vertices(_invert_points(mesh.vertices, c, radius), **info),
                  members=np.zeros((0, 2), np.int64), member_id=np.zeros(0, np.int64))
    return _reverse_faces(out)


# ------------------------------------------------------------------ on Built
def transform_built(built: Built, kind: str, **params) -> Built:
    """Apply a transform to a built mesh and carry its reference along.

    Parameters
    ----------
    built : Built
    kind : {"affine", "translate", "rotate", "scale", "shear", "projective", "inversion"}
    **params
        Arguments of the function of that name (without ``mesh``).

    Returns
    -------
    Built
        ``extras["transform_notes"]`` says when closeness could not follow exactly.
    """
    mesh = built.mesh
    if kind in ("affine", "translate", "rotate", "scale", "shear"):
        maps: dict[str, Callable[..., Mesh]] = {"affine": affine, "translate": translate, "rotate": rotate,
                                                "scale": scale, "shear": shear}
        fn = maps[kind]
        new = fn(mesh, **params)
        # Recover (A, t) from the vertex map itself: one code path for all five.
        A, t = _fit_affine(mesh.vertices, new.vertices, fn, params)
        Ainv = np.linalg.inv(A)
        inverse = lambda q: (q - t) @ Ainv.T
        pullback = lambda q, g: g @ Ainv
        similarity = _similarity_scale(A)
    elif kind == "projective":
        new = projective(mesh, **params)
        M = np.asarray(params["matrix"], dtype=np.float64)
        N = np.linalg.inv(M)

        def inverse(q):
            h = q @ N[:3, :3].T + N[:3, 3]
            return h / (q @ N[3, :3] + N[3, 3])[:, None]

        def pullback(q, g):
            hw = q @ N[3, :3] + N[3, 3]
            p = inverse(q)
            # d p / d q = (N[:3, :3] - p N[3, :3]) / hw; gradient = (dp/dq)^T g.
            return (g @ N[:3, :3] - np.einsum("ij,ij->i", g, p)[:, None] * N[3, :3]) / hw[:, None]

        similarity = None
    elif kind == "inversion":
        new = inversion(mesh, **params)
        c = np.asarray(params["center"], dtype=np.float64)
        rr = float(params["radius"]) ** 2

        def inverse(q):
            return _invert_points(q, c, rr ** 0.5)

        def pullback(q, g):
            r = q - c
            n2 = np.einsum("ij,ij->i", r, r)
            # J = rr / |r|^2 (I - 2 r r^T / |r|^2), symmetric.
            return (rr / n2)[:, None] * (g - 2 * (np.einsum("ij,ij->i", r, g) / n2)[:, None] * r)

        similarity = None
    else:
        raise ParameterError(f"unknown transform {describe(kind)}", "kind")
    ref, note = _moved_reference(built.reference, inverse, pullback, similarity)
    extras = dict(built.extras)
    notes = list(extras.get("transform_notes", []))
    if note:
        notes.append(f"{kind}: {note}")
    if notes:
        extras["transform_notes"] = notes
    if built.rulings is not None:
        notes.append(f"{kind}: rulings dropped (the mesh's members carry the transformed lines)")
    if notes:
        extras["transform_notes"] = notes
    if "guarantee" in extras:
        extras["guarantee"] = _guarantee_after(str(extras["guarantee"]), kind, similarity)
    return Built(new, ref, None, extras)


def _guarantee_after(guarantee: str, kind: str, similarity: float | None) -> str:
    """What a construction's guarantee still promises after the map ``kind``.

    Similarities keep everything; other affine maps keep parallel edges but not
    lengths or circles; projective maps keep only planarity; inversion keeps
    circles (and hence planarity) but not straight edges.
    """
    if kind == "inversion":
        return "circular (inversion of a circular mesh)"
    if similarity is not None:
        return guarantee
    if kind == "projective":
        return "planar (projective image)"
    kept = []
    for clause in guarantee.split(";"):
        parts = [p.strip().replace("isosceles trapezoids", "trapezoids") for p in clause.split(",")]
        parts = [p for p in parts if p and not p.startswith("circular")]
        if parts:
            kept.append(", ".join(parts))
    return "; ".join(kept) + f" (after a non-similar {kind} map)" if kept else \
        f"planar (after a non-similar {kind} map)"


def _fit_affine(before: np.ndarray, after: np.ndarray, fn, params) -> tuple[np.ndarray, np.ndarray]:
    """(A, t) of an affine mesh map, from the function's own matrix builders."""
    if fn is affine:
        A, t = affine_matrix(params["matrix"], params.get("offset"))
    elif fn is translate:
        A, t = np.eye(3), np.asarray(params["vector"], float)
    elif fn is rotate:
        A = rotation_matrix(params["axis"], params["angle"])
        c = np.asarray(params.get("center", (0.0, 0.0, 0.0)), float)
        t = c - A @ c
    elif fn is scale:
        f = np.broadcast_to(np.asarray(params["factors"], float), (3,))
        c = np.asarray(params.get("center", (0.0, 0.0, 0.0)), float)
        A, t = np.diag(f), c - f * c
    else:
        A, t = shear_matrix(**params), np.zeros(3)
    return A, t
