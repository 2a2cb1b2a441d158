"""Work budgets: builds too large for memory are refused before anything is allocated.

Every mesher knows, from its arguments alone, how many grid points it will
create: the §4.3 mesher ``generators x rows x (1 + 2 extend)``, the hybrid mesher
``(generators - 1) (midpoints + 1) x (divisions + 1)``, a compound
``patches x (midpoints + 1) x divisions``.  The bytes per point below were
measured (peak resident memory with ``resource.getrusage`` over builds of a few
million points on the development machine); they cover the mesh, its analysis
against the smooth surface and an export.  One limit, :data:`MAX_BUILD_BYTES`,
applies to them all, and the refusal says how much the build would need.

The other limits on work and memory live here too: the largest count a single
field may ask for, the most generators, the largest input files read.  (The
request limits of the two servers, ``ruledmesh.web`` and ``ruledmesh.hops``,
stay with the servers: they bound a protocol, not a build.)
"""

from __future__ import annotations

__all__ = ["HYBRID_BYTES_PER_NODE", "MAX_BUILD_BYTES", "MAX_COUNT", "MAX_CSV_BYTES",
           "MAX_DESIGN_BYTES", "MAX_DIVISIONS", "MAX_GENERATORS", "MAX_GRID_NODES",
           "MAX_GRID_POINTS", "MAX_MESH_BYTES", "MAX_SURFACE_FACES", "PQ_BYTES_PER_GRID_POINT",
           "check_budget", "gib"]

# Peak memory a build may need; refused above it.
MAX_BUILD_BYTES = 8 * 2**30
# §4.3 mesher, per grid point (generator x row, extension included): 745..1190 measured.
PQ_BYTES_PER_GRID_POINT = 1024
# Hybrid and compound meshers, per grid node: ~320 measured.
HYBRID_BYTES_PER_NODE = 384

# Grid points (generators x rows) of the §4.3 mesher above which a build is
# refused up front, with the memory it would need, instead of running out of
# memory half-way.
MAX_GRID_POINTS = MAX_BUILD_BYTES // PQ_BYTES_PER_GRID_POINT
# Grid nodes of the hybrid mesher refused up front, for the same reason.
MAX_GRID_NODES = MAX_BUILD_BYTES // HYBRID_BYTES_PER_NODE

# Most generators a design may ask for: at ~1 KiB per generator and row,
# 10^5 generators at the default 20 rows already need ~2 GiB, a million ~20 GiB.
# Refusing up front beats an out-of-memory kill halfway through.
MAX_GENERATORS = 100_000
# Largest count one field may ask for (rows, u, v, the compound's divisions):
# the budget above refuses large products; this keeps a single typo (1e9 rows)
# from reaching the arithmetic at all.
MAX_COUNT = 100_000
# Divisions of a generator in the hybrid mesher: its rows are cheap (one node per
# generator and division), so a finer bound than MAX_COUNT would refuse real work.
MAX_DIVISIONS = 1_000_000
# Faces (u x v) of a smooth analytic surface sampled for §2 constructions.
MAX_SURFACE_FACES = 4_000_000

# A design file is a page of TOML; the largest bundled one is 4 kB.
MAX_DESIGN_BYTES = 16 * 2**20
# MAX_GENERATORS generators of six full-precision numbers are ~13 MB.
MAX_CSV_BYTES = 64 * 2**20
# A mesh of a few million faces; its reader needs several times this in memory.
MAX_MESH_BYTES = 1 * 2**30


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
        The error class (``ParameterError``, or the design layer's error): called as
        ``err(message, field)``.
    """
    need = float(points) * bytes_per_point
    if need > MAX_BUILD_BYTES:
        raise err(f"{what} would need about {gib(need)} of memory ({points:,.0f} grid points, "
                  f"limit {gib(MAX_BUILD_BYTES)}); {advice}", field)
