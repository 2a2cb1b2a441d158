"""Buildability of §4.3 meshes: area in quads, splinters, strip quads, tolerance mode.

The exact invariants (planarity, convexity, vertices on generators, a disc) must hold on every
surface; the quality figures are held to what the mesher reaches on each regression surface, so
that a change that brings back triangles or splinters fails here.  The goals the mesher does not
reach yet are listed in docs/mesh-quality.md.
"""

import re
from pathlib import Path

import numpy as np
import pytest
from _shared import bspline_design as _design  # a helper module of tests/ (see conftest.py)
from _shared import check_exact
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.faces import area_shares, convexity, face_min_angles, face_normals, planarity
from ruledmesh.design import build_design, parse_design
from ruledmesh.mesh import FaceKind
from ruledmesh.pq import pq_mesh

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
QUALITY = EXAMPLES.parent / "benchmarks" / "quality"


curves = st.lists(st.floats(-2.0, 2.0), min_size=10, max_size=10)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(y1=curves, y2=curves, count=st.integers(40, 60), rows=st.integers(10, 30))
def test_random_director_curves_exact_and_mostly_quads(y1, y2, count, rows):
    """Two random cubic B-splines at designer sizes: exact, a disc on the generators, covering
    the patch, and most of the area in quads, or a warning that says how much is not and why
    (two nearly equal curves make a nearly developable surface)."""
    x = np.linspace(0.0, 10.0, 5)
    c1 = np.c_[x, y1[:5], 0.5 * np.asarray(y1[5:])]
    c2 = np.c_[x, y2[:5], 4.0 + 0.5 * np.asarray(y2[5:])]
    built = build_design(parse_design(_design(c1, c2, count, rows)))
    check_exact(built)
    share = area_shares(built.mesh)["quads"]
    said = [w for w in built.mesh.info["warnings"] if "of the area is not in quads" in w]
    assert share >= 0.7 or said
    if share < 0.7:
        assert f"{1 - share:.0%}" in said[0]
    # Splinters are rare: runs end before slivers, the fill is flipped for its angles, the
    # quads walling a splinter in are opened (the mesher measured 0.6-8 % of the faces below
    # 3 degrees on such surfaces, then 77 faces on 25 of them, now 7, 19 of 25 with none).
    thin = face_min_angles(built.mesh) < 3.0
    assert thin.sum() <= 4, f"{thin.sum()} of {thin.size} faces below 3 degrees"


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(lift=st.floats(1e-7, 1e-3), count=st.integers(20, 50), rows=st.integers(6, 24))
def test_tolerance_mode_respects_the_tolerance_on_a_nearly_developable_surface(lift, count, rows):
    """A cylinder with one control point lifted: every face within 1e-3, nearly all quads."""
    c1 = np.array([[0, 0, 0], [3, 2, 0], [6, -1, 0], [10, 0, 0]], float)
    c2 = c1 + [0, 0, 4]
    c2[1, 1] += lift
    text = _design(c1, c2, count, rows, "planarity_tolerance = 1e-3\n")
    built = build_design(parse_design(text))
    mesh = built.mesh
    assert planarity(mesh).max() <= 1e-3
    assert convexity(mesh).all() and mesh.euler_characteristic() == 1
    assert area_shares(mesh)["quads"] >= 0.9


def test_exact_mode_says_where_a_nearly_developable_surface_has_no_quads():
    c1 = np.array([[0, 0, 0], [3, 2, 0], [6, -1, 0], [10, 0, 0]], float)
    c2 = c1 + [0, 0, 4]
    c2[1, 1] += 1e-3
    built = build_design(parse_design(_design(c1, c2, 41, 20)))
    check_exact(built)
    warnings = " ".join(built.mesh.info["warnings"])
    assert "of the area is not in quads" in warnings and "planarity_tolerance" in warnings
    # The cause and where: every strip nearly developable, the share at the border and inside.
    said = next(w for w in built.mesh.info["warnings"] if "of the area is not in quads" in w)
    # (All 40 but the one its torsal band was spanned by: a coplanar pair, strip quads.)
    assert int(re.search(r"(\d+) strips nearly developable", said).group(1)) >= 39
    # ... and slender all over: the rows would cross the generators at under 5.7 degrees.
    slender = re.search(r"(\d+)% of the area slender \(the rows would cross the generators at "
                        r"under 5\.7 degrees there: exact quads at least 10:1\)", said)
    assert slender and int(slender[1]) >= 95, said
    match = re.search(r"(\d+)% at the border, (\d+)% inside, most between generators (\d+)-(\d+)", said)
    assert match, said
    share = int(re.match(r"(\d+)% of the area", said).group(1))
    assert share >= 90 and abs(int(match[1]) + int(match[2]) - share) <= 1
    assert 0 <= int(match[3]) < int(match[4]) <= 40


