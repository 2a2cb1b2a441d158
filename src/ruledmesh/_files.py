"""Reading the user's input files: regular files only, with a size cap.

A path given as input may name anything the file system holds: ``/dev/zero``
(endless), a named pipe (blocks until a writer comes), a terminal, a socket.  Such
inputs are refused *before* they are opened, from what :func:`os.stat` says, and a
regular file is read with a cap, so neither an endless device nor a file that
grows while it is read can exhaust memory.
"""

from __future__ import annotations

import os
import stat

__all__ = ["MAX_CSV_BYTES", "MAX_DESIGN_BYTES", "MAX_MESH_BYTES", "FileRefused",
           "not_a_regular_file", "read_capped"]

# The size caps are work limits: they live with the others in ruledmesh.budget.
from .budget import MAX_CSV_BYTES, MAX_DESIGN_BYTES, MAX_MESH_BYTES

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a named pipe"),
          (stat.S_ISSOCK, "a socket"))


class FileRefused(OSError):
    """An input path is not a regular file, or is larger than the cap; ``strerror`` says which."""


def _size(n: float) -> str:
    for unit in ("bytes", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} GiB"  # pragma: no cover


def not_a_regular_file(path: str | os.PathLike) -> str | None:
    """What ``path`` is when it is not a regular file (``"a character device"``), else ``None``.

    Follows symbolic links; a path that does not exist gives ``None`` (the
    caller reports it as missing).
    """
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return None
    if stat.S_ISREG(mode):
        return None
    return next((name for test, name in _KINDS if test(mode)), "not a regular file")


def read_capped(path: str | os.PathLike, limit: int, what: str) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them.

    Parameters
    ----------
    path : path-like
    limit : int
        Largest size accepted, in bytes.
    what : str
        What the file should be, for the message (``"a design file"``).

    Returns
    -------
    bytes

    Raises
    ------
    FileRefused
        ``path`` is not a regular file (checked before it is opened), or holds
        more than ``limit`` bytes; ``strerror`` names what it is and the cap.
    OSError
        The file cannot be opened or read (missing, permission denied).
    """
    kind = not_a_regular_file(path)
    if kind is not None:
        raise FileRefused(0, f"this is {kind}, not {what}; give a regular file", os.fspath(path))
    too_big = f"larger than {_size(limit)}, too large for {what}"
    if os.stat(path).st_size > limit:
        raise FileRefused(0, f"{_size(os.stat(path).st_size)}: {too_big}", os.fspath(path))
    with open(path, "rb") as fh:
        data = fh.read(limit + 1)
    if len(data) > limit:  # it grew while being read
        raise FileRefused(0, too_big, os.fspath(path))
    return data
