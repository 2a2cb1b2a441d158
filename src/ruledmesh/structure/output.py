"""The files of ``ruledmesh structure``, written into one folder.

=============================  ==============================================
``mesh.obj``                   the mesh the structure is built on
``offset.obj``                 the offset layer: same faces, same order
``axes.csv``                   node schedule: axis, offset point, distance,
                               deviation from the normal, worst torsion
``edges.csv``                  edge schedule: dihedral, torsion, beam-plane
                               angles to the panels, end bevels
``beams.{obj,3dm,ifc}``        edge beams (``--beams edges``)
``beams.csv``                  edge beams' table (setbacks, depths)
``generator-beams.*``          beams along the generators (``--beams generators``)
``panels.{obj,3dm,ifc}``       panels with thickness (``--thickness``)
``panels.csv``                 the panels' table
``structure.png``              a picture of it all (``render=True``)
``structure.json``             exactness, torsion, deviation, distances, files
=============================  ==============================================

Everything that can fail is computed before the first file is written, and
each file is written atomically.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ExportError, ParameterError
from ..fabricate.schedules import csv_bytes
from ..io import write_atomic
from ..io.obj import dumpb as obj_dumpb
from .beams import Solids, edge_beams, edge_table, generator_beams, thick_panels
from .support import SupportStructure

__all__ = ["BEAM_KINDS", "FORMATS", "node_table", "write_structure"]

BEAM_KINDS = ("edges", "generators")
FORMATS = ("obj", "3dm", "ifc")
_OPTIONAL = {"3dm": ("rhino3dm", "rhino"), "ifc": ("ifcopenshell", "ifc")}


def node_table(structure: SupportStructure) -> dict[str, np.ndarray]:
    """One row per vertex: position, unit axis, offset point, distance, deviation, torsion.

    Returns
    -------
    dict of (V,) arrays
        ``id``, ``x``, ``y``, ``z``, ``axis_x``, ``axis_y``, ``axis_z``,
        ``offset_x``, ``offset_y``, ``offset_z``, ``distance``,
        ``deviation_deg`` (axis against the vertex normal), ``torsion_max_deg``
        (worst edge at the node), ``valence``.
    """
    v, w, a = structure.mesh.vertices, structure.offset, structure.axes
    edges = structure.edges
    worst = np.zeros(len(v))
    np.maximum.at(worst, edges[:, 0], structure.torsion)
    np.maximum.at(worst, edges[:, 1], structure.torsion)
    return {"id": np.arange(len(v)), "x": v[:, 0], "y": v[:, 1], "z": v[:, 2],
            "axis_x": a[:, 0], "axis_y": a[:, 1], "axis_z": a[:, 2],
            "offset_x": w[:, 0], "offset_y": w[:, 1], "offset_z": w[:, 2],
            "distance": structure.lengths, "deviation_deg": structure.deviation,
            "torsion_max_deg": worst,
            "valence": np.bincount(edges.reshape(-1), minlength=len(v))}


def _formats(formats: Iterable[str] | None, notes: list[str]) -> list[str]:
    """The solid formats to write: all installed by default, the named ones otherwise."""
    import importlib.util

    if formats is None:
        out = ["obj"]
        for fmt, (module, extra) in _OPTIONAL.items():
            if importlib.util.find_spec(module) is None:
                notes.append(f".{fmt} files skipped: {module} is not installed "
                             f"(pip install 'ruledmesh[{extra}]')")
            else:
                out.append(fmt)
        return out
    chosen = list(formats)
    for fmt in chosen:
        if fmt not in FORMATS:
            raise ParameterError(f"expected formats among {', '.join(FORMATS)}, got \"{fmt}\"",
                                 "formats")
    return chosen


def _solid_writers(stem: str, solids: Solids, formats: list[str], ifc: dict[str, str]
                   ) -> list[tuple[str, Callable[[], bytes]]]:
    from .export import solids_3dm, solids_ifc, solids_obj

    table = {"obj": lambda: solids_obj(solids), "3dm": lambda: solids_3dm(solids, layer=stem),
             "ifc": lambda: solids_ifc(solids, **ifc)}
    return [(f"{stem}.{fmt}", table[fmt]) for fmt in formats] + \
        [(f"{stem}.csv", lambda: csv_bytes(solids.table))]


def _plan(structure: SupportStructure, beams: Iterable[str], width: float | None,
          depth: float | None, setback: float | str, thickness: float | None, panel_side: str
          ) -> dict[str, Solids]:
    beams = list(beams)
    for kind in beams:
        if kind not in BEAM_KINDS:
            raise ParameterError(f"expected beams among {', '.join(BEAM_KINDS)}, got \"{kind}\"",
                                 "beams")
    if width is None:
        # A tenth of the median edge: visible, and clear of the neighbours at most nodes.
        lengths = np.linalg.norm(np.diff(structure.mesh.vertices[structure.edges], axis=1), axis=2)
        width = 0.1 * float(np.median(lengths))
    solids: dict[str, Solids] = {}
    if "edges" in beams:
        solids["beams"] = edge_beams(structure, width, depth=depth, setback=setback)
    if "generators" in beams:
        solids["generator-beams"] = generator_beams(structure, width, depth=depth)
    if thickness is not None:
        solids["panels"] = thick_panels(structure, thickness, side=panel_side)
    return solids


def write_structure(structure: SupportStructure, folder: str | os.PathLike, *,
                    beams: Iterable[str] = ("edges",), width: float | None = None,
                    depth: float | None = None, setback: float | str = "auto",
                    thickness: float | None = None, panel_side: str = "outer",
                    formats: Iterable[str] | None = None, unit: str = "",
                    render: bool = False, options: dict[str, Any] | None = None,
                    progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Write the structure's files into ``folder`` (created if missing).

    Parameters
    ----------
    structure : SupportStructure
    folder : path-like
    beams : iterable of {"edges", "generators"}
        Which beams to make (none: an empty tuple).
    width, depth, setback
        Beam width (default a tenth of the median edge length), depth along
        the axes (default: to the offset layer) and setback from the node axes
        (see :func:`~ruledmesh.structure.beams.edge_beams`).
    thickness : float, optional
        Also write the panels as solids of this thickness.
    panel_side : {"outer", "inner"}
        Side of the panels (see :func:`~ruledmesh.structure.beams.thick_panels`).
    formats : iterable of {"obj", "3dm", "ifc"}, optional
        Solid formats; default OBJ plus those whose library is installed.
    unit : str
        Name of the mesh unit, recorded in ``structure.json``.
    render : bool
        Also write ``structure.png`` (needs matplotlib).
    options : dict, optional
        Recorded in ``structure.json`` as given (the command line's options).
    progress : callable, optional
        Called with each file's name before it is made (IFC files of
        thousands of solids take seconds).

    Returns
    -------
    dict
        The contents of ``structure.json``.
    """
    folder = Path(folder)
    notes: list[str] = []
    fmts = _formats(formats, notes)
    solids = _plan(structure, beams, width, depth, setback, thickness, panel_side)
    for stem, sol in solids.items():
        if sol.skipped.size:
            shown = ", ".join(map(str, sol.skipped[:10].tolist()))
            more = f" and {sol.skipped.size - 10} more" if sol.skipped.size > 10 else ""
            notes.append(f"{stem}: {sol.skipped.size} left out ({shown}{more}): {sol.skip_reason}")
    folded = int(structure.summary()["reversed_edges"])
    if folded:
        notes.append(f"the offset layer folds over: {folded} offset edges run against their "
                     "edges (the offset is larger than the radius of curvature there)")
    mesh = structure.mesh
    files: list[tuple[str, Callable[[], bytes]]] = [
        ("mesh.obj", lambda: obj_dumpb(mesh)),
        ("offset.obj", lambda: obj_dumpb(mesh.with_vertices(structure.offset,
                                                            construction="offset layer"))),
        ("axes.csv", lambda: csv_bytes(node_table(structure))),
        ("edges.csv", lambda: csv_bytes(edge_table(structure))),
    ]
    ifc = {"beams": {"ifc_class": "IfcMember", "predefined_type": "MULLION"},
           "generator-beams": {"ifc_class": "IfcMember", "predefined_type": "MEMBER"},
           "panels": {"ifc_class": "IfcPlate", "predefined_type": "CURTAIN_PANEL"}}
    for stem, sol in solids.items():
        files += _solid_writers(stem, sol, fmts, ifc[stem])
    if render:
        from .figure import render_structure

        files.append(("structure.png", lambda: render_structure(
            structure, beams=solids.get("beams"), panels=solids.get("panels"))))
    # Serialise everything before the first write: a refusal leaves the folder as it was.
    blobs = []
    for name, make in files:
        if progress is not None:
            progress(name)
        blobs.append((name, make()))
    summary = structure.summary()
    summary.update({
        "unit": unit,
        "solids": {stem: {"count": sol.count, "skipped": sol.skipped.tolist(), **_solid_stats(sol)}
                   for stem, sol in solids.items()},
        "options": options or {}, "notes": notes,
        "files": [name for name, _ in blobs] + ["structure.json"],
    })
    text = json.dumps(_finite(summary), indent=2, allow_nan=False) + "\n"
    folder.mkdir(parents=True, exist_ok=True)
    if not folder.is_dir():
        raise ExportError(f"{folder} is not a folder")
    for name, data in blobs:
        write_atomic(folder / name, data)
    write_atomic(folder / "structure.json", text.encode("utf-8"))
    return summary


def _solid_stats(sol: Solids) -> dict[str, float]:
    out = {}
    for key in ("torsion_deg", "axis_misfit_deg", "side_planarity_max", "bevel0_deg"):
        if key in sol.table and len(sol.table[key]):
            out[f"{key.removesuffix('_max')}_max"] = float(np.nanmax(sol.table[key]))
    return out


def _finite(obj: Any) -> Any:
    """JSON has no NaN: an undefined figure is written as null."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_finite(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj
