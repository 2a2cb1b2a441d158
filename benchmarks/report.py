"""Render a benchmark JSON as the Markdown of docs/benchmarks.md.

    python benchmarks/report.py RESULTS.json [--plot PATH-IN-DOCS] [--notes NOTES.md ...] > docs/benchmarks.md

Every figure in the output comes from the JSON; ``--notes`` appends a
hand-written reading of the run.  docs/benchmarks.md is made as::

    python benchmarks/report.py docs/benchmarks.json --plot benchmarks.png \
        --notes benchmarks/reading.md --notes benchmarks/measured.md > docs/benchmarks.md

(``reading.md``: the reading of this run; ``measured.md``: the later measurements with
scripts of their own, each stating its machine and load.)
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from peers import PEERS  # noqa: E402
from surfaces import SURFACES  # noqa: E402


def _e(x) -> str:
    return "-" if x is None else f"{x:.2e}"


def _g(x, unit="") -> str:
    return "-" if x is None else f"{x:.3g}{unit}"


def render(r: dict, plot: str | None = None) -> str:
    m = r["machine"]
    out = ["# Benchmarks", "",
           "ruledmesh builds planar quad meshes by construction; today a designer optimises a quad "
           "mesh instead. This page compares the two on the same surfaces, measured in one run of "
           "`python benchmarks/run.py --json FILE` "
           f"(mode `{r['mode']}`, {r['seconds_total']:.0f} s), and measures ruledmesh against "
           "the memory-bound limit. It is generated from the run's JSON by `benchmarks/report.py`.",
           "", "## Machine", "",
           f"- {m['nproc']} CPUs: {m['cpu']}; {m['ram_gib']} GiB RAM; {m['platform']}",
           f"- Python {m['python']}, numpy {m['numpy']}, scipy {m['scipy']}; peers: "
           + (", ".join(f"{k} {v}" for k, v in r["peers_installed"].items()) or "none"),
           f"- load average (1, 5, 15 min) at start {tuple(round(x, 2) for x in m.get('loadavg_1_5_15') or ())}, "
           f"at end {tuple(round(x, 2) for x in m.get('loadavg_at_end') or ())}: the machine was "
           "shared with other jobs, so times carry that noise (medians of repeats throughout).",
           ""]
    out += ["## Goals", "", "| goal | target | measured | |", "|---|---|---|---|"]
    names = {"planarity_max": "max face planarity, ruledmesh (all surfaces, sizes)",
             "displacement_max_quadrics": "max vertex distance from the quadric / diagonal, ruledmesh",
             "latency_100x100_ms": "100 x 100 build + trim + analysis (ms)",
             "ratio_1000x1000_to_bilinear": "1000 x 1000 build / numpy bilinear grid",
             "scaling_exponent": "time ~ faces^k, 1e3..3e6 faces"}
    for k, g in r["goals"].items():
        target = (f"{g['goal'][0]} .. {g['goal'][1]}" if isinstance(g["goal"], list)
                  else f"<= {g['goal']:g}")
        meas = g["measured"]
        meas = f"{meas:.3g}" if isinstance(meas, float) else str(meas)
        out.append(f"| {names.get(k, k)} | {target} | {meas} | {'met' if g['met'] else '**missed**'} |")
    out.append("")
    if plot:
        out += [f"![planarity vs displacement and time per method; scaling]({plot})", ""]
    out += ["## Surfaces and methods", ""]
    for s in SURFACES.values():
        out.append(f"- **{s.name}**: {s.description}.")
    out += ["",
            "Every method starts from the same design. The peers get the naive parameter-grid quad "
            "mesh `a_i + t_j (b_i - a_i)` (n x n vertices, all on the surface, quads not planar); "
            "ruledmesh gets the n generators and builds `pq_mesh(a, b, rows=n, trim=True)` "
            "(its face count differs: see the table). Planarity is the paper's measure for quads "
            "(distance between the diagonal lines / mean diagonal length; border polygons of "
            "ruledmesh by best-fit plane / diameter; triangles 0). Displacement is the largest "
            "distance of a vertex from the design surface divided by the patch's bounding-box "
            "diagonal: exact foot points on the quadrics, "
            "`RuledReference` (distance to the patch) on the skew surface. Seconds: ruledmesh's "
            "build from the generators (median); a peer's run from our arrays to its output "
            "(its own mesh/constraint set-up included, one run, in a child process with a time "
            "limit). `digits/s` is log10(naive grid's max planarity / reached max planarity) per "
            "second. `quads` is the share of the mesh area in four-cornered faces and `min ang` "
            "the smallest interior angle of any face (degrees); the JSON rows also count the "
            "splinters (faces with an angle below 3 degrees). The peers keep the grid's quads, so "
            "their share is 100 % by construction: what they give up is planarity, where ruledmesh "
            "gives up area to triangles.", "", "| method | tool call | configuration |", "|---|---|---|",
            "| ruledmesh | `ruledmesh.pq.pq_mesh` | rows = n, trim, automatic extension |"]
    for p in PEERS:
        out.append(f"| {p.name} | `{p.call}` | {p.config} |")
    out += ["", "## Side by side", "",
            "| method | surface | n | faces | planarity max | planarity mean | displacement max "
            "| quads | min ang | seconds | digits/s |", "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    rows = sorted(r["methods"], key=lambda x: (x["surface"], x["size"], x["tool"] != "ruledmesh",
                                               x["name"]))
    for x in rows:
        out.append(f"| {x['name']} | {x['surface']} | {x['size']} | {x['faces']} | "
                   f"{_e(x['planarity_max'])} | {_e(x['planarity_mean'])} | "
                   f"{_e(x['displacement_max'])} | {_share(x.get('quad_area_share'))} | "
                   f"{_deg(x.get('min_angle_deg'))} | {_g(x['seconds'])} | "
                   f"{_g(x['planarity_digits_per_second'])} |")
    out += ["", "The naive grids the peers started from:", "",
            "| surface | n | planarity max | planarity mean | displacement max |",
            "|---|---:|---:|---:|---:|"]
    for x in r["inputs"]:
        out.append(f"| {x['surface']} | {x['size']} | {_e(x['planarity_max'])} | "
                   f"{_e(x['planarity_mean'])} | {_e(x['displacement_max'])} |")
    if r["failures"]:
        out += ["", "Runs that gave no result:", ""]
        for f in r["failures"]:
            out.append(f"- {f['name']} on {f['surface']} {f['size']} x {f['size']}: "
                       f"{f['status']}: {f['reason']}")
    if r["skipped"]:
        out += ["", "Peers that could not be installed or imported:", ""]
        for s in r["skipped"]:
            out.append(f"- {s['tool']}: {s['reason']}")
    else:
        out += ["", "Every peer installed from PyPI and ran (libigl, compas, compas_shapeop, mpfp). "
                "Kangaroo2 and EvoluteTools run inside Rhino only and are not compared."]
    lat = r["latency"]
    out += ["", "## Live-design latency (100 x 100)", "",
            "| surface | faces | build + trim + `analyze()` ms | build ms | `analyze()` ms | "
            "build + planarity + convexity ms |", "|---|---:|---:|---:|---:|---:|"]
    for name, L in lat.items():
        out.append(f"| {name} | {L['faces']} | {L['ms']:.2f} | {L['build_ms']:.2f} | "
                   f"{L['analysis_ms']:.2f} | {L['live_ms']:.2f} |")
    out += ["", "The headline `latency_100x100_ms` is the skew surface's first column; "
            "`analyze()` is the full analysis report without a reference surface."]
    out += ["", "## Against the bilinear grid (1000 x 1000)", "",
            "| surface | mesh vertices | faces | build s | bilinear grid, same vertices, ms | ratio "
            "| ratio to the n x n grid |", "|---|---:|---:|---:|---:|---:|---:|"]
    for name, q in r["ratio"].items():
        out.append(f"| {name} | {q['mesh_vertices']} | {q['mesh_faces']} | {q['build_s']:.3f} | "
                   f"{q['bilinear_s'] * 1e3:.1f} | {q['ratio']:.1f} | {q['ratio_to_nominal_grid']:.1f} |")
    out += ["", "The bilinear grid is numpy's `a[:, None] + t[None, :, None] * (b - a)[:, None]` with "
            "as many points as the built mesh has vertices (the memory-bound limit: one broadcast, "
            "nothing decided); the headline ratio is the skew surface's."]
    out += ["", "## Scaling (skew surface, n generators x n rows)", "",
            "| n | faces | build s | peak memory MiB | bytes/face | bilinear grid ms | ratio |",
            "|---:|---:|---:|---:|---:|---:|---:|"]
    for p in r["scaling"]["points"]:
        out.append(f"| {p['generators']} | {p['faces']} | {p['seconds']:.4g} | "
                   f"{p['peak_bytes'] / 2**20:.1f} | {p['bytes_per_face']:.0f} | "
                   f"{p['bilinear_seconds'] * 1e3:.3g} | {p['ratio_to_bilinear']:.1f} |")
    out += ["", f"Fitted exponent of time ~ faces^k: k = {r['scaling_exponent']:.3f} over all points, "
            f"{r['scaling_exponent_above_5e4_faces']:.3f} above 5e4 faces; peak memory "
            f"~ faces^{r['memory_exponent']:.3f} (tracemalloc, separate run).", ""]
    return "\n".join(out)


def _share(x) -> str:
    """An area share as a percentage ("-" where the run did not measure it)."""
    return "-" if x is None else f"{100 * x:.1f} %"


def _deg(x) -> str:
    """An angle in degrees ("-" where the run did not measure it)."""
    return "-" if x is None else f"{x:.2f}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("json", type=Path)
    ap.add_argument("--plot", help="path of the plot as the Markdown should link it")
    ap.add_argument("--notes", type=Path, action="append", default=[],
                    help="Markdown appended at the end (repeatable, in order)")
    args = ap.parse_args(argv)
    text = render(json.loads(args.json.read_text()), args.plot)
    for notes in args.notes:
        text += "\n" + notes.read_text()
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
