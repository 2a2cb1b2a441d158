"""``ruledmesh export MESH -o FILE``: convert a mesh (or a design) to another format."""

from __future__ import annotations

import inspect


def add_parser(sub) -> None:
    p = sub.add_parser(
        "export",
        help="write a mesh in another format (STL, glTF, DXF, 3DM, IFC, JSON, ...)",
        description="Read a mesh file (or build a .toml design) and write it; the format "
                    "follows the extension of -o: .obj .ply .stl .glb .dxf .3dm .ifc .json. "
                    "STL and glTF are triangulated without splinters (quads along the "
                    "shorter diagonal); the others keep quads and polygons.",
        epilog="examples:\n"
               "  ruledmesh export skew.obj -o skew.glb\n"
               "  ruledmesh export examples/skew.toml -o skew.json\n"
               "  ruledmesh export skew.obj -o skew.stl --quads best\n"
               "  ruledmesh export skew.obj -o skew.ifc --units mm\n"
               "  ruledmesh export skew.obj -o skew.stl --origin auto\n\n"
               "A .json export of a design file holds the mesh and the design tables.",
    )
    p.add_argument("mesh", help="mesh file (.obj, .ply, .json) or design file (.toml)")
    p.add_argument("-o", "--output", required=True, help="file to write; its extension picks the format")
    p.add_argument("--shading", choices=["flat", "smooth"], default="flat",
                   help="glTF normals: face normals (flat) or averaged vertex normals")
    p.add_argument("--quads", choices=["shorter", "best"], default="shorter",
                   help="how STL/glTF/3DM split quads: shorter diagonal, or larger smallest angle")
    p.add_argument("--units", choices=["m", "cm", "mm", "in", "ft"],
                   help="convert to this unit (coordinates scaled; written into every format "
                        "that has a unit; glTF is always metres)")
    p.add_argument("--input-units", choices=["m", "cm", "mm", "in", "ft"],
                   help="unit of the input when its file does not state one (default m)")
    p.add_argument("--origin", metavar="X,Y,Z|auto",
                   help="STL: subtract this point before float32 rounding (auto: the lower "
                        "corner in whole units); recorded in the header")
    p.add_argument("--panels", choices=["each", "joined"], default="each",
                   help="IFC/3DM: one object per panel (default) or one per face kind")
    p.add_argument("--extras", choices=["file", "inline", "omit"], default="file",
                   help="PLY: face kinds and generators in NAME.ruledmesh.ply (default; every "
                        "reader takes NAME.ply), inline in one file (not meshio), or omitted")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="print nothing on success (no progress, no summary)")
    p.set_defaults(run=run)


def _origin(text: str | None):
    from ..errors import ParameterError

    if text is None or text == "auto":
        return text
    try:
        point = [float(x) for x in text.split(",")]
    except ValueError:
        point = []
    if len(point) != 3:
        raise ParameterError(f'expected X,Y,Z or "auto", got "{text}"', "--origin")
    return point


def run(args) -> int:
    import sys
    import warnings

    from ..analysis.report import kind_counts
    from ..errors import RuledMeshWarning
    from ..io import WRITERS, format_module, save
    from ._common import check_output_file, progress_for, read_source

    output = check_output_file(args.output, WRITERS)
    progress = progress_for(args)
    source = read_source(args.mesh, progress)
    mesh = source.mesh
    design = source.design.data if source.design is not None else None
    if args.input_units:
        mesh = mesh.with_units(args.input_units, convert=False)
    if args.units:
        mesh = mesh.with_units(args.units)
    module = format_module(output.suffix.lower(), WRITERS, "write")
    accepted = inspect.signature(module.dumpb).parameters
    options = {"shading": args.shading, "quads": args.quads, "design": design,
               "origin": _origin(args.origin), "panels": args.panels, "extras": args.extras}
    options = {k: v for k, v in options.items() if k in accepted and v is not None}
    with progress.task(f"write {args.output}"), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuledMeshWarning)
        save(output, mesh, **options)
    for w in caught:
        print(f"warning: {w.message}", file=sys.stderr)
    if not args.quiet:
        print(f"wrote {args.output}: {mesh.n_faces} faces ({kind_counts(mesh.count_kinds())}), "
              f"{mesh.n_vertices} vertices, {len(mesh.members)} members, units {mesh.units}")
    return 0
