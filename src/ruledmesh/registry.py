"""Plug-in tables that connect design files to constructions.

Design files name a surface kind (``[surface] kind = "torus"``), a mesh
method (``[mesh] method = "pq"``) and transforms (``[[transform]] type =
"inversion"``).  Each construction module registers its builder here with a
decorator, so adding a construction touches only its own module and the
:data:`PLUGINS` list.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from .mesh import Mesh

__all__ = [
    "BuildContext",
    "Built",
    "Reference",
    "SURFACE_KINDS",
    "MESH_METHODS",
    "TRANSFORMS",
    "surface_kind",
    "mesh_method",
    "transform_type",
    "load_plugins",
]


class Reference(Protocol):
    """The smooth design surface a mesh approximates (for closeness/coverage).

    ``distance(points)`` returns the (n,) distances of (n, 3) points from the
    surface; ``area()`` the area of the design patch (or ``None``).
    """

    def distance(self, points: np.ndarray) -> np.ndarray: ...

    def area(self) -> float | None: ...


@dataclass(frozen=True)
class BuildContext:
    """What a builder may need besides its own table.

    Attributes
    ----------
    source : str
        Design file name for error messages.
    base_dir : Path
        Folder relative paths in the design resolve against.
    design : mapping
        The whole design (read-only), for builders that look at other tables.
    task : Task, optional
        The build's progress task (:mod:`ruledmesh.progress`): a builder that makes
        several meshes may say which one it is at (``task.advance(0, note)``).
    """

    source: str = "<design>"
    base_dir: Path = Path(".")
    design: Mapping[str, Any] = field(default_factory=dict)
    task: Any = None


@dataclass(frozen=True)
class Built:
    """A built mesh and what it was built from.

    Attributes
    ----------
    mesh : Mesh
    reference : Reference or None
        The smooth surface, for closeness and coverage.
    rulings : object or None
        The :class:`~ruledmesh.rulings.Rulings` for ruled constructions.
    extras : dict
        Anything else a report may show (e.g. C1 residuals, circularity).
    """

    mesh: Mesh
    reference: Reference | None = None
    rulings: Any = None
    extras: Mapping[str, Any] = field(default_factory=dict)


# kind -> builder(surface_table, mesh_table, ctx) -> Built
SURFACE_KINDS: dict[str, Callable[[Mapping, Mapping, BuildContext], Built]] = {}
# method -> builder(rulings, mesh_table, ctx) -> Built
MESH_METHODS: dict[str, Callable[[Any, Mapping, BuildContext], Built]] = {}
# type -> transform(built, transform_table, path) -> Built
TRANSFORMS: dict[str, Callable[[Built, Mapping, str], Built]] = {}

# Modules that register builders when imported; a module not yet written is skipped.
PLUGINS = [
    "ruledmesh.design.pq",
    "ruledmesh.design.meshers",
    "ruledmesh.design.catalogue",
    "ruledmesh.design.transforms",
]

_loaded = False


def load_plugins() -> None:
    """Import every module of :data:`PLUGINS` once, so their builders register."""
    global _loaded
    if _loaded:
        return
    for name in PLUGINS:
        try:
            importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name != name:
                raise
    _loaded = True


def _register(table: dict, name: str):
    def deco(fn):
        table[name] = fn
        return fn
    return deco


def surface_kind(name: str):
    """Decorator: register ``fn(surface_table, mesh_table, ctx) -> Built`` as ``kind = name``."""
    return _register(SURFACE_KINDS, name)


def mesh_method(name: str):
    """Decorator: register ``fn(rulings, mesh_table, ctx) -> Built`` as ``method = name``."""
    return _register(MESH_METHODS, name)


def transform_type(name: str):
    """Decorator: register ``fn(built, table, path) -> Built`` as ``type = name``."""
    return _register(TRANSFORMS, name)
