"""What the subcommands share: reading the user's files, checking outputs first, progress.

Every message names the path exactly as the user typed it and says what to do.
Input files are recognised by their content, so a mesh given where a design is
expected (or a CSV of lines, an image, a DXF) is named for what it is instead
of failing deep inside a parser.  Outputs are checked before any work: the
folder exists and can be written, the extension is one ruledmesh writes, the
optional library of that format is installed.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import RuledMeshError
from ..progress import SILENT, Progress, TerminalProgress

__all__ = ["HelpFormatter", "InputError", "Source", "check_design_file", "check_output_file",
           "check_output_folder",
           "file_kind", "progress_for", "read_design", "read_source"]


class InputError(RuledMeshError, ValueError):
    """A file on the command line cannot be used as given; the message says why and what to do."""


class HelpFormatter(argparse.HelpFormatter):
    """Wraps prose paragraphs; keeps indented lines (examples) one per line, as written."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        out = []
        for block in re.split(r"\n\s*\n", text.strip("\n")):
            # "example: ruledmesh ..." on one line reads like the others: heading, then command.
            block = re.sub(r"^(examples?):\s+(ruledmesh\s)", r"\1:\n  \2", block)
            lines = block.splitlines()
            if any(line.startswith("  ") for line in lines):
                out.append("\n".join(indent + line for line in lines))
            else:
                out.append(super()._fill_text(" ".join(lines), width, indent))
        return "\n\n".join(out)


def progress_for(args: argparse.Namespace) -> Progress:
    """Bars on stderr when it is a terminal, unless ``-q`` or ``--json`` was given."""
    quiet = getattr(args, "quiet", False) or getattr(args, "json", False)
    # Kept on ``args`` so that main() closes bars an error leaves open before it reports.
    args.progress = TerminalProgress(enabled=not quiet)
    return args.progress


# ---------------------------------------------------------------- recognising files
# Formats by what their first bytes say: (name, test).  Order matters: specific first.
def _starts(*prefixes: bytes):
    return lambda head: any(head.startswith(p) for p in prefixes)


_BINARY_KINDS = [
    ("a glTF binary (.glb) mesh", _starts(b"glTF")),
    ("a PNG image", _starts(b"\x89PNG")),
    ("a PDF document", _starts(b"%PDF")),
    ("a Rhino 3DM model", _starts(b"3D Geometry File Format")),
    ("an IFC model", _starts(b"ISO-10303-21")),
    ("a PLY mesh", _starts(b"ply\n", b"ply\r\n")),
    ("a ZIP archive", _starts(b"PK\x03\x04")),
]

MESH_KINDS = {"an OBJ mesh": ".obj", "a PLY mesh": ".ply", "a ruledmesh JSON mesh": ".json"}


def _text_kind(text: str) -> str | None:
    """The kind of a text file by its first meaningful lines."""
    lines = [ln.strip() for ln in text.splitlines()[:200]]
    body = [ln for ln in lines if ln and not ln.startswith("#")]
    if not body:
        return "an empty file" if not text.strip() else "a file of comments only"
    first = body[0]
    if first.startswith("{"):
        return ("a ruledmesh JSON mesh" if '"ruledmesh.mesh"' in text[:4000]
                else "a JSON file that is not a ruledmesh mesh")
    if first.startswith("<?xml") or first.startswith("<svg"):
        return "an SVG image" if "<svg" in text[:4000] else "an XML file"
    if first.lower().startswith("solid"):
        return "an STL mesh"
    if first == "0" and len(body) > 1 and body[1] in ("SECTION", "HEADER"):
        return "a DXF drawing"
    if re.match(r"^(v|vn|vt|f|o|g|mtllib|usemtl|s)\s", first) and any(
            re.match(r"^v\s", ln) for ln in body[:50]):
        return "an OBJ mesh"
    if re.match(r"^\[\[?[A-Za-z_\"]", first) or re.match(r"^[A-Za-z_][\w.-]*\s*=", first):
        return "a TOML file"
    if re.match(r"^[-+\w.\"]+(\s*[,;\t]\s*[-+\w.\"]+)+$", first):
        return "a CSV table"
    return None


