"""Everything a workshop needs, written into one folder (``ruledmesh fabricate``).

Files (each written atomically):

=========================  ==================================================
``sheets/sheet-NNN.svg``   panels laid out on sheet NNN (cut, label layers)
``sheets/sheet-NNN.dxf``   the same as DXF (needs ezdxf; skipped without it)
``panels.csv``             one row per panel: kind, area, angles, class, sheet
``nodes.csv``              node schedule: id, x, y, z, valence
``edges.csv``              edge schedule: length, faces, dihedral, bend
``members.csv``            generators: end nodes, end points, length
``hotwire.csv``            synchronised tower paths (when the mesh has generators)
``hotwire.gcode``          the same as XYUV G-code
``summary.json``           panel statistics, sheet count, options, file list
=========================  ==================================================
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import GeometryError
from ..io import write_atomic
from ..mesh import Mesh
from ..progress import SILENT, Progress, stages
from ..tolerances import DEFAULT, Tolerances
from . import hotwire as hw
from .nesting import layout
from .panels import congruence_classes, panel_statistics, panel_table
from .schedules import csv_bytes, edge_schedule, member_schedule, node_schedule
from .sheets import panel_labels, sheet_dxf, sheet_svg
from .unroll import unroll

__all__ = ["fabricate"]


def fabricate(mesh: Mesh, folder: str | os.PathLike, *, sheet: tuple[float, float] | None = None,
              gap: float | None = None, unit: str = "", decimals: int = 3,
              length_tol: float | None = None, angle_tol: float = 1e-4, dxf: bool | None = None,
              hotwire: bool | None = None, span: str = "auto", up: str | None = None,
              kerf: float = 0.0, kerf_side: str = "left", feed: float = 300.0,
              require_planar: bool = True, tol: Tolerances = DEFAULT,
              progress: Progress | None = None) -> dict[str, Any]:
    """Write the fabrication files of ``mesh`` into ``folder`` (created if missing).

    Parameters
    ----------
    mesh : Mesh
    folder : path-like
    sheet : (width, height), optional
        Sheet size in mesh units (default: one square sheet that fits all).
    gap : float, optional
        Clearance between panels (default 2 % of the largest panel).
    unit : str
        Names the mesh unit in SVG/DXF/G-code: ``""``, ``"mm"``, ``"cm"``,
        ``"m"``, ``"in"``, ``"ft"``.
    decimals : int
        Decimals of the edge-length labels.
    length_tol, angle_tol : float
        Congruence tolerances (see :func:`~ruledmesh.fabricate.panels.congruence_classes`).
    dxf : bool, optional
        Write DXF sheets; default: when ezdxf is installed.
    hotwire : bool, optional
        Write hot-wire paths; default: when the mesh has generators and they
        meet the tower planes (otherwise the reason is in ``summary["notes"]``).
        ``True`` makes a refusal an error.
    span, up, kerf, kerf_side, feed
        Hot-wire options (see :func:`~ruledmesh.fabricate.hotwire.wire_paths`).
    require_planar : bool
        Refuse bent panels (see :func:`~ruledmesh.fabricate.unroll.unroll`).
    tol : Tolerances
    progress : Progress, optional
        Told the stages and each sheet as it is written (see :mod:`ruledmesh.progress`).

    Returns
    -------
    dict
        The summary also written to ``summary.json``.
    """
    folder = Path(folder)
    written: list[str] = []
    notes: list[str] = []

    def put(name: str, data: bytes) -> None:
        write_atomic(folder / name, data)
        written.append(name)

    progress = progress or SILENT
    # Not a ``with``: the caller closes what an error leaves open (TerminalProgress.close).
    task = stages(progress, "fabricate", ["unroll", "layout", "labels", "hot wire", "classes"])
    unrolled = unroll(mesh, require_planar=require_planar, tol=tol)
    task.advance(note="layout")
    lay = layout(unrolled, sheet, gap=gap)
    task.advance(note="labels")
    labels = panel_labels(lay, decimals=decimals)
    task.advance(note="hot wire")
    # Everything that can refuse runs before the first file is written.
    path = None
    if hotwire is not False and len(mesh.members):
        try:
            path = hw.wire_paths(mesh, span=span, up=up, kerf=kerf, kerf_side=kerf_side, tol=tol)
        except GeometryError as exc:
            if hotwire:
                raise
            notes.append(f"hot-wire paths skipped: {exc}")
    elif hotwire and not len(mesh.members):
        raise GeometryError("the mesh has no generators (members) to cut along")

    task.advance(note="classes")
    tolerances = {"length_tol": length_tol if length_tol is not None
                  else 1e-9 * (mesh.diagonal() or 1.0), "angle_tol": angle_tol}
    classes = congruence_classes(mesh, unrolled=unrolled, **tolerances)
    table = panel_table(mesh, unrolled=unrolled, classes=classes)
    table.update({"sheet": lay.sheet + 1, "sheet_x": lay.offset[:, 0], "sheet_y": lay.offset[:, 1],
                  "rotation_deg": np.degrees(lay.rotation)})
    task.advance()
    task.close()
    (folder / "sheets").mkdir(parents=True, exist_ok=True)
    if dxf is None:
        try:
            import ezdxf  # noqa: F401
            dxf = True
        except ImportError:
            dxf = False
            notes.append("DXF sheets skipped: ezdxf is not installed (pip install 'ruledmesh[dxf]')")
    _write_sheets(put, lay, labels, unit=unit, decimals=decimals, dxf=bool(dxf),
                  progress=progress)
    _write_schedules(put, mesh, table, progress)

    wire: dict[str, Any] | None = None
    if path is not None:
        put("hotwire.csv", csv_bytes(hw.path_table(path)))
        gunits = unit if unit in ("mm", "in") else ""
        put("hotwire.gcode", hw.gcode(path, feed=feed, units=gunits).encode("ascii"))
        wire = {"dialect": "XYUV (G1 X Y U V F)", "span": path.span, "up": path.up,
                "depth": path.depth, "planes": path.planes.tolist(),
                "shift": path.shift.tolist(), "kerf": path.kerf, "kerf_side": path.kerf_side,
                "steps": int(path.generator.size)}

    summary = {
        "panels": panel_statistics(mesh, table=table, **tolerances),
        "sheets": {"count": lay.n_sheets, "size": lay.sheet_size.tolist(), "gap": lay.gap,
                   "unit": unit},
        "max_out_of_plane": float(unrolled.out_of_plane.max()) if mesh.n_faces else 0.0,
        "hotwire": wire,
        "notes": notes,
        "files": written + ["summary.json"],
    }
    put("summary.json", (json.dumps(summary, indent=2) + "\n").encode("utf-8"))
    return summary


def _write_sheets(put, lay, labels, *, unit: str, decimals: int, dxf: bool,
                  progress: Progress) -> None:
    """One SVG (and DXF) per sheet, reported sheet by sheet."""
    with progress.task("sheets", total=lay.n_sheets) as sheets:
        for s in range(lay.n_sheets):
            put(f"sheets/sheet-{s + 1:03d}.svg",
                sheet_svg(lay, s, labels=labels, unit=unit, decimals=decimals).encode("utf-8"))
            if dxf:
                put(f"sheets/sheet-{s + 1:03d}.dxf", sheet_dxf(lay, s, labels=labels, unit=unit))
            sheets.advance()


def _write_schedules(put, mesh: Mesh, table: dict, progress: Progress) -> None:
    """The panel, node, edge and member schedules (CSV)."""
    with stages(progress, "schedules", ["panels", "nodes", "edges", "members"]) as task:
        put("panels.csv", csv_bytes(table))
        task.advance(note="nodes")
        put("nodes.csv", csv_bytes(node_schedule(mesh)))
        task.advance(note="edges")
        put("edges.csv", csv_bytes(edge_schedule(mesh)))
        task.advance(note="members")
        put("members.csv", csv_bytes(member_schedule(mesh)))
        task.advance()
