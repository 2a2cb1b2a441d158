"""``ruledmesh fabricate MESH -o DIR``: sheets, schedules, statistics, hot-wire paths."""

from __future__ import annotations

import sys

from ..tolerances import CONGRUENCE_ANGLE_DEG


def _size(text: str) -> tuple[float, float]:
    import argparse

    try:
        w, h = (float(p) for p in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f'expected WIDTHxHEIGHT, e.g. 2500x1250, got "{text}"') from None
    return w, h


def _positive(text: str) -> float:
    import argparse
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'expected a number, got "{text}"') from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(
            f"expected a positive factor, got {text}"
            + (" (a negative factor would mirror the panels; mirror the mesh explicitly "
               "with a [[transform]] scale in the design instead)" if value < 0 else ""))
    return value


def add_parser(sub) -> None:
    p = sub.add_parser(
        "fabricate",
        help="write cutting sheets, schedules and hot-wire paths for a mesh",
        description="Unroll every panel (exactly: they are planar), lay the panels out on sheets "
                    "(SVG, and DXF when ezdxf is installed), and write node/edge/member schedules, "
                    "panel statistics with congruence classes, and 4-axis hot-wire paths (CSV and "
                    "XYUV G-code) along the generators. See docs/fabrication.md.",
        epilog="examples:\n"
               "  ruledmesh fabricate skew.obj -o skew-fab\n"
               "  ruledmesh fabricate examples/fig5b-torus.toml -o torus-fab --scale 1000 --unit mm "
               "--sheet 2500x1250 --nesting shelf\n",
    )
    p.add_argument("mesh", help="mesh file (.obj, .ply, ...) or design file (.toml)")
    p.add_argument("-o", "--output", required=True, help="folder to write into (created if missing)")
    p.add_argument("--scale", type=_positive, default=1.0,
                   help="multiply coordinates first, a positive factor (e.g. 1000: m -> mm)")
    p.add_argument("--unit", default="", choices=["", "mm", "cm", "m", "in", "ft"],
                   help="unit of the (scaled) coordinates (default: the mesh's own, from the "
                        "design's units key or the file)")
    p.add_argument("--sheet", type=_size, metavar="WxH", help="sheet size (default: one square sheet)")
    p.add_argument("--gap", type=float,
                   help="clearance between panels and from the sheet border (default: --tool)")
    p.add_argument("--tool", type=float,
                   help="diameter or kerf of the sheet cutter, mesh units (default 3 mm)")
    p.add_argument("--nesting", default="auto", choices=["auto", "true-shape", "shelf"],
                   help="sheet packer: true-shape (spyrrow, pip install 'ruledmesh[nesting]'), "
                        "shelf packing of bounding boxes, or auto (true-shape when installed)")
    p.add_argument("--nest-time", type=int, default=2,
                   help="seconds the true-shape nesting may search per sheet (default 2; a sheet "
                        "takes one or two searches)")
    p.add_argument("--decimals", type=int, default=3, help="decimals of edge-length labels (default 3)")
    p.add_argument("--length-tol", type=float, help="congruence tolerance on edge lengths "
                   "(default 1e-9 x diagonal)")
    p.add_argument("--angle-tol", type=float, default=CONGRUENCE_ANGLE_DEG,
                   help="congruence tolerance on angles, degrees (default 1e-4)")
    p.add_argument("--no-dxf", action="store_true", help="do not write DXF sheets")
    p.add_argument("--span", default="auto", choices=["auto", "x", "y", "z"],
                   help="hot wire: mesh axis across the towers (default: auto)")
    p.add_argument("--up", choices=["x", "y", "z"], help="hot wire: mesh axis of Y/V (default z)")
    p.add_argument("--kerf", type=float, default=0.0, help="hot wire: slot width (default 0)")
    p.add_argument("--kerf-side", default="left", choices=["left", "right"],
                   help="hot wire: offset side, relative to travel (default left)")
    p.add_argument("--feed", type=float, default=300.0,
                   help="hot wire: feed in G-code units (mm or in) per minute (default 300)")
    p.add_argument("--travel", type=_size, metavar="WxH",
                   help="hot wire: tower travel, horizontal x vertical, in G-code units (mm or in)")
    p.add_argument("--wire-length", type=float,
                   help="hot wire: distance between the towers, G-code units (default: the cut's width)")
    p.add_argument("--max-tilt", type=float, default=90.0,
                   help="hot wire: largest wire angle from the span axis, degrees")
    p.add_argument("--lead", type=float, help="hot wire: lead-in/out length (default 10 mm / 0.5 in)")
    p.add_argument("--clearance", type=float,
                   help="hot wire: safe rapid height above the cut (default 10 mm / 0.5 in)")
    p.add_argument("--allow-bent", action="store_true",
                   help="project non-planar faces instead of refusing them")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="print nothing on success (no progress, no summary)")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..fabricate.machine import Machine
    from ..fabricate.output import fabricate
    from ._common import check_output_folder, progress_for, read_source

    check_output_folder(args.output)
    progress = progress_for(args)
    mesh = read_source(args.mesh, progress).mesh
    if args.scale != 1.0:
        mesh = mesh.with_vertices(mesh.vertices * args.scale)
    if args.unit:
        mesh = mesh.with_units(args.unit, convert=False)
    limits = (args.travel, args.wire_length, args.lead, args.clearance)
    machine = (Machine(travel=args.travel, wire_length=args.wire_length, max_tilt=args.max_tilt,
                       feed=args.feed, lead=args.lead, clearance=args.clearance)
               if any(v is not None for v in limits) or args.max_tilt != 90.0 else None)
    summary = fabricate(
        mesh, args.output, sheet=args.sheet, gap=args.gap, machine=machine, tool=args.tool,
        nesting=args.nesting, nest_seconds=args.nest_time,
        decimals=args.decimals, length_tol=args.length_tol, angle_tol=args.angle_tol,
        dxf=False if args.no_dxf else None,
        hotwire=True if args.span != "auto" else None, span=args.span, up=args.up,
        kerf=args.kerf, kerf_side=args.kerf_side, feed=args.feed,
        require_planar=not args.allow_bent, progress=progress)
    for note in summary["notes"]:
        print(f"warning: {note}", file=sys.stderr)
    if not args.quiet:
        st = summary["panels"]
        sheets = summary["sheets"]
        print(f"wrote {len(summary['files'])} files to {args.output}: {st['count']} panels "
              f"({st['distinct_panels']} distinct) on {sheets['count']} sheets, "
              f"{100 * sheets['utilisation']:.1f} % used ({sheets['nesting']} nesting)"
              + ("" if summary["hotwire"] is None else
                 f", hot-wire path of {summary['hotwire']['steps']} generators"))
    return 0