def file_kind(path: Path) -> str | None:
    """What the file at ``path`` is, in words (``"an OBJ mesh"``), or ``None`` if unknown.

    Reads the first 64 kB only.
    """
    with open(path, "rb") as fh:
        head = fh.read(65536)
    for name, test in _BINARY_KINDS:
        if test(head):
            return name
    if len(head) >= 84 and b"\0" in head[:84] and head[:5].lower() != b"solid":
        return "a binary STL mesh" if path.suffix.lower() == ".stl" else None
    try:
        text = head.decode("utf-8")
    except UnicodeDecodeError:
        try:
            text = head[:-4].decode("utf-8")            # a character cut at 64 kB
        except UnicodeDecodeError:
            return None
    return _text_kind(text)


def _existing(typed: str, what: str) -> Path:
    """``typed`` as a readable file, or an error naming it as typed and what to do.

    A relative ``examples/NAME.toml`` that does not exist here is the bundled example of
    that name, as for :func:`ruledmesh.design.load_design`.
    """
    from ..bundled import resolve

    path = Path(resolve(typed))
    if path.is_dir():
        raise InputError(f"{typed}: is a folder, not {what}; give the file inside it")
    if not path.exists():
        hint = ""
        parent = path.parent if str(path.parent) else Path(".")
        if parent.is_dir():
            import difflib

            names = [p.name for p in parent.iterdir() if p.is_file()]
            near = difflib.get_close_matches(path.name, names, n=3, cutoff=0.6)
            if near:
                where = "" if str(parent) == "." else f" in {parent}"
                hint = f" (did you mean {' or '.join(near)}{where}?)"
        raise InputError(f"{typed}: file not found; check the path{hint}")
    from .._files import not_a_regular_file

    special = not_a_regular_file(path)
    if special is not None:  # /dev/zero, a pipe, a terminal: never opened
        raise InputError(f"{typed}: this is {special}, not {what}; give a regular file")
    if not os.access(path, os.R_OK):
        raise InputError(f"{typed}: cannot be read (permission denied)")
    return path


# Contents that say nothing against being a design file (the design parser judges them).
_NOT_A_MESH = (None, "an empty file", "a file of comments only")


@dataclass(frozen=True)
class Source:
    """What a mesh-or-design argument turned out to be."""

    mesh: Any
    built: Any = None          # the Built of a design, else None
    design: Any = None         # the parsed Design, else None


def read_design(typed: str, progress: Progress | None = None, *, option: str = "") -> Any:
    """Build the design file ``typed``; a file of another kind is named, with what to do.

    Returns ``(Design, Built)``.
    """
    from dataclasses import replace

    from ..design import build_design, load_design
    from ..errors import DesignError

    path = check_design_file(typed, option=option)
    try:
        design = load_design(path)
    except DesignError as exc:  # syntax errors carry the bare file name: give the typed path
        raise exc.with_source(typed) from None
    # Messages about fields name the file as typed too ("examples/skew.toml: rulings.count: ...").
    return design, build_design(replace(design, source=typed), progress)


def check_design_file(typed: str, *, option: str = "") -> Path:
    """``typed`` as an existing design file; a file of another kind is named, with what to do."""
    what = f"a design file{' for ' + option if option else ''}"
    path = _existing(typed, what)
    kind = file_kind(path)
    # An empty design is still a design: the design parser says which table it lacks.
    if kind != "a TOML file" and kind not in _NOT_A_MESH:
        use = (f"use `ruledmesh analyze {typed}` to measure it, or pass a design file (.toml)"
               if kind in MESH_KINDS else "pass a design file (.toml)")
        if kind == "a CSV table":
            use = ("a table of generator lines is read by a design's [rulings] table "
                   "(file = \"...\"); pass that design file (.toml)")
        raise InputError(f"{typed}: this is {kind}, not {what}; {use}")
    return path


