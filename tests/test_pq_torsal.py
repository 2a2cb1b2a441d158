"""Torsal bands spanned by one coplanar pair of generators (ruledmesh.design.torsal)."""

from pathlib import Path

import numpy as np
from _shared import bspline_design as _design  # a helper module of tests/ (see conftest.py)
from _shared import check_exact, same_sense_edges
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.faces import area_shares, face_min_angles, planarity
from ruledmesh.design import build_design, build_file, parse_design
from ruledmesh.design.torsal import _sag, _twist, span_torsal_bands, twist_changes
from ruledmesh.hop import coplanarity
from ruledmesh.mesh import FaceKind
from ruledmesh.tolerances import FLAT_PAIR_MAX_SAG

QUALITY = Path(__file__).resolve().parents[1] / "benchmarks" / "quality"


def _generators(rulings):
    a = np.asarray(rulings.a)
    d = np.asarray(rulings.b) - a
    p = np.r_[a, a + d]
    return a, d, float(np.linalg.norm(p.max(0) - p.min(0)))


def _unrefined(name):
    text = (QUALITY / name).read_text().replace("[mesh]", "[mesh]\nrefine = false")
    return build_design(parse_design(text)).rulings


def _check_pairs(rulings, spanned, bands, left_out):
    """Each band is one strip between exactly coplanar generators across a twist change,
    the surface between them within the sag bound, and only generators inside it gone."""
    u, new_u = np.asarray(rulings.u), np.asarray(spanned.u)
    assert np.all(np.diff(new_u) > 0)
    a, d, scale = _generators(spanned)
    twist = coplanarity(a, d, scale)
    a0, d0, _ = _generators(rulings)
    sign = np.sign(coplanarity(a0, d0, scale))
    gone = np.zeros(len(u), bool)
    for lo, hi in bands:
        assert hi == lo + 1
        assert abs(twist[lo]) <= 1e-13, twist[lo]
        assert abs(float(_twist(spanned.surface, new_u[lo], np.array([new_u[hi]]), scale)[0])) <= 1e-13
        assert _sag(spanned.surface, (new_u[lo], new_u[hi]), scale) <= FLAT_PAIR_MAX_SAG
        inside = (u > new_u[lo]) & (u < new_u[hi])
        gone |= inside
        # The pair straddles a change of the twist's sense on the given generators.
        near = sign[max(int(np.searchsorted(u, new_u[lo])) - 1, 0):int(np.searchsorted(u, new_u[hi])) + 1]
        assert (near > 0).any() and (near < 0).any()
    assert int(gone.sum()) == left_out
    # Every generator outside the bands stays.
    assert np.isin(u[~gone], new_u).all()


def test_span_torsal_bands_gives_coplanar_pairs_on_the_right_conoid():
    rulings = _unrefined("right-conoid-wide-arc.toml")
    a, d, scale = _generators(rulings)
    assert twist_changes(a, d, scale).size
    spanned, bands, left_out = span_torsal_bands(rulings, np.ones(len(a) - 1, bool), scale)
    assert spanned is not None and bands
    _check_pairs(rulings, spanned, bands, left_out)


def test_the_sag_of_a_pair_counts_the_border_curves_within_its_plane():
    """A pair's strip is a planar quadrilateral with straight ends: where the director curves
    bow away from those ends within the plane, that is a gap of the mesh as much as a bulge
    out of it.  A flat patch between a circular arc and a line: no bulge, and the sag is the
    arc's chordal sag (it was measured as zero)."""

    class Flat:
        r = 10.0

        def a(self, u):
            th = np.asarray(u, float)
            return np.stack([self.r * np.cos(th), self.r * np.sin(th), 0.0 * th], axis=-1)

        def b(self, u):
            th = np.asarray(u, float)
            return np.stack([0.5 * self.r * np.cos(th), 0.5 * self.r * np.sin(th), 0.0 * th], axis=-1)

        def point(self, u, t):
            u, t = np.broadcast_arrays(np.asarray(u, float), np.asarray(t, float))
            return self.a(u) + t[..., None] * (self.b(u) - self.a(u))

    u0, u1 = 0.2, 0.6
    chord = Flat.r * (1.0 - np.cos((u1 - u0) / 2))
    sag = _sag(Flat(), (u0, u1), 1.0)
    assert 0.97 * chord <= sag <= chord * (1 + 1e-12)


def test_a_band_too_wide_for_its_pair_is_spanned_among_denser_generators(monkeypatch):
    """On the Pluecker conoid every pair across a torsal generator at the given spacing
    bulges from its plane by more than the bound: without added generators no band is
    spanned; with the spacing around the bands halved, both are, within the bound."""
    import ruledmesh.design.torsal as torsal

    rulings = _unrefined("plucker-conoid.toml")
    a, d, scale = _generators(rulings)
    u = np.asarray(rulings.u)
    changes = twist_changes(a, d, scale)
    assert changes.size == 2
    for g in changes.tolist():
        pair = torsal._pair(rulings.surface, u, g - 1, g + 1, scale)
        assert pair is None or _sag(rulings.surface, pair, scale) > FLAT_PAIR_MAX_SAG
    with monkeypatch.context() as m:
        m.setattr(torsal, "_DENSER_LEVELS", 0)
        spanned, bands, left_out = span_torsal_bands(rulings, np.ones(len(a) - 1, bool), scale)
        assert spanned is None and bands == [] and left_out == 0
    spanned, bands, left_out = span_torsal_bands(rulings, np.ones(len(a) - 1, bool), scale)
    assert spanned is not None and len(bands) == 2
    _check_pairs(rulings, spanned, bands, left_out)
    # The added generators lie around the bands only, and are counted.
    new_u = np.asarray(spanned.u)
    added = new_u[~np.isin(new_u, u)]
    assert spanned.info["inserted"] - rulings.info.get("inserted", 0) == added.size > 2 * 2
    near = np.zeros(added.size, bool)
    for g in changes.tolist():
        near |= (added >= u[g - 2]) & (added <= u[g + 2])
    assert near.all()


