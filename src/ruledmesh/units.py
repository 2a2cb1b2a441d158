"""Length units of a mesh: what one coordinate unit is, and converting between them.

A design states its unit with the top-level key ``units`` (``"m"``, ``"cm"``,
``"mm"``, ``"in"`` or ``"ft"``; default ``"m"``).  The built mesh carries it
in ``mesh.info["units"]`` (see :attr:`ruledmesh.mesh.Mesh.units`), every
writer states it in the file in the format's own terms (IFC unit assignment,
3DM model unit system, DXF ``$INSUNITS``, a header comment in OBJ/PLY/STL)
and glTF, whose unit is the metre by specification, is scaled to metres.
"""

from __future__ import annotations

from enum import Enum
from typing import Any

from ._validation import check_choice
from .errors import ParameterError

__all__ = ["DEFAULT_UNIT", "Unit", "conversion_factor", "metres_per_unit", "unit_of"]


class Unit(str, Enum):
    """A length unit of mesh coordinates."""

    M = "m"
    CM = "cm"
    MM = "mm"
    IN = "in"
    FT = "ft"

    @property
    def metres(self) -> float:
        """Length of one unit in metres (exact by definition for in and ft)."""
        return _METRES[self]

    @property
    def metric(self) -> bool:
        """True for the SI units (m, cm, mm)."""
        return self in (Unit.M, Unit.CM, Unit.MM)


_METRES = {Unit.M: 1.0, Unit.CM: 0.01, Unit.MM: 0.001, Unit.IN: 0.0254, Unit.FT: 0.3048}
DEFAULT_UNIT = Unit.M


def unit_of(value: Any, name: str = "units", *, err: type = ParameterError) -> Unit:
    """The :class:`Unit` named ``value`` (``None`` is the default, metres).

    Parameters
    ----------
    value : str or Unit or None
    name : str
        Parameter or field named in the error.
    err : type
        Exception class raised for a bad value.
    """
    if value is None:
        return DEFAULT_UNIT
    return check_choice(value, Unit, name, err=err)


def metres_per_unit(value: Any) -> float:
    """Length in metres of one unit ``value`` (e.g. ``0.001`` for ``"mm"``)."""
    return unit_of(value).metres


def conversion_factor(source: Any, target: Any) -> float:
    """The factor that turns coordinates in ``source`` units into ``target`` units.

    >>> conversion_factor("m", "mm")
    1000.0
    >>> round(conversion_factor("ft", "in"), 12)
    12.0
    """
    a, b = unit_of(source, "units"), unit_of(target, "units")
    if a is b:
        return 1.0
    return a.metres / b.metres