def read_source(typed: str, progress: Progress | None = None) -> Source:
    """A mesh file, or a design file (built): recognised by content, errors naming ``typed``."""
    from ..io import READERS

    path = _existing(typed, "a mesh or design file")
    kind = file_kind(path)
    if kind == "a TOML file" or (path.suffix.lower() == ".toml" and kind in _NOT_A_MESH):
        design, built = read_design(typed, progress)
        return Source(built.mesh, built, design)
    ext = MESH_KINDS.get(kind or "", path.suffix.lower() if kind is None else None)
    if ext not in READERS:
        readable = ", ".join(sorted(READERS))
        raise InputError(f"{typed}: this is {kind or 'a file of unknown kind'}; ruledmesh reads "
                         f"meshes ({readable}) and design files (.toml)")
    from .._files import MAX_MESH_BYTES, FileRefused, read_capped
    from ..errors import ParameterError
    from ..io import format_module

    with (progress or SILENT).task(f"read {typed}"):
        try:
            # Content decides the reader: an OBJ saved as .txt is still read as OBJ.
            data = read_capped(path, MAX_MESH_BYTES, "a mesh file")
            mesh = format_module(ext, READERS, "read").loadb(data)
        except FileRefused as exc:
            raise InputError(f"{typed}: {exc.strerror}") from None
        except ParameterError as exc:
            raise InputError(f"{typed}: cannot be read as a {ext} mesh: {exc.detail}") from None
    if mesh.n_faces == 0:
        raise InputError(f"{typed}: the mesh has no faces ({mesh.n_vertices} vertices); "
                         "nothing to work on, give a mesh with faces")
    return Source(mesh)


# ------------------------------------------------------------------- outputs
# Writers that need an optional library: extension -> (module, extra).
OPTIONAL_WRITERS = {".dxf": ("ezdxf", "dxf"), ".3dm": ("rhino3dm", "rhino"),
                    ".ifc": ("ifcopenshell", "ifc")}


def _writable_folder(folder: Path, typed: str) -> None:
    """Refuse a folder that does not exist or cannot be written into (tried, not guessed)."""
    shown = str(folder) if str(folder) not in ("", ".") else "the current folder"
    if not folder.exists():
        raise InputError(f"{typed}: folder {shown} does not exist; create it first or choose "
                         "another output path")
    if not folder.is_dir():
        raise InputError(f"{typed}: {shown} is a file, not a folder; choose another output path")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise InputError(f"{typed}: cannot write into {shown} ({exc.strerror or exc}); "
                         "choose another output folder") from None


def check_output_file(typed: str, formats: dict[str, Any] | list[str], *,
                      optional: dict[str, tuple[str, str]] | None = None) -> Path:
    """Check an output file before any work: known extension, library present, folder writable.

    Parameters
    ----------
    typed : str
        The path as the user typed it.
    formats : container of str
        Extensions the command writes (``".obj"``, ...).
    optional : mapping, optional
        Extension -> (module, extra) of formats that need an optional library.

    Returns
    -------
    Path
    """
    path = Path(typed)
    known = ", ".join(sorted(formats))
    if path.is_dir() or typed.endswith(("/", os.sep)):
        example = ".obj" if ".obj" in formats else sorted(formats)[0]
        raise InputError(f"{typed}: is a folder; give a file name with one of the extensions "
                         f"{known} (e.g. {Path(typed) / ('mesh' + example)})")
    ext = path.suffix.lower()
    if ext not in formats:
        got = f'cannot write "{path.suffix}" files' if path.suffix else "has no extension"
        raise InputError(f"{typed}: {got}; the extension picks the format, one of {known}")
    need = (optional if optional is not None else OPTIONAL_WRITERS).get(ext)
    if need and importlib.util.find_spec(need[0]) is None:
        raise InputError(f"{typed}: writing {ext} files needs {need[0]}: "
                         f"pip install 'ruledmesh[{need[1]}]'")
    _writable_folder(path.parent, typed)
    return path


def check_output_folder(typed: str) -> Path:
    """Check an output folder before any work: a folder (or creatable) and writable."""
    path = Path(typed)
    if path.exists():
        if not path.is_dir():
            raise InputError(f"{typed}: is a file, not a folder; give a folder to write into")
        _writable_folder(path, typed)
        return path
    parent = path.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise InputError(f"{typed}: {parent} is a file, not a folder; choose another output folder")
    _writable_folder(parent, typed)
    return path
