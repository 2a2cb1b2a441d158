"""``ruledmesh render MESH -o out.png``: a picture of a mesh, faces coloured by a measure."""

from __future__ import annotations


def _pair(text: str, kind=float) -> tuple:
    import argparse

    parts = text.replace("x", ",").split(",") if kind is int else text.split(",")
    try:
        a, b = (kind(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected two numbers separated by "
                                         f"{'x' if kind is int else 'a comma'}, got \"{text}\"") from None
    return a, b


def add_parser(sub) -> None:
    p = sub.add_parser(
        "render",
        help="render a mesh to PNG/SVG/PDF (needs matplotlib)",
        description="Render a mesh file (or a design file, built first) with its faces coloured "
                    "by planarity, closeness to the design surface, or face kind, the generators "
                    "drawn as dark lines, and a colour bar. The format follows the extension of -o.",
        epilog="examples:\n"
               "  ruledmesh render skew.obj -o skew.png\n"
               "  ruledmesh render skew.obj --design examples/skew.toml --color closeness -o c.png\n"
               "  ruledmesh render examples/skew.toml --color kind --view 30,-45 -o k.png\n"
               "  ruledmesh render skew.obj -o big.png --size 3000x2400 --edges off --title Skew\n"
               "  ruledmesh render skew.obj -o labelled.png --labels on --size 2000x1600\n\n"
               "Large meshes: face outlines are dropped once faces get smaller than a few "
               "pixels, and only an evenly spaced subset of the generators is drawn "
               "(--edges auto, --generators auto); 'on' or 'off' forces either.",
    )
    p.add_argument("mesh", help="mesh file (.obj, .ply, ...) or design file (.toml)")
    p.add_argument("-o", "--output", required=True, help="image to write (.png, .svg, .pdf)")
    p.add_argument("--color", default="planarity", choices=["planarity", "closeness", "kind"],
                   help="what the face colours show (default: planarity)")
    p.add_argument("--design", help="design file the mesh was built from (for --color closeness)")
    p.add_argument("--view", type=_pair, default=(25.0, -60.0), metavar="ELEV,AZIM",
                   help="camera elevation and azimuth in degrees (default: 25,-60)")
    p.add_argument("--size", type=lambda s: _pair(s, int), default=(1000, 800), metavar="WxH",
                   help="image size in pixels (default: 1000x800)")
    p.add_argument("--title", help="title, drawn at the top of the image")
    p.add_argument("--edges", choices=["on", "off", "auto"], default="auto",
                   help="outline the faces (default auto: only while faces are large enough)")
    p.add_argument("--generators", choices=["on", "off", "auto"], default="auto",
                   help="draw the generators (default auto: thinned out on dense meshes)")
    p.add_argument("--labels", choices=["on", "off", "auto"], default="off",
                   help="write each panel's label (P0, P1, ... as on the fabrication sheets and in "
                        "panels.csv) at its centroid, where the camera sees it (default off; auto: "
                        "only while faces are large enough to read them)")
    p.add_argument("--no-generators", dest="generators", action="store_const", const="off",
                   help="same as --generators off")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..render import FORMATS, save_render
    from ._common import check_output_file, progress_for, read_design, read_source

    check_output_file(args.output, FORMATS,
                      optional=dict.fromkeys(FORMATS, ("matplotlib", "plot")))
    progress = progress_for(args)
    source = read_source(args.mesh, progress)
    reference = source.built.reference if source.built is not None else None
    if args.design:
        reference = read_design(args.design, progress, option="--design")[1].reference
    with progress.task(f"render {args.output}"):
        save_render(args.output, source.mesh, color=args.color, reference=reference,
                    view=args.view, size=args.size, title=args.title, edges=args.edges,
                    generators=args.generators, labels=args.labels)
    if not args.quiet:
        print(f"wrote {args.output}")
    return 0
