"""Mesh quality on the regression surfaces of benchmarks/quality/, built with the CLI.

Each surface is built once per module with the command line (``ruledmesh build``,
its entry point run in two long-lived worker processes: ``quality.BuildPool``), read
back from OBJ and measured by ``benchmarks/quality.py``, independently of
``ruledmesh.analysis``.  The figures asserted are the fabrication bar for PQ
meshes of skew surfaces:

exact mode (the default)
    at most 25 % of the area in triangles on every general surface (5 % at
    300 x 300); no face with an angle below 3 deg; every quad planar to 1e-12
    (beyond what rounding the written coordinates explains), its diagonals
    crossing inside both; no degenerate face; every vertex on a generator (and
    on the quadric for quadric line sets); coverage of the smooth patch within
    1 %; no point of the smooth patch farther than 2e-3 of the diagonal from
    the mesh.
tolerance mode (``[mesh] planarity_tolerance``)
    at most 10 % of the area in triangles on every surface, nearly developable
    ones included, and every face within the stated tolerance; the other
    figures as in exact mode.
"""

from __future__ import annotations

import math
from concurrent.futures import Future

import pytest
from _shared import bench_module

quality = bench_module("quality")

EXACT_PLANARITY = 1e-12
MAX_TRIANGLE_SHARE = 0.25
MAX_TRIANGLE_SHARE_LARGE = 0.05
MAX_TRIANGLE_SHARE_TOLERANCE = 0.10
MIN_ANGLE_DEG = 3.0
MAX_GAP = 2e-3
COVERAGE = 0.01
ON_GENERATOR = 1e-10            # relative to the diagonal, plus the coordinates' rounding

ALL = quality.default_surfaces(large=True)
EXACT = [s for s in ALL if s.tolerance is None]
TOLERANCE = [s for s in ALL if s.tolerance is not None]
LARGE = [s for s in EXACT if "large" in s.flags]
QUADRIC = [s for s in ALL if "quadric" in s.flags]

# Where the mesher does not reach the bar yet, as measured (docs/mesh-quality.md). Strict: a
# surface that starts to pass fails here until it is taken off the list, so the list cannot
# go stale and the bar is never lowered.
SHORT_OF_ANGLE: dict[str, str] = {}
SHORT_OF_GENERATOR: dict[str, str] = {}
SHORT_OF_SHARE = {
    "plucker-lines-tol1e-3": "15.6% of the area in triangles (teeth along the outer edge; the lines are "
                             "given, so no generator can be added)",
    "moebius-lines-tol1e-3": "13.3% of the area in triangles (rows through both edges' end points): teeth "
                             "where the rows run nearly along the edge, at 16 to 48 rows alike, and strip "
                             "quads between lines 2.5 degrees apart are not planar within 1e-3",
    "skew-bspline-301x300": "14.6% of the area in triangles; 13% of the patch is slender "
                            "(every exact face there a 10:1 panel or worse)",
}
SHORT_OF_GAP: dict[str, str] = {}


def _marked(surfaces, short: dict) -> list:
    return [pytest.param(s, id=s.name, marks=pytest.mark.xfail(strict=True, reason=short[s.name]))
            if s.name in short else pytest.param(s, id=s.name) for s in surfaces]


def _ids(surfaces):
    return [s.name for s in surfaces]


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    """Build and measure each surface once per module; failed builds fail every test of it.

    Two builds run at once, in the two workers of a :class:`quality.BuildPool` (one
    interpreter start and one set of imports each, not one per surface): asking for a
    surface also starts the build of the next one in :data:`ALL` (the order the
    parametrised tests ask in).
    """
    cache: dict[str, dict] = {}
    builds: dict[str, Future] = {}
    work = tmp_path_factory.mktemp("quality")
    pool = quality.BuildPool(2)

    def start(surface) -> Future:
        if surface.name not in builds:
            builds[surface.name] = pool.submit(surface.path, quality.obj_path(surface, work))
        return builds[surface.name]

    def get(surface) -> dict:
        if surface.name not in cache:
            fut = start(surface)
            later = [s for s in ALL if s.name not in builds]
            if later:
                start(later[0])
            cache[surface.name] = quality.run_surface(surface, work, fut.result())
        row = cache[surface.name]
        if row["status"] != "ok":
            pytest.fail(f"{surface.name}: {row['status']}: {row.get('error')}", pytrace=False)
        if row["faces"] == 0:
            pytest.fail(f"{surface.name}: the build wrote no faces", pytrace=False)
        return row

    yield get
    pool.close()


