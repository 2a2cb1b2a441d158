"""ruledmesh against the limit: latency, scaling, and the bilinear-grid ratio.

* latency: ``pq_mesh`` (trim on) + :func:`ruledmesh.analysis.report.analyze`
  for 100 generators x 100 rows, median of repeats;
* ratio: the 1000 x 1000 build (``pq_mesh``, trim on) against numpy's
  evaluation of the plain bilinear grid ``a_i + t_j (b_i - a_i)`` with the
  same number of vertices as the built mesh (the memory-bound limit: one
  broadcast, nothing to decide);
* scaling: build time and peak traced memory (tracemalloc, in a separate run
  so tracing does not slow the timed one) from 1e3 to 1e7 faces, and the
  exponent of ``time ~ faces^k`` fitted by least squares in log-log.

The generators are computed before any clock starts: they belong to the
design, not to the mesher.
"""

from __future__ import annotations

import gc
import math
import time
import tracemalloc
from collections.abc import Callable
from functools import partial

import numpy as np

__all__ = ["median_time", "latency", "bilinear_ratio", "scaling", "fit_exponent", "bilinear_grid"]


def median_time(fn: Callable[[], object], *, min_repeats: int = 3, max_repeats: int = 25,
                budget: float = 1.0, warmup: bool = True) -> tuple[float, list[float]]:
    """Median wall time of ``fn()`` in seconds, and all the times.

    Repeats at least ``min_repeats`` times and goes on (up to ``max_repeats``)
    while the total stays under ``budget`` seconds.
    """
    if warmup:
        fn()
    times: list[float] = []
    # As timeit does: one collection first, none while timing (a collection per repeat
    # costs more than the build in a process with a large heap, such as a test run).
    gc.collect()
    enabled = gc.isenabled()
    gc.disable()
    try:
        while len(times) < min_repeats or (len(times) < max_repeats and sum(times) < budget):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
    finally:
        if enabled:
            gc.enable()
    return float(np.median(times)), times


def bilinear_grid(a: np.ndarray, b: np.ndarray, cols: int) -> np.ndarray:
    """(m, cols, 3): the plain ruled/bilinear grid ``a_i + t_j (b_i - a_i)``."""
    t = np.linspace(0.0, 1.0, cols)
    return a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]


def latency(a: np.ndarray, b: np.ndarray, rows: int, *, repeats: int = 30) -> dict:
    """Build + trim + analysis time of one design (medians of ``repeats``).

    ``ms`` is ``pq_mesh`` (trim on) followed by the full analysis report
    (:func:`ruledmesh.analysis.report.analyze`, no reference surface);
    ``live_ms`` replaces the report by what a live view colours faces with
    (planarity and convexity); ``build_ms`` and ``analysis_ms`` are the parts.
    """
    from ruledmesh.analysis.faces import convexity, planarity
    from ruledmesh.analysis.report import analyze
    from ruledmesh.pq import pq_mesh

    def build():
        return pq_mesh(a, b, rows=rows, trim=True)

    def full():
        analyze(build())

    def live():
        mesh = build()
        planarity(mesh)
        convexity(mesh)

    mesh = build()
    med, times = median_time(full, min_repeats=repeats, max_repeats=repeats)
    med_build, _ = median_time(build, min_repeats=repeats, max_repeats=repeats)
    med_live, _ = median_time(live, min_repeats=repeats, max_repeats=repeats)
    med_an, _ = median_time(lambda: analyze(mesh), min_repeats=repeats, max_repeats=repeats)
    return {"ms": med * 1e3, "build_ms": med_build * 1e3, "analysis_ms": med_an * 1e3,
            "live_ms": med_live * 1e3, "min_ms": min(times) * 1e3, "repeats": len(times),
            "generators": len(a), "rows": rows, "faces": mesh.n_faces}


def bilinear_ratio(a: np.ndarray, b: np.ndarray, rows: int, *, repeats: int = 3) -> dict:
    """The pq build against the bilinear grid of the same vertex count."""
    from ruledmesh.pq import pq_mesh

    mesh = pq_mesh(a, b, rows=rows, trim=True)          # also the warm-up
    build, build_times = median_time(lambda: pq_mesh(a, b, rows=rows, trim=True),
                                     min_repeats=repeats, max_repeats=repeats, warmup=False)
    cols = math.ceil(mesh.n_vertices / len(a))
    grid, grid_times = median_time(lambda: bilinear_grid(a, b, cols), min_repeats=max(5, repeats),
                                   max_repeats=max(5, repeats))
    # The same grid at the nominal size (generators x rows), for reference.
    nominal, _ = median_time(lambda: bilinear_grid(a, b, rows), min_repeats=max(5, repeats),
                             max_repeats=max(5, repeats))
    return {"ratio": build / grid, "build_s": build, "bilinear_s": grid,
            "bilinear_vertices": len(a) * cols, "mesh_vertices": mesh.n_vertices,
            "mesh_faces": mesh.n_faces, "ratio_to_nominal_grid": build / nominal,
            "nominal_grid_s": nominal, "generators": len(a), "rows": rows,
            "build_times_s": build_times, "bilinear_times_s": grid_times}


def _peak_memory(fn: Callable[[], object]) -> int:
    gc.collect()
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def scaling(generators: Callable[[int], tuple[np.ndarray, np.ndarray]], sizes: list[int],
            *, log: Callable[[str], None] = lambda s: None) -> list[dict]:
    """Build time and peak memory for ``n`` generators x ``n`` rows, n in ``sizes``."""
    from ruledmesh.pq import pq_mesh

    points = []
    for n in sizes:
        a, b = generators(n)
        mesh = pq_mesh(a, b, rows=n, trim=True)
        faces, verts = mesh.n_faces, mesh.n_vertices
        del mesh
        big = faces > 2e6
        sec, times = median_time(partial(pq_mesh, a, b, rows=n, trim=True),
                                 min_repeats=1 if big else 3, max_repeats=1 if big else 9,
                                 budget=2.0, warmup=False)
        grid_cols = math.ceil(verts / n)
        grid_s, _ = median_time(partial(bilinear_grid, a, b, grid_cols), min_repeats=3, max_repeats=9,
                                budget=1.0, warmup=not big)
        peak = _peak_memory(partial(pq_mesh, a, b, rows=n, trim=True))
        grid_peak = _peak_memory(partial(bilinear_grid, a, b, grid_cols))
        points.append({"generators": n, "rows": n, "faces": faces, "vertices": verts,
                       "seconds": sec, "repeats": len(times), "peak_bytes": peak,
                       "bytes_per_face": peak / max(faces, 1), "bilinear_seconds": grid_s,
                       "bilinear_peak_bytes": grid_peak, "ratio_to_bilinear": sec / grid_s})
        log(f"  scaling n={n}: {faces} faces, {sec * 1e3:.1f} ms, peak {peak / 2**20:.0f} MiB, "
            f"bilinear {grid_s * 1e3:.1f} ms")
    return points


def fit_exponent(x, y) -> float:
    """Least-squares slope of log y against log x (nan with fewer than 2 points)."""
    x, y = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    if len(x) < 2:
        return float("nan")
    return float(np.polyfit(x, y, 1)[0])