def test_share_warning_names_the_strips_that_hold_the_triangles():
    """skew-bspline-b-51x30 with its own generators: most of the area outside quads lies
    beside its torsal generators, and the warning gives those strips with their shares."""
    text = (QUALITY / "skew-bspline-b-51x30.toml").read_text() + "refine = false\n"
    built = build_design(parse_design(text))
    said = next(w for w in built.mesh.info["warnings"] if "of the area is not in quads" in w)
    ranges = re.findall(r"(\d+)-(\d+) \((\d+)%\)", said.split("most between generators")[1])
    assert ranges
    mesh = built.mesh
    gen = np.asarray(mesh.vertex_data["generator"])
    _, area = face_normals(mesh)
    g0 = np.minimum.reduceat(gen[mesh.face_indices], mesh.face_offsets[:-1])
    for lo, hi, pct in ranges:
        inside = (g0 >= int(lo)) & (g0 < int(hi)) & (mesh.valences != 4)
        # The named range holds at least its stated share (border faces of the range included).
        assert area[inside].sum() / area.sum() >= int(pct) / 100 - 0.006


def test_coplanar_generators_carry_exact_strip_quads():
    """A general cylinder (a curve and its translate): every strip is coplanar, all strip quads."""
    t = np.linspace(0, 1, 25)
    a = np.c_[10 * t, 2 * np.sin(3 * t), np.zeros_like(t)]
    mesh = pq_mesh(a, a + [0.3, 0.2, 5.0], rows=12)
    assert set(mesh.count_kinds()) == {"strip"}
    assert planarity(mesh).max() <= 1e-12 and convexity(mesh).all()


# ---------------------------------------------------------------- regressions
# (file, at most this share of the area outside quads, at least this smallest face angle).
# Runs end before faces thinner than RESTART_ANGLE_DEG and the kept triangles are flipped
# for their smallest angle: a few points of share traded for far fewer splinters.
REGRESSIONS = [
    ("skew.toml", 0.08, 3.0),                    # was 19 %, 0.19 deg (two crease bands)
    ("fig10-skew-surface.toml", 0.12, 3.0),      # was 20 %, 0.03 deg; then 11 % with 5 splinters
    # was 30 %, then 20 % with 109 splinters, 18 % with 24 (0.01 deg): opening the quads
    # around them costs 3 points
    ("right-conoid-arc.toml", 0.22, 3.0),
    ("conoidal-director-plane.toml", 0.22, 1.0),  # was 33 %, then 16 % with 59 splinters, 0.11 deg
    ("three-directrices.toml", 0.09, 3.0),       # was 20 %, then 10 % at 0.19 deg; 8.5 % spanned
    ("parameter-distribution.toml", 0.11, 3.0),  # was 18 %, then 10 % with 17 splinters; 10.4 %
]


@pytest.mark.parametrize("name,share,angle", REGRESSIONS)
def test_example_quality_does_not_regress(name, share, angle):
    from ruledmesh.design import build_file

    built = build_file(EXAMPLES / name)
    check_exact(built)
    mesh = built.mesh
    assert 1.0 - area_shares(mesh)["quads"] <= share
    if angle is not None:
        assert face_min_angles(mesh).min() >= angle


def test_two_bspline_director_curves_51_by_30():
    """The first quality surface: 55 % of the area was in triangles and 220 splinters;
    generators are added where the rows need them and the share falls under a quarter."""
    c1 = [[0.0, 1.34, -1.68], [2.5, -1.44, -0.62], [5.0, 1.66, -0.92], [7.5, -2.19, 0.96],
          [10.0, 1.63, -1.61]]
    c2 = [[0.0, -0.52, 4.67], [2.5, -2.47, 3.40], [5.0, -1.19, 5.13], [7.5, -0.39, 4.77],
          [10.0, -1.97, 3.66]]
    text = (f'[curves.c1]\ntype = "bspline"\ndegree = 3\npoints = {c1}\n'
            f'[curves.c2]\ntype = "bspline"\ndegree = 4\npoints = {c2}\n'
            '[rulings]\nbetween = ["c1", "c2"]\ncount = 51\n[mesh]\nrows = 30\n')
    built = build_design(parse_design(text))
    check_exact(built)
    assert 1.0 - area_shares(built.mesh)["quads"] <= 0.25
    assert np.count_nonzero(face_min_angles(built.mesh) < 3.0) == 0        # was 220, 107, then 10
    assert built.rulings.info["inserted"] > 0
    assert any("generators of the smooth surface added" in w for w in built.mesh.info["warnings"])
    given = build_design(parse_design(text.replace("rows = 30", "rows = 30\nrefine = false")))
    assert len(given.rulings.a) == 51
    assert area_shares(given.mesh)["quads"] < area_shares(built.mesh)["quads"]


