"""Live-speed figures of the public mesher: latency, ratio to a bilinear grid, scaling, memory.

    python benchmarks/live.py [--quick] [--json FILE] [--label NAME]

On the skew surface of the benchmarks (two cubic B-splines, generators at equal
arc length), with ``pq_mesh(a, b, rows=n, trim=True)``:

* ``latency_100x100_ms``: build + :func:`ruledmesh.analysis.planarity` +
  :func:`ruledmesh.analysis.convexity` of 100 generators x 100 rows, the
  minimum CPU time over repeats, with the kernels loaded first
  (:func:`ruledmesh.kernels.load`, what a live application does), and
  ``latency_100x100_numpy_ms`` the same in numpy only;
* ``ratio_1000x1000_to_bilinear``: the 1000 x 1000 build over numpy's bilinear
  grid ``a + t (b - a)`` of the same size, minima of repeats in the same run;
* ``scaling_exponent``: the slope of log CPU time over log faces from about
  1e5 to 3e6 faces (1e5 to 1e6 with ``--quick``);
* ``peak_rss_bytes_per_face``: the peak resident memory of a fresh process
  that imports ruledmesh and builds 1000 x 1000 once, per face; and the same
  less the resident memory of the process before the build; and both again in a
  process that loaded the kernels and built once before (``warm``: what the
  build itself holds, without the one-off cost of loading numba), and in a fresh
  process in numpy only (``numpy``, ``RULEDMESH_KERNELS=0``: whether numba's
  runtime is the floor).

Times are CPU times of this process (``time.process_time``), the least
sensitive to other jobs on a shared machine; the load average is recorded with
them.  ``--label`` names the run in the JSON, which keeps the runs already there.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from surfaces import SURFACES  # noqa: E402

_CHILD = """
import sys
sys.path.insert(0, {here!r})
from surfaces import SURFACES
from ruledmesh.pq import pq_mesh
warm = {warm!r}
if warm:
    try:
        from ruledmesh.kernels import load
        load()
    except ImportError:
        pass
    pq_mesh(*SURFACES["skew"].generators(100), rows=100)
a, b = SURFACES["skew"].generators({n})
with open("/proc/self/status") as f:
    base = int(next(l for l in f if l.startswith("VmRSS")).split()[1]) * 1024
m = pq_mesh(a, b, rows={n}, trim=True)
# VmHWM, not ru_maxrss: the latter keeps the parent's peak across exec.
with open("/proc/self/status") as f:
    peak = int(next(l for l in f if l.startswith("VmHWM")).split()[1]) * 1024
print(m.n_faces, base, peak)
"""


def cpu_min(fn, repeats: int) -> float:
    """Minimum CPU seconds of ``fn()`` over ``repeats`` calls."""
    best = math.inf
    for _ in range(repeats):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def latency(repeats: int) -> dict:
    """100 x 100 build + planarity + convexity, numpy only and with the kernels, same run."""
    from ruledmesh.analysis import convexity, planarity
    from ruledmesh.pq import pq_mesh

    a, b = SURFACES["skew"].generators(100)
    mesh = pq_mesh(a, b, rows=100)
    run = lambda: (planarity(m := pq_mesh(a, b, rows=100, trim=True)), convexity(m))
    build = lambda: pq_mesh(a, b, rows=100, trim=True)
    out = {"faces_100x100": mesh.n_faces, "planarity_max_100x100": float(planarity(mesh).max())}
    saved = os.environ.get("RULEDMESH_KERNELS")
    try:
        os.environ["RULEDMESH_KERNELS"] = "0"
        out["latency_100x100_numpy_ms"] = cpu_min(run, repeats) * 1e3
        out["build_100x100_numpy_ms"] = cpu_min(build, repeats) * 1e3
        try:
            from ruledmesh.kernels import load
        except ImportError:         # a version without kernels
            return {**out, "latency_100x100_ms": out["latency_100x100_numpy_ms"]}
        os.environ["RULEDMESH_KERNELS"] = saved or "auto"
        t0 = time.perf_counter()
        loaded = load()
        out["kernels_load_s"] = time.perf_counter() - t0
        run()                       # first calls (and, on a new machine, compiles)
        out["latency_100x100_ms"] = cpu_min(run, repeats) * 1e3 if loaded else out["latency_100x100_numpy_ms"]
        out["build_100x100_ms"] = cpu_min(build, repeats) * 1e3
    finally:
        if saved is None:
            os.environ.pop("RULEDMESH_KERNELS", None)
        else:
            os.environ["RULEDMESH_KERNELS"] = saved
    return out


def bilinear(a: np.ndarray, b: np.ndarray, n: int) -> np.ndarray:
    t = np.linspace(0.0, 1.0, n)
    return a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]


def ratio(repeats: int) -> dict:
    from ruledmesh.analysis import planarity
    from ruledmesh.pq import pq_mesh

    a, b = SURFACES["skew"].generators(1000)
    build = cpu_min(lambda: pq_mesh(a, b, rows=1000, trim=True), repeats)
    grid = cpu_min(lambda: bilinear(a, b, 1000), repeats * 5)
    mesh = pq_mesh(a, b, rows=1000, trim=True)
    return {"build_1000x1000_s": build, "bilinear_1000x1000_s": grid,
            "ratio_1000x1000_to_bilinear": build / grid, "faces_1000x1000": mesh.n_faces,
            "planarity_max_1000x1000": float(planarity(mesh).max())}


def scaling(sizes: list[int], repeats: int) -> dict:
    from ruledmesh.pq import pq_mesh

    faces, secs = [], []
    for n in sizes:
        a, b = SURFACES["skew"].generators(n)
        faces.append(pq_mesh(a, b, rows=n).n_faces)
        secs.append(cpu_min(lambda a=a, b=b, n=n: pq_mesh(a, b, rows=n, trim=True), repeats))
    k = float(np.polyfit(np.log(faces), np.log(secs), 1)[0])
    return {"scaling_sizes": sizes, "scaling_faces": faces, "scaling_cpu_s": secs, "scaling_exponent": k}


def memory(n: int = 1000) -> dict:
    out = {}
    for key, warm, kernels in (("fresh", False, None), ("warm", True, None), ("numpy", False, "0")):
        code = _CHILD.format(here=str(HERE), warm=warm, n=n)
        env = dict(os.environ)
        if kernels is not None:
            env["RULEDMESH_KERNELS"] = kernels
        run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                             timeout=1800, env=env)
        faces, base, peak = (int(x) for x in run.stdout.split())
        out[f"peak_rss_{key}_bytes"] = peak
        out[f"base_rss_{key}_bytes"] = base
        out[f"peak_rss_{key}_bytes_per_face"] = peak / faces
        out[f"build_rss_{key}_bytes_per_face"] = (peak - base) / faces
        out["faces_memory"] = faces
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--json", type=Path)
    parser.add_argument("--label", default="run")
    args = parser.parse_args(argv)
    load = os.getloadavg()
    sizes = [480, 700, 1000] if args.quick else [480, 700, 1000, 1400, 2000, 2600]
    run = {"loadavg_start": load, "kernels": os.environ.get("RULEDMESH_KERNELS", "auto")}
    run.update(memory())
    run.update(latency(10 if args.quick else 30))
    run.update(ratio(2 if args.quick else 3))
    run.update(scaling(sizes, 1 if args.quick else 2))
    run["loadavg_end"] = os.getloadavg()
    for k, v in run.items():
        print(f"{k:>36}: {v}")
    if args.json:
        data = json.loads(args.json.read_text()) if args.json.is_file() else {}
        data[args.label] = run
        args.json.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
