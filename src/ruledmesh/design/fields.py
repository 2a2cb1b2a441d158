"""Reading ``[surface]`` and ``[mesh]`` tables: each field once, named by its dotted path.

Builders call :class:`Fields` so that every message reads like
``torus.toml: surface.r: expected a number > 0, got -1``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar, overload

import numpy as np

from .._validation import (
    check_bool,
    check_choice,
    check_float,
    check_int,
    check_keys,
    check_points,
    check_vector,
    describe,
)
from ..budget import MAX_COUNT, MAX_SURFACE_FACES
from ..errors import DesignError

__all__ = ["Fields", "mesh_counts"]


class Fields:
    """Typed access to one design table, with errors naming ``prefix.key``.

    Parameters
    ----------
    table : mapping
        The TOML table.
    prefix : str
        Its dotted path (``"surface"``).
    allowed : iterable of str
        Keys the table may have besides ``selector``.
    selector : str
        The key that chose the builder (``kind`` for surfaces, ``type`` for transforms).
    """

    #: Pass as ``default`` for a key that must be given.
    REQUIRED: ClassVar[Any]

    def __init__(self, table: Mapping[str, Any], prefix: str, allowed, selector: str = "kind"):
        self.table = table
        self.prefix = prefix
        check_keys(table, [selector, *allowed], prefix, err=DesignError)

    def path(self, key: str) -> str:
        return f"{self.prefix}.{key}"

    def has(self, key: str) -> bool:
        return key in self.table

    def _get(self, key: str, default: Any):
        if key not in self.table:
            if default is _REQUIRED:
                raise DesignError("missing value", self.path(key))
            return default, False
        return self.table[key], True

    def number(self, key: str, default: Any = None, **bounds) -> float:
        value, given = self._get(key, default)
        return check_float(value, self.path(key), err=DesignError, **bounds) if given else value

    def integer(self, key: str, default: Any = None, **bounds) -> int:
        value, given = self._get(key, default)
        return check_int(value, self.path(key), err=DesignError, **bounds) if given else value

    def boolean(self, key: str, default: Any = None) -> bool:
        value, given = self._get(key, default)
        return check_bool(value, self.path(key), err=DesignError) if given else value

    def vector(self, key: str, default: Any, *, dim: int = 3,
               nonzero: bool = False) -> np.ndarray:
        """A ``dim``-vector; ``default`` (never ``None``) when the key is absent."""
        value, given = self._get(key, default)
        if not given:
            return np.asarray(value, dtype=np.float64)
        return check_vector(value, self.path(key), dim=dim, nonzero=nonzero, err=DesignError)

    def optional_vector(self, key: str, *, dim: int = 3,
                        nonzero: bool = False) -> np.ndarray | None:
        """A ``dim``-vector, or ``None`` when the key is absent."""
        return self.vector(key, Fields.REQUIRED, dim=dim, nonzero=nonzero) if key in self.table else None

    def points(self, key: str, default: Any, *, dim: int = 3,
               min_count: int = 1) -> np.ndarray:
        """An ``(n, dim)`` array of points; ``default`` (never ``None``) when the key is absent."""
        value, given = self._get(key, default)
        if not given:
            return np.asarray(value, dtype=np.float64)
        return check_points(value, self.path(key), dim=dim, min_count=min_count, err=DesignError)

    def floats(self, key: str, default: Any, *, count: int | None = None,
               positive: bool = False) -> np.ndarray:
        """A list of numbers (``count`` of them if given); ``default`` (never ``None``) when absent."""
        value, given = self._get(key, default)
        if not given:
            return np.asarray(value, dtype=np.float64)
        if isinstance(value, (str, Mapping)) or not isinstance(value, (list, tuple)):
            raise DesignError(f"expected a list of numbers, got {describe(value)}", self.path(key))
        out = np.array([check_float(v, f"{self.path(key)}[{k}]", err=DesignError,
                                    lo=0.0 if positive else None, lo_open=positive)
                        for k, v in enumerate(value)], dtype=np.float64)
        if count is not None and out.size != count:
            raise DesignError(f"expected {count} numbers, got {out.size}", self.path(key))
        return out

    def choice(self, key: str, enum, default: Any = None):
        value, given = self._get(key, default)
        return check_choice(value, enum, self.path(key), err=DesignError) if given else enum(value)

    def raw(self, key: str, default: Any = None):
        value, _ = self._get(key, default)
        return value


_REQUIRED = object()
Fields.REQUIRED = _REQUIRED


@overload
def mesh_counts(mesh_table: Mapping[str, Any], default_u: int, default_v: int,
                *, min_u: int = 1, min_v: int = 1) -> tuple[int, int]: ...
@overload
def mesh_counts(mesh_table: Mapping[str, Any], default_u: int, default_v: None,
                *, min_u: int = 1, min_v: int = 1) -> tuple[int, None]: ...
@overload
def mesh_counts(mesh_table: Mapping[str, Any], default_u: None, default_v: int,
                *, min_u: int = 1, min_v: int = 1) -> tuple[None, int]: ...
def mesh_counts(mesh_table: Mapping[str, Any], default_u: int | None, default_v: int | None,
                *, min_u: int = 1, min_v: int = 1) -> tuple[int | None, int | None]:
    """``[mesh] u`` and ``v``: the numbers of steps in the two directions of a kind.

    A default of ``None`` means the kind has no such direction (the key is refused).
    """
    allowed = [k for k, d in (("u", default_u), ("v", default_v)) if d is not None]
    check_keys(mesh_table, allowed, "mesh", err=DesignError)
    out: list[int | None] = []
    for key, default, lo in (("u", default_u, min_u), ("v", default_v, min_v)):
        out.append(None if default is None else
                   check_int(mesh_table.get(key, default), f"mesh.{key}", lo=lo, hi=MAX_COUNT,
                             err=DesignError))
    u, v = out
    if (u or 1) * (v or 1) > MAX_SURFACE_FACES:
        raise DesignError(f"u * v = {(u or 1) * (v or 1)} faces is too many "
                          f"(at most {MAX_SURFACE_FACES})", "mesh")
    return u, v