def _rounding(row: dict) -> float:
    """Relative distance the float64 rounding of the written coordinates alone can cause."""
    return 2 * quality.ROUNDING * row["max_abs_coordinate"] / row["diagonal"]


# --------------------------------------------------------------------------- both modes

@pytest.mark.parametrize("surface", _marked(ALL, SHORT_OF_ANGLE))
def test_no_splinters(surface, measured):
    row = measured(surface)
    assert row["min_angle_deg"] >= MIN_ANGLE_DEG, (
        f"smallest face angle {row['min_angle_deg']:.3g} deg, {row['faces_below_3deg']} faces "
        f"below {MIN_ANGLE_DEG} deg")


@pytest.mark.parametrize("surface", ALL, ids=_ids(ALL))
def test_quads_convex(surface, measured):
    row = measured(surface)
    assert row["bowties"] == 0 and row["nonconvex_polygons"] == 0, (
        f"{row['bowties']} bow-tie quads, {row['nonconvex_polygons']} non-convex polygons")


@pytest.mark.parametrize("surface", ALL, ids=_ids(ALL))
def test_no_degenerate_faces(surface, measured):
    assert measured(surface)["degenerate_faces"] == 0


@pytest.mark.parametrize("surface", _marked(ALL, SHORT_OF_GENERATOR))
def test_vertices_on_generators(surface, measured):
    row = measured(surface)
    bound = ON_GENERATOR + _rounding(row)
    assert row["max_generator_distance"] <= bound, (
        f"a vertex is {row['max_generator_distance']:.2e} of the diagonal off every generator")
    assert row.get("max_overshoot", 0.0) <= bound, "a vertex lies beyond the patch's border curves"


@pytest.mark.parametrize("surface", QUADRIC, ids=_ids(QUADRIC))
def test_vertices_on_the_quadric(surface, measured):
    row = measured(surface)
    assert row["max_quadric_distance"] <= ON_GENERATOR + _rounding(row)


def test_the_quadric_of_explicit_lines_is_fitted_to_the_lines():
    """The checker's quadric of a line set passes through the lines, not through its own
    interpolated patch between them (which lies on no quadric: a hyperboloid of 48 lines
    read 1.4e-8 of the diagonal off its quadric, its vertices being 3e-14 off)."""
    import numpy as np

    phi = np.linspace(0.0, np.pi, 20)
    a = np.stack([np.cos(phi) - np.sin(phi), np.sin(phi) + np.cos(phi), -np.ones(20)], axis=1)
    b = np.stack([np.cos(phi) + np.sin(phi), np.sin(phi) - np.cos(phi), np.ones(20)], axis=1)
    t = np.linspace(0.0, 1.0, 11)[None, :, None]
    grid = a[:, None] + t * (b - a)[:, None]
    grid = grid + 1e-3 * np.sin(7 * t) * np.array([0.0, 0.0, 1.0])   # off the quadric
    ref = quality.Reference(a, b, grid, phi, None, True)
    on_lines = (0.3 * a + 0.7 * b)
    assert quality.quadric_distance(on_lines, ref).max() <= 1e-12
    assert quality.quadric_distance(on_lines + [0.0, 0.0, 1e-3], ref).min() > 1e-4


def test_slender_share_of_known_patches():
    """The checker's slender share: none on a hyperboloid whose two reguli cross at large
    angles or on a right helicoid (rows at right angles to the rulings), all of a cylinder
    and of a plane strip (developable: the rows would run along the generators)."""
    import numpy as np

    t = np.linspace(0.0, 1.0, 33)[None, :, None]

    def ref_of(a, b):
        grid = a[:, None] + t * (b - a)[:, None]
        return quality.Reference(a, b, grid, np.arange(len(a), dtype=float), None, True)

    phi = np.linspace(0.0, np.pi, 41)
    ring = np.stack([np.cos(phi), np.sin(phi), 0 * phi], 1)
    turned = np.stack([np.cos(phi + 2.0), np.sin(phi + 2.0), 0 * phi + 0.5], 1)
    assert quality.slender_share(ref_of(ring, turned)) == 0.0
    assert quality.slender_share(ref_of(ring, ring + [0.0, 0.0, 2.0])) == 1.0
    s = np.linspace(0.0, 1.0, 201)
    heli_a = np.stack([0 * s, 0 * s, s], 1)
    heli_b = np.stack([np.cos(s), np.sin(s), s], 1)
    assert quality.slender_share(ref_of(heli_a, heli_b)) == 0.0
    assert quality.slender_share(ref_of(heli_a, heli_a + [1.0, 0.0, 0.0])) == 1.0


