"""Shop-ready hot-wire programs: parsed by gcodeparser and pygcode, checked
against the machine before anything is written."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from ruledmesh.cli import main
from ruledmesh.errors import GeometryError, ParameterError
from ruledmesh.fabricate.hotwire import gcode, wire_paths
from ruledmesh.fabricate.machine import Machine, machine_unit, program
from ruledmesh.io import save
from ruledmesh.mesh import Mesh


def grid(n=7, m=5):
    """Planar parallelogram quads X[i, j] = p_i + q_j; straight generators along q, tilted."""
    s = np.linspace(0.0, 3.0, n)
    t = np.linspace(0.0, 0.8, m)
    p = np.c_[s, np.zeros(n), 0.3 * np.sin(s)]
    q = np.c_[0.3 * t, t, 0.5 * t]
    x = (p[:, None, :] + q[None, :, :]).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(m - 1), indexing="ij")
    a = (i * m + j).ravel()
    faces = np.stack([a, a + m, a + m + 1, a + 1], axis=1)
    start = (np.arange(n)[:, None] * m + np.arange(m - 1)).ravel()
    return Mesh.from_faces(x, faces, members=np.stack([start, start + 1], 1),
                           member_id=np.repeat(np.arange(n), m - 1))


def _moves(text):
    return [ln for ln in text.splitlines() if ln.startswith(("G0 ", "G1 "))]


def test_gcodeparser_reads_only_the_program():
    gcodeparser = pytest.importorskip("gcodeparser")
    path = wire_paths(grid())
    text = gcode(path, units="m")
    parsed = list(gcodeparser.parse_gcode_lines(text))
    code_lines = [ln for ln in text.splitlines() if not ln.startswith(";")]
    # One parsed command per program line: no comment is read as a command.
    assert [p.command_str for p in parsed] == [ln.split()[0] for ln in code_lines]
    for p in parsed:
        if p.command_str in ("G0", "G1"):
            assert set(p.params) <= {"X", "Y", "U", "V", "F"}
    assert sum(p.command_str == "G1" for p in parsed) == path.generator.size + 1


def test_pygcode_reads_only_the_program():
    pygcode = pytest.importorskip("pygcode")
    text = gcode(wire_paths(grid()), units="m")
    for ln in text.splitlines():
        line = pygcode.Line(ln)
        if ln.startswith(";"):
            assert line.block.words == [] and line.comment is not None
        else:
            letters = {w.letter for w in line.block.words}
            assert letters <= {"G", "M", "X", "Y", "U", "V", "F", "P"}
            assert line.comment is None


def test_program_units_lead_and_safe_rapids():
    mesh = grid()
    path = wire_paths(mesh)
    prog = program(path, "m", Machine(lead=20.0, clearance=15.0))
    assert prog.unit == "mm"
    cut = prog.cut
    inner = cut[1:-1]
    np.testing.assert_allclose(np.diff(inner, axis=0), np.diff(np.c_[path.xy, path.uv] * 1000, axis=0),
                               atol=1e-9)
    lo, hi = inner[:, [0, 2]].min(), inner[:, [0, 2]].max()
    # Lead-in start and lead-out end: the wire moved along X/U alike (same tilt), both
    # ends at least the lead outside the cut's extent.
    for end, gen in ((cut[0], cut[1]), (cut[-1], cut[-2])):
        move = end - gen
        assert move[1] == move[3] == 0 and move[0] == pytest.approx(move[2])
        xs = end[[0, 2]]
        assert np.all(xs <= lo - 20 + 1e-9) or np.all(xs >= hi + 20 - 1e-9)
    safe = inner[:, [1, 3]].max() + 15
    # Rapids: up to the safe height, across above the lead-in start, down outside the stock.
    np.testing.assert_allclose(prog.rapid_in[0, [1, 3]], safe)
    np.testing.assert_allclose(prog.rapid_in[1], [cut[0, 0], safe, cut[0, 2], safe])
    np.testing.assert_allclose(prog.rapid_in[2], cut[0])
    np.testing.assert_allclose(prog.rapid_out[0, [1, 3]], safe)
    assert cut[:, [0, 2]].min() >= 0 and cut[:, [1, 3]].min() >= 0
    text = gcode(path, units="ft")
    assert "G20" in text.splitlines() and "G21" not in text.splitlines()
    unit, k = machine_unit("ft")
    assert unit == "in" and k == 12.0


def test_too_small_machine_refused_with_what_it_needs():
    path = wire_paths(grid())
    need = program(path, "m").extent()
    with pytest.raises(GeometryError, match=rf"travel of {need[0]:.1f} x {need[1]:.1f} mm"):
        gcode(path, units="m", machine=Machine(travel=(1000.0, 500.0)))
    tilt = program(path, "m").tilt_deg
    with pytest.raises(GeometryError, match=rf"wire tilt of {tilt:.1f} degrees"):
        gcode(path, units="m", machine=Machine(max_tilt=tilt / 2))
    gcode(path, units="m", machine=Machine(travel=tuple(need + 1), max_tilt=tilt + 1))
    with pytest.raises(ParameterError, match="max_tilt"):
        Machine(max_tilt=120)


def test_cli_refuses_a_cut_the_machine_cannot_run(tmp_path, capsys):
    save(tmp_path / "m.obj", grid())
    out = tmp_path / "fab"
    assert main(["fabricate", str(tmp_path / "m.obj"), "-o", str(out),
                 "--travel", "1000x500"]) == 2
    err = capsys.readouterr().err
    assert re.search(r"needs a travel of [0-9.]+ x [0-9.]+ mm \(the machine has 1000 x 500\)", err)
    assert not out.exists()
    assert main(["fabricate", str(tmp_path / "m.obj"), "-o", str(out), "--wire-length", "500"]) == 2
    assert "wire length of at least 800.0" in capsys.readouterr().err
    assert not out.exists()


def test_cli_machine_fits(tmp_path):
    save(tmp_path / "m.obj", grid())
    out = tmp_path / "fab"
    assert main(["fabricate", str(tmp_path / "m.obj"), "-o", str(out), "--travel", "5000x3000",
                 "--wire-length", "1200", "--max-tilt", "45", "--feed", "250", "--nesting", "shelf",
                 "-q"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    wire = summary["hotwire"]
    assert wire["gcode_unit"] == "mm" and wire["wire_length"] == pytest.approx(1200.0)
    assert wire["planes"][1] - wire["planes"][0] == pytest.approx(1.2)
    text = (out / "hotwire.gcode").read_text()
    assert " F250" in text and "G21" in text.splitlines()
    assert len(_moves(text)) == 3 + (wire["steps"] + 1) + 1
