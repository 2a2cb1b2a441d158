"""``ruledmesh schema [-o FILE]``: the JSON Schema of design files, for editors and validators."""

from __future__ import annotations


def add_parser(sub) -> None:
    import argparse

    p = sub.add_parser(
        "schema",
        help="print the JSON Schema of design files (for editor completion and checks)",
        description="Print the JSON Schema (draft 2020-12) of ruledmesh design files, read off "
                    "the design file reader itself: every table, every key a surface kind, mesh "
                    "method or transform allows, value types, bounds and choices. Point a TOML "
                    "editor extension (Taplo, Even Better TOML) at the file to get completion "
                    "and checks while writing a design.",
        epilog="examples:\n  ruledmesh schema -o ruledmesh-design.schema.json\n"
               "  ruledmesh schema",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("-o", "--output", metavar="FILE", help="write the schema to FILE (atomically)")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..design.schema import main

    code = main([args.output] if args.output else [])
    if args.output:
        print(f"wrote {args.output}")
    return code
