"""Compiled kernels of the hot paths, and when to use them.

The mesher and the per-face measures are written in numpy; their hot stages
also exist as numba kernels (:mod:`ruledmesh.kernels.geometry`,
:mod:`ruledmesh.kernels.grid`, :mod:`ruledmesh.kernels.strips`) that do the same arithmetic in the same order,
one pass per face instead of one array operation per formula term, so their
results are bit for bit the numpy ones (the tests compare both on random
designs).

Importing numba costs about 0.45 s and the first call of a kernel on a new
machine compiles it (a few seconds, then cached on disk): a small build is
faster in numpy.  So the kernels are loaded only when a stage meets
:data:`MIN_ITEMS` items (faces, grid points), and once loaded they are used for
every size.  ``RULEDMESH_KERNELS=0`` forces numpy everywhere, ``=1`` the
kernels everywhere (the tests use both).

The on-disk cache lives beside the package; where that is not writable (an
installation owned by another user, a read-only image) it goes to
``$NUMBA_CACHE_DIR`` if set, else to ``~/.cache/ruledmesh/numba``, else to the
temporary directory.
"""

from __future__ import annotations

import importlib
import os
import sys
import tempfile
from pathlib import Path
from types import ModuleType

__all__ = ["MIN_ITEMS", "wanted"]

#: Items (faces, grid points) from which a stage loads the kernels.  The bundled
#: small designs stay below it, so ``ruledmesh build`` of them never imports numba.
MIN_ITEMS = 4096

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
    if mode in ("1", "on", "numba") or items >= MIN_ITEMS or _loaded():
        return _load(name)
    return None

