"""``ruledmesh structure DESIGN|MESH --offset D -o DIR``: node axes, offset layer, beams."""

from __future__ import annotations

import sys
from pathlib import Path


def _list(choices: tuple[str, ...]):
    import argparse

    def parse(text: str) -> list[str]:
        items = [t.strip() for t in text.split(",") if t.strip()]
        if items == ["none"]:
            return []
        bad = [t for t in items if t not in choices]
        if bad:
            raise argparse.ArgumentTypeError(f"expected a comma-separated list of "
                                             f"{', '.join(choices)} (or none), got \"{bad[0]}\"")
        return items

    return parse


def _setback(text: str):
    import argparse

    if text == "auto":
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'expected a number or "auto", got "{text}"') from None


def add_parser(sub) -> None:
    p = sub.add_parser(
        "structure",
        help="node axes, an offset layer and beams behind a mesh (torsion-free where possible)",
        description="Give every vertex a node axis so that the axes at the ends of every edge "
                    "are coplanar with it (a torsion-free support structure), move the vertices "
                    "along their axes to an offset layer at distance D, and build beams with "
                    "planar sides through the axes. Exact for circular meshes and wherever the "
                    "space of parallel meshes holds a near-normal offset; otherwise the normal "
                    "axes are used and the torsion of every edge is reported. See "
                    "docs/structure.md.",
        epilog="examples:\n"
               "  ruledmesh structure examples/fig7b-hyperboloid-circular.toml --offset 0.2 -o hyp\n"
               "  ruledmesh structure skew.obj --offset 0.5 --beams edges,generators "
               "--width 0.05 -o skew-frame\n"
               "  ruledmesh structure skew.obj --offset -0.3 --thickness 0.02 --render -o out",
    )
    p.add_argument("mesh", help="design file (.toml) or mesh file (.obj, .ply, .json)")
    p.add_argument("--offset", type=float, required=True, metavar="D",
                   help="distance of the offset layer along the normals (negative: other side)")
    p.add_argument("-o", "--output", required=True, help="folder to write into (created if missing)")
    p.add_argument("--axes", default="auto", choices=["auto", "circular", "parallel", "normal"],
                   help="how to choose the node axes (default auto: circular, else the closest "
                        "parallel mesh if near-normal, else the normals)")
    p.add_argument("--max-deviation", type=float, default=15.0, metavar="DEG",
                   help="auto: largest angle between exact (circular or parallel) axes and the "
                        "normals (default 15)")
    p.add_argument("--beams", type=_list(("edges", "generators")), default=["edges"],
                   metavar="LIST", help="beams to build: edges, generators, both "
                                        "(edges,generators) or none (default edges)")
    p.add_argument("--width", type=float, help="beam width (default: 1/10 of the median edge)")
    p.add_argument("--depth", type=float, help="beam depth along the axes (default: to the offset)")
    p.add_argument("--setback", type=_setback, default="auto",
                   help='beam ends set back from the node axes: a distance or "auto" '
                        "(clear of the neighbouring beams; the default)")
    p.add_argument("--thickness", type=float, help="also write the panels as solids this thick")
    p.add_argument("--panel-side", default="outer", choices=["outer", "inner"],
                   help="panels away from the offset layer (outer, default) or towards it")
    p.add_argument("--formats", type=_list(("obj", "3dm", "ifc")), metavar="LIST",
                   help="solid formats (default: obj, plus 3dm and ifc when installed)")
    p.add_argument("--scale", type=float, default=1.0, help="multiply coordinates first")
    p.add_argument("--unit", default="", choices=["", "mm", "cm", "m", "in", "ft"],
                   help="name of the (scaled) mesh unit, recorded in structure.json")
    p.add_argument("--render", action="store_true", help="also write structure.png (matplotlib)")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    p.set_defaults(run=run)


def _check(args) -> None:
    import math

    from ..errors import ParameterError

    for name in ("offset", "max_deviation", "width", "depth", "thickness", "scale"):
        value = getattr(args, name)
        if value is not None and not math.isfinite(value):
            raise ParameterError(f"expected a finite number, got {value}", f"--{name.replace('_', '-')}")
    positive = ("width", "depth", "thickness", "scale")
    for name in positive:
        value = getattr(args, name)
        if value is not None and value <= 0:
            raise ParameterError(f"expected a number > 0, got {value:g}", f"--{name}")
    if isinstance(args.setback, float) and not (math.isfinite(args.setback) and args.setback >= 0):
        raise ParameterError(f"expected a number >= 0 or auto, got {args.setback:g}", "--setback")


def _progress(quiet: bool):
    """A progress line per file on a terminal; nothing in pipes and logs."""
    if quiet or not sys.stderr.isatty():
        return None
    return lambda name: print(f"making {name} ...", file=sys.stderr, flush=True)


# Library parameter -> the command-line option that sets it.
_OPTION_OF = {"distance": "--offset", "method": "--axes", "max_deviation": "--max-deviation"}


def run(args) -> int:
    from ..design import build_file
    from ..errors import ParameterError
    from ..io import load
    from ..structure import support_structure
    from ..structure.output import write_structure

    _check(args)
    path = Path(args.mesh)
    mesh = build_file(path).mesh if path.suffix.lower() == ".toml" else load(path)
    if args.scale != 1.0:
        mesh = mesh.with_vertices(mesh.vertices * args.scale)
    try:
        structure = support_structure(mesh, args.offset, method=args.axes,
                                      max_deviation=args.max_deviation)
    except ParameterError as exc:
        # The library names its parameters; on the command line they are options.
        option = _OPTION_OF.get(exc.field or "", exc.field)
        raise ParameterError(exc.detail, option) from None
    options = {k: getattr(args, k) for k in ("offset", "axes", "max_deviation", "beams", "width",
                                             "depth", "setback", "thickness", "panel_side",
                                             "formats", "scale")}
    options["source"] = str(path)
    summary = write_structure(structure, args.output, beams=args.beams, width=args.width,
                              depth=args.depth, setback=args.setback, thickness=args.thickness,
                              panel_side=args.panel_side, formats=args.formats, unit=args.unit,
                              render=args.render, options=options,
                              progress=_progress(args.quiet))
    for note in summary["notes"]:
        print(f"warning: {note}", file=sys.stderr)
    if not args.quiet:
        dev = summary["axis_deviation_deg"]
        print(f"wrote {len(summary['files'])} files to {args.output}: {summary['method']} axes, "
              f"{'exact (torsion-free)' if summary['exact'] else 'NOT torsion-free'}, "
              f"largest torsion {summary['torsion_max_deg']:.3g} deg, axes within "
              f"{dev['max']:.3g} deg of the normals (median {dev['median']:.3g})")
    return 0
