"""``ruledmesh build DESIGN -o FILE``: build a design and write the mesh."""

from __future__ import annotations

import json
import sys


def add_parser(sub) -> None:
    p = sub.add_parser(
        "build",
        help="build a mesh from a design file",
        description="Build the mesh a design file describes and write it; the format "
                    "follows the extension of -o.",
        epilog="example: ruledmesh build examples/skew.toml -o skew.obj",
    )
    p.add_argument("design", help="design file (.toml)")
    p.add_argument("-o", "--output", required=True, help="mesh file to write (.obj, .ply, ...)")
    p.add_argument("--json", action="store_true", help="print the analysis summary as JSON")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..analysis.report import analyze, format_summary
    from ..design import build_file
    from ..io import save

    built = build_file(args.design)
    report = analyze(built.mesh, reference=built.reference, extras=built.extras)
    save(args.output, built.mesh)
    if args.json:
        json.dump(report, sys.stdout, indent=2)
        sys.stdout.write("\n")
    elif not args.quiet:
        print(f"wrote {args.output}: {format_summary(report)}")
        for warning in report.get("warnings", []):
            print(f"warning: {warning}", file=sys.stderr)
    return 0
