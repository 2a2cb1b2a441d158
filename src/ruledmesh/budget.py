"""Work budgets: builds too large for memory are refused before anything is allocated.

Every mesher knows, from its arguments alone, how many grid points it will
create: the §4.3 mesher ``generators x rows x (1 + 2 extend)``, the hybrid mesher
``(generators - 1) (midpoints + 1) x (divisions + 1)``, a compound
``patches x (midpoints + 1) x divisions``.  The bytes per point below were
measured (peak resident memory with ``resource.getrusage`` over builds of a few
million points on the development machine); they cover the mesh, its analysis
against the smooth surface and an export.  One limit, :data:`MAX_BUILD_BYTES`,
applies to them all, and the refusal says how much the build would need.
"""

from __future__ import annotations

__all__ = ["HYBRID_BYTES_PER_NODE", "MAX_BUILD_BYTES", "PQ_BYTES_PER_GRID_POINT",
           "check_budget", "gib"]

# Peak memory a build may need; refused above it.
MAX_BUILD_BYTES = 8 * 2**30
# §4.3 mesher, per grid point (generator x row, extension included): 745..1190 measured.
PQ_BYTES_PER_GRID_POINT = 1024
# Hybrid and compound meshers, per grid node: ~320 measured.
HYBRID_BYTES_PER_NODE = 384


def gib(n_bytes: float) -> str:
    """``n_bytes`` in GiB for a message (``"12.3 GiB"``)."""
    return f"{n_bytes / 2**30:.1f} GiB"


def check_budget(points: float, bytes_per_point: int, what: str, advice: str, field: str,
                 err: type[Exception]) -> None:
    """Refuse a build of ``points`` grid points that would need more than :data:`MAX_BUILD_BYTES`.

    Parameters
    ----------
    points : float
        Grid points the build would create (a float: products of user counts may be huge).
    bytes_per_point : int
        Measured peak memory per point.
    what : str
        How the count arises, for the message (``"40 generators x 2001 rows"``).
    advice : str
        What to reduce.
    field : str
        The parameter or field path the message names.
    err : type
        The error class (``ParameterError`` or ``DesignError``): called as ``err(message, field)``.
    """
    need = float(points) * bytes_per_point
    if need > MAX_BUILD_BYTES:
        raise err(f"{what} would need about {gib(need)} of memory ({points:,.0f} grid points, "
                  f"limit {gib(MAX_BUILD_BYTES)}); {advice}", field)
