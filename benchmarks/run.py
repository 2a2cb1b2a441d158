"""ruledmesh side by side with the planarisation tools, and against the limit.

    python benchmarks/run.py [--quick | --tiny] [--json FILE] [--plot FILE]

Prints a table and writes a JSON (``latency_100x100_ms``,
``ratio_1000x1000_to_bilinear``, ``scaling_exponent``, ``methods``, and the
details behind them) and a PNG plot (needs matplotlib).  ``--quick`` runs the
peers on 12 x 12 grids with their defaults and the scaling up to 1e5 faces
(under a minute on 2 cores); the full run adds 20 x 20 and 100 x 100 for the
peers with more iterations, ruledmesh up to 1000 x 1000, and scaling to 3e6
faces (2400 x 2400: a grid of 4472 x 4472 is beyond the build's memory budget).
``--tiny`` is a smoke test of every code path in a few seconds.

Sizes: ``n x n`` is ``n`` generators for ruledmesh (``pq_mesh(a, b, rows=n)``)
and an ``n x n`` vertex grid for the peers; the face counts are in the table.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

import limits  # noqa: E402
import peers as peer_mod  # noqa: E402
from surfaces import SURFACES  # noqa: E402

GOALS = {
    "planarity_max": 1e-12,
    "displacement_max_quadrics": 1e-10,
    "ratio_1000x1000_to_bilinear": 3.0,
    "latency_100x100_ms": 2.0,
    "scaling_exponent": (0.9, 1.1),
}

MODES = {
    #          ruledmesh sizes      peer sizes   peer configs   timeout  scaling sizes                  ratio n
    "tiny": {"rm": [8, 12], "peer": [5], "configs": "default", "timeout": 20.0, "scaling": [20, 30], "ratio": 40,
                 "latency_n": 20, "latency_repeats": 3, "ratio_repeats": 1, "peer_surfaces": ["skew"]},
    "quick": {"rm": [12, 20, 100], "peer": [12], "configs": "default", "timeout": 15.0, "scaling": [45, 141, 447],
                  "ratio": 1000, "latency_n": 100, "latency_repeats": 20, "ratio_repeats": 1},
    "full": {"rm": [12, 20, 100, 300, 1000], "peer": [12, 20, 100], "configs": "all", "timeout": 60.0,
                 "scaling": [45, 141, 447, 1414, 2400], "ratio": 1000, "latency_n": 100, "latency_repeats": 50,
                 "ratio_repeats": 3},
}


# ---------------------------------------------------------------------- machine
def machine() -> dict:
    """nproc, CPU model, RAM, Python and numpy versions."""
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    ram = None
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal"):
                ram = round(int(line.split()[1]) / 2**20, 1)
                break
    except OSError:
        pass
    import scipy

    load = os.getloadavg() if hasattr(os, "getloadavg") else None
    return {"nproc": os.cpu_count(), "cpu": cpu, "loadavg_1_5_15": load, "ram_gib": ram,
            "python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
            "platform": platform.platform()}


# ---------------------------------------------------------------------- measures
def _floor(x: float) -> float:
    return max(float(x), 1e-17)


SPLINTER_DEG = 3.0


def _quad_angles(P: np.ndarray) -> np.ndarray:
    """(F,) smallest interior angle, degrees, of quads ``P`` (F, 4, 3)."""
    u = np.roll(P, 1, axis=1) - P
    w = np.roll(P, -1, axis=1) - P
    cos = np.einsum("fkc,fkc->fk", u, w) / np.maximum(
        np.linalg.norm(u, axis=2) * np.linalg.norm(w, axis=2), 1e-300)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).min(axis=1)


def _shape(quad_share: float, min_angles: np.ndarray) -> dict:
    """What a fabricator reads beside planarity: area share in quads, smallest angle, splinters."""
    return {"quad_area_share": float(quad_share),
            "min_angle_deg": float(min_angles.min()) if min_angles.size else 0.0,
            "splinters": int(np.count_nonzero(min_angles < SPLINTER_DEG))}


def _row(name, tool, config, surface, size, faces, plan, disp_max, disp_mean, seconds,
         start_planarity, **extra) -> dict:
    pmax = float(plan.max()) if plan.size else 0.0
    digits = math.log10(_floor(start_planarity) / _floor(pmax))
    return {"name": name, "tool": tool, "config": config, "surface": surface, "size": size,
            "faces": int(faces), "planarity_max": pmax,
            "planarity_mean": float(plan.mean()) if plan.size else 0.0,
            "displacement_max": float(disp_max), "displacement_mean": float(disp_mean),
            "seconds": float(seconds),
            # Orders of magnitude of planarity gained over the naive grid, per second.
            "planarity_digits_per_second": digits / max(seconds, 1e-9), **extra}


def measure_ruledmesh(surface, n: int) -> dict:
    """pq_mesh of n generators x n rows: median build time and its figures."""
    from ruledmesh.analysis.faces import area_shares, face_min_angles, planarity
    from ruledmesh.pq import pq_mesh

    a, b = surface.generators(n)
    mesh = pq_mesh(a, b, rows=n, trim=True)
    sec, times = limits.median_time(lambda: pq_mesh(a, b, rows=n, trim=True), min_repeats=1 if n >= 1000 else 3,
                                    max_repeats=15, budget=1.0, warmup=False)
    plan = planarity(mesh)
    used = np.unique(mesh.face_indices)
    dist = surface.distance(mesh.vertices[used]) / surface.diagonal
    V, F = surface.naive_grid(min(n, 200))
    from ruledmesh.analysis.faces import quad_planarity

    start = quad_planarity(V[F]).max()
    return _row("ruledmesh", "ruledmesh", "pq_mesh(rows=n, trim=True)", surface.name, n,
                mesh.n_faces, plan, dist.max(), dist.mean(), sec, start,
                vertices=mesh.n_vertices, kinds=mesh.count_kinds(), repeats=len(times),
                **_shape(area_shares(mesh)["quads"], face_min_angles(mesh)),
                warnings=list(mesh.info.get("warnings", [])))


def naive_figures(surface, n: int) -> dict:
    from ruledmesh.analysis.faces import quad_planarity

    V, F = surface.naive_grid(n)
    p = quad_planarity(V[F])
    return {"surface": surface.name, "size": n, "faces": len(F), "planarity_max": float(p.max()),
            "planarity_mean": float(p.mean()),
            "displacement_max": float(surface.distance(V).max() / surface.diagonal)}


def measure_peer(peer, surface, n: int, timeout: float) -> tuple[dict | None, dict | None]:
    """(row, None) on success, (None, failure) otherwise."""
    from ruledmesh.analysis.faces import quad_planarity

    V, F = surface.naive_grid(n)
    res = peer_mod.run_peer(peer, V, F, timeout)
    if res["status"] != "ok":
        return None, {"name": peer.name, "tool": peer.tool, "surface": surface.name, "size": n,
                      "status": res["status"], "reason": res["reason"]}
    W = res["vertices"]
    if not np.all(np.isfinite(W)):
        return None, {"name": peer.name, "tool": peer.tool, "surface": surface.name, "size": n,
                      "status": "error", "reason": "non-finite vertices in the output"}
    plan = quad_planarity(W[F])
    dist = surface.distance(W) / surface.diagonal
    start = quad_planarity(V[F]).max()
    return _row(peer.name, peer.tool, peer.config, surface.name, n, len(F), plan, dist.max(),
                dist.mean(), res["seconds"], start, vertices=len(W), call=peer.call,
                # The peers keep the grid's quads (all of the area), bent to near planarity.
                **_shape(1.0, _quad_angles(W[F])),
                moved_max=float(np.linalg.norm(W - V, axis=1).max() / surface.diagonal)), None


# ---------------------------------------------------------------------- output
def format_table(methods: list[dict]) -> str:
    head = (f"{'method':22s} {'surface':22s} {'size':>5s} {'faces':>8s} {'plan max':>9s} "
            f"{'plan mean':>9s} {'disp max':>9s} {'quads':>6s} {'min ang':>7s} {'seconds':>9s} "
            f"{'digits/s':>9s}")
    lines = [head, "-" * len(head)]
    for r in methods:
        lines.append(f"{r['name']:22s} {r['surface']:22s} {r['size']:5d} {r['faces']:8d} "
                     f"{r['planarity_max']:9.2e} {r['planarity_mean']:9.2e} "
                     f"{r['displacement_max']:9.2e} {r.get('quad_area_share', 1.0):6.1%} "
                     f"{r.get('min_angle_deg', float('nan')):7.2f} {r['seconds']:9.3g} "
                     f"{r['planarity_digits_per_second']:9.3g}")
    return "\n".join(lines)


def plot(result: dict, path: Path) -> str | None:
    """Planarity vs displacement and vs time per method, and the scaling."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        return f"no plot: {exc}"
    methods = result["methods"]
    tools = sorted({m["tool"] for m in methods}, key=lambda t: (t != "ruledmesh", t))
    markers = dict(zip(sorted({m["surface"] for m in methods}), "o^s"))
    colours = dict(zip(tools, plt.get_cmap("tab10").colors))
    fig, axes = plt.subplots(1, 3, figsize=(17, 5.2))
    for m in methods:
        kw = {"color": colours[m["tool"]], "marker": markers[m["surface"]], "alpha": 0.8,
                  "s": 20 + 8 * math.log2(max(m["size"], 2)), "edgecolors": "none"}
        axes[0].scatter(_floor(m["displacement_max"]), _floor(m["planarity_max"]), **kw)
        axes[1].scatter(m["seconds"], _floor(m["planarity_max"]), **kw)
    for ax in axes[:2]:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.axhline(GOALS["planarity_max"], color="grey", lw=0.8, ls="--")
        ax.grid(True, which="major", alpha=0.3)
        ax.set_ylabel("max planarity (diagonal gap / mean diagonal)")
    axes[0].set_xlabel("max vertex distance from the design surface / bbox diagonal\n"
                       "(1e-17 stands for 0)")
    axes[1].set_xlabel("seconds (ruledmesh: build; peers: optimisation of the naive grid)")
    handles = [plt.Line2D([], [], color=colours[t], marker="o", ls="", label=t) for t in tools]
    handles += [plt.Line2D([], [], color="k", marker=mk, ls="", label=s) for s, mk in markers.items()]
    axes[0].legend(handles=handles, fontsize=8, loc="center right")
    axes[0].set_title("planarity vs displacement (marker size ~ mesh size)")
    axes[1].set_title("planarity vs time")
    sc = result["scaling"]["points"]
    if sc:
        f = np.array([p["faces"] for p in sc], float)
        ax = axes[2]
        ax.loglog(f, [p["seconds"] for p in sc], "o-", color=colours.get("ruledmesh", "C0"),
                  label=f"ruledmesh build (k = {result['scaling_exponent']:.2f})")
        ax.loglog(f, [p["bilinear_seconds"] for p in sc], "s--", color="grey",
                  label="numpy bilinear grid, same vertices")
        ax2 = ax.twinx()
        ax2.loglog(f, [p["peak_bytes"] / 2**20 for p in sc], "d:", color="C3", label="peak memory")
        ax2.set_ylabel("peak traced memory (MiB)", color="C3")
        ax.set_xlabel("faces")
        ax.set_ylabel("seconds")
        ax.grid(True, which="major", alpha=0.3)
        lines = ax.get_legend_handles_labels()
        l2 = ax2.get_legend_handles_labels()
        ax.legend(lines[0] + l2[0], lines[1] + l2[1], fontsize=8, loc="upper left")
        ax.set_title("scaling")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return None


