"""Malformed design files: one line naming the file, the field and what was
expected; exit code 2; no traceback; no output file.

The unknown-key test walks every table of every bundled example (including
``[surface]`` kinds, their profile tables, ``[mesh]`` and ``[[transform]]``),
adds a near-miss of an existing key and expects it reported with the
suggestion.
"""

from __future__ import annotations

import copy
import os
import shutil
import tomllib
from pathlib import Path

import pytest

from ruledmesh.cli import main
from ruledmesh.web.toml_writer import dumps

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))


def run_bad(tmp_path: Path, capsys, text: str | bytes, name: str = "bad.toml") -> str:
    """Build ``text`` written to ``tmp_path/name``; it must fail cleanly.  Returns the line."""
    design = tmp_path / name
    if isinstance(text, bytes):
        design.write_bytes(text)
    else:
        design.write_text(text)
    for csv in (ROOT / "examples").glob("*.csv"):
        shutil.copy(csv, tmp_path)
    target = tmp_path / "out.obj"
    # Run from the folder with the name as a user types it: errors quote the path as typed.
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        code = main(["build", name, "-o", "out.obj"])
    finally:
        os.chdir(cwd)
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert code == 2, (code, err)
    assert "Traceback" not in err and "internal error" not in err
    assert len(err.splitlines()) == 1, err
    assert err.startswith(f"ruledmesh: error: {name}: "), err
    assert not target.exists() and not list(tmp_path.glob(".out.obj*"))
    return err[len("ruledmesh: error: "):]


def _tables(data, path: str = ""):
    """Every (dotted path, table) inside ``data``; arrays of tables as ``name[k]``."""
    if isinstance(data, dict):
        yield path, data
        for key, value in data.items():
            yield from _tables(value, f"{path}.{key}" if path else key)
    elif isinstance(data, list):
        for k, value in enumerate(data):
            yield from _tables(value, f"{path}[{k}]")


def _near_miss_cases():
    for example in EXAMPLES:
        data = tomllib.loads(example.read_text())
        for path, table in _tables(data):
            if path == "curves":        # curve names are free: a new name is a new curve
                continue
            keys = [k for k in table if len(k) > 1]
            if keys:
                yield pytest.param(example, path, keys[0], id=f"{example.stem}:{path or '<top>'}")


@pytest.mark.parametrize("example, path, key", list(_near_miss_cases()))
def test_unknown_key_in_every_table_is_reported_with_a_suggestion(tmp_path, capsys, example,
                                                                  path, key):
    data = tomllib.loads(example.read_text())
    bad = copy.deepcopy(data)
    table = dict(_tables(bad))[path]
    typo = key + key[-1]                                  # "count" -> "countt"
    table[typo] = table[key]
    line = run_bad(tmp_path, capsys, dumps(bad), example.name)
    where = f"{path}.{typo}" if path else typo
    assert line.startswith(f'{example.name}: {where}: unknown key (did you mean "{key}"?)'), line


def test_every_example_round_trips_through_the_writer_unchanged():
    # guards the test above: the TOML writer must not change what it copies
    for example in EXAMPLES:
        data = tomllib.loads(example.read_text())
        assert tomllib.loads(dumps(data)) == data, example.name


SKEW = """[curves.c1]
type = "bspline"
degree = 3
points = [[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]]
[curves.c2]
type = "polyline"
points = [[0, 2, 4], [3, 4, 5], [6, 3, 3], [10, 3, 4]]
[rulings]
between = ["c1", "c2"]
count = 11
"""
TORUS = '[surface]\nkind = "torus"\nR = 3\nr = 1\n[mesh]\nu = 8\nv = 6\n'