@pytest.mark.parametrize("surface", ALL, ids=_ids(ALL))
def test_coverage_of_the_patch(surface, measured):
    row = measured(surface)
    assert abs(row["coverage"] - 1.0) <= COVERAGE, f"coverage {row['coverage']:.4f}"


@pytest.mark.parametrize("surface", _marked(ALL, SHORT_OF_GAP))
def test_no_gap_to_the_smooth_patch(surface, measured):
    row = measured(surface)
    at = row["max_gap_at"]
    assert row["max_gap"] <= MAX_GAP, (
        f"the smooth patch is {row['max_gap']:.2e} of the diagonal from the mesh at "
        f"u = {at['u']:.4f}, t = {at['t']:.4f}")


def _triangle_bound(surface) -> float | None:
    """Largest triangle area share allowed: tolerance mode 10 %, 300 x 300 5 %, general 25 %.

    Nearly developable surfaces in exact mode have no bound: exact planar quads
    degenerate there, which is what tolerance mode is for.
    """
    if surface.tolerance is not None:
        return MAX_TRIANGLE_SHARE_TOLERANCE
    if "large" in surface.flags:
        return MAX_TRIANGLE_SHARE_LARGE
    return MAX_TRIANGLE_SHARE if "general" in surface.flags else None


BOUNDED = [s for s in ALL if _triangle_bound(s) is not None]


@pytest.mark.parametrize("surface", _marked(BOUNDED, SHORT_OF_SHARE))
def test_triangle_area_share(surface, measured):
    row = measured(surface)
    bound = _triangle_bound(surface)
    assert row["triangle_area_share"] <= bound, (
        f"{row['triangle_area_share']:.1%} of the area in {row['triangles']} triangles "
        f"(at most {bound:.0%})")


# --------------------------------------------------------------------------- exact mode

@pytest.mark.parametrize("surface", EXACT, ids=_ids(EXACT))
def test_exact_mode_faces_planar(surface, measured):
    row = measured(surface)
    assert row["max_planarity_beyond_rounding"] <= EXACT_PLANARITY, (
        f"planarity {row['max_planarity']:.2e}")


# --------------------------------------------------------------------------- tolerance mode

@pytest.mark.parametrize("surface", TOLERANCE, ids=_ids(TOLERANCE))
def test_tolerance_mode_faces_within_tolerance(surface, measured):
    row = measured(surface)
    assert math.isfinite(row["max_planarity"])
    assert row["max_planarity_beyond_rounding"] <= surface.tolerance, (
        f"planarity {row['max_planarity']:.2e} > {surface.tolerance:g}")


# --------------------------------------------------------------------------- the instrument

def test_surfaces_cover_the_cases():
    names = {s.name for s in ALL}
    assert len(TOLERANCE) >= 5 and LARGE and len(QUADRIC) >= 3
    assert {"skew", "fig10-skew-surface"} <= names
    for s in ALL:
        assert s.description, f"{s.path}: the first line must be a comment describing it"


def test_face_measures_of_known_faces():
    import numpy as np

    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    bent = square.copy()
    bent[2, 2] = 0.1
    bowtie = square[[0, 1, 3, 2]]
    m = quality.face_measures(np.stack([square, bent, bowtie]))
    # Bent: the diagonal lines (0,0,0)-(1,1,0.1) and (1,0,0)-(0,1,0) have the common normal
    # (-0.1, -0.1, 2) and are 0.1 / sqrt(4.02) apart.
    mean_diag = 0.5 * (math.sqrt(2.01) + math.sqrt(2))
    assert m.planarity[0] == 0 and m.planarity[1] == pytest.approx(0.1 / math.sqrt(4.02) / mean_diag)
    assert list(m.convex) == [True, True, False]
    assert m.min_angle[0] == pytest.approx(90)
    sliver = np.array([[[0, 0, 0], [1, 0, 0], [0.5, 0.01, 0]]], float)
    assert quality.face_measures(sliver).min_angle[0] == pytest.approx(math.degrees(math.atan(0.02)))
    flat = np.array([[[0, 0, 0], [1, 0, 0], [2, 0, 0]]], float)
    assert quality.face_measures(flat).degenerate[0]
    dart = np.array([[[0, 0, 0], [2, 0, 0], [2, 2, 0], [1, 0.5, 0], [0, 2, 0]]], float)
    dm = quality.face_measures(dart)
    assert not dm.convex[0] and dm.planarity[0] == 0 and dm.area[0] == pytest.approx(2.5)


