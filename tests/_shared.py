"""What several test files share: the small design, in one copy.

Importable from any test file as ``import _shared`` (``conftest.py`` makes the helper modules of
``tests/`` importable; the suite runs with ``--import-mode=importlib``, where the tests folder is
not on ``sys.path``).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def bench_module(name: str):
    """The module ``benchmarks/<name>.py`` (not a package), loaded once per test run."""
    key = f"ruledmesh_bench_{name}"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, BENCHMARKS / f"{name}.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[key] = module            # dataclasses look their module up by name
        spec.loader.exec_module(module)
    return sys.modules[key]

__all__ = ["SMALL_DESIGN", "bench_module", "bspline_design", "check_exact", "same_sense_edges", "small_design"]


def small_design(*, name: str = "small", count: int = 9, rows: int = 6) -> str:
    """A small ruled design: ``count`` generators between a B-spline and a polyline, ``rows`` rows.

    Quick to build, with every part of the pipeline in it (curves, rulings, the §4.3 mesher).
    """
    return f"""\
name = "{name}"

[curves.c1]
type = "bspline"
degree = 3
points = [[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]]

[curves.c2]
type = "polyline"
points = [[0, 2, 4], [3, 4, 5], [6, 3, 3], [10, 3, 4]]

[rulings]
between = ["c1", "c2"]
distribution = "parameter"
count = {count}

[mesh]
method = "pq"
rows = {rows}
"""


#: The default :func:`small_design` (nine generators, six rows).
SMALL_DESIGN = small_design()


def bspline_design(c1, c2, count, rows, extra=""):
    """A design between two cubic B-splines through control points ``c1``, ``c2`` (5, 3)."""
    return (f'[curves.c1]\ntype = "bspline"\ndegree = 3\npoints = {np.round(c1, 6).tolist()}\n'
            f'[curves.c2]\ntype = "bspline"\ndegree = 3\npoints = {np.round(c2, 6).tolist()}\n'
            f'[rulings]\nbetween = ["c1", "c2"]\ncount = {count}\n'
            f"[mesh]\nrows = {rows}\n{extra}")


def _segment_distance(p, a, b):
    d = b - a
    s = np.clip(np.einsum("pgi,gi->pg", p[:, None, :] - a[None], d) / np.einsum("gi,gi->g", d, d),
                0.0, 1.0)
    return np.linalg.norm(p[:, None, :] - (a[None] + s[..., None] * d[None]), axis=2)


def check_exact(built, ptol=1e-12):
    """The exact invariants of a §4.3 build: finite, planar, convex, no degenerate face, a
    disc turned one way, every vertex on a generator, the patch's area within 2 %."""
    from ruledmesh.analysis.faces import convexity, degenerate_faces, planarity

    mesh = built.mesh
    assert np.all(np.isfinite(mesh.vertices))
    assert planarity(mesh).max() <= ptol
    assert convexity(mesh).all()
    assert not degenerate_faces(mesh).any()
    assert mesh.euler_characteristic() == 1
    # One orientation: no edge run through twice in the same direction.
    assert same_sense_edges(mesh) == 0
    r = built.rulings
    on = _segment_distance(mesh.vertices, np.asarray(r.a), np.asarray(r.b)).min(axis=1)
    assert on.max() <= 1e-9 * mesh.diagonal()
    patch = built.reference.area()
    assert abs(float(np.sum(_areas(mesh))) / patch - 1.0) < 0.02


def _areas(mesh):
    from ruledmesh.analysis.faces import face_areas

    return face_areas(mesh)


def same_sense_edges(mesh) -> int:
    """Edges two faces run through in the same direction (their normals disagree)."""
    idx = mesh.face_indices.astype(np.int64)
    key = idx * mesh.n_vertices + idx[mesh.next_corners()]
    return int((np.unique(key, return_counts=True)[1] > 1).sum())
