"""Regression tests of the second robustness round (docs/robustness.md).

One test per reproduced defect: deep nesting, special files, work budgets,
messages with control characters, broken pipes, empty or low-coverage meshes,
strict JSON, one planarity measure, and examples that say what they build.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ruledmesh.cli import main
from ruledmesh.errors import (
    DesignError,
    GeometryError,
    ParameterError,
    RuledMeshError,
    printable,
)

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

TWO_LINES = """
[curves.c1]
type = "line"
points = [[0, 0, 0], [4, 0, 0]]
[curves.c2]
type = "line"
points = [[0, 3, 1], [4, 3, -1]]
"""


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def one_error_line(code: int, err: str) -> str:
    """The one bounded, printable error line of a refused command."""
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ruledmesh: error: "), err
    assert "Traceback" not in err and len(lines[0]) <= 2100
    assert lines[0].isprintable(), repr(lines[0])
    return lines[0]


def hyperboloid_lines(m: int = 12) -> tuple[np.ndarray, np.ndarray]:
    phi = np.linspace(0, np.pi, m)
    a = np.stack([np.cos(phi) - np.sin(phi), np.sin(phi) + np.cos(phi), -np.ones(m)], 1)
    b = np.stack([np.cos(phi) + np.sin(phi), np.sin(phi) - np.cos(phi), np.ones(m)], 1)
    return a, b


# ------------------------------------------------------------ loading
@pytest.mark.parametrize("text", [
    "a = " + "{b = " * 400 + "1" + "}" * 400,          # inline tables 400 deep (6 kB)
    "a = " + "[" * 1000 + "]" * 1000,                  # arrays 1000 deep
    "a = " + "[" * 40 + "]" * 40,                      # readable, but deeper than any design
], ids=["tables-400", "arrays-1000", "arrays-40"])
def test_deeply_nested_toml_is_a_design_error_not_recursion(tmp_path, capsys, text):
    path = tmp_path / "deep.toml"
    path.write_text(text)
    code, _, err = run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))
    line = one_error_line(code, err)
    assert "nested" in line and str(path) in line
    assert not (tmp_path / "o.obj").exists()


@pytest.mark.parametrize("command", ["build", "analyze"])
def test_dev_zero_is_refused_before_reading(tmp_path, capsys, command):
    argv = [command, "/dev/zero"] + (["-o", str(tmp_path / "o.obj")] if command == "build" else [])
    line = one_error_line(*run_cli(capsys, *argv)[::2])
    assert "/dev/zero: this is a character device" in line


def test_named_pipe_is_refused_without_blocking(tmp_path, capsys):
    fifo = tmp_path / "design.toml"
    os.mkfifo(fifo)
    line = one_error_line(*run_cli(capsys, "build", str(fifo), "-o", str(tmp_path / "o.obj"))[::2])
    assert "named pipe" in line


def test_rulings_file_dev_zero_says_what_it_is(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text('[rulings]\nfile = "/dev/zero"\n')
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert 'rulings.file: "/dev/zero" is a character device' in line
    assert "no such file" not in line


def test_load_design_api_refuses_special_files():
    from ruledmesh.design import load_design
    from ruledmesh.rulings import from_csv

    with pytest.raises(DesignError, match="character device"):
        load_design("/dev/zero")
    with pytest.raises(DesignError, match="character device"):
        from_csv("/dev/zero")


def test_oversized_design_file_is_refused(tmp_path, capsys):
    from ruledmesh import _files

    path = tmp_path / "big.toml"
    path.write_bytes(b"# " + b"x" * (_files.MAX_DESIGN_BYTES + 10) + b"\n")
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "too large for a design file" in line


# ------------------------------------------------------------ messages
def test_printable_escapes_controls_and_cuts():
    assert printable("a\nb\u202ec\x1b[0m") == "a\\nb\\u202ec\\x1b[0m"
    assert printable("x" * 500) == "x" * 79 + "…"
    assert printable("é ü ∑") == "é ü ∑"


def test_newline_and_rtl_override_in_a_name_stay_on_one_line(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text('[rulings]\nbetween = ["c1", "c2"]\n[curves."x\\ny\\u202e"]\ntype = "lin"\n')
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "x\\ny\\u202e" in line and "\u202e" not in line


def test_huge_user_strings_are_cut(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(f'[surface]\nkind = "{"z" * 100_000}"\n')
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "…" in line and len(line) < 1000


@pytest.mark.parametrize("argv", [["examples"], ["analyze", "examples/skew.toml", "--json"]])
def test_broken_pipe_ends_quietly(argv):
    cmd = [sys.executable, "-m", "ruledmesh", *argv]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT)
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.read(10)
    proc.stdout.close()  # what `| head -c 10` does
    err = proc.stderr.read().decode()
    code = proc.wait(timeout=300)
    assert "Broken pipe" not in err and "Traceback" not in err and "Exception" not in err, err
    assert code in (0, 141)


# ------------------------------------------------------------ work budgets
def test_extend_counts_in_the_design_budget(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(TWO_LINES + '[rulings]\nbetween = ["c1", "c2"]\ncount = 200\n'
                    "[mesh]\nrows = 40\nextend = 1000\ntrim = false\n")
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "mesh.rows: 200 generators x 41 rows x (1 + 2 x extend 1000) would need about" in line
    assert "GiB" in line


def test_hybrid_divisions_count_in_the_design_budget(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(TWO_LINES + '[rulings]\nbetween = ["c1", "c2"]\ncount = 2000\n'
                    '[mesh]\nmethod = "hybrid"\nmidpoints = 100\ndivisions = 100000\n')
    line = one_error_line(*run_cli(capsys, "build", str(path), "-o", str(tmp_path / "o.obj"))[::2])
    assert "mesh.divisions:" in line and "GiB" in line


@pytest.mark.parametrize("kwargs", [{"rows": 10**7}, {"rows": 10**7, "extend": 0},
                                    {"rows": 4 * 10**6}, {"rows": 1000, "extend": 1000}])
def test_pq_mesh_refuses_a_huge_grid_with_its_own_error(kwargs):
    from ruledmesh.pq import pq_mesh

    a, b = hyperboloid_lines(5)
    with pytest.raises(GeometryError, match=r"would need about [\d.]+ GiB \(limit 8 GiB\)"):
        pq_mesh(a, b, **kwargs)


def test_hybrid_and_compound_refuse_huge_grids():
    from ruledmesh.compound import compound_mesh
    from ruledmesh.hybrid import hybrid_mesh

    a, b = hyperboloid_lines(200)
    with pytest.raises(ParameterError, match="GiB"):
        hybrid_mesh(a, b, midpoints=1000, divisions=1000)
    P = np.zeros((4, 4, 3))
    P[..., 0], P[..., 1] = np.meshgrid(np.arange(4.0), np.arange(4.0), indexing="ij")
    with pytest.raises(ParameterError, match="GiB"):
        compound_mesh(P, midpoints=10_000, divisions=100_000)


def test_every_refusal_is_a_ruledmesh_error():
    assert issubclass(GeometryError, RuledMeshError) and issubclass(DesignError, RuledMeshError)
