"""``ruledmesh build DESIGN -o FILE``: build a design and write the mesh."""

from __future__ import annotations

import json
import sys
import warnings


def add_parser(sub) -> None:
    p = sub.add_parser(
        "build",
        help="build a mesh from a design file",
        description="Build the mesh a design file describes and write it; the format "
                    "follows the extension of -o (.obj .ply .stl .glb .json .dxf .3dm .ifc). "
                    "The output is checked before the build starts. Progress is shown on "
                    "stderr when it is a terminal.",
        epilog="examples:\n"
               "  ruledmesh build examples/skew.toml -o skew.obj\n"
               "  ruledmesh build examples/fig5b-torus.toml -o torus.glb --json\n"
               "  ruledmesh build examples/skew.toml -o skew.stl --origin auto\n",
    )
    p.add_argument("design", help="design file (.toml)")
    p.add_argument("-o", "--output", required=True, help="mesh file to write (.obj, .ply, ...)")
    p.add_argument("--json", action="store_true", help="print the analysis summary as JSON")
    p.add_argument("--origin", metavar="X,Y,Z|auto",
                   help="STL: subtract this point before float32 rounding (auto: the lower "
                        "corner in whole units); recorded in the header")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="print nothing on success (no progress, no summary; the mesh is "
                        "not analysed)")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..analysis.report import analyze, format_summary, require_faces
    from ..errors import ParameterError, RuledMeshWarning
    from ..io import WRITERS, save
    from ._common import check_output_file, progress_for, read_design
    from .export import _origin

    output = check_output_file(args.output, WRITERS)
    origin = _origin(args.origin)
    if origin is not None and output.suffix.lower() != ".stl":
        raise ParameterError(f"applies to .stl output only, not {output.suffix or 'this file'}",
                             "--origin")
    progress = progress_for(args)
    _, built = read_design(args.design, progress)
    # Quiet without --json prints nothing the analysis would say: no need to measure
    # (an empty mesh is still refused, as the analysis would).
    require_faces(built.mesh)
    report = None if args.quiet and not args.json else \
        analyze(built.mesh, reference=built.reference, extras=built.extras, progress=progress)
    with progress.task(f"write {args.output}"), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuledMeshWarning)
        save(output, built.mesh, **({} if origin is None else {"origin": origin}))
    for w in caught:
        print(f"warning: {w.message}", file=sys.stderr)
    if report is None:
        return 0
    if args.json:
        json.dump(report, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print(f"wrote {args.output}: {format_summary(report)}")
        for warning in report.get("warnings", []):
            print(f"warning: {warning}", file=sys.stderr)
    return 0
