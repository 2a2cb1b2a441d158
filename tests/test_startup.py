"""Start-up: which modules ``import ruledmesh``, ``ruledmesh --help`` and a small
``ruledmesh build`` load, read from ``python -X importtime`` in a fresh process.

Times are not asserted (the machine is shared); the figures are in
benchmarks/startup.py and docs/benchmarks.md.  What is guarded is the set of modules:
no scipy, no plotting, no exporter the command does not write.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).parents[1] / "examples"

# Never needed to start, nor for a small build written as OBJ.
HEAVY = ("scipy", "matplotlib", "tqdm", "trimesh", "ezdxf", "rhino3dm", "ifcopenshell",
         "spyrrow", "PIL", "jsonschema", "numba")
LAZY_OURS = ("ruledmesh.render", "ruledmesh.web", "ruledmesh.structure", "ruledmesh.hops",
             "ruledmesh.io.gltf", "ruledmesh.io.ifc", "ruledmesh.io.rhino", "ruledmesh.io.dxf",
             "ruledmesh.io.stl", "ruledmesh.fabricate.nesting", "ruledmesh.fabricate.true_shape",
             "ruledmesh.blender")


# Printed after the code runs: the modules loaded through importlib.import_module (the
# lazy attributes of ruledmesh, the CLI's subcommands, the report's hooks) are not in the
# -X importtime trace, which logs only import statements.
_MODULES = "\nimport json, sys\nprint('@@modules ' + json.dumps(sorted(sys.modules)))"


def imported(code: str, cwd: Path) -> set[str]:
    """Modules a fresh interpreter imports running ``code`` (``-X importtime`` and ``sys.modules``)."""
    run = subprocess.run([sys.executable, "-X", "importtime", "-c", code + _MODULES], capture_output=True,
                         text=True, cwd=cwd, timeout=300, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    names = set()
    for line in run.stderr.splitlines():
        if line.startswith("import time:") and "|" in line and "self [us]" not in line:
            names.add(line.rsplit("|", 1)[1].strip())
    listed = [line for line in run.stdout.splitlines() if line.startswith("@@modules ")]
    assert len(listed) == 1, run.stdout[-2000:]
    names |= set(json.loads(listed[0].split(" ", 1)[1]))
    assert "numpy" in names
    return names


# Parts of numpy a start or a build outside the §4 meshers has no use for: masked arrays
# (numpy's np.unique, np.median and np.percentile import them: 10-25 ms cold) and the
# polynomial classes (the Legendre nodes of the arc-length tables are computed when a
# curve's length is first asked for).
NUMPY_EXTRAS = ("numpy.ma", "numpy.polynomial")


def _offenders(names: set[str], extras: tuple[str, ...] = ()) -> list[str]:
    return sorted(n for n in names if n.split(".")[0] in HEAVY
                  or any(n == m or n.startswith(m + ".") for m in LAZY_OURS + extras))


def test_import_ruledmesh_loads_no_heavy_module(tmp_path):
    names = imported("import ruledmesh", tmp_path)
    assert _offenders(names, NUMPY_EXTRAS) == []
    assert not any(n.startswith(("ruledmesh.pq", "ruledmesh.skew", "ruledmesh.curves")) for n in names)


def test_cli_help_loads_no_heavy_module(tmp_path):
    names = imported("from ruledmesh.cli import main\ntry:\n    main(['--help'])\n"
                     "except SystemExit:\n    pass", tmp_path)
    assert _offenders(names, NUMPY_EXTRAS) == []
    # Help text only: nothing that builds or measures a mesh.
    assert not any(n.startswith(("ruledmesh.analysis", "ruledmesh.design", "ruledmesh.io.", "ruledmesh.pq",
                                 "ruledmesh.skew", "ruledmesh.curves", "ruledmesh.rulings"))
                   for n in names), sorted(n for n in names if n.startswith("ruledmesh."))


@pytest.mark.parametrize("example", ["skew", "fig7b-hyperboloid-circular"])
def test_small_build_loads_no_scipy(tmp_path, example):
    """A bundled design built to OBJ with its analysis summary: numpy only."""
    code = (f"from ruledmesh.cli import main\n"
            f"assert main(['build', {str(EXAMPLES / (example + '.toml'))!r}, '-o', 'm.obj']) == 0")
    names = imported(code, tmp_path)
    assert (tmp_path / "m.obj").is_file()
    assert _offenders(names) == []
    # The command line names its subcommand: the other subcommands' modules stay unloaded.
    from ruledmesh.cli import COMMANDS

    # (build writes its file through export's options)
    others = {f"ruledmesh.cli.{c}" for c in COMMANDS if c not in ("build", "export")}
    assert not others & names, sorted(others & names)


@pytest.mark.parametrize("example", ["fig7b-hyperboloid-circular", "fig8-helicoid", "fig6a-prism", "skew"])
def test_small_build_loads_no_masked_arrays(tmp_path, example):
    """The analysis, the exact constructions and the §4.3 mesher (the README's example) take
    order statistics, unique values and memberships without numpy.ma (ruledmesh._arrays)."""
    code = (f"from ruledmesh.cli import main\n"
            f"assert main(['build', {str(EXAMPLES / (example + '.toml'))!r}, '-o', 'm.obj']) == 0")
    names = imported(code, tmp_path)
    assert _offenders(names, ("numpy.ma",)) == []


QUALITY = Path(__file__).parents[1] / "benchmarks" / "quality"

# numpy.ma replaced by a module that hands out the real one's attributes and notes who asked:
# numpy's own functions ask it whether an array is masked (a plain np.unique, np.isin of many
# values, np.median), so the first frame outside numpy is the code that called them.
_ASKERS = """\
import json, os, sys, traceback, types
import numpy as np
import numpy.ma as _real

_asked = set()


class _Recorder(types.ModuleType):
    def __getattr__(self, name):
        caller = [f for f in traceback.extract_stack()[:-1]
                  if os.sep + "numpy" + os.sep not in f.filename][-1]
        parts = caller.filename.split(os.sep)
        # The innermost package folder of the caller's path (a checkout may sit in a folder
        # named ruledmesh, with scipy installed below it); our own frames with their line.
        unit = next((p for p in reversed(parts) if p in ("ruledmesh", "scipy", "numba")), None)
        if unit == "ruledmesh":
            where = parts[len(parts) - 1 - parts[::-1].index("ruledmesh"):]
            unit = "/".join(where) + f":{caller.lineno}"
        _asked.add(unit or caller.filename)
        return getattr(_real, name)


sys.modules["numpy.ma"] = np.ma = _Recorder("numpy.ma")
"""


@pytest.mark.parametrize("design", ["skew-bspline-b-51x30", "plucker-lines-tol1e-3"])
def test_torsal_and_tolerance_builds_ask_nothing_of_masked_arrays(tmp_path, design):
    """Builds with torsal pairs (skew-bspline-b) and in tolerance mode load numpy.ma all the same:
    scipy's array-API layer imports it with the smooth surface's spline or the analysis' tree, and
    numba's argument typing asks every array whether it is masked.  None of the asking is ours:
    the builds' order statistics, unique values and memberships are ruledmesh._arrays'."""
    code = (_ASKERS + "from ruledmesh.cli import main\n"
            f"assert main(['build', {str(QUALITY / (design + '.toml'))!r}, '-o', 'm.obj', '-q']) == 0\n"
            "np.unique(np.arange(3))  # asked from here: the recorder sees a plain np.unique\n"
            "print('@@asked ' + json.dumps(sorted(_asked)))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                         timeout=300, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    assert (tmp_path / "m.obj").is_file()
    listed = [line for line in run.stdout.splitlines() if line.startswith("@@asked ")]
    assert len(listed) == 1, run.stdout[-2000:]
    asked = set(json.loads(listed[0].split(" ", 1)[1]))
    assert "<string>" in asked, asked
    assert sorted(asked - {"<string>", "scipy", "numba"}) == []