def test_a_spanned_band_is_one_strip_of_exact_strip_quads():
    """right-conoid-wide-arc: 15.8 % of the area was in triangles with its torsal band
    closed by triangles; with the band spanned by a coplanar pair 11.9 %."""
    built = build_file(QUALITY / "right-conoid-wide-arc.toml")
    check_exact(built)
    mesh = built.mesh
    said = [w for w in mesh.info["warnings"] if "spanned by a coplanar pair" in w]
    assert said, mesh.info["warnings"]
    strip = mesh.face_kind == FaceKind.STRIP
    assert strip.any() and planarity(mesh)[strip].max() <= 1e-12
    assert 1.0 - area_shares(mesh)["quads"] <= 0.13
    assert face_min_angles(mesh).min() >= 3.0


curves = st.lists(st.floats(-2.0, 2.0), min_size=10, max_size=10)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(y1=curves, y2=curves, count=st.integers(30, 60))
def test_spanned_bands_are_coplanar_on_random_director_curves(y1, y2, count):
    x = np.linspace(0.0, 10.0, 5)
    c1 = np.c_[x, y1[:5], 0.5 * np.asarray(y1[5:])]
    c2 = np.c_[x, y2[:5], 4.0 + 0.5 * np.asarray(y2[5:])]
    rulings = build_design(parse_design(_design(c1, c2, count, 4, "refine = false\n"))).rulings
    a, _, scale = _generators(rulings)
    spanned, bands, left_out = span_torsal_bands(rulings, np.ones(len(a) - 1, bool), scale)
    if spanned is None:
        assert bands == [] and left_out == 0
        return
    _check_pairs(rulings, spanned, bands, left_out)


def test_strip_quads_turn_the_way_their_neighbours_do():
    """The strip quads and the fill between runs were laid out by their strips and came out
    turned against the runs' faces (8 edges on right-conoid-wide-arc, 170 on
    skew-bspline-51x30 at 1e-3): every face now turns one way."""
    for name in ("right-conoid-wide-arc.toml", "skew-bspline-51x30-tol1e-3.toml", "corner-90deg-tol1e-3.toml",
                 "twisted-helices-tol1e-3.toml", "near-cone.toml"):
        mesh = build_file(QUALITY / name).mesh
        assert same_sense_edges(mesh) == 0, name


def test_large_strip_quads_are_cut_to_the_size_of_the_other_panels():
    """right-conoid-wide-arc: the spanned strip had 4 quads of 17 times the median quad's
    area; they are cut along lines between its generators, the triangles beside them fanned,
    with no face turned, no angle lowered and the share in quads as it was."""
    from ruledmesh.analysis.faces import convexity, face_normals

    built = build_file(QUALITY / "right-conoid-wide-arc.toml")
    check_exact(built)
    mesh = built.mesh
    assert mesh.info["cut"] >= 2
    area = face_normals(mesh)[1]
    quads = mesh.valences == 4
    strip = mesh.face_kind == FaceKind.STRIP
    assert area[strip].max() <= 10.0 * np.median(area[quads & ~strip])
    assert convexity(mesh).all() and same_sense_edges(mesh) == 0
    assert face_min_angles(mesh).min() >= 3.0
    # The members along the cut generators still run end to end, one piece per edge.
    g = np.asarray(mesh.vertex_data["generator"])
    assert np.all(g[mesh.members[:, 0]] == g[mesh.members[:, 1]])
    assert np.all(g[mesh.members[:, 0]] == mesh.member_id)


# Two zigzag polylines in one plane, c2 doubling back along one line: generator 2 ends where
# generator 0 starts, and a pass merges the two corners into generator 0's vertex.
DOUBLED_BACK = """
[curves.c1]
type = "bspline"
points = [[0, 0, 0], [0, 1, 0], [0, 0, 1], [0, 1, 0]]
degree = 1
[curves.c2]
type = "bspline"
points = [[0, 0, 1], [0, 0, 0], [0, 0, 1], [0, 0, 0]]
degree = 1
[rulings]
between = ["c1", "c2"]
count = 3
[mesh]
rows = 1
refine = false
"""


def test_a_quad_with_merged_corners_is_not_cut_as_a_strip_quad():
    """Found by the fuzzing (test_fuzz_ruled_designs): a large strip quad whose corners a pass
    had merged across generators was cut as if two of its edges lay on generators; its new
    points, labelled with a generator and t, lay up to 0.4 (of a 1.4 patch) off it."""
    built = build_design(parse_design(DOUBLED_BACK, "doubled-back.toml"))
    mesh, r = built.mesh, built.rulings
    a, b = np.asarray(r.a), np.asarray(r.b)
    g, t = np.asarray(mesh.vertex_data["generator"]), np.asarray(mesh.vertex_data["t"])
    assert np.abs(a[g] + t[:, None] * (b[g] - a[g]) - mesh.vertices).max() <= 1e-12