def test_read_obj(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\ng quad\nf 1/1 2/2 3/3 4/4\n"
                    "g fill\nf -4 5 -3\nl 1 2\n")
    mesh = quality.read_obj(path)
    assert mesh.vertices.shape == (5, 3)
    assert mesh.faces[4].tolist() == [[0, 1, 2, 3]] and mesh.faces[3].tolist() == [[1, 4, 2]]
    assert list(mesh.groups[3]) == ["fill"]


def test_distance_to_mesh_is_exact():
    import numpy as np

    rng = np.random.default_rng(1)
    tris = rng.normal(size=(60, 3, 3))
    tris[:5] *= 8                                   # a few large triangles get bisected
    p = rng.normal(size=(500, 3)) * 2
    brute = quality.point_triangle_distance(
        np.repeat(p, 60, 0), *np.tile(tris, (500, 1, 1)).transpose(1, 0, 2)).reshape(500, 60)
    assert np.allclose(quality.distance_to_mesh(p, tris), brute.min(axis=1), rtol=0, atol=1e-12)
    # Against dense samples of the triangles: never farther, and close.
    w = rng.dirichlet([1, 1, 1], size=4000)
    from scipy.spatial import cKDTree
    dense = cKDTree(np.einsum("sk,tki->tsi", w, tris).reshape(-1, 3)).query(p)[0]
    assert np.all(brute.min(axis=1) <= dense + 1e-12)


def test_line_distance_by_cells_is_the_all_pairs_figure():
    # The cells only choose which lines to measure: the distances are the all-pairs numbers,
    # to the bit, for points on the lines, near them and anywhere, near the origin and far.
    import numpy as np

    rng = np.random.default_rng(3)
    a = rng.normal(size=(40, 3)) * 3
    b = a + rng.normal(size=(40, 3))
    g = rng.integers(0, 40, 3000)
    on = a[g] + rng.uniform(-1, 2, (3000, 1)) * (b[g] - a[g]) + rng.normal(size=(3000, 3)) * 1e-3
    p = np.concatenate([on, rng.normal(size=(1000, 3)) * 5])
    for shift in (0.0, 2.6e6):
        pa, aa, bb = p + shift, a + shift, b + shift
        d = bb - aa
        every = quality._line_distance_all(pa, aa, d, np.einsum("ij,ij->i", d, d), 4096)
        assert np.array_equal(quality.line_distance(pa, aa, bb, chunk=16), every)   # by cells
        assert np.array_equal(quality.line_distance(pa, aa, bb), every)             # few: all pairs
    # ... and they are the distances to the lines (|w x d| / |d|, another formula).
    across = np.cross(p[:, None, :] - a, b - a) / np.linalg.norm(b - a, axis=1)[:, None]
    assert np.allclose(quality.line_distance(p, a, b, chunk=16),
                       np.linalg.norm(across, axis=2).min(axis=1), rtol=0, atol=1e-12)


