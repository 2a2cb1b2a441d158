"""Per-call overhead of the PQ mesher on small and designer-sized builds.

    python benchmarks/overhead.py [--repeats N] [--against SRC] [--json FILE] [--label NAME]

Four cases, each the mesher calls (:func:`ruledmesh.pq.pq_mesh`) that one
build makes, with the arguments the build passes:

* ``tiny``: a 9-generator, 6-row design (B-spline and polyline director curves),
  ``refine = false``: one mesher call, 59 faces;
* ``tiny_refine``: the same design refined (three mesher calls today);
* ``designer_default``: the design the designer opens with (41 generators at
  equal arc length, 40 rows; three mesher calls today);
* ``designer_100x100``: the tiny design at 101 generators x 100 rows, refined (the
  design of the designer's slider-to-frame test; the refinement decides how many
  mesher calls);
* ``skew_100x100``: the benchmark skew surface, 100 generators x 100 rows.

Each case is timed in numpy only and with the compiled kernels
(``ruledmesh.kernels.everywhere``), the minimum CPU time
(``time.process_time``) over the repeats; the load average is recorded.  With
``--against SRC`` (a ``src`` folder of other sources of ruledmesh, e.g. from
``git archive``) the same calls also go through those sources, alternately in
the same process (the two copies are timed against the same load), and their
meshes, vertex data and info must be the same bit for bit.

At these sizes a build is thousands of numpy calls on arrays of a few hundred
numbers: the figures measure per-call overhead, which the printed Python-level
call counts per build (cProfile, independent of the load) follow too.
"""

from __future__ import annotations

import argparse
import cProfile
import importlib
import json
import math
import os
import pstats
import shutil
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from surfaces import SURFACES  # noqa: E402

# The small design of the tests (tests/_shared.py), so the figures follow the design the
# designer tests build.
sys.path.insert(0, str(HERE.parent / "tests"))
from _shared import small_design  # noqa: E402


def _calls(text: str) -> list[tuple[tuple, dict]]:
    """The mesher calls (arguments) of one build of the design ``text``."""
    import ruledmesh.design.pq as design_pq
    from ruledmesh.design import build_design, parse_design

    seen: list[tuple[tuple, dict]] = []
    real = design_pq.pq_mesh

    def spy(*args, **kwargs):
        seen.append((args, kwargs))
        return real(*args, **kwargs)

    design_pq.pq_mesh = spy
    try:
        build_design(parse_design(text))
    finally:
        design_pq.pq_mesh = real
    return seen


def cases() -> dict[str, list[tuple[tuple, dict]]]:
    """Case name -> the mesher calls of its build."""
    from ruledmesh.web.session import DEFAULT_DESIGN

    a, b = SURFACES["skew"].generators(100)
    tiny = small_design()
    return {"tiny": _calls(tiny + "refine = false\n"), "tiny_refine": _calls(tiny),
            "designer_default": _calls(DEFAULT_DESIGN),
            "designer_100x100": _calls(small_design(count=101, rows=100)),
            "skew_100x100": [((a, b), {"rows": 100, "trim": True})]}


def _other_mesher(src: str):
    """``pq_mesh`` of the ruledmesh sources in ``src``, imported as another package."""
    root = Path(tempfile.mkdtemp(prefix="ruledmesh-against-"))
    shutil.copytree(Path(src) / "ruledmesh", root / "ruledmesh_against")
    sys.path.insert(0, str(root))
    return importlib.import_module("ruledmesh_against.skew.pq.mesher").pq_mesh


def _same(m1, m2) -> bool:
    arrays = ("vertices", "face_offsets", "face_indices", "face_kind", "members", "member_id")
    return all(getattr(m1, k).tobytes() == getattr(m2, k).tobytes() for k in arrays) \
        and m1.vertex_data.keys() == m2.vertex_data.keys() \
        and all(np.asarray(m1.vertex_data[k]).tobytes() == np.asarray(m2.vertex_data[k]).tobytes()
                for k in m1.vertex_data) and m1.info == m2.info


def _python_calls(fn) -> int:
    prof = cProfile.Profile()
    prof.enable()
    fn()
    prof.disable()
    return int(pstats.Stats(prof).total_calls)  # type: ignore[attr-defined]


def measure(repeats: int, against: str | None) -> dict:
    """Figures of every case, numpy only and with the kernels."""
    from ruledmesh import kernels
    from ruledmesh.skew.pq.mesher import pq_mesh

    other = _other_mesher(against) if against else None
    out: dict = {"load_average": list(os.getloadavg())}
    for name, calls in cases().items():
        def run(f, calls=calls):
            for args, kwargs in calls:
                f(*args, **kwargs)

        row: dict = {"mesher_calls": len(calls)}
        for mode in ("numpy", "kernels"):
            os.environ["RULEDMESH_KERNELS"] = "0" if mode == "numpy" else "1"
            if mode == "kernels":
                kernels.load()
            meshers = {"ms": pq_mesh} | ({"against_ms": other} if other else {})
            for f in meshers.values():
                run(f)                                # warm: caches, kernels compiled or loaded
            if other:
                for args, kwargs in calls:
                    if not _same(pq_mesh(*args, **kwargs), other(*args, **kwargs)):
                        raise SystemExit(f"{name} ({mode}): the meshes differ from {against}")
            best = dict.fromkeys(meshers, math.inf)
            for _ in range(repeats):
                for key, f in meshers.items():      # alternately: both under the same load
                    t0 = time.process_time()
                    run(f)
                    best[key] = min(best[key], time.process_time() - t0)
            for key, v in best.items():
                row[f"{mode}_{key}"] = round(v * 1e3, 2)
            for key, f in meshers.items():
                calls_key = "python_calls" if key == "ms" else "against_python_calls"
                row[f"{mode}_{calls_key}"] = _python_calls(lambda f=f: run(f))
        os.environ.pop("RULEDMESH_KERNELS", None)
        out[name] = row
    out["load_average_after"] = list(os.getloadavg())
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--repeats", type=int, default=20)
    p.add_argument("--against", help="src folder of other ruledmesh sources to compare with")
    p.add_argument("--json", type=Path)
    p.add_argument("--label", default="run")
    args = p.parse_args(argv)
    warnings.simplefilter("ignore")
    res = measure(args.repeats, args.against)
    for name, row in res.items():
        print(name, row)
    if args.json:
        data = json.loads(args.json.read_text()) if args.json.exists() else {}
        data[args.label] = res
        args.json.write_text(json.dumps(data, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
