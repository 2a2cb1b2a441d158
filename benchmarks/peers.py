"""The planarisation tools designers use today, run on the naive grid.

Every peer takes the parameter-grid quad mesh ``(V, F)`` and returns moved
vertices ``W`` (same order).  Each configuration is a real call of the peer's
own code: its documented defaults, and more iterations.  Runs happen in a
child process with a time limit, so a slow, crashing or hanging solver costs
at most the limit and is reported as such.

The time of a run is measured inside the child, from our arrays to the
peer's output as an array (building the peer's own mesh object and any
constraint set-up included, imports excluded).
"""

from __future__ import annotations

import multiprocessing as mp
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Peer", "PEERS", "available", "run_peer"]


# ------------------------------------------------------------------ the adapters
def _libigl(V, F, max_iter=100, threshold=0.005):
    import igl

    return np.asarray(igl.planarize_quad_mesh(np.ascontiguousarray(V, np.float64),
                                              np.ascontiguousarray(F, np.int64),
                                              max_iter, threshold))


def _compas(V, F, kmax=100):
    # COMPAS's own (pure Python) planariser; compas.geometry.quadmesh_planarize
    # is only a plugin point that needs compas_libigl.
    from compas.datastructures import Mesh
    from compas.geometry.quadmesh_planarize_none import mesh_planarize_faces

    mesh = Mesh.from_vertices_and_faces(V.tolist(), F.tolist())
    mesh_planarize_faces(mesh, kmax=kmax)
    return np.array([mesh.vertex_coordinates(v) for v in mesh.vertices()])


def _shapeop(V, F, iterations=10, plane_weight=1e5, closeness_weight=1e5):
    # Plane constraint per face plus closeness to the initial position of every
    # vertex (Bouaziz et al.); weights default to the ones compas_shapeop documents.
    from compas_shapeop.shapeop import Solver

    s = Solver()
    s.points = V
    for f in F.tolist():
        s.add_plane_constraint(f, plane_weight)
    s.add_closeness_constraints(list(range(len(V))), closeness_weight)
    s.init()
    s.solve(iterations)
    return np.array(s.points)


def _mpfp(V, F, optimization_rounds=50, max_iterations=10):
    import mpfp

    st = mpfp.MakePlanarSettings()
    st.verbose = False
    st.optimization_rounds = optimization_rounds
    st.max_iterations = max_iterations
    out = mpfp.make_planar_faces(list(V), F.tolist(), [], st)
    return np.asarray(out, dtype=np.float64).reshape(-1, 3)


@dataclass(frozen=True)
class Peer:
    """One configuration of one tool."""

    name: str             # unique per configuration, used as the method name
    tool: str             # the PyPI distribution
    module: str           # what to import to know it is there
    call: str             # the function called, for the docs
    config: str           # "default", "more iterations", ...
    fn: Callable
    kwargs: dict = field(default_factory=dict)


PEERS: list[Peer] = [
    Peer("libigl-default", "libigl", "igl", "igl.planarize_quad_mesh", "maxIter=100, threshold=0.005 (defaults)",
         _libigl),
    Peer("libigl-1000it", "libigl", "igl", "igl.planarize_quad_mesh", "maxIter=1000, threshold=1e-9",
         _libigl, {"max_iter": 1000, "threshold": 1e-9}),
    Peer("compas-default", "compas", "compas", "compas mesh_planarize_faces", "kmax=100 (default)", _compas),
    Peer("compas-1000it", "compas", "compas", "compas mesh_planarize_faces", "kmax=1000", _compas,
         {"kmax": 1000}),
    Peer("shapeop-default", "compas_shapeop", "compas_shapeop", "compas_shapeop Solver (plane + closeness)",
         "plane 1e5, closeness 1e5, solve(10) (defaults)", _shapeop),
    Peer("shapeop-1000it", "compas_shapeop", "compas_shapeop", "compas_shapeop Solver (plane + closeness)",
         "plane 1e5, closeness 1e5, solve(1000)", _shapeop, {"iterations": 1000}),
    Peer("shapeop-planar-first", "compas_shapeop", "compas_shapeop",
         "compas_shapeop Solver (plane + closeness)", "plane 1e5, closeness 1, solve(1000)", _shapeop,
         {"iterations": 1000, "closeness_weight": 1.0}),
    Peer("mpfp-default", "mpfp", "mpfp", "mpfp.make_planar_faces",
         "50 rounds x 10 iterations, closeness 5 (defaults)", _mpfp),
    Peer("mpfp-100rounds", "mpfp", "mpfp", "mpfp.make_planar_faces", "100 rounds x 20 iterations",
         _mpfp, {"optimization_rounds": 100, "max_iterations": 20}),
]


def available() -> tuple[dict[str, str], dict[str, str]]:
    """Installed tools (tool -> version) and missing ones (tool -> first error line)."""
    import importlib
    from importlib import metadata

    ok, missing = {}, {}
    for tool, module in {p.tool: p.module for p in PEERS}.items():
        try:
            importlib.import_module(module)
            ok[tool] = metadata.version(tool)
        except Exception as exc:  # noqa: BLE001 - any import failure means the peer cannot run here
            missing[tool] = (f"{type(exc).__name__}: {exc}".splitlines() or [""])[0]
    return ok, missing


def _child(conn, fn, V, F, kwargs) -> None:
    try:
        t0 = time.perf_counter()
        W = fn(V, F, **kwargs)
        seconds = time.perf_counter() - t0
        conn.send(("ok", np.asarray(W, dtype=np.float64), seconds))
    except BaseException as exc:  # noqa: BLE001 - report any failure of the peer to the parent
        conn.send(("error", (f"{type(exc).__name__}: {exc}".splitlines() or [""])[0],
                   traceback.format_exc(limit=2)))
    finally:
        conn.close()


def run_peer(peer: Peer, V: np.ndarray, F: np.ndarray, timeout: float) -> dict[str, Any]:
    """Run one peer configuration in a child process.

    Returns
    -------
    dict
        ``{"status": "ok", "vertices": W, "seconds": s}``, or
        ``{"status": "error" | "timeout", "reason": str}``.
    """
    ctx = mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(child, peer.fn, V, F, peer.kwargs), daemon=True)
    proc.start()
    child.close()
    try:
        if parent.poll(timeout):
            msg = parent.recv()
        else:
            msg = None
    except EOFError:
        msg = ("error", f"the process died (exit code {proc.exitcode})", "")
    finally:
        if proc.is_alive():
            proc.kill()
        proc.join()
    if msg is None:
        return {"status": "timeout", "reason": f"no result within {timeout:g} s (killed)"}
    if msg[0] == "ok":
        W = msg[1]
        if W.shape != V.shape:
            return {"status": "error", "reason": f"returned {W.shape} vertices for {V.shape}"}
        return {"status": "ok", "vertices": W, "seconds": float(msg[2])}
    return {"status": "error", "reason": msg[1]}
