"""Start-up and generator timings: wall time of fresh processes, generators from curves.

    python benchmarks/startup.py [--label NAME] [--json FILE] [--repeats N]

Start-up: the minimum wall time and CPU time (user + system, less sensitive to other
jobs on the machine) over ``--repeats`` fresh processes of ``python -c "import
numpy"`` (the floor), ``import ruledmesh``, ``ruledmesh --help`` and ``ruledmesh
build examples/skew.toml -o FILE.obj`` (the README's quick start, analysis summary
included), and the ratio of each to the floor; run alternately so load changes hit
all alike.  Generators: the minimum over repeats of ``rulings.between(c1, c2, n,
"arc-length")`` on the director curves of examples/skew.toml (a cubic B-spline and a
polyline), freshly parsed each time so no cached table helps, for designer sizes n = 50
and 100, of ``BSpline.arclength_params(n)`` alone on a fresh curve (table and
inverse), and of it again on the same curve (the inverse alone: Newton on the table)
(CPU time of this process).  The load average is recorded
with the figures (the machine may be shared).  ``--label`` names the run in the JSON,
which keeps the runs already there (e.g. ``before`` and ``after``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SKEW = ROOT / "examples" / "skew.toml"


def _commands(out: str) -> dict[str, list[str]]:
    py = sys.executable
    return {
        "import numpy": [py, "-c", "import numpy"],
        "import ruledmesh": [py, "-c", "import ruledmesh"],
        "ruledmesh --help": [py, "-m", "ruledmesh", "--help"],
        "ruledmesh build skew": [py, "-m", "ruledmesh", "build", str(SKEW), "-o", out],
    }


def _child_cpu() -> float:
    use = resource.getrusage(resource.RUSAGE_CHILDREN)
    return use.ru_utime + use.ru_stime


def startup(repeats: int) -> tuple[dict[str, float], dict[str, float]]:
    """Minimum wall and CPU seconds (user + system) of each command over ``repeats`` rounds.

    The children may write bytecode (as an installed package has it) and a first
    untimed round writes it, so no round times the compiling of the sources.
    """
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    with tempfile.TemporaryDirectory() as tmp:
        cmds = _commands(str(Path(tmp) / "skew.obj"))
        wall = dict.fromkeys(cmds, float("inf"))
        cpu = dict.fromkeys(cmds, float("inf"))
        for cmd in cmds.values():
            subprocess.run(cmd, check=True, capture_output=True, cwd=tmp, env=env)
        for _ in range(repeats):
            for name, cmd in cmds.items():
                c0, t0 = _child_cpu(), time.perf_counter()
                subprocess.run(cmd, check=True, capture_output=True, cwd=tmp, env=env)
                wall[name] = min(wall[name], time.perf_counter() - t0)
                cpu[name] = min(cpu[name], _child_cpu() - c0)
    return wall, cpu


def generators(repeats: int) -> dict[str, float]:
    """Minimum CPU seconds of generators from the skew example's director curves."""
    from ruledmesh.design.curves import curve_from_spec
    from ruledmesh.rulings import between

    spec = tomllib.loads(SKEW.read_text(encoding="utf-8"))["curves"]
    out = {}
    for n in (50, 100):
        best_between = best_params = best_inverse = float("inf")
        for _ in range(repeats):
            c1, c2 = (curve_from_spec(spec[k], k) for k in ("c1", "c2"))
            t0 = time.process_time()
            between(c1, c2, n, "arc-length")
            best_between = min(best_between, time.process_time() - t0)
            c1 = curve_from_spec(spec["c1"], "c1")
            t0 = time.process_time()
            c1.arclength_params(n)
            best_params = min(best_params, time.process_time() - t0)
            # The same curve again: its arc-length table is built, only the inverse is timed.
            t0 = time.process_time()
            c1.arclength_params(n)
            best_inverse = min(best_inverse, time.process_time() - t0)
        out[f"between arc-length {n}"] = best_between
        out[f"bspline arclength_params {n}"] = best_params
        out[f"bspline inverse only {n}"] = best_inverse
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--label", default="run")
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    load = os.getloadavg()
    start, cpu = startup(args.repeats)
    gens = generators(args.repeats * 4)
    floor, cpu_floor = start["import numpy"], cpu["import numpy"]
    run = {"loadavg_start": load, "loadavg_end": os.getloadavg(), "repeats": args.repeats,
           "startup_s": start, "ratio_to_numpy": {k: v / floor for k, v in start.items()},
           "startup_cpu_s": cpu, "cpu_ratio_to_numpy": {k: v / cpu_floor for k, v in cpu.items()},
           "generators_ms": {k: v * 1e3 for k, v in gens.items()}}
    for k, v in start.items():
        print(f"{k:>24}: {v * 1e3:7.1f} ms wall ({v / floor:.2f} x import numpy), "
              f"{cpu[k] * 1e3:7.1f} ms CPU ({cpu[k] / cpu_floor:.2f} x)")
    for k, v in gens.items():
        print(f"{k:>30}: {v * 1e3:7.3f} ms")
    print(f"load average {tuple(round(x, 2) for x in load)} -> "
          f"{tuple(round(x, 2) for x in run['loadavg_end'])}")
    if args.json:
        data = json.loads(args.json.read_text()) if args.json.is_file() else {}
        data[args.label] = run
        args.json.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
