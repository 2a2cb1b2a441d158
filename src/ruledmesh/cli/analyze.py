"""``ruledmesh analyze FILE``: planarity, convexity, areas, closeness, coverage."""

from __future__ import annotations

import json
import sys


def add_parser(sub) -> None:
    p = sub.add_parser(
        "analyze",
        help="analyse a mesh file or a design",
        description="Analyse a mesh file (geometric measures) or a design file (builds it, "
                    "then adds closeness to the smooth surface and coverage of the patch). "
                    "Give --design with a mesh file to measure it against that design; a "
                    "design the mesh does not match is reported. A construction's guarantee "
                    "is shown with the figures that confirm it, or flagged as not met.",
        epilog="examples:\n"
               "  ruledmesh analyze skew.obj\n"
               "  ruledmesh analyze examples/skew.toml\n"
               "  ruledmesh analyze skew.obj --design examples/skew.toml --json\n",
    )
    p.add_argument("file", help="mesh file (.obj, .ply, .json) or design file (.toml)")
    p.add_argument("--design", help="design file the mesh was built from (for closeness, coverage)")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--compare", action="store_true",
                   help="also triangulate the smooth surface the standard ways (parameter grid, "
                        "OCCT BRepMesh if installed) and compare triangle quality (slow)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress display")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..analysis.report import analyze, format_table
    from ._common import progress_for, read_design, read_source

    progress = progress_for(args)
    source = read_source(args.file, progress)
    reference, extras = None, {}
    if source.built is not None:
        reference, extras = source.built.reference, source.built.extras
    if args.design:
        _, built = read_design(args.design, progress, option="--design")
        reference, extras = built.reference, built.extras
    report = analyze(source.mesh, reference=reference, extras=extras, compare=args.compare,
                     progress=progress)
    report["file"] = args.file
    if args.json:
        json.dump(report, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        sys.stdout.write(format_table(report))
    return 0
