"""The functions a user types first: build, load, save, analyze, fabricate.

They are re-exported at the top level (``ruledmesh.build`` ...) and are thin
calls into :mod:`ruledmesh.design`, :mod:`ruledmesh.io`,
:mod:`ruledmesh.analysis.report` and :mod:`ruledmesh.fabricate.output`, which
are imported only when a function is called.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, Union

from .errors import ParameterError
from .mesh import Mesh

if TYPE_CHECKING:
    from .registry import Built

__all__ = ["analyze", "build", "build_full", "fabricate", "load", "save"]

#: What :func:`build` accepts: a design file path, TOML text or the tables as a mapping.
DesignLike = Union[str, "os.PathLike[str]", Mapping[str, Any]]


def _design(design: Any, base_dir: str | os.PathLike | None):
    """A parsed :class:`~ruledmesh.design.Design` from a path, TOML text or a mapping."""
    from .design import Design, design_from_tables, load_design, parse_design

    if isinstance(design, Design):
        return design
    if isinstance(design, Mapping):
        return design_from_tables(design, "<dict>", base_dir if base_dir is not None else ".")
    if isinstance(design, os.PathLike):
        return load_design(design)
    if isinstance(design, str):
        if "\n" not in design and (design.lower().endswith(".toml") or Path(design).is_file()):
            return load_design(design)
        return parse_design(design, "<text>", base_dir if base_dir is not None else ".")
    raise ParameterError(f"expected a design file path, TOML text or a dict, got "
                         f"{type(design).__name__}", "design")


def build_full(design: DesignLike, *, base_dir: str | os.PathLike | None = None) -> Built:
    """Like :func:`build`, but also return the smooth reference surface and the rulings.

    Returns
    -------
    Built
        ``mesh``, ``reference`` (for closeness and coverage), ``rulings`` and
        ``extras`` (construction-specific figures).
    """
    from .design import build_design

    return build_design(_design(design, base_dir))


def build(design: DesignLike, *, base_dir: str | os.PathLike | None = None) -> Mesh:
    """Build the mesh a design describes.

    Parameters
    ----------
    design : path-like, str or mapping
        A design file (``.toml``; a relative ``examples/NAME.toml`` that does
        not exist here is the bundled example), TOML text, or the design's
        tables as a dict (as :func:`tomllib.loads` returns them).
    base_dir : path-like, optional
        Folder that relative paths inside TOML text or a dict resolve against
        (default: the working folder; a file's own folder for a file).

    Returns
    -------
    Mesh

    Raises
    ------
    DesignError
        A malformed design, naming the field and what was expected.
    GeometryError
        Geometry that cannot be meshed as asked.

    Examples
    --------
    >>> import ruledmesh
    >>> mesh = ruledmesh.build("examples/skew.toml")
    >>> mesh.count_kinds()["quad"] > 500       # planar quads, plus border faces and fill triangles
    True
    >>> design = {
    ...     "curves": {"c1": {"type": "line", "points": [[0, 0, 0], [4, 0, 0]]},
    ...                "c2": {"type": "line", "points": [[0, 3, 2], [4, 3, -2]]}},
    ...     "rulings": {"between": ["c1", "c2"], "count": 9},
    ...     "mesh": {"rows": 8},
    ... }
    >>> hp = ruledmesh.build(design)      # a hyperbolic paraboloid patch
    >>> float(ruledmesh.analyze(hp)["planarity"]["max"]) < 1e-12
    True
    """
    return build_full(design, base_dir=base_dir).mesh


def load(path: str | os.PathLike) -> Mesh:
    """Read a mesh file (``.obj``, ``.ply``, ``.json``), face kinds and generators kept.

    Examples
    --------
    >>> import ruledmesh, tempfile, pathlib
    >>> mesh = ruledmesh.build("examples/skew.toml")
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = ruledmesh.save(pathlib.Path(tmp) / "skew.obj", mesh)
    ...     back = ruledmesh.load(path)
    >>> back.n_faces == mesh.n_faces and back.count_kinds() == mesh.count_kinds()
    True
    """
    from .io import load as _load

    return _load(path)


def save(path: str | os.PathLike, mesh: Mesh, **options: Any) -> Path:
    """Write ``mesh`` to ``path`` atomically; the extension picks the format.

    Parameters
    ----------
    path : path-like
        ``.obj .ply .stl .glb .json .dxf .3dm .ifc`` (DXF, 3DM and IFC need
        the extras ``dxf``, ``rhino``, ``ifc``).
    mesh : Mesh
    **options
        Options of the format's writer (see ``docs/exports.md``).

    Returns
    -------
    Path
        The written file.
    """
    from .io import save as _save

    return _save(path, mesh, **options)


def _as_mesh(mesh: Any) -> Mesh:
    if isinstance(mesh, Mesh):
        return mesh
    if isinstance(mesh, (str, os.PathLike)):
        if Path(mesh).suffix.lower() == ".toml":
            return build(mesh)
        return load(mesh)
    raise ParameterError(f"expected a Mesh or a file path, got {type(mesh).__name__}", "mesh")


def analyze(mesh: Mesh | str | os.PathLike, design: DesignLike | Built | None = None, *,
            compare: bool = False) -> dict[str, Any]:
    """The analysis report of ``mesh``: the dictionary ``ruledmesh analyze --json`` prints.

    Parameters
    ----------
    mesh : Mesh or path-like
        A mesh, a mesh file, or a design file (built first).
    design : path-like, str, mapping or Built, optional
        The design ``mesh`` was built from: adds the closeness to the smooth
        surface and the coverage of the patch.  A design file given as
        ``mesh`` counts as its own design.
    compare : bool
        Also compare the triangulation with standard tessellations of the
        smooth surface (slow).

    Returns
    -------
    dict
        JSON-serialisable figures: ``planarity``, ``kinds``, ``area``,
        ``closeness``, ``coverage``, ``warnings``... (see
        :func:`ruledmesh.analysis.report.analyze`).

    Examples
    --------
    >>> import json, ruledmesh
    >>> report = ruledmesh.analyze(ruledmesh.build("examples/skew.toml"), "examples/skew.toml")
    >>> report["kinds"]["quad"] > 500, report["planarity"]["max"] < 1e-12
    (True, True)
    >>> round(report["coverage"]["ratio"], 2)
    1.0
    >>> text = json.dumps(report)        # plain JSON, no numpy types
    """
    from .analysis.report import analyze as _analyze
    from .registry import Built

    if design is None and isinstance(mesh, (str, os.PathLike)) \
            and Path(mesh).suffix.lower() == ".toml":
        full = build_full(mesh)
        built: Built | None = full
        target = full.mesh
    else:
        target = _as_mesh(mesh)
        built = design if isinstance(design, Built) or design is None else build_full(design)
    if built is None:
        return _analyze(target, compare=compare)
    return _analyze(target, reference=built.reference, extras=built.extras, compare=compare)


def fabricate(mesh: Mesh | str | os.PathLike, folder: str | os.PathLike,
              **options: Any) -> dict[str, Any]:
    """Write the fabrication files of ``mesh`` into ``folder``: sheets, schedules, hot wire.

    Parameters
    ----------
    mesh : Mesh or path-like
        A mesh, a mesh file or a design file.
    folder : path-like
        Created if missing.
    **options
        ``sheet=(w, h)``, ``unit``, ``gap``, ``kerf`` ... (see
        :func:`ruledmesh.fabricate.output.fabricate` and ``docs/fabrication.md``).

    Returns
    -------
    dict
        The summary also written to ``summary.json``.

    Examples
    --------
    >>> import ruledmesh, tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     summary = ruledmesh.fabricate("examples/skew.toml", tmp, dxf=False)
    >>> summary["panels"]["count"] == ruledmesh.build("examples/skew.toml").n_faces
    True
    """
    from .fabricate.output import fabricate as _fabricate

    return _fabricate(_as_mesh(mesh), folder, **options)
