"""The ``ruledmesh`` command line: one module per subcommand.

Each subcommand module defines ``add_parser(subparsers)``, which registers its
parser and sets ``run=function(args) -> int``.  :func:`main` turns every
:class:`~ruledmesh.errors.RuledMeshError` (and unreadable files) into one line
on stderr and exit code 2, never a traceback; ``--debug`` shows tracebacks.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from ..errors import RuledMeshError

__all__ = ["main", "COMMANDS"]

# Subcommand modules (relative to ruledmesh.cli), in the order --help lists them.
COMMANDS = ["build", "analyze", "export", "render", "fabricate", "compare", "design", "structure",
            "examples", "schema", "hops", "blender"]

EPILOG = """examples:
  ruledmesh build examples/skew.toml -o skew.obj     build a PQ mesh from a design file
  ruledmesh analyze skew.obj                         planarity, convexity, areas (table)
  ruledmesh analyze examples/skew.toml --json        full analysis incl. closeness, coverage
  ruledmesh <command> --help                         options of one command
"""


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The top-level parser with every available subcommand, or with ``only`` that one.

    A command line naming its subcommand needs no other: their modules (and what
    they import) stay unloaded, which a small build's start-up notices.
    """
    from .. import __version__

    parser = argparse.ArgumentParser(
        prog="ruledmesh",
        description="Planar quad meshes of ruled surfaces, by construction.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"ruledmesh {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS if only is None else [only]:
        try:
            module = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
            continue
        module.add_parser(sub)
    from ._common import HelpFormatter

    # One formatter for every subcommand: prose wrapped, examples one per line.
    for child in sub.choices.values():
        child.formatter_class = HelpFormatter
    return parser


def _published_name(filename) -> str:
    """The file the user asked for, not the hidden ``.NAME.*.part`` temporary it is written as."""
    import re
    from pathlib import Path

    path = Path(str(filename))
    # ruledmesh.io.write_atomic's two temporary names: .NAME.PID.FD.HEX8.part, .NAME.XXXXXXXX.part
    m = (re.fullmatch(r"\.(.+)\.\d+\.\d+\.[0-9a-f]{8}\.part", path.name)
         or re.fullmatch(r"\.(.+)\.[A-Za-z0-9_]{8}\.part", path.name))
    if not m:
        return str(filename)
    return str(path.with_name(m.group(1)))


def _run(args: argparse.Namespace) -> int:
    """The subcommand; progress bars it leaves open are closed before any message."""
    try:
        return int(args.run(args) or 0)
    finally:
        progress = getattr(args, "progress", None)
        if progress is not None:
            progress.close()


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code.

    Exit codes: 0 success, 2 bad input (design file, parameters, files),
    3 an internal error (a bug: please report it with ``--debug`` output),
    130 interrupted, 141 the reader of stdout went away (``| head``).
    """
    words = list(sys.argv[1:] if argv is None else argv)
    # The top-level options take no value: the first word that is not one is the subcommand.
    first = next((w for w in words if not w.startswith("-")), None)
    parser = build_parser(first if first in COMMANDS else None)
    args = parser.parse_args(words)
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    try:
        return _run(args)
    except BrokenPipeError:
        return _broken_pipe()
    except RuledMeshError as exc:
        if args.debug:
            raise
        _say(f"ruledmesh: error: {exc}")
        return 2
    except RecursionError:  # a design nested too deep for any reader; never a traceback
        if args.debug:
            raise
        _say("ruledmesh: error: the input is nested too deeply to be read")
        return 2
    except OSError as exc:
        if args.debug:
            raise
        where = f"{_published_name(exc.filename)}: " if exc.filename else ""
        _say(f"ruledmesh: error: {where}{exc.strerror or exc}")
        return 2
    except KeyboardInterrupt:
        print("ruledmesh: interrupted", file=sys.stderr)
        return 130
    except MemoryError:
        if args.debug:
            raise
        print("ruledmesh: error: out of memory; reduce the counts in the design", file=sys.stderr)
        return 2
    except Exception as exc:  # a bug: one line, not a traceback, unless --debug
        if args.debug:
            raise
        _say(f"ruledmesh: internal error: {type(exc).__name__}: {exc} "
             "(run with --debug and report it)")
        return 3


def _say(message: str) -> None:
    """One line on stderr: control characters escaped, bounded (see :func:`printable`)."""
    from ..errors import MAX_MESSAGE, printable

    print(printable(message, MAX_MESSAGE), file=sys.stderr)


def _broken_pipe() -> int:
    """The reader of stdout went away (``ruledmesh examples | head``): end quietly.

    Later writes (the interpreter flushes stdout at exit) go to the null device, so
    Python prints no "Exception ignored" either.  Exit code 141 is what a shell reports
    for a process ended by SIGPIPE.
    """
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # stdout replaced by an object without a descriptor
        pass
    return 141


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
