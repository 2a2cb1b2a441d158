"""``ruledmesh analyze FILE``: planarity, convexity, areas, closeness, coverage (``--quick``: the first three)."""

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
               "  ruledmesh analyze skew.obj --design examples/skew.toml --json\n"
               "  ruledmesh analyze examples/skew.toml --quick\n",
    )
    p.add_argument("file", help="mesh file (.obj, .ply, .json) or design file (.toml)")
    p.add_argument("--design", help="design file the mesh was built from (for closeness, coverage)")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--compare", action="store_true",
                   help="also triangulate the smooth surface the standard ways (parameter grid, "
                        "OCCT BRepMesh if installed) and compare triangle quality (slow)")
    p.add_argument("--quick", action="store_true",
                   help="counts, planarity, convexity and areas only, in one pass (what the "
                        "designer shows live); no angles, closeness or triangle quality")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress display")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..analysis.report import analyze
    from ._common import progress_for, read_design, read_source

    if args.quick:
        _refuse_with_quick(args)
    progress = progress_for(args)
    source = read_source(args.file, progress)
    if args.quick:
        return _quick(args, source.mesh)
    reference, extras = None, {}
    if source.built is not None:
        reference, extras = source.built.reference, source.built.extras
    if args.design:
        _, built = read_design(args.design, progress, option="--design")
        reference, extras = built.reference, built.extras
    report = analyze(source.mesh, reference=reference, extras=extras, compare=args.compare,
                     progress=progress)
    return _print(args, report)


def _print(args, report: dict) -> int:
    """``report`` (naming the file) as JSON with ``--json``, else as a table."""
    from ..analysis.report import format_table

    report["file"] = args.file
    if args.json:
        json.dump(report, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        sys.stdout.write(format_table(report))
    return 0


def _refuse_with_quick(args) -> None:
    """--design and --compare add figures of the full report only: refused before any work."""
    from ..errors import ParameterError

    for option in ("design", "compare"):
        if getattr(args, option):
            raise ParameterError(f"--{option} needs the full report; leave out --quick", "--quick")


def _quick(args, mesh) -> int:
    """Print the live figures (:func:`ruledmesh.analysis.live.live_figures`) of ``mesh``."""
    from ..analysis.live import live_figures

    return _print(args, live_figures(mesh))
