"""Time of the support structure (node axes, offset layer, beams) against mesh size.

    python benchmarks/structure.py [--sizes 40,100,200] [--json FILE]

For each size ``n`` the skew example is built with ``n + 1`` generators and
``n`` rows; the table gives the vertex count, the time of
:func:`~ruledmesh.structure.support_structure` (auto: the closest parallel
mesh is solved, then the normal axes measured), of the edge beams, and of
their OBJ serialisation, each the best of three runs.
"""

from __future__ import annotations

import argparse
import json
import time
from functools import partial
from pathlib import Path

from ruledmesh.design import build_design, parse_design
from ruledmesh.structure import support_structure
from ruledmesh.structure.beams import edge_beams
from ruledmesh.structure.export import solids_obj

SKEW = Path(__file__).resolve().parent.parent / "examples" / "skew.toml"


def _best(fn, repeats: int = 3) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def run(sizes: list[int]) -> list[dict]:
    rows = []
    for n in sizes:
        text = SKEW.read_text().replace("count = 41", f"count = {n + 1}").replace(
            "rows = 40 ", f"rows = {n} ")
        mesh = build_design(parse_design(text, "skew.toml", SKEW.parent)).mesh
        d, width = 0.05 * mesh.diagonal(), 0.002 * mesh.diagonal()
        t_s, s = _best(partial(support_structure, mesh, d))
        t_b, beams = _best(partial(edge_beams, s, width))
        t_o, _ = _best(partial(solids_obj, beams))
        rows.append({"n": n, "vertices": mesh.n_vertices, "faces": mesh.n_faces,
                     "structure_s": t_s, "beams_s": t_b, "beams_obj_s": t_o,
                     "method": s.method.value})
        print(f"n={n:4d}  vertices={mesh.n_vertices:7d}  structure {t_s:7.3f} s  "
              f"beams {t_b:6.3f} s  beams.obj {t_o:6.3f} s  ({s.method.value})", flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="40,100,200")
    ap.add_argument("--json", help="write the rows as JSON")
    args = ap.parse_args()
    rows = run([int(x) for x in args.sizes.split(",")])
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