# (design text, expected start of the message after "bad.toml: ")
BAD = {
    "count-word": (SKEW.replace("count = 11", 'count = "forty"'),
                   'rulings.count: expected an integer >= 3, got "forty"'),
    "count-float": (SKEW.replace("count = 11", "count = 2.5"),
                    "rulings.count: expected an integer >= 3, got 2.5"),
    "count-bool": (SKEW.replace("count = 11", "count = true"),
                   "rulings.count: expected an integer >= 3, got true"),
    "count-small": (SKEW.replace("count = 11", "count = 2"),
                    "rulings.count: expected an integer >= 3, got 2"),
    "count-missing": (SKEW.replace("count = 11", ""), "rulings.count: missing; expected an integer"),
    "count-huge": (SKEW.replace("count = 11", "count = 99999999999999999"),
                   "rulings.count: expected at most 100000 generators"),
    "points-2d": (SKEW.replace("[0, 2, 4], [3, 4, 5]", "[0, 2], [3, 4, 5]"),
                  "curves.c2.points: expected "),
    "points-string": (SKEW.replace("points = [[0, 2, 4], [3, 4, 5], [6, 3, 3], [10, 3, 4]]",
                                   'points = "abc"'),
                      'curves.c2.points: expected numbers, got "abc"'),
    "points-nan": (SKEW.replace("[6, 3, 3]", "[6, nan, 3]"),
                   "curves.c2.points: expected finite coordinates, got NaN or infinity"),
    "points-inf": (SKEW.replace("[6, 3, 3]", "[6, inf, 3]"),
                   "curves.c2.points: expected finite coordinates, got NaN or infinity"),
    "points-overflow": (SKEW.replace("[6, 3, 3]", "[6, 1e400, 3]"),
                        "curves.c2.points: expected finite coordinates, got NaN or infinity"),
    "degree": (SKEW.replace("degree = 3", "degree = 7"), "curves.c1.degree: expected an integer"),
    "curve-type": (SKEW.replace('type = "bspline"', 'type = "bsplin"'),
                   'curves.c1.type: expected one of'),
    "curve-not-table": (SKEW.replace("[curves.c2]\ntype = \"polyline\"\n", "[curves]\nc2 = 3\n"
                                     ).replace("points = [[0, 2, 4], [3, 4, 5], [6, 3, 3], "
                                               "[10, 3, 4]]\n[rulings]", "[rulings]"),
                        "curves.c2: expected a table, got 3"),
    "between-string": (SKEW.replace('between = ["c1", "c2"]', 'between = "c1"'),
                       'rulings.between: expected two or three curve names, got "c1"'),
    "between-unknown": (SKEW.replace('between = ["c1", "c2"]', 'between = ["c1", "c9"]'),
                        'rulings.between: no curve named "c9" (defined: c1, c2)'),
    "distribution": (SKEW + 'distribution = "arc_length"\n',
                     'rulings.distribution: expected one of'),
    "rulings-missing": (SKEW.split("[rulings]")[0], "rulings: expected a [rulings] table"),
    "rulings-not-table": ("rulings = 3\n", "rulings: expected a table, got 3"),
    "mesh-not-table": ("mesh = 4\n" + SKEW, "mesh: expected a table, got 4"),
    "mesh-method": (SKEW + '[mesh]\nmethod = "hybird"\n',
                    'mesh.method: expected one of "hybrid" | "pq", got "hybird" '
                    '(did you mean "hybrid"?)'),
    "rows-zero": (SKEW + "[mesh]\nrows = 0\n", "mesh.rows: expected an integer >= 1"),
    "rows-string": (SKEW + '[mesh]\nrows = "ten"\n', 'mesh.rows: expected an integer'),
    "option": (SKEW + "[mesh]\noption = 2\n", "mesh.option: expected an integer >= 0 and <= 1"),
    "primary": (SKEW + '[mesh]\nprimary = "centre"\n', 'mesh.primary: expected "middle" or an index'),
    "extend": (SKEW + "[mesh]\nextend = -1\n", "mesh.extend: expected a number >= 0"),
    "trim": (SKEW + '[mesh]\ntrim = "yes"\n', 'mesh.trim: expected true or false, got "yes"'),
    "kind": (TORUS.replace('"torus"', '"torsu"'),
             'surface.kind: expected one of "canal" | '),
    "kind-missing": (TORUS.replace('kind = "torus"\n', ""), "surface.kind: expected one of"),
    "torus-r": (TORUS.replace("r = 1", "r = 4"), "surface."),
    "torus-R-word": (TORUS.replace("R = 3", 'R = "big"'), 'surface.R: expected a number'),
    "u-zero": (TORUS.replace("u = 8", "u = 0"), "mesh.u: expected an integer"),
    "surface-and-rulings": (TORUS + '[rulings]\nbetween = ["a", "b"]\n',
                            "rulings: give either [surface] or [rulings], not both"),
    "transform-not-array": ("transform = 3\n" + TORUS,
                            "transform: expected [[transform]] tables"),
    "transform-type": (TORUS + '[[transform]]\ntype = "rotat"\nangle = 30\n',
                       'transform[0].type: expected one of'),
    "transform-angle": (TORUS + '[[transform]]\ntype = "rotate"\nangle = "thirty"\n',
                        'transform[0].angle: expected a number, got "thirty"'),
    "transform-second": (TORUS + '[[transform]]\ntype = "translate"\nvector = [1, 0, 0]\n'
                         '[[transform]]\ntype = "scale"\nfactor = 0\n',
                         "transform[1].factor: expected non-zero factors"),
    "transform-matrix": (TORUS + '[[transform]]\ntype = "affine"\nmatrix = [[1, 0], [0, 1]]\n',
                         "transform[0].matrix: expected a 3x3 or 3x4 or 4x4 matrix"),
    "lines-shape": ('[rulings]\nlines = [[0, 0, 0], [1, 1, 1]]\n',
                    "rulings.lines: expected at least 2 lines"),
    "file-missing": ('[rulings]\nfile = "nowhere.csv"\n', 'rulings.file: no such file "nowhere.csv"'),
    "two-sources": ('[rulings]\nlines = []\nfile = "x.csv"\n',
                    "rulings.file: give only one of between, lines, file or conoid"),
    # found by tests/test_fuzz.py (docs/robustness.md)
    "fuzz-denormal-normal": (SKEW + 'distribution = "director-plane"\n'
                             "director_plane = [0, 0, 1.7e-298]\n",
                             "rulings.director_plane: expected a vector of length between"),
    "fuzz-point-bspline": (SKEW.replace("points = [[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]]",
                                        "points = [[1, 2, 3], [1, 2, 3], [1, 2, 3], [1, 2, 3]]"),
                           "curves.c1.points: points 0 and 1 coincide"),
    "fuzz-kind-list": (TORUS.replace('kind = "torus"', "kind = []"),
                       "surface.kind: expected one of"),
    "fuzz-method-table": (SKEW + "[mesh]\nmethod = {x = 1}\n", "mesh.method: expected one of"),
    "fuzz-transform-type-number": (TORUS + "[[transform]]\ntype = 3\n",
                                   "transform[0].type: expected one of"),
    "fuzz-linear-bspline-repeat": (SKEW.replace('degree = 3', 'degree = 1').replace(
        "points = [[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]]",
        "points = [[0, 0, 0], [0, 0, 0], [10, 0, 1]]"),
        "curves.c1.points: points 0 and 1 coincide"),
    "fuzz-flat-circle-level": ('[curves.c1]\ntype = "line"\npoints = [[0, 0, 0], [0, 0, 1]]\n'
                               '[curves.c2]\ntype = "helix"\ncenter = [0, 0, 0]\n'
                               "axis = [3, 1, 0]\nradius = 1\npitch = 0\nturns = 1\n"
                               '[rulings]\nbetween = ["c1", "c2"]\ncount = 3\n'
                               'distribution = "director-plane"\ndirector_plane = [3, 1, 0]\n',
                               "director-plane: c1 lies in a plane parallel to the director"),
    "toml-syntax": ("[mesh\nrows = 3\n", "invalid TOML"),
    "toml-duplicate": ("[mesh]\nrows = 3\nrows = 4\n", "invalid TOML"),
    "empty": ("", "rulings: expected a [rulings] table"),
    "unknown-top": ("[rulngs]\ncount = 3\n", 'rulngs: unknown key (did you mean "rulings"?)'),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_schema_error_names_file_field_and_expectation(tmp_path, capsys, case):
    text, expected = BAD[case]
    line = run_bad(tmp_path, capsys, text)
    assert line.startswith(f"bad.toml: {expected}"), line


def test_not_utf8(tmp_path, capsys):
    design = tmp_path / "bad.toml"
    design.write_bytes(b"name = \"\xff\xfe\"\n")
    code = main(["build", str(design), "-o", str(tmp_path / "o.obj")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert "bad.toml: cannot read: 'utf-8' codec can't decode" in err


def test_missing_file_and_directory(tmp_path, capsys):
    for target in (tmp_path / "nothing.toml", tmp_path):
        code = main(["build", str(target), "-o", str(tmp_path / "o.obj")])
        err = capsys.readouterr().err.strip()
        assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
        assert err.startswith("ruledmesh: error: ") and target.name in err


def test_unwritable_output_folder(tmp_path, capsys):
    design = tmp_path / "skew.toml"
    design.write_text(SKEW)
    code = main(["build", str(design), "-o", str(tmp_path / "no" / "such" / "o.obj")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "does not exist" in err, err


def test_unknown_output_format(tmp_path, capsys):
    design = tmp_path / "skew.toml"
    design.write_text(SKEW)
    code = main(["build", str(design), "-o", str(tmp_path / "o.xyz")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and '".xyz"' in err, err
    assert not (tmp_path / "o.xyz").exists()
