"""Sheet nesting against the nesting library's own strip packing, in the same run.

    python benchmarks/nesting.py [--quick] [--json FILE]

For each case (panels of a bundled example at 1:1000, i.e. millimetres, on
standard sheets with a 3 mm gap) it times ``layout(method="true-shape")``
(sheet by sheet) and then gives spyrrow's strip packing of the same panels, at
the sheets' usable height, the same total time (at least the per-sheet
budget), and 4 seconds (its budget in earlier releases).  ``ratio`` is the
sheets' trimmed utilisation (the last sheet counted
up to its rightmost panel) over the strip's density (spyrrow's own: panel area
over the usable strip area, so the sheets' border gap counts against them).
The shelf packer runs on the same panels for comparison.  Wall times depend on
the machine's load: the load average is recorded with the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

from ruledmesh.design import build_file
from ruledmesh.fabricate.nesting import layout
from ruledmesh.fabricate.true_shape import panel_areas, strip_pack
from ruledmesh.fabricate.unroll import unroll

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
GAP = 3.0
# (example, number of panels (0: all), sheet)
CASES = [
    ("skew", 120, (2500.0, 1250.0)),
    ("skew", 300, (2500.0, 1250.0)),
    ("skew", 300, (3000.0, 1500.0)),
    ("fig7b-hyperboloid-circular", 0, (2500.0, 1250.0)),
]
QUICK = CASES[:1]


def panels(example: str, count: int):
    """The example's faces in millimetres (1:1000), the first ``count`` of them."""
    mesh = build_file(EXAMPLES / f"{example}.toml").mesh
    mesh = mesh.with_vertices(mesh.vertices * 1000.0, units="mm")
    if count:
        mesh = mesh.select_faces(np.arange(mesh.n_faces) < count).compact()
    return unroll(mesh)


def run_case(example: str, count: int, sheet: tuple[float, float], seconds: int) -> dict:
    """Nest one case sheet by sheet, then strip-pack it for the same time."""
    u = panels(example, count)
    t0 = time.perf_counter()
    lay = layout(u, sheet, gap=GAP, method="true-shape", seconds=seconds)
    t_sheets = time.perf_counter() - t0
    budget = max(seconds, round(t_sheets))
    t0 = time.perf_counter()
    _, _, width = strip_pack(u, sheet[1] - 2 * GAP, GAP, seconds=budget)
    t_strip = time.perf_counter() - t0
    area = float(panel_areas(u).sum())
    strip = area / (width * (sheet[1] - 2 * GAP))
    _, _, width4 = strip_pack(u, sheet[1] - 2 * GAP, GAP, seconds=4)
    strip4 = area / (width4 * (sheet[1] - 2 * GAP))
    shelf = layout(u, sheet, gap=GAP, method="shelf")
    return {"example": example, "panels": u.n_faces, "sheet": list(sheet), "gap": GAP,
            "seconds_per_sheet": seconds, "method": lay.method, "sheets": lay.n_sheets,
            "utilisation": lay.utilisation(), "utilisation_trimmed": lay.utilisation_trimmed(),
            "wall_s": t_sheets, "strip_budget_s": budget, "strip_wall_s": t_strip,
            "strip_density": strip, "ratio": lay.utilisation_trimmed() / strip,
            "strip_density_4s": strip4, "ratio_4s": lay.utilisation_trimmed() / strip4,
            "shelf_sheets": shelf.n_sheets, "shelf_utilisation_trimmed": shelf.utilisation_trimmed()}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the first case only")
    parser.add_argument("--seconds", type=int, default=2, help="solver budget per sheet")
    parser.add_argument("--json", type=Path, help="write the figures here")
    args = parser.parse_args(argv)
    load = os.getloadavg()
    rows = []
    for example, count, sheet in QUICK if args.quick else CASES:
        row = run_case(example, count, sheet, args.seconds)
        rows.append(row)
        print(f"{row['example']:>28} {row['panels']:4d} panels {sheet[0]:g}x{sheet[1]:g}: "
              f"{row['sheets']} sheets, trimmed {row['utilisation_trimmed']:.3f} in "
              f"{row['wall_s']:.1f} s; strip {row['strip_density']:.3f} in {row['strip_wall_s']:.1f} s; "
              f"ratio {row['ratio']:.3f}; strip 4 s {row['strip_density_4s']:.3f}, ratio "
              f"{row['ratio_4s']:.3f}; shelf {row['shelf_utilisation_trimmed']:.3f} "
              f"({row['shelf_sheets']} sheets)", flush=True)
    result = {"loadavg_start": load, "loadavg_end": os.getloadavg(), "nproc": os.cpu_count(),
              "cases": rows}
    print(f"load average {tuple(round(x, 2) for x in load)} -> "
          f"{tuple(round(x, 2) for x in result['loadavg_end'])}; lowest ratio "
          f"{min(r['ratio'] for r in rows):.3f} (same time), {min(r['ratio_4s'] for r in rows):.3f} "
          "(strip 4 s)")
    if args.json:
        args.json.write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
