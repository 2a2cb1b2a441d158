"""Mesh files: one module per format behind one registry.

Each format module provides pure serialisers, ``dumpb(mesh, **options) ->
bytes`` (and ``loadb(data) -> Mesh`` where ruledmesh reads the format back).
:func:`save` picks the format by file extension, refuses a mesh with NaN or
infinite coordinates, and writes atomically: the bytes go to a temporary file
in the target folder which is renamed over the target only when complete, so
an interrupted export never leaves a truncated file.
"""

from __future__ import annotations

import importlib
import os
import tempfile
from pathlib import Path

import numpy as np

from ..errors import ExportError, ParameterError
from ..mesh import Mesh

__all__ = ["READERS", "WRITERS", "formats", "load", "require", "save", "write_atomic"]

# extension -> module (relative to ruledmesh.io) providing dumpb / loadb.
WRITERS: dict[str, str] = {
    ".obj": "obj",
    ".ply": "ply",
    ".stl": "stl",
    ".glb": "gltf",
    ".json": "json_mesh",
    ".dxf": "dxf",
    ".3dm": "rhino",
    ".ifc": "ifc",
}
READERS: dict[str, str] = {
    ".obj": "obj",
    ".ply": "ply",
    ".json": "json_mesh",
}


def require(module: str, extra: str, what: str):
    """Import an optional dependency of a format, or say which extra installs it.

    Parameters
    ----------
    module : str
        Module to import (dotted names import their parents too).
    extra : str
        The ruledmesh extra that provides it.
    what : str
        The format, for the message, e.g. ``"DXF export"``.
    """
    try:
        return importlib.import_module(module)
    except ImportError:
        raise ExportError(f"{what} needs {module.split('.')[0]}: pip install 'ruledmesh[{extra}]'") from None


def formats() -> list[str]:
    """Extensions :func:`save` can write."""
    return sorted(WRITERS)


def format_module(ext: str, table: dict[str, str], what: str):
    """The module of ``ruledmesh.io`` that handles extension ``ext`` in ``table`` (READERS/WRITERS).

    Raises ``ParameterError`` naming ``path`` and the known extensions for any other ``ext``;
    ``what`` is the verb of that message ("read", "write").
    """
    try:
        name = table[ext]
    except KeyError:
        known = ", ".join(sorted(table))
        raise ParameterError(f"cannot {what} \"{ext or '(no extension)'}\" files; known: {known}",
                             "path") from None
    return importlib.import_module(f"{__name__}.{name}")


def _write_all(fd: int, data: bytes) -> None:
    with os.fdopen(fd, "wb", closefd=False) as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())


def _link_fd(fd: int, name: Path) -> bool:
    """Give the unnamed file ``fd`` the name ``name`` (``linkat`` through /proc).

    ``os.link`` cannot do it: it calls ``link(2)``, which does not follow the
    /proc/self/fd magic link, so libc's ``linkat`` with AT_SYMLINK_FOLLOW is used.
    """
    import ctypes

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        linkat = libc.linkat
    except (OSError, AttributeError):
        return False
    at_fdcwd, at_symlink_follow = -100, 0x400
    return linkat(at_fdcwd, f"/proc/self/fd/{fd}".encode(), at_fdcwd, os.fsencode(name),
                  at_symlink_follow) == 0


def _publish_anonymous(folder: Path, path: Path, data: bytes) -> bool:
    """Write through an unnamed file (Linux ``O_TMPFILE``), then name it.

    While the bytes are being written the file has no name at all, so a
    process killed mid-write (even by SIGKILL) leaves nothing behind; it is
    linked under a hidden name only once complete and renamed over ``path``.
    Returns False where the system or file system does not support it.
    """
    flag = getattr(os, "O_TMPFILE", None)
    proc = Path("/proc/self/fd")
    if flag is None or not proc.is_dir():
        return False
    try:
        fd = os.open(folder, flag | os.O_WRONLY, 0o666)
    except OSError:
        return False
    try:
        _write_all(fd, data)
        tmp = folder / f".{path.name}.{os.getpid()}.{fd}.{os.urandom(4).hex()}.part"
        if not _link_fd(fd, tmp):
            return False
        try:
            os.replace(tmp, path)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
    finally:
        os.close(fd)
    return True


def write_atomic(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` completely or not at all.

    The bytes go to a temporary file in the target folder, which is renamed
    over ``path`` only when complete, so ``path`` never holds a truncated file.
    On Linux the temporary file is unnamed while it is written (``O_TMPFILE``):
    an export killed midway leaves no file at all.  Elsewhere it is a hidden
    ``.NAME.*.part`` file, removed on any error, but left behind if the process
    is killed outright (SIGKILL, power loss).

    Parameters
    ----------
    path : path-like
    data : bytes

    Returns
    -------
    Path
        The written path.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ExportError(f"{path}: folder {folder} does not exist")
    if _publish_anonymous(folder, path, data):
        return path
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=folder)
    try:
        try:
            _write_all(fd, data)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path


def check_finite(mesh: Mesh) -> None:
    """Refuse to export a mesh with NaN or infinite coordinates."""
    if not np.all(np.isfinite(mesh.vertices)):
        bad = int(np.count_nonzero(~np.all(np.isfinite(mesh.vertices), axis=1)))
        raise ExportError(f"mesh has {bad} vertices with NaN or infinite coordinates; nothing written")


def save(path: str | os.PathLike, mesh: Mesh, **options) -> Path:
    """Write ``mesh`` to ``path``; the format follows the extension.

    Parameters
    ----------
    path : path-like
        Target file; its extension picks the format (see :func:`formats`).
    mesh : Mesh
    **options
        Passed to the format's ``dumpb``.

    Returns
    -------
    Path
    """
    path = Path(path)
    module = format_module(path.suffix.lower(), WRITERS, "write")
    check_finite(mesh)
    data = module.dumpb(mesh, **options)
    # Formats that keep part of the mesh in companion files (PLY generators).
    extra = module.companions(path, mesh, **options) if hasattr(module, "companions") else {}
    for other, other_data in extra.items():
        write_atomic(other, other_data)
    return write_atomic(path, data)


def load(path: str | os.PathLike) -> Mesh:
    """Read a mesh file written by ruledmesh (or any plain OBJ/PLY polygon mesh)."""
    from .._files import MAX_MESH_BYTES, read_capped

    path = Path(path)
    module = format_module(path.suffix.lower(), READERS, "read")
    try:
        # Special files (a device, a pipe) and oversized files are refused before reading.
        data = read_capped(path, MAX_MESH_BYTES, "a mesh file")
    except OSError as exc:
        raise ParameterError(f"cannot read {path}: {exc.strerror}", "path") from None
    try:
        mesh = module.loadb(data)
        if hasattr(module, "load_companions"):
            mesh = module.load_companions(path, mesh)
        return mesh
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc.detail}", exc.field) from None
