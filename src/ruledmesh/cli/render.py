"""``ruledmesh render MESH -o out.png``: a picture of a mesh, faces coloured by a measure."""

from __future__ import annotations

from pathlib import Path


def _pair(text: str, kind=float) -> tuple:
    import argparse

    parts = text.replace("x", ",").split(",") if kind is int else text.split(",")
    try:
        a, b = (kind(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected two numbers separated by "
                                         f"{'x' if kind is int else 'a comma'}, got \"{text}\"")
    return a, b


def add_parser(sub) -> None:
    p = sub.add_parser(
        "render",
        help="render a mesh to PNG/SVG/PDF (needs matplotlib)",
        description="Render a mesh file (or a design file, built first) with its faces coloured "
                    "by planarity, closeness to the design surface, or face kind, the generators "
                    "drawn as dark lines, and a colour bar. The format follows the extension of -o.",
        epilog="examples:\n  ruledmesh render skew.obj -o skew.png\n"
               "  ruledmesh render skew.obj --design examples/skew.toml --color closeness -o c.png\n"
               "  ruledmesh render examples/skew.toml --color kind --view 30,-45 -o k.png",
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
    p.add_argument("--title", help="title above the picture")
    p.add_argument("--no-generators", action="store_true", help="do not draw the generators")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..design import build_file
    from ..io import load
    from ..render import save_render

    path = Path(args.mesh)
    reference = None
    if path.suffix.lower() == ".toml":
        built = build_file(path)
        mesh, reference = built.mesh, built.reference
    else:
        mesh = load(path)
    if args.design:
        reference = build_file(args.design).reference
    save_render(args.output, mesh, color=args.color, reference=reference, view=args.view,
                size=args.size, title=args.title, generators=not args.no_generators)
    if not args.quiet:
        print(f"wrote {args.output}")
    return 0
