"""The design-file builders of the §4 meshers besides §4.3: hybrid (§4.1) and compound HP (§4.2).

``[mesh] method = "hybrid"`` meshes the generators of ``[rulings]`` with
:func:`ruledmesh.skew.hybrid_mesh`; ``[surface] kind = "compound-hp"`` builds the
C1 net of :func:`ruledmesh.skew.compound_net` and meshes it.  Each value is
checked here once, with messages naming the field.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .._validation import check_bool, check_int, check_keys, check_points, describe
from ..budget import MAX_COUNT, MAX_DIVISIONS
from ..errors import DesignError
from ..mesh import FaceKind
from ..registry import BuildContext, Built, mesh_method, surface_kind
from ..skew.compound import CompoundReference, c1_residual, check_steps, compound_mesh, compound_net
from ..skew.hybrid import hybrid_mesh
from ..surfaces import RuledReference
from ..tolerances import DEFAULT, Tolerances

__all__ = ["COMPOUND_MESH_KEYS", "HYBRID_MESH_KEYS", "build_compound", "build_hybrid"]


HYBRID_MESH_KEYS = ("method", "midpoints", "divisions", "flip", "orient")


@mesh_method("hybrid")
def build_hybrid(rulings, table: Mapping[str, Any], ctx: BuildContext) -> Built:
    """Design-file builder for ``[mesh] method = "hybrid"``."""
    check_keys(table, HYBRID_MESH_KEYS, "mesh", err=DesignError)
    midpoints = check_int(table.get("midpoints", 1), "mesh.midpoints", lo=0, hi=10_000,
                          err=DesignError)
    divisions = check_int(table.get("divisions", 8), "mesh.divisions", lo=1, hi=MAX_DIVISIONS,
                          err=DesignError)
    flip = check_bool(table.get("flip", False), "mesh.flip", err=DesignError)
    orient = check_bool(table.get("orient", True), "mesh.orient", err=DesignError)
    mesh = hybrid_mesh(rulings.a, rulings.b, midpoints=midpoints, divisions=divisions, flip=flip,
                       orient=orient)
    reference = None
    if getattr(rulings, "surface", None) is not None:
        reference = RuledReference(rulings.surface)
    extras = {"hybrid": {"triangles": int(np.count_nonzero(mesh.face_kind == FaceKind.TRIANGLE)),
                         "quads": int(np.count_nonzero(mesh.face_kind == FaceKind.QUAD)),
                         "collapsed_faces": mesh.info["collapsed_faces"]}}
    return Built(mesh.with_info(source=ctx.source), reference, rulings, extras)


_COMPOUND_SURFACE_KEYS = ("kind", "seed", "u_steps", "v_steps")
COMPOUND_MESH_KEYS = ("midpoints", "divisions", "border")


@surface_kind("compound-hp")
def build_compound(surface: Mapping[str, Any], mesh_table: Mapping[str, Any],
                   ctx: BuildContext, tol: Tolerances = DEFAULT) -> Built:
    """Design-file builder for ``[surface] kind = "compound-hp"``."""
    check_keys(surface, _COMPOUND_SURFACE_KEYS, "surface", err=DesignError)
    check_keys(mesh_table, COMPOUND_MESH_KEYS, "mesh", err=DesignError)
    if "seed" not in surface:
        raise DesignError("missing: the first two generators [[a0, b0], [a1, b1]]", "surface.seed")
    seed = surface["seed"]
    try:
        arr = np.asarray(seed, dtype=np.float64)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.shape != (2, 2, 3):
        raise DesignError(f"expected two generators [[a0, b0], [a1, b1]], got {describe(seed)}",
                          "surface.seed")
    check_points(arr.reshape(4, 3), "surface.seed", err=DesignError)
    steps = {}
    for key in ("u_steps", "v_steps"):
        value = surface.get(key, [])
        if not isinstance(value, list):
            raise DesignError(f"expected a list of [lambda, sigma, tau], got {describe(value)}",
                              f"surface.{key}")
        for k, row in enumerate(value):
            if not isinstance(row, list) or len(row) != 3:
                raise DesignError(f"expected [lambda, sigma, tau], got {describe(row)}",
                                  f"surface.{key}[{k}]")
        steps[key] = check_steps(value, f"surface.{key}", err=DesignError)
    midpoints = check_int(mesh_table.get("midpoints", 1), "mesh.midpoints", lo=0, hi=10_000,
                          err=DesignError)
    divisions = check_int(mesh_table.get("divisions", 8), "mesh.divisions", lo=1, hi=MAX_COUNT,
                          err=DesignError)
    border = mesh_table.get("border", "notched")
    if border not in ("notched", "triangles"):
        raise DesignError(f'expected "notched" or "triangles", got {describe(border)}',
                          "mesh.border")
    # The steps are ratios and slides along the joints (affine-invariant): the net is
    # grown in the seed's unit frame and mapped back, so its arithmetic never
    # overflows; a net that is not finite is refused by compound_net.
    from ..normalise import unit_frame

    centre, unit = unit_frame(arr.reshape(4, 3))
    with np.errstate(all="ignore"):
        P, gap = compound_net((arr - centre) / unit, steps["u_steps"], steps["v_steps"])
    P, gap = P * unit + centre, gap * unit
    mesh = compound_mesh(P, midpoints, divisions, border)
    c1 = c1_residual(P)
    scale = float(np.linalg.norm(np.ptp(P.reshape(-1, 3), axis=0))) or 1.0
    warnings = []
    if c1["max"] > tol.planarity * 1e3:
        warnings.append(f"compound: tangent planes differ along a joint by {c1['max']:.2e} "
                        "(sine of the angle)")
    I, J = P.shape[0] - 1, P.shape[1] - 1
    extras = {"c1": {"max_sine": c1["max"], "joints": c1["joints"],
                     "corner_gap": gap / scale, "patches": [I, J],
                     "free_numbers": 12 + 3 * (I - 1) + 3 * (J - 1),
                     "net_numbers": 3 * (I + 1) * (J + 1)}}
    mesh = mesh.with_info(source=ctx.source, warnings=warnings)
    return Built(mesh, CompoundReference(P), None, extras)