def test_border_quads_end_at_the_director_points():
    from ruledmesh.design import build_file

    mesh = build_file(EXAMPLES / "skew.toml").mesh
    t = mesh.vertex_data["t"]
    border = np.flatnonzero((mesh.face_kind == FaceKind.BORDER) & (mesh.valences == 4))
    assert border.size
    corners = mesh.face_indices[mesh.face_offsets[border][:, None] + np.arange(4)]
    on_curve = (t[corners] <= 1e-12) | (t[corners] >= 1 - 1e-12)
    assert np.all(on_curve.any(axis=1))


def test_analysis_reports_area_shares_and_splinters():
    from ruledmesh.analysis.report import analyze
    from ruledmesh.design import build_file

    mesh = build_file(EXAMPLES / "skew.toml").mesh
    q = analyze(mesh)["quality"]
    shares = q["area_share"]
    assert abs(sum(shares["by_kind"].values()) - 1.0) < 1e-12
    assert abs(shares["quads"] + shares["triangles"] + shares["polygons"] - 1.0) < 1e-12
    assert q["faces_below_3deg"] == int(np.count_nonzero(face_min_angles(mesh) < 3))
    assert q["degenerate_faces"] == 0


def test_pluecker_conoid_closeness_finds_the_right_sheet():
    """The nearest-point search used to stop on the other sheet of a self-intersecting surface
    (1.9e-3 reported where the vertices lie on the surface to 1e-16)."""
    from ruledmesh.analysis.report import analyze

    theta = np.radians(np.linspace(0, 180, 25))
    pts = np.c_[3 * np.cos(theta), 3 * np.sin(theta), 1.5 * np.sin(2 * theta)]
    text = ('[curves.rim]\ntype = "bspline"\ninterpolate = true\n'
            f"points = {np.round(pts, 9).tolist()}\n"
            '[rulings]\nconoid = { curve = "rim", directrix = [[0, 0, -2], [0, 0, 2]], '
            "director_plane = [0, 0, 1] }\ncount = 61\n[mesh]\nrows = 20\n")
    built = build_design(parse_design(text))
    report = analyze(built.mesh, built.reference)
    assert report["closeness"]["vertices_max"] <= 1e-10


def _triangulated_grid(n, bend=0.0):
    """An n x n grid of squares, each cut into two triangles; ``bend`` lifts alternate rows."""
    from ruledmesh.mesh import Mesh

    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    V = np.c_[i.ravel(), j.ravel(), bend * (j.ravel() % 2) * (i.ravel() % 2)].astype(float)
    k = (i[:-1, :-1] * (n + 1) + j[:-1, :-1]).ravel()
    tris = np.concatenate([np.c_[k, k + n + 1, k + n + 2], np.c_[k, k + n + 2, k + 1]])
    off = np.arange(len(tris) + 1) * 3
    return Mesh(V, off, tris.ravel(), np.full(len(tris), FaceKind.FILL, np.uint8),
                vertex_data={"generator": (V[:, 0]).astype(np.int64), "t": V[:, 1] / n})


def test_pairing_makes_quads_of_coplanar_triangle_pairs():
    from ruledmesh.analysis.faces import face_areas
    from ruledmesh.skew.pq.pairing import pair_triangles

    mesh = _triangulated_grid(6)
    paired, made = pair_triangles(mesh, 1e-3)
    assert made == 36 and paired.n_faces == 36 and np.all(paired.valences == 4)
    assert np.isclose(face_areas(paired).sum(), face_areas(mesh).sum())
    assert convexity(paired).all() and planarity(paired).max() <= 1e-12
    # The squares' corners lie on two generators each: strip quads.
    assert np.all(paired.face_kind == FaceKind.STRIP)
    # Orientation is kept: every normal still points up.
    from ruledmesh.analysis.faces import face_normals
    assert np.all(face_normals(paired)[0][:, 2] > 0)


def test_pairing_refuses_quads_beyond_the_tolerance():
    from ruledmesh.skew.pq.pairing import pair_triangles

    mesh = _triangulated_grid(4, bend=0.05)
    loose, n_loose = pair_triangles(mesh, 0.1)
    tight, n_tight = pair_triangles(mesh, 1e-4)
    assert n_loose > n_tight
    assert planarity(tight).max() <= 1e-4 and planarity(loose).max() <= 0.1