def test_generator_distance_iterates_the_moving_points_only():
    # Points left where they were by a step are not stepped again: the u found, and so the
    # distances, are those of stepping every point until all have stopped.
    import numpy as np

    ref = quality.reference_of(quality.SURFACES / "skew-bspline-51x30.toml")
    surf = ref.surface
    rng = np.random.default_rng(4)
    u = rng.uniform(ref.grid_u[0], ref.grid_u[-1], 400)
    off = rng.normal(size=(400, 3)) * 1e-3 * ref.diagonal
    p = surf.point(u, rng.uniform(-0.1, 1.1, 400)) + off
    dist, t, length = quality.surface_generator_distance(p, ref, starts=1, polish=False)
    T = ref.grid.shape[1]
    from scipy.spatial import cKDTree

    w = ref.grid_u[cKDTree(ref.grid.reshape(-1, 3)).query(p)[1] // T].astype(float)
    lo, hi = float(ref.grid_u[0]), float(ref.grid_u[-1])
    for _ in range(100):
        a, b = surf.a(w), surf.b(w)
        da, db = surf.rail_a.deriv(w), surf.rail_b.deriv(w)
        d = b - a
        tt = np.einsum("ij,ij->i", p - a, d) / np.einsum("ij,ij->i", d, d)
        r = p - a - tt[:, None] * d
        jac = -(da + tt[:, None] * (db - da))
        jj = np.einsum("ij,ij->i", jac, jac)
        w_new = np.clip(w - np.einsum("ij,ij->i", r, jac) / np.where(jj > 0, jj, 1.0), lo, hi)
        stop = np.all(np.abs(w_new - w) <= 1e-15)
        w = w_new
        if stop:
            break
    a, b = surf.a(w), surf.b(w)
    d = b - a
    tt = np.einsum("ij,ij->i", p - a, d) / np.einsum("ij,ij->i", d, d)
    assert np.array_equal(dist, quality._norm(p - a - tt[:, None] * d))
    assert np.array_equal(t, tt) and np.array_equal(length, quality._norm(d))
    # Each point is off its own generator by its offset: the nearest one is no farther.
    assert np.all(dist <= np.linalg.norm(off, axis=1) * (1 + 1e-9))
    # More starts can only find nearer generators.
    assert np.all(quality.surface_generator_distance(p, ref, polish=False)[0] <= dist)


def test_generator_distance_finds_generators_next_to_a_cusp():
    # Next to a cusp of a director curve every generator passes the cusp point closely and
    # the distance has a local minimum on each side: points on generators just past the cusp
    # (where the descent from the nearest patch point lands on the wrong side) are on.
    import numpy as np

    ref = quality.reference_of(quality.SURFACES / "cusp-3d-tol1e-3.toml")
    u = np.linspace(0.5 - 0.01, 0.5 + 0.01, 41)
    t = np.tile([0.002, 0.006, 0.02], len(u))
    p = ref.surface.point(np.repeat(u, 3), t)
    one = quality.surface_generator_distance(p, ref, starts=1, polish=False)[0] / ref.diagonal
    assert one.max() > 1e-5                  # the case this guards: one start misses
    assert quality.surface_generator_distance(p, ref)[0].max() / ref.diagonal <= 1e-12


def test_the_smooth_patch_itself_passes_and_a_hole_is_found(tmp_path):
    # A mesh made of the reference grid's own cells, coarsened: full coverage, on the
    # generators, no gap; the same mesh with one cell left out is caught by the gap.
    import numpy as np

    design = quality.SURFACES / "hp-two-lines.toml"
    ref = quality.reference_of(design)
    keep = np.r_[0:len(ref.grid):37, len(ref.grid) - 1]      # not the design's generators
    g = ref.grid[keep, ::8]
    n, m = g.shape[:2]
    ids = np.arange(n * m).reshape(n, m)
    quads = np.stack([ids[:-1, :-1], ids[1:, :-1], ids[1:, 1:], ids[:-1, 1:]], -1).reshape(-1, 4)
    verts = g.reshape(-1, 3)
    mesh = quality.ObjMesh(verts, {4: quads}, {4: np.array([""] * len(quads), dtype=object)})
    row = quality.measure(mesh, ref, quadric=True)
    assert abs(row["coverage"] - 1) < 1e-3 and row["max_gap"] < 2e-3
    assert row["max_design_generator_distance"] > 1e-6      # the coarse grid is off most of them
    assert row["max_generator_distance"] < 1e-12            # ... but on generators of the surface
    assert row["max_quadric_distance"] < 1e-12
    holed = quality.ObjMesh(verts, {4: np.delete(quads, len(quads) // 2, 0)}, {})
    assert quality.measure(holed, ref)["max_gap"] > 5e-3
    # One interior vertex pushed off the surface by 1e-6 of the diagonal, and the last row
    # of vertices moved 2 % of the generator beyond c2: both are seen.
    moved = verts.copy()
    moved[ids[n // 2, m // 2]] += 1e-6 * ref.diagonal * np.array([0.0, 0.0, 1.0])
    row = quality.measure(quality.ObjMesh(moved, {4: quads}, {}), ref, quadric=True)
    assert 1e-7 < row["max_generator_distance"] < 2e-6
    assert 1e-7 < row["max_quadric_distance"] < 2e-6
    beyond = verts.copy()
    last = ids[:, -1]
    beyond[last] += 0.02 * (g[:, -1] - g[:, 0])
    row = quality.measure(quality.ObjMesh(beyond, {4: quads}, {}), ref)
    length = np.linalg.norm(g[:, -1] - g[:, 0], axis=1).max()
    assert row["max_overshoot"] == pytest.approx(0.02 * length / ref.diagonal, rel=1e-6)
    assert row["max_generator_distance"] < 1e-12 and row["coverage"] > 1.005
