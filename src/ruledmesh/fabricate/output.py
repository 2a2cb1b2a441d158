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
from ..tolerances import CONGRUENCE_ANGLE_DEG, DEFAULT, ROUNDING, Tolerances
from . import hotwire as hw
from . import machine as hm
from .nesting import layout
from .panels import congruence_classes, panel_statistics, panel_table
from .schedules import csv_bytes, edge_schedule, member_schedule, node_schedule
from .sheets import panel_labels, sheet_dxf, sheet_svg
from .unroll import unroll

__all__ = ["fabricate"]


def _want_dxf(dxf: bool | None, notes: list[str]) -> bool:
    """Whether to write DXF sheets (default: when ezdxf is installed, else a note)."""
    if dxf is not None:
        return dxf
    try:
        import ezdxf  # noqa: F401
    except ImportError:
        notes.append("DXF sheets skipped: ezdxf is not installed (pip install 'ruledmesh[dxf]')")
        return False
    return True


def _wire_summary(path: hw.WirePath, unit: str, machine: hm.Machine) -> dict[str, Any]:
    prog = hm.program(path, unit, machine)
    return {"dialect": "XYUV (G1 X Y U V F)", "span": path.span, "up": path.up,
            "gcode_unit": prog.unit, "travel_needed": prog.extent().tolist(),
            "max_tilt_deg": prog.tilt_deg, "wire_length": prog.wire_length,
            "depth": path.depth, "planes": path.planes.tolist(),
            "shift": path.shift.tolist(), "kerf": path.kerf, "kerf_side": path.kerf_side,
            "steps": int(path.generator.size)}


def _spyrrow_available() -> bool:
    from .true_shape import available

    return available()


def _hotwire(mesh: Mesh, unit: str, machine: hm.Machine, **options: Any):
    """The wire path on ``machine`` and its G-code; raises before anything is written."""
    path = hw.wire_paths(mesh, **options)
    if machine.wire_length is not None:
        _, k = hm.machine_unit(unit)
        axis = hw.AXES[path.span]
        lo, hi = mesh.bounding_box()[:, axis]
        length = machine.wire_length / k
        if hi - lo > length * (1 + ROUNDING):
            raise GeometryError(
                f"the hot-wire cut does not fit the machine: it needs a wire length of at least "
                f"{(hi - lo) * k:.1f} (the machine has {machine.wire_length:g}); nothing written")
        c = 0.5 * (lo + hi)
        path = hw.wire_paths(mesh, **{**options, "span": path.span},
                             planes=(c - length / 2, c + length / 2))
    return path, hw.gcode(path, units=unit, machine=machine)


def _checked_hotwire(mesh: Mesh, unit: str, hotwire: bool | None, machine: hm.Machine | None,
                     notes: list[str], *, feed: float, **options: Any) -> tuple[Any, str | None]:
    """Hot-wire path and G-code, computed before any file is written (or a note why not).

    ``hotwire=True`` or a given ``machine`` make a refusal an error; by default it is a note.
    """
    if hotwire is not False and len(mesh.members):
        try:
            return _hotwire(mesh, unit, machine or hm.Machine(feed=feed), **options)
        except GeometryError as exc:
            if hotwire or machine is not None:
                raise
            notes.append(f"hot-wire paths skipped: {exc}")
    elif hotwire and not len(mesh.members):
        raise GeometryError("the mesh has no generators (members) to cut along")
    return None, None


def _sheet_summary(lay: Any, unit: str) -> dict[str, Any]:
    return {"count": lay.n_sheets, "size": lay.sheet_size.tolist(), "gap": lay.gap,
            "unit": unit, "nesting": lay.method, "panel_area": lay.panel_area(),
            "utilisation": lay.utilisation(), "utilisation_trimmed": lay.utilisation_trimmed()}


def _layout(unrolled: Any, sheet: Any, gap: float | None, unit: str, nesting: str,
            seconds: int, notes: list[str]) -> Any:
    if nesting == "auto" and not _spyrrow_available():
        notes.append("sheets packed by shelves: true-shape nesting needs spyrrow "
                     "(pip install 'ruledmesh[nesting]')")
    return layout(unrolled, sheet, gap=gap, units=unit, method=nesting, seconds=seconds)


def _panel_table(mesh: Mesh, unrolled: Any, lay: Any, tolerances: dict[str, Any]) -> dict[str, Any]:
    """The ``panels.csv`` columns: congruence classes and the place of each panel on its sheet."""
    classes = congruence_classes(mesh, unrolled=unrolled, **tolerances)
    table = panel_table(mesh, unrolled=unrolled, classes=classes)
    table.update({"sheet": lay.sheet + 1, "sheet_x": lay.offset[:, 0], "sheet_y": lay.offset[:, 1],
                  "rotation_deg": np.degrees(lay.rotation)})
    return table


