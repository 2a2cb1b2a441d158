"""A 4-axis hot-wire machine, and the shop-ready program of a wire path on it.

The machine is what the workshop knows about its cutter: the tower travel
(horizontal X/U by vertical Y/V), the wire length between the towers (the
distance of the tower planes), the largest tilt of the wire from the span
axis the towers can follow, and the feed.  :func:`program` turns a
:class:`~ruledmesh.fabricate.hotwire.WirePath` into moves in machine units
(millimetres for metric meshes, ``G21``; inches for imperial ones, ``G20``):

1. rapid (``G0``) up to the safe height (``clearance`` above the highest
   point of the cut) and across to above the lead-in start, then down to
   it; the lead-in start is the first generator's wire moved along X/U
   (both towers alike, so the wire keeps its tilt) until both ends are
   ``lead`` outside the cut's X/U extent, so no rapid move passes through
   the stock (assumed within the cut's extent);
2. wire on, dwell, feed (``G1``) along the lead-in to the first generator;
3. the cut, generator after generator;
4. the lead-out, the same way out of the cut's extent on the nearer side,
   wire off, rapid up to the safe height.

:func:`check` refuses a program the machine cannot run, before anything is
written, naming the travel, wire length and tilt it would need.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import check_float
from ..errors import GeometryError, ParameterError
from ..tolerances import ROUNDING
from ..units import Unit, unit_of

__all__ = ["Machine", "Program", "check", "machine_unit", "program"]


@dataclass(frozen=True)
class Machine:
    """A 4-axis hot-wire cutter, lengths in machine units (mm or in).

    Attributes
    ----------
    travel : (width, height) or None
        Tower travel, horizontal (X/U) and vertical (Y/V); ``None``: not checked.
    wire_length : float or None
        Distance between the tower planes; the wire ends are placed there
        (the paths extended along the generators).  ``None``: the tower planes
        are the faces of the cut (its extent along the span axis).
    max_tilt : float
        Largest angle (degrees) between the wire and the span axis.
    feed : float
        Cutting feed, machine units per minute.
    lead : float or None
        Length of the lead-in and lead-out moves (default 10 mm / 0.5 in).
    clearance : float or None
        Height of the safe rapid plane above the cut (default 10 mm / 0.5 in).
    """

    travel: tuple[float, float] | None = None
    wire_length: float | None = None
    max_tilt: float = 90.0
    feed: float = 300.0
    lead: float | None = None
    clearance: float | None = None

    def __post_init__(self):
        if self.travel is not None:
            if np.ndim(self.travel) != 1 or len(self.travel) != 2:
                raise ParameterError(f"expected (width, height), got {self.travel!r}", "travel")
            for v in self.travel:
                check_float(v, "travel", lo=0.0, lo_open=True)
        if self.wire_length is not None:
            check_float(self.wire_length, "wire_length", lo=0.0, lo_open=True)
        check_float(self.max_tilt, "max_tilt", lo=0.0, hi=90.0, lo_open=True)
        check_float(self.feed, "feed", lo=0.0, lo_open=True)
        for name in ("lead", "clearance"):
            if getattr(self, name) is not None:
                check_float(getattr(self, name), name, lo=0.0)


# Exact factors (a ratio of metres would round 1000 to 1000.0000000000001).
_MACHINE_UNIT = {Unit.M: ("mm", 1000.0), Unit.CM: ("mm", 10.0), Unit.MM: ("mm", 1.0),
                 Unit.IN: ("in", 1.0), Unit.FT: ("in", 12.0)}


def machine_unit(units: str) -> tuple[str, float]:
    """G-code unit of a mesh unit, and the factor from mesh to machine units.

    >>> machine_unit("m")
    ('mm', 1000.0)
    >>> machine_unit("ft")
    ('in', 12.0)
    """
    unit = unit_of(units)
    return _MACHINE_UNIT[unit]


@dataclass(frozen=True, eq=False)
class Program:
    """Moves of a hot-wire program in machine units.

    Attributes
    ----------
    rapid_in : (3, 4) float64
        X, Y, U, V of the rapid moves to the lead-in start (up, across, down).
    cut : (n + 2, 4) float64
        Lead-in start, the generators in order, lead-out end.
    rapid_out : (1, 4) float64
        The rapid move up from the lead-out end.
    unit : str
        ``"mm"`` or ``"in"``.
    tilt_deg : float
        Largest angle of the wire from the span axis.
    wire_length : float
        Distance between the tower planes.
    lead : float
        Distance of the lead-in start and lead-out end from the cut's X/U extent.
    safe : float
        Height (Y and V) of the rapid moves.
    """

    rapid_in: np.ndarray
    cut: np.ndarray
    rapid_out: np.ndarray
    unit: str
    tilt_deg: float
    wire_length: float
    lead: float
    safe: float

    def extent(self) -> np.ndarray:
        """(2,) float64: horizontal and vertical travel used (from 0)."""
        pts = np.vstack([self.rapid_in, self.cut, self.rapid_out])
        return np.array([pts[:, [0, 2]].max(), pts[:, [1, 3]].max()])


def program(path, units: str, machine: Machine = Machine()) -> Program:
    """The moves of ``path`` on ``machine`` (see the module notes).

    Parameters
    ----------
    path : WirePath
        Its tower planes must be the machine's (see :func:`ruledmesh.fabricate.hotwire.wire_paths`
        with ``planes``).
    units : str
        Unit of the mesh the path was made from.
    machine : Machine
    """
    unit, k = machine_unit(units)
    default = 10.0 if unit == "mm" else 0.5
    lead = default if machine.lead is None else machine.lead
    clearance = default if machine.clearance is None else machine.clearance
    pts = np.column_stack([path.xy, path.uv]) * k  # X Y U V, shifted to a zero minimum
    lo_x, hi_x = pts[:, [0, 2]].min(), pts[:, [0, 2]].max()
    first, last = pts[0], pts[-1]
    # Enter and leave on the side of the nearer X/U extent, both towers moved
    # alike so the wire keeps the tilt of the first (last) generator.
    def outside(p):
        left = (p[0] + p[2]) / 2 - lo_x <= hi_x - (p[0] + p[2]) / 2
        dx = lo_x - lead - max(p[0], p[2]) if left else hi_x + lead - min(p[0], p[2])
        return p + np.array([dx, 0.0, dx, 0.0])

    start, end = outside(first), outside(last)
    cut = np.vstack([start, pts, end])
    # Work zero: the lower front corner of everything the wire visits.
    shift_x = min(cut[:, [0, 2]].min(), 0.0)
    cut[:, [0, 2]] -= shift_x
    safe = float(cut[:, [1, 3]].max() + clearance)
    s = cut[0]
    rapid_in = np.array([[0.0, safe, 0.0, safe], [s[0], safe, s[2], safe], s])
    rapid_out = np.array([[cut[-1, 0], safe, cut[-1, 2], safe]])
    span = float(path.planes[1] - path.planes[0]) * k
    offset = np.hypot(pts[:, 2] - pts[:, 0], pts[:, 3] - pts[:, 1])
    tilt = float(np.degrees(np.arctan2(offset, span)).max()) if pts.size else 0.0
    return Program(rapid_in, cut, rapid_out, unit, tilt, span, lead, safe)


def check(prog: Program, machine: Machine) -> None:
    """Refuse ``prog`` if ``machine`` cannot run it, naming what it would need.

    Raises
    ------
    GeometryError
        Travel, wire length or tilt beyond the machine's.
    """
    need = prog.extent()
    problems = []
    if machine.travel is not None and np.any(need > np.asarray(machine.travel) * (1 + ROUNDING)):
        problems.append(f"a travel of {need[0]:.1f} x {need[1]:.1f} {prog.unit} (the machine has "
                        f"{machine.travel[0]:g} x {machine.travel[1]:g})")
    if prog.tilt_deg > machine.max_tilt:
        problems.append(f"a wire tilt of {prog.tilt_deg:.1f} degrees (the machine allows "
                        f"{machine.max_tilt:g})")
    if problems:
        raise GeometryError("the hot-wire cut does not fit the machine: it needs "
                            + " and ".join(problems) + "; nothing written")
