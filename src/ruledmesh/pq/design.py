"""Design-file builder for ``[mesh] method = "pq"``."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .._validation import check_bool, check_float, check_int, check_keys, describe
from ..errors import DesignError
from ..registry import BuildContext, Built, mesh_method
from .mesher import pq_mesh

__all__ = ["MESH_KEYS", "build_pq"]

MESH_KEYS = ("method", "rows", "primary", "option", "extend", "trim", "max_extend",
             "planarity_tolerance")


@mesh_method("pq")
def build_pq(rulings, table: Mapping[str, Any], ctx: BuildContext) -> Built:
    """Design-file builder for ``[mesh] method = "pq"``."""
    check_keys(table, MESH_KEYS, "mesh", err=DesignError)
    rows = check_int(table.get("rows", 20), "mesh.rows", lo=1, hi=100_000, err=DesignError)
    primary = table.get("primary", "middle")
    m = len(rulings.a)
    if isinstance(primary, str):
        if primary != "middle":
            raise DesignError(f'expected "middle" or an index, got {describe(primary)}', "mesh.primary")
    else:
        primary = check_int(primary, "mesh.primary", lo=-m, hi=m - 1, err=DesignError)
    option = check_int(table.get("option", 0), "mesh.option", lo=0, hi=1, err=DesignError)
    extend = table.get("extend", "auto")
    if extend != "auto":
        if isinstance(extend, str):
            raise DesignError(f'expected "auto" or a number >= 0, got {describe(extend)}', "mesh.extend")
        extend = check_float(extend, "mesh.extend", lo=0.0, hi=1e3, err=DesignError)
    trim = check_bool(table.get("trim", True), "mesh.trim", err=DesignError)
    max_extend = check_float(table.get("max_extend", 20.0), "mesh.max_extend", lo=0.0, hi=1e3,
                             err=DesignError)
    # Relative, the paper's measure (analysis.planarity); 1e-12 (the default) is exact.
    ptol = check_float(table.get("planarity_tolerance", 1e-12), "mesh.planarity_tolerance",
                       lo=0.0, hi=0.1, err=DesignError)
    mesh = pq_mesh(rulings.a, rulings.b, rows=rows, primary=primary, option=option, extend=extend,
                   trim=trim, max_extend=max_extend, creases=rulings.info.get("creases"),
                   crease_generators=rulings.info.get("crease_generators"),
                   planarity_tolerance=ptol)
    reference = None
    if getattr(rulings, "surface", None) is not None:
        from ..analysis.surface import RuledReference

        reference = RuledReference(rulings.surface)
    return Built(mesh.with_info(source=ctx.source), reference, rulings)