def _write_hotwire(put: Any, path: Any, program_text: str, unit: str,
                   machine: hm.Machine) -> dict[str, Any]:
    put("hotwire.csv", csv_bytes(hw.path_table(path)))
    put("hotwire.gcode", program_text.encode("ascii"))
    return _wire_summary(path, unit, machine)


def fabricate(mesh: Mesh, folder: str | os.PathLike, *, sheet: tuple[float, float] | None = None,
              gap: float | None = None, unit: str | None = None, decimals: int = 3,
              length_tol: float | None = None, angle_tol: float = CONGRUENCE_ANGLE_DEG, dxf: bool | None = None,
              hotwire: bool | None = None, span: str = "auto", up: str | None = None,
              kerf: float = 0.0, kerf_side: str = "left", feed: float = 300.0,
              machine: hm.Machine | None = None, nesting: str = "auto", nest_seconds: int = 2,
              tool: float | None = None, require_planar: bool = True,
              tol: Tolerances = DEFAULT, progress: Progress | None = None) -> dict[str, Any]:
    """Write the fabrication files of ``mesh`` into ``folder`` (created if missing).

    Parameters
    ----------
    mesh : Mesh
    folder : path-like
    sheet : (width, height), optional
        Sheet size in mesh units (default: one square sheet that fits all).
    gap : float, optional
        Clearance between panels and from the sheet border (default ``tool``).
    unit : str, optional
        The mesh unit (``"mm"``, ``"cm"``, ``"m"``, ``"in"``, ``"ft"``) for
        SVG/DXF sizes and G-code; default :attr:`Mesh.units <ruledmesh.mesh.Mesh.units>`.
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
    nesting : {"auto", "true-shape", "shelf"}
        Sheet packer (see :mod:`.nesting`); ``"auto"``: true-shape when
        ``spyrrow`` is installed, else shelf packing (with a note).
    nest_seconds : int
        Time budget of the true-shape nesting per sheet (a sheet takes one or
        two solves).
    tool : float, optional
        Diameter or kerf of the sheet cutter, mesh units (default 3 mm).
    machine : Machine, optional
        The hot-wire machine (travel, wire length, tilt, feed, lead, clearance
        in G-code units); a cut it cannot run is refused before anything is
        written.  Default: no limits, ``feed``.
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

    unit, progress = unit or mesh.units, progress or SILENT
    # Not a ``with``: the caller closes what an error leaves open (TerminalProgress.close).
    task = stages(progress, "fabricate", ["unroll", "hot wire", "layout", "labels", "classes"])
    unrolled = unroll(mesh, require_planar=require_planar, tol=tol)
    task.advance(note="hot wire")
    # Everything that can refuse runs before the first file is written, the quick
    # checks before the nesting search.
    path, program_text = _checked_hotwire(mesh, unit, hotwire, machine, notes, feed=feed, span=span,
                                          up=up, kerf=kerf, kerf_side=kerf_side, tol=tol)
    task.advance(note="layout")
    lay = _layout(unrolled, sheet, tool if gap is None else gap, unit, nesting, nest_seconds, notes)
    task.advance(note="labels")
    labels = panel_labels(lay, decimals=decimals)
    task.advance(note="classes")
    tolerances = {"length_tol": length_tol if length_tol is not None
                  else DEFAULT.degenerate * (mesh.diagonal() or 1.0), "angle_tol": angle_tol}
    table = _panel_table(mesh, unrolled, lay, tolerances)
    task.advance()
    task.close()
    (folder / "sheets").mkdir(parents=True, exist_ok=True)
    _write_sheets(put, lay, labels, unit=unit, decimals=decimals, dxf=bool(_want_dxf(dxf, notes)),
                  progress=progress)
    _write_schedules(put, mesh, table, progress)
    wire: dict[str, Any] | None = None
    if path is not None and program_text is not None:
        wire = _write_hotwire(put, path, program_text, unit, machine or hm.Machine(feed=feed))
    summary = {
        "panels": panel_statistics(mesh, table=table, **tolerances),
        "sheets": _sheet_summary(lay, unit),
        "max_out_of_plane": float(unrolled.out_of_plane.max()) if mesh.n_faces else 0.0,
        "hotwire": wire, "notes": notes, "files": written + ["summary.json"],
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
