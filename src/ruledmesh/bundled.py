"""The example designs that ship inside the package (``ruledmesh examples``).

The design files live in the package folder ``ruledmesh/examples`` (the
repository's ``examples/`` folder is the same folder), so they are there in
every install, wheel or source.  A relative path ``examples/NAME.toml`` that
does not exist in the working folder falls back to the bundled file of that
name (:func:`resolve`): the examples in ``--help`` texts and docs then work
from any folder.
"""

from __future__ import annotations

import os
import re
import shutil
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ._validation import near_miss
from .errors import ParameterError

__all__ = ["companions", "copy", "description", "folder", "names", "path", "resolve", "text"]

_MAX_DESCRIPTION = 100


def folder() -> Path:
    """The folder of the bundled example designs."""
    return Path(__file__).resolve().parent / "examples"


def names() -> list[str]:
    """Names of the bundled examples (file names without ``.toml``), sorted."""
    return sorted(p.stem for p in folder().glob("*.toml"))


def path(name: str) -> Path:
    """The file of the bundled example ``name`` (with or without ``.toml``).

    Raises
    ------
    ParameterError
        For a name that is not a bundled example (with the nearest names).
    """
    stem = name[:-5] if name.lower().endswith(".toml") else name
    known = names()
    if stem not in known:
        raise ParameterError(f'no bundled example "{name}"{near_miss(stem, known)}; '
                             "ruledmesh examples lists them", "name")
    return folder() / f"{stem}.toml"


def text(name: str) -> str:
    """The TOML text of the bundled example ``name``."""
    return path(name).read_text(encoding="utf-8")


def description(name: str) -> str:
    """One line saying what the example shows.

    The ``description`` or ``name`` field of the design if it has one,
    otherwise the first sentence of its leading comment block.
    """
    source = text(name)
    data = tomllib.loads(source)
    for key in ("description", "name"):
        if isinstance(data.get(key), str) and data[key].strip():
            return _shorten(data[key])
    comment = []
    for line in source.splitlines():
        if not line.startswith("#"):
            break
        comment.append(line.lstrip("#").strip())
    joined = " ".join(part for part in comment if part)
    sentence = re.split(r"(?<=[.!?:])\s", joined, maxsplit=1)[0]
    return _shorten(sentence)


def _shorten(line: str) -> str:
    line = " ".join(line.split())
    if len(line) <= _MAX_DESCRIPTION:
        return line
    return line[:_MAX_DESCRIPTION - 3].rsplit(" ", 1)[0] + "..."


def _strings(value: Any) -> Iterator[str]:
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for item in value.values():
            yield from _strings(item)
    elif isinstance(value, list):
        for item in value:
            yield from _strings(item)


def companions(name: str) -> list[Path]:
    """Files the example reads beside itself (e.g. the CSV of a ``file = ...`` field)."""
    data = tomllib.loads(text(name))
    base = folder()
    found = {base / s for s in _strings(data)
             if "/" not in s and "\\" not in s and s not in (".", "..") and (base / s).is_file()}
    return sorted(found)


def copy(name: str, target: str | os.PathLike) -> list[Path]:
    """Copy the example ``name`` and its companion files into the folder ``target``.

    The folder is created if missing.  Existing files of the same names are
    replaced.

    Returns
    -------
    list of Path
        The written files, the design first.
    """
    target = Path(target)
    target.mkdir(parents=True, exist_ok=True)
    written = []
    for source in [path(name), *companions(name)]:
        destination = target / source.name
        shutil.copyfile(source, destination)
        written.append(destination)
    return written


def resolve(design_path: str | os.PathLike) -> Path:
    """``design_path``, or the bundled example it names where it does not exist.

    Only a relative path of the form ``examples/NAME.toml`` falls back, and
    only when no such file exists relative to the working folder.
    """
    p = Path(design_path)
    if p.exists() or p.is_absolute() or len(p.parts) != 2 or p.parts[0] != "examples":
        return p
    candidate = folder() / p.name
    return candidate if candidate.suffix == ".toml" and candidate.is_file() else p
