"""``ruledmesh compare DESIGN``: one surface meshed with §4.3 PQ and §4.1 hybrid, side by side."""

from __future__ import annotations

import json
import sys

# (label, report path, format)
ROWS = [
    ("faces", ("faces",), "{:d}"),
    # Users read a share as a share of the surface: the area first, the count labelled.
    ("area in triangles", ("quality", "area_share", "triangles"), "{:.1%}"),
    ("triangles (of the faces)", ("triangle_share",), "{:.1%}"),
    ("max planarity", ("planarity", "max"), "{:.2e}"),
    ("closeness (max, centroids)", ("closeness", "centroids_max"), "{:.2e}"),
    ("closeness (mean, centroids)", ("closeness", "centroids_mean"), "{:.2e}"),
    ("coverage", ("coverage", "ratio"), "{:.4f}"),
    ("min angle (deg)", ("min_angle_deg",), "{:.1f}"),
    ("non-convex faces", ("non_convex",), "{:d}"),
]


def add_parser(sub) -> None:
    p = sub.add_parser(
        "compare",
        help="mesh one design with the PQ and the hybrid method and compare",
        description="Build the rulings of a design file once and mesh them with the §4.3 PQ "
                    "method and the §4.1 hybrid HP-patch method; print faces, the share of "
                    "the area in triangles and of the faces that are triangles, max planarity, closeness to "
                    "the smooth surface, coverage and "
                    "min angle for both. Options of the design's [mesh] table that belong to "
                    "one method are passed to it.",
        epilog="examples:\n"
               "  ruledmesh compare examples/fig10-skew-surface.toml --rows 16\n"
               "  ruledmesh compare examples/skew.toml --json\n",
    )
    p.add_argument("design", help="design file (.toml) with [rulings]")
    p.add_argument("--rows", type=int, help="PQ: rows (divisions of the primary generator)")
    p.add_argument("--divisions", type=int, help="hybrid: divisions of the generators")
    p.add_argument("--midpoints", type=int, help="hybrid: generators inserted per strip")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.set_defaults(run=run)


def _get(report, path):
    value = report
    for key in path:
        if not isinstance(value, dict) or key not in value:
            return None
        value = value[key]
    return value


def compare(design, rows=None, divisions=None, midpoints=None) -> dict:
    """Reports of the PQ and the hybrid mesh of one design.

    Parameters
    ----------
    design : Design
        A parsed design with a ``[rulings]`` table.
    rows, divisions, midpoints : int, optional
        Overrides of the methods' options.

    Returns
    -------
    dict
        ``{"pq": report, "hybrid": report}`` (see :func:`ruledmesh.analysis.report.analyze`),
        each with ``triangle_share`` (the share of the faces that are triangles)
        added; the share of the area is the report's ``quality.area_share.triangles``.
    """
    from ..analysis.report import analyze
    from ..design import Design, build_design
    from ..design.meshers import HYBRID_MESH_KEYS as HYBRID_KEYS
    from ..design.pq import MESH_KEYS as PQ_KEYS
    from ..errors import DesignError

    if "rulings" not in design.data:
        raise DesignError("compare needs a design with a [rulings] table (generators), not a "
                          "catalogue [surface]", "rulings", design.source)
    mesh_table = dict(design.data.get("mesh", {}))
    out = {}
    for method, keys, extra in (("pq", PQ_KEYS, {"rows": rows}),
                                ("hybrid", HYBRID_KEYS, {"divisions": divisions,
                                                         "midpoints": midpoints})):
        table = {k: v for k, v in mesh_table.items() if k in keys and k != "method"}
        table.update({k: v for k, v in extra.items() if v is not None})
        table["method"] = method
        data = {**design.data, "mesh": table}
        built = build_design(Design(data, design.source, design.base_dir))
        report = analyze(built.mesh, reference=built.reference, extras=built.extras)
        report["triangle_share"] = (float((built.mesh.valences == 3).mean())
                                    if built.mesh.n_faces else 0.0)
        out[method] = report
    return out


def format_comparison(reports: dict) -> str:
    """The comparison as an aligned text table (methods as columns)."""
    methods = list(reports)
    cells = []
    for label, path, fmt in ROWS:
        row = [label]
        for m in methods:
            value = _get(reports[m], path)
            row.append("-" if value is None else fmt.format(value))
        cells.append(row)
    header = ["", *(f"{m} (§4.3)" if m == "pq" else f"{m} (§4.1)" for m in methods)]
    widths = [max(len(r[c]) for r in [header, *cells]) for c in range(len(header))]
    lines = ["  ".join(h.ljust(w) if c == 0 else h.rjust(w) for c, (h, w) in
                       enumerate(zip(r, widths))) for r in [header, *cells]]
    return "\n".join(lines) + "\n"


def run(args) -> int:
    from ..design import load_design
    from ._common import check_design_file

    reports = compare(load_design(check_design_file(args.design)), args.rows, args.divisions, args.midpoints)
    if args.json:
        json.dump({m: dict(r.items()) for m, r in reports.items()}, sys.stdout,
                  indent=2, default=str)
        sys.stdout.write("\n")
    else:
        sys.stdout.write(format_comparison(reports))
        for m, r in reports.items():
            for w in r.get("warnings", []):
                print(f"warning ({m}): {w}", file=sys.stderr)
    return 0
