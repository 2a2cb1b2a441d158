"""``ruledmesh export MESH -o FILE``: convert a mesh (or a design) to another format."""

from __future__ import annotations

import inspect
from pathlib import Path


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
               "  ruledmesh export examples/skew.toml -o skew.json   (mesh + design tables)",
    )
    p.add_argument("mesh", help="mesh file (.obj, .ply, .json) or design file (.toml)")
    p.add_argument("-o", "--output", required=True, help="file to write; its extension picks the format")
    p.add_argument("--shading", choices=["flat", "smooth"], default="flat",
                   help="glTF normals: face normals (flat) or averaged vertex normals")
    p.add_argument("--quads", choices=["shorter", "best"], default="shorter",
                   help="how STL/glTF/3DM split quads: shorter diagonal, or larger smallest angle")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..io import WRITERS, _module, load, save

    source = Path(args.mesh)
    output = Path(args.output)
    design = None
    if source.suffix.lower() == ".toml":
        from ..design import build_design, load_design

        parsed = load_design(source)
        mesh = build_design(parsed).mesh
        design = parsed.data
    else:
        mesh = load(source)
    module = _module(output.suffix.lower(), WRITERS, "write")
    accepted = inspect.signature(module.dumpb).parameters
    options = {"shading": args.shading, "quads": args.quads, "design": design}
    options = {k: v for k, v in options.items() if k in accepted and v is not None}
    save(output, mesh, **options)
    if not args.quiet:
        print(f"wrote {output}: {mesh.n_faces} faces, {mesh.n_vertices} vertices, "
              f"{len(mesh.members)} members")
    return 0
