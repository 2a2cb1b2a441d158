"""The ``[[transforms]]`` tables of a design file: each read once, then applied.

One function per ``type``, registered with :mod:`ruledmesh.registry`; each reads
its table through :class:`~ruledmesh.design.fields.Fields` and calls
:func:`ruledmesh.transforms.transform_built`.  A ``ParameterError`` or
``GeometryError`` of the transform comes back as a ``DesignError`` naming the
table (``transforms[0].radius``).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .._validation import describe
from ..errors import DesignError, GeometryError, ParameterError
from ..registry import Built, transform_type
from ..transforms import transform_built
from .fields import Fields

__all__ = ["design_inversion"]


def _fields(table: Mapping, path: str, allowed) -> Fields:
    return Fields(table, path, allowed, selector="type")


def _matrix(table: Mapping, key: str, path: str, shapes):
    value = table.get(key)
    if value is None:
        raise DesignError("missing value", f"{path}.{key}")
    try:
        m = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        m = None
    if m is None or m.shape not in shapes or not np.all(np.isfinite(m)):
        listed = " or ".join(f"{r}x{c}" for r, c in shapes)
        raise DesignError(f"expected a {listed} matrix (a list of rows), got {describe(value)}",
                          f"{path}.{key}")
    return m


def _run(built: Built, path: str, kind: str, **params) -> Built:
    try:
        return transform_built(built, kind, **params)
    except (ParameterError, GeometryError) as exc:
        field = getattr(exc, "field", None)
        detail = getattr(exc, "detail", str(exc))
        raise DesignError(detail, f"{path}.{field}" if field else path) from None


@transform_type("affine")
def _design_affine(built: Built, table: Mapping, path: str) -> Built:
    f = _fields(table, path, ["matrix", "offset"])
    m = _matrix(table, "matrix", path, [(3, 3), (3, 4), (4, 4)])
    return _run(built, path, "affine", matrix=m, offset=f.optional_vector("offset"))


@transform_type("translate")
def _design_translate(built: Built, table: Mapping, path: str) -> Built:
    f = _fields(table, path, ["vector"])
    return _run(built, path, "translate", vector=f.vector("vector", f.REQUIRED))


@transform_type("rotate")
def _design_rotate(built: Built, table: Mapping, path: str) -> Built:
    f = _fields(table, path, ["axis", "angle", "center"])
    return _run(built, path, "rotate", axis=f.vector("axis", [0.0, 0.0, 1.0], nonzero=True),
                angle=f.number("angle", f.REQUIRED), center=f.vector("center", [0.0, 0.0, 0.0]))


@transform_type("scale")
def _design_scale(built: Built, table: Mapping, path: str) -> Built:
    f = _fields(table, path, ["factor", "center"])
    raw = f.raw("factor", f.REQUIRED)
    factors = (f.floats("factor", f.REQUIRED, count=3) if isinstance(raw, list) else f.number("factor"))
    if np.any(np.asarray(factors) == 0):
        raise DesignError("expected non-zero factors", f"{path}.factor")
    return _run(built, path, "scale", factors=factors, center=f.vector("center", [0.0, 0.0, 0.0]))


@transform_type("shear")
def _design_shear(built: Built, table: Mapping, path: str) -> Built:
    keys = ["xy", "xz", "yx", "yz", "zx", "zy"]
    f = _fields(table, path, keys)
    return _run(built, path, "shear", **{k: f.number(k, 0.0) for k in keys})


@transform_type("projective")
def _design_projective(built: Built, table: Mapping, path: str) -> Built:
    _fields(table, path, ["matrix"])
    return _run(built, path, "projective", matrix=_matrix(table, "matrix", path, [(4, 4)]))


@transform_type("inversion")
def design_inversion(built: Built, table: Mapping, path: str) -> Built:
    """Invert ``built`` in the sphere of ``table`` (``center``, ``radius``); errors name ``path``."""
    f = _fields(table, path, ["center", "radius"])
    return _run(built, path, "inversion", center=f.vector("center", f.REQUIRED),
                radius=f.number("radius", f.REQUIRED, lo=0.0, lo_open=True))