def test_tolerance_mode_pairs_triangles_on_a_general_surface():
    """Tolerance mode takes triangle pairs planar within the tolerance: fewer triangles than
    exact mode, and every face within it."""
    text = (EXAMPLES.parent / "benchmarks" / "quality" / "skew-bspline-51x30.toml").read_text()
    exact = build_design(parse_design(text)).mesh
    loose = build_design(parse_design(text.replace("[mesh]", "[mesh]\nplanarity_tolerance = 1e-3", 1))).mesh
    assert loose.info["paired"] > 0
    assert planarity(loose).max() <= 1e-3 and convexity(loose).all()
    assert area_shares(loose)["triangles"] < area_shares(exact)["triangles"] - 0.03


def test_build_warns_of_splinters_with_the_figures_analyze_reports():
    from ruledmesh.analysis.faces import SPLINTER_DEG

    built = build_design(parse_design((EXAMPLES / "fig10-skew-surface.toml").read_text()))
    angles = face_min_angles(built.mesh)
    n = int(np.count_nonzero(angles < SPLINTER_DEG))
    said = [w for w in built.mesh.info["warnings"] if "faces have an angle below" in w]
    if n == 0:
        assert not said
    else:
        assert len(said) == 1 and said[0].startswith(f"{n} faces have an angle below 3 deg")
        assert f"smallest {angles.min():.2g} deg" in said[0]


def test_share_warning_in_tolerance_mode_does_not_advise_the_tolerance():
    # Unrefined and from 31 generators: refined, or unrefined from its 41, the example has
    # less than the warning's 30 % in triangles (40 % here).
    text = (EXAMPLES / "linear-directrix.toml").read_text().replace(
        "[mesh]\n", "[mesh]\nplanarity_tolerance = 1e-3\nrefine = false\n").replace(
        "count = 41\n", "count = 31\n")
    built = build_design(parse_design(text))
    said = [w for w in built.mesh.info["warnings"] if "of the area is not in quads" in w]
    assert said and "planarity_tolerance" not in said[0] and "more generators" in said[0]


def test_no_warning_in_tolerance_mode_advises_the_tolerance():
    """The Pluecker conoid at 1e-3: its generators without rows were still told to use it."""
    text = (QUALITY / "plucker-conoid.toml").read_text().replace("[mesh]\n", "[mesh]\nplanarity_tolerance = 1e-3\n")
    warnings = build_design(parse_design(text)).mesh.info["warnings"]
    assert any("carry no §4.3 rows" in w for w in warnings)
    assert not any("planarity_tolerance" in w for w in warnings), warnings


def test_rounds_take_back_only_their_own_generators_next_to_splinters(monkeypatch):
    """A refinement round with splinters is tried again without the generators it added near
    them: never a generator the round started from, none farther than the reach, and the
    Pluecker conoid's round with one splinter comes back without it."""
    import ruledmesh.design.pq as refine

    seen = []
    real = refine._unsplintered

    def spy(candidate, mesh, given_u, options):
        out = real(candidate, mesh, given_u, options)
        seen.append((candidate, mesh, np.asarray(given_u), out))
        return out

    monkeypatch.setattr(refine, "_unsplintered", spy)
    built = build_design(parse_design((QUALITY / "plucker-conoid.toml").read_text()))
    taken = [s for s in seen if s[3] is not None]
    assert taken, "no round had splinters to take generators back from"
    fewer = 0
    for candidate, mesh, start, (rulings, new_mesh) in taken:
        u, kept = np.asarray(candidate.u), np.asarray(rulings.u)
        assert np.isin(start, kept).all() and np.isin(kept, u).all() and len(kept) < len(u)
        angles = face_min_angles(mesh)
        gen = np.asarray(mesh.vertex_data["generator"])[mesh.face_indices]
        lo = np.minimum.reduceat(gen, mesh.face_offsets[:-1])[angles < 3.0]
        hi = np.maximum.reduceat(gen, mesh.face_offsets[:-1])[angles < 3.0]
        for k in np.flatnonzero(~np.isin(u, kept)):
            assert ((lo - refine._TAKE_BACK_STRIPS <= k) & (k <= hi + refine._TAKE_BACK_STRIPS)).any()
        fewer += int((face_min_angles(new_mesh) < 3.0).sum() < (angles < 3.0).sum())
    assert fewer >= 1
    assert face_min_angles(built.mesh).min() >= 3.0
