"""Boundary checks whose messages name the parameter and what was received.

Every public function validates its inputs once, here, and the maths below it
trusts them.  Each helper takes the parameter's ``name`` (a dotted field path
for design files) and the error class to raise, so the same checks serve the
Python API (:class:`~ruledmesh.errors.ParameterError`) and the design-file
reader of :mod:`ruledmesh.design` (its own error class).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable, Mapping
from enum import Enum
from typing import Any, TypeVar

import numpy as np

from .errors import ParameterError, printable

E = TypeVar("E", bound=Enum)

__all__ = [
    "describe",
    "check_points",
    "check_vector",
    "check_int",
    "check_float",
    "check_bool",
    "check_choice",
    "check_keys",
    "near_miss",
]


def describe(value: Any) -> str:
    """A short, quoted description of a received value for an error message."""
    if isinstance(value, str):
        return f'"{printable(value)}"'
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape}"
    if isinstance(value, Mapping):
        return "a table"
    if isinstance(value, (list, tuple)):
        text = repr(list(value))
        return text if len(text) <= 60 else f"a list of {len(value)} items"
    return repr(value)


def near_miss(value: Any, choices: Iterable[str]) -> str:
    """`` (did you mean "x"?)`` for the closest of ``choices`` to ``value``, or ``""``."""
    if not isinstance(value, str):
        return ""
    near = difflib.get_close_matches(value, list(choices), n=1)
    return f' (did you mean "{near[0]}"?)' if near else ""


def _as_float_array(value: Any, name: str, err: type) -> np.ndarray:
    if isinstance(value, (str, Mapping)):
        raise err(f"expected numbers, got {describe(value)}", name)
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise err(f"expected numbers, got {describe(value)}", name) from None
    return arr


def check_points(value: Any, name: str, *, dim: int = 3, min_count: int = 1,
                 err: type = ParameterError) -> np.ndarray:
    """Return ``value`` as an ``(n, dim)`` float64 array of finite numbers.

    Parameters
    ----------
    value : array_like
        The points.
    name : str
        Parameter name for the error message.
    dim : int
        Coordinates per point.
    min_count : int
        Least number of points.
    err : type
        Error class to raise.

    Returns
    -------
    points : (n, dim) float64
    """
    arr = _as_float_array(value, name, err)
    if arr.ndim != 2 or arr.shape[1] != dim:
        raise err(f"expected a list of points with {dim} coordinates each, got {describe(value)}", name)
    if arr.shape[0] < min_count:
        raise err(f"expected at least {min_count} points, got {arr.shape[0]}", name)
    if not np.all(np.isfinite(arr)):
        raise err("expected finite coordinates, got NaN or infinity", name)
    return np.ascontiguousarray(arr)


def check_vector(value: Any, name: str, *, dim: int = 3, nonzero: bool = False,
                 err: type = ParameterError) -> np.ndarray:
    """Return ``value`` as a finite ``(dim,)`` float64 vector.

    Parameters
    ----------
    value : array_like
    name : str
    dim : int
    nonzero : bool
        Refuse the zero vector (a direction or a normal).
    err : type

    Returns
    -------
    vector : (dim,) float64
    """
    arr = _as_float_array(value, name, err)
    if arr.shape != (dim,):
        raise err(f"expected {dim} numbers, got {describe(value)}", name)
    if not np.all(np.isfinite(arr)):
        raise err("expected finite numbers, got NaN or infinity", name)
    if nonzero:
        if not np.any(arr):
            raise err("expected a non-zero vector, got [0, 0, 0]", name)
        # A direction gets normalised: its length must neither underflow to 0
        # (denormal components) nor overflow to infinity.
        big = float(np.abs(arr).max())
        length = big * float(np.linalg.norm(arr / big))    # scaled: no under/overflow here
        if not 1e-150 <= length <= 1e150:
            raise err(f"expected a vector of length between 1e-150 and 1e150, got length "
                      f"{length:g}", name)
    return arr


def _bound_text(lo: float | None, hi: float | None, lo_open: bool = False) -> str:
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        parts.append(f"<= {hi:g}")
    return (" " + " and ".join(parts)) if parts else ""


def check_int(value: Any, name: str, *, lo: int | None = None, hi: int | None = None,
              err: type = ParameterError) -> int:
    """Return ``value`` as an ``int`` within ``[lo, hi]``.

    Booleans and floats with a fraction are refused; ``4.0`` is accepted.
    """
    expected = f"expected an integer{_bound_text(lo, hi)}"
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise err(f"{expected}, got {describe(value)}", name)
    if isinstance(value, (float, np.floating)) and (not math.isfinite(value) or value != int(value)):
        raise err(f"{expected}, got {describe(value)}", name)
    ivalue = int(value)
    if (lo is not None and ivalue < lo) or (hi is not None and ivalue > hi):
        raise err(f"{expected}, got {ivalue}", name)
    return ivalue


def check_float(value: Any, name: str, *, lo: float | None = None, hi: float | None = None,
                lo_open: bool = False, err: type = ParameterError) -> float:
    """Return ``value`` as a finite ``float`` within the given bounds.

    ``lo_open`` makes the lower bound strict (``> lo``).
    """
    expected = f"expected a number{_bound_text(lo, hi, lo_open)}"
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise err(f"{expected}, got {describe(value)}", name)
    fvalue = float(value)
    if not math.isfinite(fvalue):
        raise err(f"{expected}, got {describe(value)}", name)
    if lo is not None and (fvalue < lo or (lo_open and fvalue == lo)):
        raise err(f"{expected}, got {fvalue:g}", name)
    if hi is not None and fvalue > hi:
        raise err(f"{expected}, got {fvalue:g}", name)
    return fvalue


def check_bool(value: Any, name: str, *, err: type = ParameterError, word: str | None = None) -> bool:
    """Return ``value`` if it is a boolean (the error names ``word`` too where it is also accepted)."""
    if not isinstance(value, (bool, np.bool_)):
        expected = f'"{word}", true or false' if word else "true or false"
        raise err(f"expected {expected}, got {describe(value)}", name)
    return bool(value)


def check_choice(value: Any, enum: type[E], name: str, *, err: type = ParameterError) -> E:
    """Return the member of ``enum`` whose value is ``value``.

    The error lists the valid choices and suggests the nearest one.
    """
    if isinstance(value, enum):
        return value
    choices = [m.value for m in enum]
    if isinstance(value, str) and value in choices:
        return enum(value)
    listed = " | ".join(f'"{c}"' for c in choices)
    raise err(f"expected one of {listed}, got {describe(value)}{near_miss(value, choices)}", name)


def check_keys(table: Mapping[str, Any], allowed: Iterable[str], name: str, *,
               err: type = ParameterError) -> None:
    """Refuse keys of ``table`` not in ``allowed``, suggesting near misses.

    ``name`` is the path of the table; the error names the offending key.
    """
    allowed = list(allowed)
    for key in table:
        if key not in allowed:
            hint = near_miss(str(key), allowed)
            where = f"{name}.{key}" if name else str(key)
            raise err(f"unknown key{hint}; expected one of: {', '.join(allowed)}", where)
