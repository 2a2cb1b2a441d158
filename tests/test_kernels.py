"""The numba kernels against their numpy references, bit for bit, on random designs.

Each test runs the same stage twice, ``RULEDMESH_KERNELS=0`` (numpy) and ``=1``
(the kernels), and compares every array exactly (NaN where numpy gives NaN).
Also: the kernels' on-disk cache works from a read-only installation.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
from _shared import SMALL_DESIGN  # a helper module of tests/ (see conftest.py)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ruledmesh.analysis import faces
from ruledmesh.pq import pq_mesh
from ruledmesh.skew.pq.runs import Division, mesh_run
from ruledmesh.tolerances import DEFAULT

SETTINGS = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


def both(monkeypatch, fn):
    """``fn()`` with numpy, then with the kernels."""
    monkeypatch.setenv("RULEDMESH_KERNELS", "0")
    ref = fn()
    monkeypatch.setenv("RULEDMESH_KERNELS", "1")
    return ref, fn()


def same(x, y) -> bool:
    x, y = np.asarray(x), np.asarray(y)
    if x.dtype.kind == "f":
        # Bit for bit, zeros' signs included (NaN payloads aside).
        return x.shape == y.shape and bool(np.all((x.view(np.int64) == y.view(np.int64))
                                                  | (np.isnan(x) & np.isnan(y))))
    return x.shape == y.shape and x.dtype == y.dtype and np.array_equal(x, y)


def design(seed: int, m: int, twist: float, wobble: float) -> tuple[np.ndarray, np.ndarray]:
    """Generators of a random skew surface: two wobbly curves, shifted, twisted, scaled."""
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 1.0, m)
    c1 = np.stack([4 * u, wobble * np.sin(3 * u + rng.uniform(0, 6)), rng.uniform(-.2, .2) * u ** 2], 1)
    c2 = np.stack([4 * u + twist * np.cos(2 * u), 1 + wobble * np.cos(2 * u), 1 + twist * u], 1)
    scale = 10.0 ** rng.uniform(-3, 4)
    shift = rng.uniform(-1e3, 1e3, 3)
    return c1 * scale + shift, c2 * scale + shift


@SETTINGS
@given(seed=st.integers(0, 2**31), n=st.integers(1, 300), spread=st.floats(-3, 6))
def test_quad_crossing_and_planarity(monkeypatch, seed, n, spread):
    rng = np.random.default_rng(seed)
    C = rng.standard_normal((n, 4, 3)) * 10.0 ** spread + rng.uniform(-1e4, 1e4, (n, 1, 3))
    k = n // 4
    C[:k, 2] = C[:k, 0]                                     # a zero diagonal
    C[k:2 * k, 3] = C[k:2 * k, 1] + (C[k:2 * k, 2] - C[k:2 * k, 0])   # parallel diagonals
    if n > 2:
        C[-1, 1, 0] = np.nan
    ref, got = both(monkeypatch, lambda: faces.quad_diagonal_crossing(C) + (faces.quad_planarity(C),))
    assert all(same(r, g) for r, g in zip(ref, got))


@SETTINGS
@given(seed=st.integers(0, 2**31), n=st.integers(1, 300), k=st.integers(3, 7), spread=st.floats(-3, 6))
def test_polygon_angles(monkeypatch, seed, n, k, spread):
    """Corner angles of polygons (the flips' and the slivers' measure), repeated corners included."""
    rng = np.random.default_rng(seed)
    C = rng.standard_normal((n, k, 3)) * 10.0 ** spread + rng.uniform(-1e4, 1e4, (n, 1, 3))
    C[: n // 3, 1] = C[: n // 3, 0]                          # a zero edge: zero dot products
    if n > 2:
        C[-1, 1, 0] = np.nan
    ref, got = both(monkeypatch, lambda: faces.polygon_angles(C))
    assert same(ref, got)


@SETTINGS
@given(seed=st.integers(0, 2**31), n=st.integers(3, 80), f=st.integers(0, 200), k=st.integers(3, 5),
       spread=st.floats(-3, 6))
def test_min_corner_angles(monkeypatch, seed, n, f, k, spread):
    """Smallest angles straight from corner indices: repeated and NaN corners included."""
    rng = np.random.default_rng(seed)
    V = rng.standard_normal((n, 3)) * 10.0 ** spread + rng.uniform(-1e4, 1e4, 3)
    V[-1, 1] = np.nan
    F = rng.integers(0, n, (f, k))
    F[: f // 4, 1] = F[: f // 4, 0]
    ref, got = both(monkeypatch, lambda: faces.min_corner_angles(V, F))
    assert same(ref, got)
    assert same(ref, faces.polygon_angles(V[F]).min(axis=1))


@SETTINGS
@given(seed=st.integers(0, 2**31), n=st.integers(4, 60), pairs=st.integers(1, 300), spread=st.floats(-3, 6))
def test_flip_measures(monkeypatch, seed, n, pairs, spread):
    """The flips' measures of triangle pairs: nearly flat ones, repeated and NaN corners included."""
    from ruledmesh.skew.pq.flips import _pair_measures

    rng = np.random.default_rng(seed)
    V = rng.standard_normal((n, 3)) * 10.0 ** spread + rng.uniform(-1e4, 1e4, 3)
    V[: n - 2, 2] = V[0, 2] + 1e-4 * V[: n - 2, 2]          # most of them nearly in a plane
    V[-1, 0] = np.nan
    a, b, c, d = (rng.integers(0, n, pairs) for _ in range(4))
    d[: pairs // 5] = a[: pairs // 5]                        # a == d: never taken
    old = rng.uniform(0.0, 30.0, pairs)
    old[: pairs // 7] = np.nan
    scale = float(100 * 10.0 ** spread)
    ref, got = both(monkeypatch, lambda: _pair_measures(V, a, b, c, d, old, scale))
    assert all(same(r, g) for r, g in zip(ref, got))


def _triangulated_grid(rng, m: int, squash: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of an m x m grid cut along random diagonals, some columns
    squashed together (needles)."""
    x = np.cumsum(rng.uniform(0.0, 1.0, m))
    x[rng.integers(1, m, max(1, m // 3))] -= squash * rng.uniform(0.5, 1.0)
    X, Y = np.meshgrid(x, np.arange(m, dtype=float), indexing="ij")
    V = np.stack([X.ravel(), Y.ravel(), 0.05 * rng.standard_normal(m * m)], axis=1)
    i, j = np.meshgrid(np.arange(m - 1), np.arange(m - 1), indexing="ij")
    a, b, c, d = (i * m + j).ravel(), ((i + 1) * m + j).ravel(), ((i + 1) * m + j + 1).ravel(), \
        (i * m + j + 1).ravel()
    cut = rng.random(a.size) < 0.5
    tri = np.concatenate([np.where(cut[:, None], np.stack([a, b, c], 1), np.stack([a, b, d], 1)),
                          np.where(cut[:, None], np.stack([a, c, d], 1), np.stack([b, c, d], 1))])
    return V, tri


@SETTINGS
@given(seed=st.integers(0, 2**31), m=st.integers(3, 12), squash=st.floats(0.0, 1.0),
       spread=st.floats(-3, 6))
def test_collapse_measures(monkeypatch, seed, m, squash, spread):
    """The collapses' gains and verdicts of every directed edge of a triangle mesh with
    needles, the border's and those the link condition refuses included."""
    from ruledmesh.mesh import FaceKind, Mesh
    from ruledmesh.skew.pq.collapses import _evaluate, _Stars

    rng = np.random.default_rng(seed)
    V, tri = _triangulated_grid(rng, m, squash)
    V = V * 10.0 ** spread + rng.uniform(-1e4, 1e4, 3)
    mesh = Mesh(V, np.arange(0, tri.size + 1, 3), tri.reshape(-1), np.full(len(tri), FaceKind.FILL))
    keys, _ = mesh.edge_uses()
    n = len(V)
    v, u = keys // n, keys % n
    v, u = np.concatenate([v, u]), np.concatenate([u, v])
    faces_at = np.bincount(tri.reshape(-1), minlength=n)
    scale = float(10 * 10.0 ** spread)
    ref, got = both(monkeypatch, lambda: _evaluate(V, tri, _Stars(tri, keys, n), keys, faces_at, v, u, scale))
    assert all(same(r, g) for r, g in zip(ref, got))


@SETTINGS
@given(seed=st.integers(0, 2**31), m=st.integers(3, 12), squash=st.floats(0.0, 1.0),
       ghosts=st.integers(0, 40), spread=st.floats(-3, 6))
def test_ghosts_kept(monkeypatch, seed, m, squash, ghosts, spread):
    """Which collapses keep the vertices removed earlier near a face: ghosts on, beside and
    far from the mesh, several at one anchor."""
    from ruledmesh.mesh import FaceKind, Mesh
    from ruledmesh.skew.pq.collapses import _keeps_ghosts, _Stars

    rng = np.random.default_rng(seed)
    V, tri = _triangulated_grid(rng, m, squash)
    anchors = rng.integers(0, len(V), ghosts)
    G = V[anchors] + rng.standard_normal((ghosts, 3)) * rng.choice([0.0, 1e-4, 1e-2, 1.0], (ghosts, 1))
    shift = rng.uniform(-1e4, 1e4, 3)
    V, G = V * 10.0 ** spread + shift, G * 10.0 ** spread + shift
    mesh = Mesh(V, np.arange(0, tri.size + 1, 3), tri.reshape(-1), np.full(len(tri), FaceKind.FILL))
    keys, _ = mesh.edge_uses()
    n = len(V)
    v, u = np.concatenate([keys // n, keys % n]), np.concatenate([keys % n, keys // n])
    scale = float(10 * 10.0 ** spread)
    ref, got = both(monkeypatch, lambda: _keeps_ghosts(V, tri, _Stars(tri, keys, n), v, u, G, anchors, scale))
    assert same(ref, got)


@SETTINGS
@given(seed=st.integers(0, 2**31), m=st.integers(3, 40), rows=st.integers(1, 40),
       twist=st.floats(0.1, 3.0), wobble=st.floats(0.0, 1.5), option=st.integers(0, 1))
def test_run_grid(monkeypatch, seed, m, rows, twist, wobble, option):
    """Vertices, half-faces, poles and the convexity counts of a run."""
    a, b = design(seed, m, twist, wobble)
    d = b - a
    scale = float(np.linalg.norm(np.ptp(np.r_[a, b], axis=0)))
    div = Division(rows, option)
    ref, got = both(monkeypatch, lambda: mesh_run(a, d, 3, m // 2, div, DEFAULT, scale, []))
    for name in ("vertices", "t", "gen", "far", "left", "right", "pole", "centre_gen", "failing",
                 "on_patch"):
        assert same(getattr(ref, name), getattr(got, name)), name


@SETTINGS
@given(seed=st.integers(0, 2**31), m=st.integers(3, 30), rows=st.integers(1, 30),
       twist=st.floats(0.1, 3.0), wobble=st.floats(0.0, 1.5), trim=st.booleans())
def test_whole_build_and_measures(monkeypatch, seed, m, rows, twist, wobble, trim):
    """The mesh, its warnings and every per-face measure the kernels compute."""
    a, b = design(seed, m, twist, wobble)

    def run():
        mesh = pq_mesh(a, b, rows=rows, trim=trim)
        return (mesh, faces.planarity(mesh), faces.convexity(mesh), *faces.face_normals(mesh),
                faces.face_min_angles(mesh))

    ref, got = both(monkeypatch, run)
    for name in ("vertices", "face_offsets", "face_indices", "face_kind", "members"):
        assert same(getattr(ref[0], name), getattr(got[0], name)), name
    assert ref[0].info["warnings"] == got[0].info["warnings"]
    assert all(same(r, g) for r, g in zip(ref[1:], got[1:]))


def test_small_stage_stays_numpy(monkeypatch):
    """Below the size threshold, in a process that never loaded them, numpy does the work."""
    code = textwrap.dedent("""
        import sys, numpy as np
        from ruledmesh.pq import pq_mesh
        from ruledmesh.analysis import planarity
        phi = np.linspace(0, np.pi, 12)
        a = np.stack([np.cos(phi) - np.sin(phi), np.sin(phi) + np.cos(phi), -np.ones(12)], 1)
        b = np.stack([np.cos(phi) + np.sin(phi), np.sin(phi) - np.cos(phi), np.ones(12)], 1)
        planarity(pq_mesh(a, b, rows=10))
        assert "numba" not in sys.modules
    """)
    env = {k: v for k, v in os.environ.items() if k != "RULEDMESH_KERNELS"}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         timeout=300, check=False)
    assert run.returncode == 0, run.stderr[-2000:]


def test_designer_worker_compiles_every_kernel_before_its_first_edit():
    """Regression (CI, edit 327 of a live session): the kernels compiled inside an edit that
    crossed MIN_WORK, took over the 20 s limit and the edit was refused.  The worker holds
    the kernels until it is idle; after its warm-up, builds of other designs and sizes
    compile nothing more."""
    code = textwrap.dedent("""
        import numba
        from ruledmesh import kernels
        from ruledmesh.design import build_design, parse_design
        from ruledmesh.web.builder import _warm_up
        from ruledmesh.web.session import DEFAULT_DESIGN, frame_data

        import sys
        kernels.hold()          # as the worker does from its start
        assert kernels.wanted(10**7) is None and "ruledmesh.kernels.geometry" not in sys.modules
        default = parse_design(DEFAULT_DESIGN)
        assert _warm_up(lambda: frame_data(default.data, build_design(default)))

        def compiled():
            return {(m.__name__, k): len(v.signatures) for m in (kernels.geometry, kernels.grid,
                    kernels.strips) for k, v in vars(m).items()
                    if isinstance(v, numba.core.registry.CPUDispatcher)}

        before = compiled()
        assert sum(before.values()) > 0
        for text in (%r, DEFAULT_DESIGN.replace("count = 41", "count = 90").replace("rows = 40",
                     "rows = 7").replace('primary = "middle"', 'primary = 3')):
            d = parse_design(text)
            frame_data(d.data, build_design(d))
        assert compiled() == before, {k: (before.get(k), v) for k, v in compiled().items()
                                      if before.get(k) != v}
    """) % (SMALL_DESIGN,)
    env = {k: v for k, v in os.environ.items() if k != "RULEDMESH_KERNELS"}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         timeout=600, check=False)
    assert run.returncode == 0, run.stderr[-2000:]


def test_cache_from_read_only_install(tmp_path):
    """A copy of the package without write access still compiles, caches and reruns from the cache."""
    import shutil

    import ruledmesh

    src = os.path.dirname(ruledmesh.__file__)
    site = tmp_path / "site"
    shutil.copytree(src, site / "ruledmesh", ignore=shutil.ignore_patterns("__pycache__"))
    for root, dirs, files in os.walk(site):
        for x in dirs + files:
            os.chmod(os.path.join(root, x), 0o555 if x in dirs else 0o444)
    _cache_roundtrip(site, tmp_path)


def _cache_roundtrip(site, tmp_path) -> None:
    # Root writes through read-only modes: there the child is told the package is not writable.
    pretend = ("import os\n_access = os.access\nos.access = lambda p, mode, **kw: False if str(p)"
               f".startswith({str(site)!r}) and mode & os.W_OK else _access(p, mode, **kw)\n")
    code = (pretend + "import os, numpy as np\nfrom ruledmesh.kernels import wanted\nk = wanted(10**6)\n"
            "s, t, g = k.crossing(np.random.default_rng(0).standard_normal((5, 4, 3)))\n"
            "print(os.environ.get('NUMBA_CACHE_DIR', ''))")
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "RULEDMESH_KERNELS")}
    env.update(PYTHONPATH=str(site), HOME=str(tmp_path / "home"))
    for _ in range(2):
        run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                             cwd=tmp_path, timeout=600, check=False)
        assert run.returncode == 0, run.stderr[-2000:]
    cache = run.stdout.strip()
    assert cache.startswith(str(tmp_path / "home")), cache
    assert any(f.endswith(".nbi") for _, _, fs in os.walk(cache) for f in fs)


@SETTINGS
@given(seed=st.integers(0, 2**31), m=st.integers(3, 30), rows=st.integers(1, 30),
       twist=st.floats(0.1, 3.0), wobble=st.floats(0.0, 1.5))
def test_strip_paths(monkeypatch, seed, m, rows, twist, wobble):
    """The trimming's kept halves, jumps and gaps, on the inputs a real build hands it."""
    from ruledmesh.skew.pq import assemble, strips

    seen = []
    real = strips.strip_paths

    def spy(*args):
        seen.append(args)
        return real(*args)

    monkeypatch.setattr(assemble, "strip_paths", spy)
    monkeypatch.setenv("RULEDMESH_KERNELS", "0")
    a, b = design(seed, m, twist, wobble)
    pq_mesh(a, b, rows=rows)
    assert seen
    for args in seen:
        ref, got = both(monkeypatch, lambda args=args: real(*args))
        for r, g in zip(ref[:2] + ref[3:], got[:2] + got[3:]):
            assert same(r, g)
        for name in ("strip", "k0", "l0", "na", "nb"):
            assert same(getattr(ref[2], name), getattr(got[2], name)), name


@SETTINGS
@given(seed=st.integers(0, 2**31), n=st.integers(0, 400), m=st.integers(1, 30), upper=st.booleans(),
       ties=st.booleans())
def test_near_border(monkeypatch, seed, n, m, upper, ties):
    """Which generators' nearest vertex is the border point: sorting (numpy) or two minima (kernel)."""
    from ruledmesh.skew.pq import strips

    rng = np.random.default_rng(seed)
    gi = rng.integers(0, m, n)
    ti = rng.uniform(0, 1, n) ** 3 if not upper else 1 - rng.uniform(0, 1, n) ** 3
    if ties and n:
        ti[rng.integers(0, n, n // 3)] = ti[0]
    rel = rng.uniform(1e-4, 2.0, m)
    ref, got = both(monkeypatch, lambda: strips._near_border(gi, ti, m, rel, upper))
    assert same(ref, got)


def test_newell_large_polygons(monkeypatch):
    """Polygons of many corners (numpy's pairwise blocks of 8, and past 128 its halving)."""
    from ruledmesh.mesh import Mesh

    rng = np.random.default_rng(5)
    sizes = [3, 4, 9, 17, 64, 128, 129, 130, 300]
    ring = [np.c_[np.cos(u), np.sin(u), 0.01 * rng.standard_normal(len(u))] * 10.0 ** rng.uniform(-2, 3)
            for u in (np.sort(rng.uniform(0, 2 * np.pi, n)) for n in sizes)]
    V = np.concatenate(ring) + rng.uniform(-1e3, 1e3, 3)
    off = np.r_[0, np.cumsum(sizes)]
    mesh = Mesh.from_arrays(V, off, np.arange(len(V)))
    ref, got = both(monkeypatch, lambda: (*faces.face_normals(mesh), faces.face_min_angles(mesh)))
    assert all(same(r, g) for r, g in zip(ref, got))
    small = Mesh.from_arrays(V[:off[7]], off[:8], np.arange(off[7]))
    ref, got = both(monkeypatch, lambda: faces.face_normals(small))
    assert all(same(r, g) for r, g in zip(ref, got))