# ---------------------------------------------------------------------- main
def run(mode: str = "quick", log=print) -> dict:
    cfg = MODES[mode]
    t_start = time.perf_counter()
    result: dict = {"mode": mode, "machine": machine(), "goals": {}}
    installed, missing = peer_mod.available()
    result["peers_installed"] = installed
    result["skipped"] = [{"tool": t, "reason": r} for t, r in missing.items()]
    for t, r in missing.items():
        log(f"skipped {t}: {r}")
    methods, failures, inputs = [], [], []
    # Limits first, on a quiet machine: latency, ratio, scaling (general skew surface).
    skew = SURFACES["skew"]
    a, b = skew.generators(cfg["latency_n"])
    lat = limits.latency(a, b, cfg["latency_n"], repeats=cfg["latency_repeats"])
    lat_all = {"skew": lat}
    if mode == "full":
        for s in SURFACES.values():
            if s.name != "skew":
                lat_all[s.name] = limits.latency(*s.generators(100), 100, repeats=cfg["latency_repeats"])
    log(f"latency {cfg['latency_n']}x{cfg['latency_n']} (build+trim+analysis): {lat['ms']:.2f} ms "
        f"(build {lat['build_ms']:.2f} ms, analysis {lat['analysis_ms']:.2f} ms, build+planarity+"
        f"convexity {lat['live_ms']:.2f} ms)")
    a, b = skew.generators(cfg["ratio"])
    ratio = limits.bilinear_ratio(a, b, cfg["ratio"], repeats=cfg["ratio_repeats"])
    ratio_all = {"skew": ratio}
    if mode == "full":
        for s in SURFACES.values():
            if s.name != "skew":
                ratio_all[s.name] = limits.bilinear_ratio(*s.generators(cfg["ratio"]), cfg["ratio"],
                                                          repeats=cfg["ratio_repeats"])
    log(f"{cfg['ratio']}x{cfg['ratio']} build {ratio['build_s']:.3f} s, bilinear grid "
        f"{ratio['bilinear_s'] * 1e3:.1f} ms: ratio {ratio['ratio']:.1f}")
    points = limits.scaling(skew.generators, cfg["scaling"], log=log)
    faces = [p["faces"] for p in points]
    k = limits.fit_exponent(faces, [p["seconds"] for p in points])
    big = [p for p in points if p["faces"] >= 5e4]
    k_big = limits.fit_exponent([p["faces"] for p in big], [p["seconds"] for p in big])
    k_mem = limits.fit_exponent(faces, [p["peak_bytes"] for p in points])
    log(f"scaling exponent {k:.3f} (>= 5e4 faces: {k_big:.3f}; memory {k_mem:.3f})")
    # ruledmesh on every surface and size.
    for s in SURFACES.values():
        for n in cfg["rm"]:
            methods.append(measure_ruledmesh(s, n))
            log(f"ruledmesh {s.name} {n}x{n}: {methods[-1]['seconds'] * 1e3:.2f} ms")
    # Peers on the naive grid.
    chosen = [p for p in peer_mod.PEERS if p.tool in installed
              and (cfg["configs"] == "all" or p.name.endswith("-default"))]
    for s in SURFACES.values():
        if s.name not in cfg.get("peer_surfaces", SURFACES):
            continue
        for n in cfg["peer"]:
            inputs.append(naive_figures(s, n))
            for p in chosen:
                # More iterations only where they fit in the time budget of the run.
                if n >= 100 and not p.name.endswith("-default"):
                    continue
                row, fail = measure_peer(p, s, n, cfg["timeout"])
                if row:
                    methods.append(row)
                    log(f"{p.name} {s.name} {n}x{n}: {row['seconds']:.3g} s, planarity "
                        f"{row['planarity_max']:.2e}, displacement {row['displacement_max']:.2e}")
                else:
                    failures.append(fail)
                    log(f"{p.name} {s.name} {n}x{n}: {fail['status']}: {fail['reason']}")
    rm = [m for m in methods if m["tool"] == "ruledmesh"]
    quad_rm = [m for m in rm if m["surface"] != "skew"]
    result.update({
        "latency_100x100_ms": lat["ms"] if cfg["latency_n"] == 100 else None,
        "ratio_1000x1000_to_bilinear": ratio["ratio"] if cfg["ratio"] == 1000 else None,
        "scaling_exponent": k,
        "scaling_exponent_above_5e4_faces": k_big,
        "memory_exponent": k_mem,
        "latency": lat_all,
        "ratio": ratio_all,
        "scaling": {"surface": "skew", "points": points},
        "methods": methods,
        "failures": failures,
        "inputs": inputs,
    })
    g = result["goals"]
    g["planarity_max"] = {"goal": GOALS["planarity_max"],
                          "measured": max(m["planarity_max"] for m in rm),
                          "met": all(m["planarity_max"] <= GOALS["planarity_max"] for m in rm)}
    g["displacement_max_quadrics"] = {
        "goal": GOALS["displacement_max_quadrics"],
        "measured": max(m["displacement_max"] for m in quad_rm),
        "met": all(m["displacement_max"] <= GOALS["displacement_max_quadrics"] for m in quad_rm)}
    if result["latency_100x100_ms"] is not None:
        g["latency_100x100_ms"] = {"goal": GOALS["latency_100x100_ms"], "measured": lat["ms"],
                                   "met": lat["ms"] <= GOALS["latency_100x100_ms"]}
    if result["ratio_1000x1000_to_bilinear"] is not None:
        g["ratio_1000x1000_to_bilinear"] = {"goal": GOALS["ratio_1000x1000_to_bilinear"],
                                            "measured": ratio["ratio"],
                                            "met": ratio["ratio"] <= GOALS["ratio_1000x1000_to_bilinear"]}
    lo, hi = GOALS["scaling_exponent"]
    g["scaling_exponent"] = {"goal": [lo, hi], "measured": k, "met": lo <= k <= hi}
    result["seconds_total"] = time.perf_counter() - t_start
    result["machine"]["loadavg_at_end"] = os.getloadavg() if hasattr(os, "getloadavg") else None
    return result


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--quick", action="store_true", help="small peer sizes, scaling to 1e5 faces")
    mode.add_argument("--tiny", action="store_true", help="smoke test of every code path")
    ap.add_argument("--json", type=Path, help="write the results here")
    ap.add_argument("--plot", type=Path, help="PNG plot (default: the JSON path with .png)")
    ap.add_argument("-q", "--silent", action="store_true", help="no progress lines")
    args = ap.parse_args(argv)
    name = "tiny" if args.tiny else "quick" if args.quick else "full"
    log = (lambda s: None) if args.silent else (lambda s: print(s, file=sys.stderr, flush=True))
    result = run(name, log=log)
    print(format_table(result["methods"]))
    for f in result["failures"]:
        print(f"{f['name']} {f['surface']} {f['size']}x{f['size']}: {f['status']}: {f['reason']}")
    for s in result["skipped"]:
        print(f"skipped {s['tool']}: {s['reason']}")
    print()
    for key, goal in result["goals"].items():
        print(f"{key:30s} measured {goal['measured']!s:24.24} goal {goal['goal']!s:12s} "
              f"{'met' if goal['met'] else 'MISSED'}")
    print(f"scaling exponent above 5e4 faces {result['scaling_exponent_above_5e4_faces']:.3f}; "
          f"total {result['seconds_total']:.1f} s")
    plot_path = args.plot or (args.json.with_suffix(".png") if args.json else None)
    if plot_path:
        err = plot(result, plot_path)
        result["plot"] = None if err else str(plot_path)
        if err:
            print(err)
    if args.json:
        args.json.write_text(json.dumps(result, indent=1, default=float) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
