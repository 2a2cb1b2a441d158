"""``ruledmesh blender-addon -o ruledmesh_blender.zip``: write the Blender add-on."""

from __future__ import annotations


def add_parser(sub) -> None:
    import argparse

    p = sub.add_parser(
        "blender-addon",
        help="write the Blender add-on (File > Import > ruledmesh design)",
        description="Write the add-on ruledmesh_blender as a zip for Blender's add-on installer "
                    "(Edit > Preferences > Add-ons > Install from Disk). It builds design files "
                    "with the ruledmesh installed in Blender's Python (install it there with "
                    "Blender's python -m pip install ruledmesh). See docs/blender.md.",
        epilog="example:\n  ruledmesh blender-addon -o ruledmesh_blender.zip",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("-o", "--output", default="ruledmesh_blender.zip",
                   help="zip file to write (default ruledmesh_blender.zip)")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..blender import write_addon

    print(f"wrote {write_addon(args.output)}")
    return 0
