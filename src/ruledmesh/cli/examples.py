"""``ruledmesh examples [NAME] [-o DIR]``: the example designs bundled with the package."""

from __future__ import annotations

import sys


def add_parser(sub) -> None:
    import argparse

    p = sub.add_parser(
        "examples",
        help="list, print or copy the bundled example designs",
        description="Without NAME, list the example designs that ship with ruledmesh, one line "
                    "each. With NAME, print that design file, or with -o copy it (and any file "
                    "it reads, e.g. a CSV of lines) into a folder. A path examples/NAME.toml "
                    "given to any command finds the bundled file when there is no such file in "
                    "the working folder.",
        epilog="examples:\n  ruledmesh examples\n  ruledmesh examples skew\n"
               "  ruledmesh examples lines-file -o my-designs\n"
               "  ruledmesh build examples/skew.toml -o skew.obj",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("name", nargs="?", help="example to print or copy (see the list)")
    p.add_argument("-o", "--output", metavar="DIR", help="copy the example into this folder")
    p.set_defaults(run=run)


def run(args) -> int:
    from .. import bundled
    from ..errors import ParameterError

    if args.name is None:
        if args.output:
            raise ParameterError("give the NAME of the example to copy", "name")
        known = bundled.names()
        width = max(len(n) for n in known)
        for name in known:
            print(f"{name:<{width}}  {bundled.description(name)}")
        return 0
    if args.output:
        for written in bundled.copy(args.name, args.output):
            print(f"wrote {written}")
        return 0
    sys.stdout.write(bundled.text(args.name))
    return 0
