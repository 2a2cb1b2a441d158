"""Compiled kernels of the hot paths, and when to use them.

The mesher and the per-face measures are written in numpy; their hot stages
also exist as numba kernels (:mod:`ruledmesh.kernels.geometry`,
:mod:`ruledmesh.kernels.grid`, :mod:`ruledmesh.kernels.strips`) that do the
same arithmetic in the same order, one pass per face instead of one array
operation per formula term, so their results are bit for bit the numpy ones
(the tests compare both on random designs).

Importing numba and loading the compiled kernels from the on-disk cache costs
about 0.9 s of CPU once per process (compiling them on a new machine, once,
about 30-35 s), where a small build takes milliseconds in numpy.  So the kernels
are loaded when one stage has :data:`MIN_ITEMS` items (a build that takes a
good part of a second in numpy), or when the process has put :data:`MIN_WORK`
items through the stages (a designer or a notebook rebuilding the same design
over and over); once loaded they are used for every size.  A one-off build of a
small design never imports numba.  An application that knows it will rebuild
live (a server) calls :func:`hold` at start and, when it is idle, :func:`load`
and one build inside :func:`everywhere`, so that compiling (or loading from
the cache) never happens inside an edit that happens to cross
:data:`MIN_WORK`.  ``RULEDMESH_KERNELS=0`` forces numpy
everywhere, ``=1`` the kernels everywhere (the tests use both); the results are
the same either way.

The on-disk cache lives beside the package; where that is not writable (an
installation owned by another user, a read-only image) it goes to
``$NUMBA_CACHE_DIR`` if set, else to ``~/.cache/ruledmesh/numba``, else to the
temporary directory.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

__all__ = ["MIN_ITEMS", "MIN_WORK", "everywhere", "hold", "load", "wanted"]

#: Items (faces, grid points) from which a single stage loads the kernels.
MIN_ITEMS = 100_000
#: Items put through the stages of this process from which the kernels are loaded.
MIN_WORK = 1_000_000

_work = [0]
# Depth of open :func:`everywhere` blocks.
_forced = [0]
# Set by :func:`hold`: numpy for every stage until :func:`load`.
_held = [False]

_state: dict[str, ModuleType | bool | None] = {"geometry": None, "grid": None, "strips": None, "failed": False}


def _cache_dir_fallback() -> None:
    """Point numba's cache at a writable directory when the package's own is not."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    here = Path(__file__).resolve().parent
    if os.access(here, os.W_OK):
        return
    for base in (Path.home() / ".cache" / "ruledmesh" / "numba",
                 Path(tempfile.gettempdir()) / f"ruledmesh-numba-{os.getuid() if hasattr(os, 'getuid') else 0}"):
        try:
            base.mkdir(parents=True, exist_ok=True)
        except OSError:
            continue
        if os.access(base, os.W_OK):
            os.environ["NUMBA_CACHE_DIR"] = str(base)
            return


def _mode() -> str:
    return os.environ.get("RULEDMESH_KERNELS", "auto").strip().lower()


def _load(name: str) -> ModuleType | None:
    mod = _state[name]
    if isinstance(mod, ModuleType):
        return mod
    if _state["failed"]:
        return None
    try:
        _cache_dir_fallback()
        loaded = importlib.import_module(f"{__name__}.{name}")
    except ImportError:
        # numba is a dependency; without it (a broken environment) numpy does the work.
        _state["failed"] = True
        return None
    _state[name] = loaded
    return loaded


def _loaded() -> bool:
    return any(isinstance(_state[k], ModuleType) for k in ("geometry", "grid", "strips")) \
        or "ruledmesh.kernels.geometry" in sys.modules


def wanted(items: int, name: str = "geometry") -> ModuleType | None:
    """The kernel module ``name`` if a stage of ``items`` items should use it, else None.

    Parameters
    ----------
    items : int
        Size of the stage (faces, grid points).
    name : {"geometry", "grid", "strips"}

    Returns
    -------
    module or None
        None: use the numpy path.
    """
    mode = _mode()
    if mode in ("0", "off", "numpy"):
        return None
    _work[0] += items
    if _held[0] and not _forced[0]:
        return None
    if _forced[0] or mode in ("1", "on", "numba") or items >= MIN_ITEMS or _work[0] >= MIN_WORK or _loaded():
        return _load(name)
    return None



def load() -> bool:
    """Load every kernel now (a live application, before its first request).

    Returns
    -------
    bool
        Whether the kernels are in use (False: numba is missing, or
        ``RULEDMESH_KERNELS=0``).
    """
    if _mode() in ("0", "off", "numpy"):
        return False
    _held[0] = False
    return all(_load(name) is not None for name in ("geometry", "grid", "strips"))


def hold() -> None:
    """Use numpy for every stage, whatever its size, until :func:`load` is called.

    For a process with a time limit on each build (the designer's build
    worker): compiling the kernels inside a build would count against it, so
    the worker holds them and loads them when it is idle.
    """
    _held[0] = True


@contextlib.contextmanager
def everywhere() -> Iterator[None]:
    """Use the kernels for every stage inside the block, whatever its size.

    numba compiles a kernel on its first call (or loads it from the on-disk
    cache); a build of a small design inside this block does that for every
    kernel the mesher calls, so a live application pays it at start.
    ``RULEDMESH_KERNELS=0`` still wins: then the block changes nothing.
    """
    _forced[0] += 1
    try:
        yield
    finally:
        _forced[0] -= 1
