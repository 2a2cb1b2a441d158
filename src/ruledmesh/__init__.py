"""ruledmesh: planar quad meshes of ruled surfaces, by construction.

The package follows the paper (D. Lordick, *Intuitive design and meshing of
non-developable ruled surfaces*): director curves -> discrete generators ->
PQ meshes (§4.3), hybrid HP-patch meshes (§4.1), and the exact PQ analogues of
§2-§3, plus analysis, exports and fabrication outputs.

The top level is the short way in:

=====================================  =============================================
``build(design)``                      design file, TOML text or dict -> :class:`Mesh`
``load(path)``, ``save(path, mesh)``   mesh files, every format (atomic writes)
``analyze(mesh, design=None)``         the report ``ruledmesh analyze --json`` prints
``fabricate(mesh, folder)``            sheets, schedules, hot-wire paths
``pq_mesh(a, b, rows)``                §4.3 PQ mesh of generators ``a_i b_i``
``hybrid_mesh(a, b)``                  §4.1 hybrid quad/triangle mesh of any lines
``examples()``                         names of the bundled example designs
=====================================  =============================================

>>> import ruledmesh
>>> mesh = ruledmesh.build("examples/skew.toml")
>>> mesh  # doctest: +ELLIPSIS
Mesh(vertices=..., faces=... [quad=..., ...], members=...)
>>> ruledmesh.analyze(mesh)["planarity"]["max"] < 1e-12
True

The maths modules (:mod:`ruledmesh.pq`, :mod:`ruledmesh.skew`,
:mod:`ruledmesh.analysis` ...) are imported when first used.
"""

from __future__ import annotations

import importlib
from typing import Any

# ``ruledmesh.fabricate`` names both a subpackage and the function from .api. The import system
# sets a package attribute only when it first loads a submodule, so importing the subpackage
# here, before the function is bound, keeps a later ``import ruledmesh.fabricate.output`` from
# replacing the function with the module (it is cheap: no scipy).
from . import fabricate as _fabricate_package  # noqa: F401
from ._version import __version__
from .api import analyze, build, build_full, fabricate, load, save
from .errors import (
    DesignError,
    ExportError,
    GeometryError,
    ParameterError,
    RuledMeshError,
)
from .mesh import FaceKind, Mesh
from .tolerances import DEFAULT as DEFAULT_TOLERANCES
from .tolerances import Tolerances

# name -> module that defines it; imported on first access (PEP 562).
_LAZY = {
    "pq_mesh": "ruledmesh.skew.pq",
    "hybrid_mesh": "ruledmesh.skew.hybrid",
    "planarity": "ruledmesh.analysis.faces",
}

__all__ = [
    "DEFAULT_TOLERANCES",
    "DesignError",
    "ExportError",
    "FaceKind",
    "GeometryError",
    "Mesh",
    "ParameterError",
    "RuledMeshError",
    "Tolerances",
    "__version__",
    "analyze",
    "build",
    "build_full",
    "examples",
    "fabricate",
    "hybrid_mesh",
    "load",
    "planarity",
    "pq_mesh",
    "save",
]


def examples() -> list[str]:
    """Names of the example designs bundled with the package.

    ``ruledmesh.build("examples/NAME.toml")`` builds one from any folder; see
    :mod:`ruledmesh.bundled` for their files and descriptions.

    >>> "skew" in examples()
    True
    """
    from .bundled import names

    return names()


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'ruledmesh' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
