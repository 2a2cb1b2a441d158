"""``ruledmesh analyze FILE``: planarity, convexity, areas, closeness, coverage."""

from __future__ import annotations

import json
import sys
from pathlib import Path


def add_parser(sub) -> None:
    p = sub.add_parser(
        "analyze",
        help="analyse a mesh file or a design",
        description="Analyse a mesh file (geometric measures) or a design file (builds it, "
                    "then adds closeness to the smooth surface and coverage of the patch). "
                    "Give --design with a mesh file to measure it against that design.",
        epilog="examples:\n  ruledmesh analyze skew.obj\n  ruledmesh analyze skew.obj --design "
               "examples/skew.toml --json",
    )
    p.add_argument("file", help="mesh file (.obj, .ply, ...) or design file (.toml)")
    p.add_argument("--design", help="design file the mesh was built from (for closeness, coverage)")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--compare", action="store_true",
                   help="also triangulate the smooth surface the standard ways (parameter grid, "
                        "OCCT BRepMesh if installed) and compare triangle quality (slow)")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..analysis.report import analyze, format_table
    from ..design import build_file
    from ..io import load

    path = Path(args.file)
    reference = None
    extras = {}
    if path.suffix.lower() == ".toml":
        built = build_file(path)
        mesh, reference, extras = built.mesh, built.reference, built.extras
    else:
        mesh = load(path)
        if args.design:
            built = build_file(args.design)
            reference, extras = built.reference, built.extras
    report = analyze(mesh, reference=reference, extras=extras, compare=args.compare)
    report["file"] = str(path)
    if args.json:
        json.dump(report, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        sys.stdout.write(format_table(report))
    return 0
