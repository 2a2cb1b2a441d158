"""Invariants of the §4.3 PQ mesher (paper §4.3)."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ruledmesh import GeometryError, ParameterError
from ruledmesh.analysis.faces import convexity, face_areas, planarity
from ruledmesh.hop import hop
from ruledmesh.mesh import FaceKind
from ruledmesh.pq import pq_mesh
from ruledmesh.tolerances import DEFAULT


def hyperboloid_lines(a, c, phi0, phi1, m, h=1.0):
    """Generators of one regulus of (x^2 + y^2)/a^2 - z^2/c^2 = 1 between z = -h c and h c."""
    phi = np.linspace(phi0, phi1, m)
    p = lambda s: np.stack([a * (np.cos(phi) - s * h * np.sin(phi)),
                            a * (np.sin(phi) + s * h * np.cos(phi)),
                            np.full(m, s * h * c)], axis=1)
    return p(-1.0), p(1.0)


def hp_lines(a, b, x0, x1, m, y=1.0):
    """Generators x = const of the hyperbolic paraboloid z = x y / (a b)."""
    x = np.linspace(x0, x1, m)
    A = np.stack([x, np.full(m, -y), -x * y / (a * b)], axis=1)
    B = np.stack([x, np.full(m, y), x * y / (a * b)], axis=1)
    return A, B


def check_mesh(mesh, tol=DEFAULT):
    assert np.all(np.isfinite(mesh.vertices))
    assert planarity(mesh).max() <= tol.planarity
    assert convexity(mesh).all()
    assert face_areas(mesh).min() > 0
    assert mesh.euler_characteristic() == 1


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(a=st.floats(0.5, 3), c=st.floats(0.5, 3), phi0=st.floats(0, 6.3), span=st.floats(0.6, 3.0),
       m=st.integers(5, 40), rows=st.integers(2, 30), option=st.integers(0, 1),
       primary=st.floats(0, 0.999))
def test_hyperboloid_regulus_vertices_on_quadric(a, c, phi0, span, m, rows, option, primary):
    A, B = hyperboloid_lines(a, c, phi0, phi0 + span, m)
    mesh = pq_mesh(A, B, rows=rows, option=option, primary=int(primary * m))
    v = mesh.vertices
    scale = mesh.diagonal()
    # Distance to the quadric, to first order: |F| / |grad F|.
    F = (v[:, 0] ** 2 + v[:, 1] ** 2) / a**2 - v[:, 2] ** 2 / c**2 - 1
    grad = 2 * np.sqrt((v[:, 0] ** 2 + v[:, 1] ** 2) / a**4 + v[:, 2] ** 2 / c**4)
    assert np.max(np.abs(F) / grad) / scale <= 1e-10
    check_mesh(mesh)
    if m >= 10 and rows >= 6:
        assert np.count_nonzero(mesh.face_kind == FaceKind.QUAD) > 0


@settings(max_examples=40, deadline=None)
@given(a=st.floats(0.3, 3), b=st.floats(0.3, 3), x0=st.floats(-3, 0), w=st.floats(0.5, 4),
       m=st.integers(3, 40), rows=st.integers(1, 30), option=st.integers(0, 1))
def test_hp_regulus_vertices_on_quadric(a, b, x0, w, m, rows, option):
    A, B = hp_lines(a, b, x0, x0 + w, m)
    mesh = pq_mesh(A, B, rows=rows, option=option)
    v = mesh.vertices
    F = v[:, 2] - v[:, 0] * v[:, 1] / (a * b)
    grad = np.sqrt(1 + (v[:, 0] ** 2 + v[:, 1] ** 2) / (a * b) ** 2)
    assert np.max(np.abs(F) / grad) / mesh.diagonal() <= 1e-10
    check_mesh(mesh)


def test_hp_mesh_is_all_quads_inside():
    """A gently twisted patch: rows stay near t = const, interior faces are all PQ quads."""
    A, B = hp_lines(1, 1, -1, 1, 21)
    mesh = pq_mesh(A, B, rows=20)
    kinds = mesh.count_kinds()
    assert kinds["quad"] == 180 and "split" not in kinds
    # Every quad has one diagonal on a generator: its corners 1 and 3 share a generator.
    _ids, quads = mesh.faces_of_valence(4)
    gen = mesh.vertex_data["generator"]
    assert np.all(gen[quads[:, 1]] == gen[quads[:, 3]])
    assert np.all(np.abs(gen[quads[:, 0]] - gen[quads[:, 2]]) == 2)


def test_members_are_generator_segments():
    A, B = hyperboloid_lines(1, 1, 0, 2, 15)
    mesh = pq_mesh(A, B, rows=12)
    gen = mesh.vertex_data["generator"]
    m0, m1 = mesh.members.T
    assert np.all(gen[m0] == mesh.member_id) and np.all(gen[m1] == mesh.member_id)
    # Each member lies on its generator line.
    d = B - A
    for end in (m0, m1):
        g = mesh.member_id
        rel = mesh.vertices[end] - A[g]
        assert np.abs(np.cross(rel, d[g])).max() < 1e-12
    # Every generator's members chain from t = 0 to t = 1: total length = generator length.
    lengths = np.linalg.norm(mesh.vertices[m1] - mesh.vertices[m0], axis=1)
    per_gen = np.bincount(mesh.member_id, lengths)
    np.testing.assert_allclose(per_gen, np.linalg.norm(d, axis=1), rtol=1e-12)


def _quads(mesh):
    """Corner coordinates of the §4.3 quads (kind QUAD), in a canonical order."""
    ids = np.flatnonzero(mesh.face_kind == FaceKind.QUAD)
    return mesh.vertices[mesh.face_indices[mesh.face_offsets[ids][:, None] + np.arange(4)]]


def test_affine_maps_commute_with_the_checkerboard():
    """The §4.3 construction is affine: the quads map to the quads.  (The fill between them is
    shaped by angles and lengths, which affine maps do not keep; similarities below.)"""
    rng = np.random.default_rng(3)
    A, B = hyperboloid_lines(1.2, 0.8, 0.3, 2.5, 17)
    M = rng.normal(size=(3, 3)) + 3 * np.eye(3)
    t = rng.normal(size=3)
    f = lambda p: p @ M.T + t
    direct = pq_mesh(A, B, rows=10)
    mapped = pq_mesh(f(A), f(B), rows=10)
    qd, qm = _quads(direct), _quads(mapped)
    assert len(qd) == len(qm) > 0
    np.testing.assert_allclose(qm, f(qd), atol=1e-11 * mapped.diagonal())


def test_similarities_commute_with_the_whole_mesh():
    rng = np.random.default_rng(4)
    A, B = hyperboloid_lines(1.2, 0.8, 0.3, 2.5, 17)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    t = rng.normal(size=3) * 100
    f = lambda p: 7.5 * p @ Q.T + t
    direct = pq_mesh(A, B, rows=10)
    mapped = pq_mesh(f(A), f(B), rows=10)
    assert mapped.n_faces == direct.n_faces
    np.testing.assert_array_equal(mapped.face_indices, direct.face_indices)
    np.testing.assert_allclose(mapped.vertices, f(direct.vertices), atol=1e-11 * mapped.diagonal())


def test_projective_maps_commute_with_the_hop():
    rng = np.random.default_rng(5)
    a, d = rng.normal(size=(3, 3)), rng.normal(size=(3, 3))
    P = a[0] + rng.uniform(-1, 1, size=(20, 1)) * d[0]
    H = np.eye(4) + 0.1 * rng.normal(size=(4, 4))

    def proj(x):
        xh = np.c_[x, np.ones(len(x))] @ H.T
        return xh[:, :3] / xh[:, 3:]

    Q, R, ok = hop(P, a[1], d[1], a[2], d[2])
    assert ok.all()
    # Map the lines by mapping two points of each.
    a2 = proj(a)
    d2 = proj(a + d) - a2
    Qp, Rp, ok2 = hop(proj(P), a2[1], d2[1], a2[2], d2[2])
    assert ok2.all()
    np.testing.assert_allclose(Qp, proj(Q), atol=1e-9)
    np.testing.assert_allclose(Rp, proj(R), atol=1e-9)


def test_hop_at_infinity_is_flagged_not_nan():
    # g2 parallel to the plane through P and g1: Q at infinity.
    P = np.array([[0.0, 0.0, 0.0]])
    a1, d1 = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    a2, d2 = np.array([2.0, 0, 1]), np.array([1.0, 0, 0])
    Q, R, ok = hop(P, a1, d1, a2, d2)
    assert not ok[0] and np.all(np.isfinite(Q)) and np.all(np.isfinite(R))


def test_torsal_pair_builds_with_fill_triangles():
    A, B = hp_lines(1, 1, -1, 1, 21)
    # Generators 10 and 11 meet: they share their end point on c2.
    B[11] = B[10]
    mesh = pq_mesh(A, B, rows=20)
    check_mesh(mesh)
    assert any("torsal strips" in w for w in mesh.info["warnings"])
    assert mesh.count_kinds().get("fill", 0) > 0


def test_sign_change_of_twist_is_a_torsal_cut():
    # Rotate the generator direction one way, then back: the twist changes sign in the middle.
    m = 31
    u = np.linspace(0, 1, m)
    ang = 0.8 * np.sin(np.pi * u)
    A = np.stack([4 * u, np.zeros(m), np.zeros(m)], 1)
    B = A + np.stack([np.zeros(m), np.cos(ang), np.sin(ang)], 1) * 2
    mesh = pq_mesh(A, B, rows=16)
    check_mesh(mesh)
    assert any("torsal strips" in w for w in mesh.info["warnings"])


def test_parallel_generators_cylinder_is_a_prism_of_strip_quads():
    """No hop across parallel generators; each coplanar strip carries planar quads (§3.1)."""
    m = 12
    phi = np.linspace(0, 2, m)
    A = np.stack([np.cos(phi), np.sin(phi), np.zeros(m)], 1)
    B = A + [0, 0, 2]
    mesh = pq_mesh(A, B, rows=8)
    check_mesh(mesh)
    assert mesh.count_kinds() == {"strip": mesh.n_faces}
    assert np.all(np.diff(mesh.face_offsets) == 4)


def test_untrimmed_mesh_keeps_the_extension():
    A, B = hp_lines(1, 1, -1, 1, 11)
    trimmed = pq_mesh(A, B, rows=10, extend=0.5)
    untrimmed = pq_mesh(A, B, rows=10, extend=0.5, trim=False)
    t = untrimmed.vertex_data["t"]
    assert t.min() < -0.4 and t.max() > 1.4
    assert trimmed.vertex_data["t"].min() >= 0 and trimmed.vertex_data["t"].max() <= 1
    check_mesh(untrimmed)


def test_bad_arguments_name_the_parameter():
    A, B = hp_lines(1, 1, -1, 1, 5)
    with pytest.raises(ParameterError, match="option"):
        pq_mesh(A, B, option=2)
    with pytest.raises(ParameterError, match="primary"):
        pq_mesh(A, B, primary=9)
    with pytest.raises(ParameterError, match="extend"):
        pq_mesh(A, B, extend="lots")
    with pytest.raises(ParameterError, match="b"):
        pq_mesh(A, B[:4])
    B2 = B.copy()
    B2[2] = A[2]
    with pytest.raises(GeometryError, match="generator 2 has zero length"):
        pq_mesh(A, B2)
    with pytest.raises(ParameterError, match="finite"):
        pq_mesh(np.where(A[0, 0] == A, np.nan, A), B)


def test_huge_grid_is_refused_up_front_with_its_memory():
    A, B = hp_lines(1, 1, -1, 1, 1_000_000)
    with pytest.raises(GeometryError, match="GiB"):
        pq_mesh(A, B, rows=200)


def test_far_rows_are_never_emitted():
    # A strongly twisted set of lines: rows run off to infinity on some generators.
    rng = np.random.default_rng(11)
    A = rng.normal(size=(15, 3))
    B = A + rng.normal(size=(15, 3))
    mesh = pq_mesh(A, B, rows=12)
    assert np.all(np.isfinite(mesh.vertices))
    lo = np.minimum(A.min(0), B.min(0))
    hi = np.maximum(A.max(0), B.max(0))
    # Trimmed vertices lie on the generator segments, so inside the lines' bounding box.
    assert np.all(mesh.vertices >= lo - 1e-9) and np.all(mesh.vertices <= hi + 1e-9)
    assert planarity(mesh).max() <= DEFAULT.planarity
    assert convexity(mesh).all()


def test_kink_of_a_director_polyline_gets_a_generator_and_matched_rows():
    """A polyline corner makes a crease: a generator is put through it, the rows restart there
    with a matched division, and the crease costs no band of splinters."""
    from pathlib import Path

    from ruledmesh.design import build_file

    built = build_file(Path(__file__).resolve().parents[1] / "examples" / "skew.toml")
    mesh = built.mesh
    check_mesh(mesh)
    info = built.rulings.info
    assert len(info["crease_generators"]) == 2 and info["inserted"] >= 2
    assert len(built.rulings.a) == 41 + info["inserted"]
    # The two corners of c2 lie exactly on the inserted generators.
    corners = np.array([[3, 4, 5], [6, 3, 3]], float)
    for k, c in zip(info["crease_generators"], corners):
        assert np.linalg.norm(built.rulings.b[k] - c) < 1e-9
    assert "creases" not in info
    kinds = mesh.count_kinds()
    assert kinds.get("split", 0) < 0.05 * kinds["quad"]
    A, B = built.rulings.a, built.rulings.b
    with pytest.raises(ParameterError, match="creases"):
        pq_mesh(A, B, creases=[len(A) - 1])
    with pytest.raises(ParameterError, match="crease_generators"):
        pq_mesh(A, B, crease_generators=[0])


@pytest.mark.parametrize("h", [np.sqrt(3.0), 3.0])
def test_strongly_twisted_hyperboloid_carries_rows_to_its_side_generators(h):
    """Half a hyperboloid whose generators turn by 120 (h = sqrt 3) or 143 degrees: the rows
    of the primary's part reach its middle third only, the rest lies far out on the primary,
    where even steps bunched into slivers.  48 % and 72 % of the area were triangles and the
    side generators carried no rows; with the bunching rows left out 15 % and 20 %."""
    from ruledmesh.analysis.faces import area_shares, face_min_angles

    A, B = hyperboloid_lines(2.0, 1.0, 0.0, np.pi, 61, h=h)
    mesh = pq_mesh(A, B, rows=24)
    check_mesh(mesh)
    assert 1.0 - area_shares(mesh)["quads"] <= 0.22
    assert face_min_angles(mesh).min() >= 3.0
    assert not any("carry no" in w for w in mesh.info["warnings"])


def test_full_extension_keeps_the_rows_that_auto_leaves_out():
    """extend = "full" covers what "auto" covers, with every row of the even division: on
    the twisted hyperboloid the bunched rows cut the runs short again, so the side
    generators carry no rows (what thinning avoids); the mesh is as exact, and a misspelt
    word is refused naming the parameter."""
    A, B = hyperboloid_lines(2.0, 1.0, 0.0, np.pi, 61, h=3.0)
    auto = pq_mesh(A, B, rows=24)
    full = pq_mesh(A, B, rows=24, extend="full")
    check_mesh(full)
    assert (auto.info["extend"], full.info["extend"]) == ("auto", "full")

    assert any("carry no" in w for w in full.info["warnings"])
    assert not any("carry no" in w for w in auto.info["warnings"])
    with pytest.raises(ParameterError, match="extend"):
        pq_mesh(A, B, rows=24, extend="fill")


def test_rows_that_do_not_bunch_are_all_kept():
    from ruledmesh.skew.pq.extension import thinned_rows

    tau = np.arange(-10, 41) / 24.0
    tau = tau[:len(tau) // 2 * 2]
    M = np.tile(np.eye(2), (5, 1, 1))
    M[:, 0, 1] = np.linspace(-0.5, 0.5, 5)                  # shifted copies: the same spacing
    assert np.array_equal(thinned_rows(M, tau, (0.0, 1.0), 24), tau)


@given(st.integers(8, 60), st.floats(0.2, 3.0))
@settings(max_examples=60, deadline=None)
def test_rows_beyond_the_primary_part_are_spread_where_they_bunch(rows, k):
    """One generator takes the primary's tau to t = k / tau: far out even steps land ever
    closer.  Beyond [0, 1] the a-rows kept land there about half of _BUNCHING of a step
    apart or more (the last, the margin, excepted: a row is kept where the running sum of
    the steps' shares passes a whole number, so two kept rows are at least max(s, 1 - s)
    apart for steps of share s, less the change of s from step to step), every a-row of
    the primary's part stays, and so do the ends."""
    from ruledmesh.skew.pq import extension
    from ruledmesh.skew.pq.extension import thinned_rows

    tau = np.arange(-4, 20 * rows + 2) / rows
    tau = tau[:len(tau) // 2 * 2]
    M = np.array([np.eye(2), [[0.0, k], [1.0, 0.0]]])
    out = thinned_rows(M, tau, (0.0, 1.0), rows)
    assert np.all(np.diff(out) > 0)
    a, kept = tau[0::2], out[0::2]
    own = a[(a >= 0.0) & (a <= 1.0)]
    assert np.isin(own, kept).all() and kept[0] == a[0] and kept[-1] == a[-1]
    # (Up to 1.05 the primary itself lands on its patch and keeps the rows.)
    beyond = kept[kept > 1.05 + 2.0 / rows]
    image = k / beyond
    lands = image[:-1] < 1.0 + 0.05
    gaps = -np.diff(image)[lands[:len(image) - 1]][:-1]
    assert np.all(gaps >= 0.4 * extension._BUNCHING * 2.0 / rows)
    assert len(kept) < len(a)
    # Where even steps already land on the patch _BUNCHING of a step apart, none is left out.
    far = a[:-1] > 1.0
    far[far] = k / a[1:][far] < 1.0 + 0.05
    wide = np.zeros(len(a) - 1, bool)
    wide[far] = k / a[:-1][far] - k / a[1:][far] >= extension._BUNCHING * 2.0 / rows
    assert np.isin(a[1:][wide], kept).all()


def test_respaced_restarts_keep_the_rows_spread_on_a_strongly_twisted_surface():
    """Between two half circles turned by 160 degrees (a hyperboloid near its waist cone) the
    rows of an even division bunch on the generators a quarter turn away and gape elsewhere;
    restarting where they gape, with the division evened there, puts more of the area in
    quads, the faces as exact, and the widest gap between the rows on the patch shrinks."""
    from ruledmesh.skew.pq.respacing import SPREAD

    h = np.tan(np.radians(80.0))
    A, B = hyperboloid_lines(4.0 / np.hypot(1.0, h), 1.5 / h, 0.0, np.pi, 61, h=h)
    plain = pq_mesh(A, B, rows=24)
    spaced = pq_mesh(A, B, rows=24, respace=True)
    check_mesh(spaced)
    assert (plain.info["respace"], spaced.info["respace"]) == (False, True)
    assert spaced.info["restarts"] > plain.info["restarts"]

    def quads(mesh):
        area = face_areas(mesh)
        return area[mesh.valences == 4].sum() / area.sum()

    def widest_gap(mesh):
        g, t = mesh.vertex_data["generator"], mesh.vertex_data["t"]
        order = np.lexsort((t, g))
        g, t = g[order], t[order]
        return np.max(np.where(g[1:] == g[:-1], np.diff(t), 0.0))

    assert quads(spaced) > quads(plain) + 0.03, (quads(plain), quads(spaced))
    assert widest_gap(spaced) < widest_gap(plain)
    assert widest_gap(plain) > SPREAD * 2 / 24
    with pytest.raises(ParameterError, match="respace"):
        pq_mesh(A, B, rows=24, respace="yes")


@given(st.lists(st.floats(0.0, 1.0), min_size=2, max_size=60, unique=True), st.integers(2, 80))
@settings(max_examples=200, deadline=None)
def test_evened_division_steps_stay_within_half_and_one_and_a_half_steps(values, rows):
    """The evened division keeps its ends and only entries of the division it evens, and
    every entry of that division lies within half a step of one it keeps; its steps stay
    within half a step and a step and a half (unless the whole division is shorter)."""
    from ruledmesh.skew.pq.respacing import evened

    t = np.sort(np.asarray(values))
    out = evened(t, rows)
    step = 2.0 / rows
    assert np.all(np.diff(out) > 0)
    assert (out[0], out[-1]) == (t[0], t[-1])
    kept = out[np.isin(out, t)]
    nearest = np.abs(t[:, None] - kept[None, :]).min(axis=1)
    assert np.all(nearest < 0.5 * step + 1e-12)
    if t[-1] - t[0] >= 0.5 * step:
        assert np.diff(out).min() >= 0.5 * step * (1 - 1e-9)
    assert np.diff(out).max() <= 1.5 * step * (1 + 1e-9)


def test_spread_generators_are_those_whose_rows_gape():
    from ruledmesh.skew.pq.respacing import spread_generators

    even = np.linspace(0.0, 1.0, 13)                 # the division's own step, 2 / 24
    gaping = np.r_[np.linspace(0.0, 0.3, 8), 0.9]    # a gap of 0.6: 7.2 steps
    short = np.array([0.45])                         # one vertex: left to the torsal cases
    t = np.r_[even, gaping, short, even - 0.5]       # the last: half beyond the border
    gen = np.repeat([5, 6, 7, 8], [13, 9, 1, 13])
    far = np.zeros(t.size, bool)
    got = spread_generators(t, gen, far, 5, 4, rows=24)
    assert got.tolist() == [False, True, False, True]
    far[gen == 6] = True
    assert not spread_generators(t, gen, far, 5, 4, rows=24)[1]


def moebius_band_lines(n=60, turn=5.2, r=5.0, w=0.8):
    """Generators of a Moebius band (centre circle of radius ``r``, half-width ``w``, the
    generator turning by half the angle about the circle), over ``turn`` radians."""
    phi = np.linspace(0.0, turn, n)
    c = np.stack([r * np.cos(phi), r * np.sin(phi), 0 * phi], 1)
    e = np.stack([np.cos(phi) * np.cos(phi / 2), np.sin(phi) * np.cos(phi / 2), np.sin(phi / 2)], 1)
    return c - w * e, c + w * e


def _quad_share_of_border_edges(mesh, side):
    """Of the mesh's edges between the end points ``t = side`` of consecutive generators,
    the share that are edges of quads."""
    t, g = mesh.vertex_data["t"], mesh.vertex_data["generator"]
    idx = mesh.face_indices
    nxt = idx[mesh.next_corners()]
    face = np.repeat(np.arange(mesh.n_faces), mesh.valences)
    on = np.abs(t - side) <= 1e-12
    edge = on[idx] & on[nxt] & (np.abs(g[idx] - g[nxt]) == 1)
    return float(np.mean(mesh.valences[face[edge]] == 4)), int(edge.sum())


def test_rows_through_the_end_points_leave_no_teeth_on_that_curve():
    """Rows through the generators' end points on c1 (c2) make the border there edges of
    quads: on a Moebius band, where the rows run steeply across the generators, none of the
    border edges is a quad edge with the rows from the primary, most are from either curve,
    and the band of teeth along it (half the triangles) goes."""
    A, B = moebius_band_lines()
    plain = pq_mesh(A, B, rows=16)
    assert plain.info["rows_from"] == "primary"
    shares = {}
    for side, rows_from in ((0.0, "c1"), (1.0, "c2")):
        mesh = pq_mesh(A, B, rows=16, rows_from=rows_from)
        check_mesh(mesh)
        assert mesh.info["rows_from"] == rows_from
        on_generators = A[mesh.vertex_data["generator"]] + mesh.vertex_data["t"][:, None] * (
            B - A)[mesh.vertex_data["generator"]]
        assert np.abs(mesh.vertices - on_generators).max() <= 1e-12 * np.abs(A).max()
        share, edges = _quad_share_of_border_edges(mesh, side)
        assert edges >= 50 and share >= 0.8, (share, edges)
        assert _quad_share_of_border_edges(plain, side)[0] == 0.0
        area = face_areas(mesh)
        shares[rows_from] = area[mesh.valences == 3].sum() / area.sum()
    plain_area = face_areas(plain)
    plain_share = plain_area[plain.valences == 3].sum() / plain_area.sum()
    assert plain_share > 0.45 and max(shares.values()) < 0.35, (plain_share, shares)
    with pytest.raises(ParameterError, match="rows_from"):
        pq_mesh(A, B, rows_from="c3")


def test_rows_through_the_end_points_on_both_curves_fill_where_one_family_turns_back():
    """On the closed Moebius band of moebius-lines (73 lines, half-width 1 about a circle of
    radius 4) the rows through one edge's end points turn back over a stretch before they reach
    the other edge; the rows through both edges' end points are one division in which the other
    family fills that stretch: less of the area in triangles than from either edge alone
    (13.3 % against 15.4-15.6 %), every face still exact, convex and on the generators."""
    phi = np.linspace(0.0, 2 * np.pi, 73)
    e_r = np.stack([np.cos(phi), np.sin(phi), 0 * phi], 1)
    e = np.cos(phi / 2)[:, None] * e_r + np.sin(phi / 2)[:, None] * np.array([0.0, 0.0, 1.0])
    A, B = 4 * e_r - e, 4 * e_r + e

    def triangles(mesh):
        area = face_areas(mesh)
        return area[mesh.valences == 3].sum() / area.sum()

    one = [pq_mesh(A, B, rows=16, rows_from=side) for side in ("c1", "c2")]
    both = pq_mesh(A, B, rows=16, rows_from="both")
    assert both.info["rows_from"] == "both"
    # The band is closed (its last line is its first, reversed): not a disc, so no Euler check.
    assert planarity(both).max() <= DEFAULT.planarity and convexity(both).all()
    assert face_areas(both).min() > 0
    g, t = both.vertex_data["generator"], both.vertex_data["t"]
    assert np.abs(both.vertices - (A[g] + t[:, None] * (B - A)[g])).max() <= 1e-12 * 5
    assert ((t >= -1e-12) & (t <= 1 + 1e-12)).all()
    assert triangles(both) < min(triangles(m) for m in one) - 0.015
    # Rows pass through end points of both edges.
    for side in (0.0, 1.0):
        assert _quad_share_of_border_edges(both, side)[1] >= 20


def _same_mesh(m1, m2) -> bool:
    return all(np.array_equal(getattr(m1, k), getattr(m2, k)) for k in (
        "vertices", "face_offsets", "face_indices", "face_kind", "members", "member_id"))


def test_rows_from_per_generator_give_each_segment_its_own():
    """``rows_from`` (and ``option``) per generator: each segment between torsal generators
    (here where the twist changes sign) takes the value of the generator its rows start from;
    one value for every generator is the mesh of that value, bit for bit."""
    s = np.linspace(0.0, 1.0, 41)[:, None]
    A = np.c_[10 * s, 0 * s, 0 * s]
    B = np.c_[10 * s, 3 * np.sin(2 * np.pi * s), 4 + 0 * s]
    c1 = pq_mesh(A, B, rows=12, rows_from="c1")
    assert _same_mesh(c1, pq_mesh(A, B, rows=12, rows_from=["c1"] * 41))
    segments = c1.info["row_segments"]
    assert sorted(sg[:2] for sg in segments) == [[0, 10], [11, 30], [31, 40]]
    per = ["c1"] * 41
    per[11:31] = ["c2"] * 20
    mixed = pq_mesh(A, B, rows=12, rows_from=per)
    check_mesh(mixed)
    assert mixed.info["rows_from"] == "mixed"
    assert sorted(mixed.info["row_segments"]) == [[0, 10, "c1", 0], [11, 30, "c2", 0], [31, 40, "c1", 0]]
    assert mixed.info["option"] == 0
    g, t = mixed.vertex_data["generator"], mixed.vertex_data["t"]
    assert np.abs(mixed.vertices - (A[g] + t[:, None] * (B - A)[g])).max() <= 1e-12 * 10
    # The middle segment's faces are those of the mesh with every row from c2.
    c2 = pq_mesh(A, B, rows=12, rows_from="c2")

    def inner(m):
        gf = m.vertex_data["generator"][m.face_indices].reshape(-1)
        first = np.add.reduceat(gf, m.face_offsets[:-1]) / m.valences
        sel = (first > 12) & (first < 29)
        return np.sort(np.round(face_areas(m)[sel], 12))
    assert np.array_equal(inner(mixed), inner(c2)) and not np.array_equal(inner(mixed), inner(c1))
    # The checkerboard per generator likewise.
    colours = pq_mesh(A, B, rows=12, rows_from="c1", option=[0] * 11 + [1] * 20 + [0] * 10)
    check_mesh(colours)
    assert colours.info["option"] == "mixed" and colours.info["rows_from"] == "c1"
    assert sorted(s[3] for s in colours.info["row_segments"]) == [0, 0, 1]
    with pytest.raises(ParameterError, match=r"option\[3\]"):
        pq_mesh(A, B, option=[0] * 3 + [2] * 38)
    with pytest.raises(ParameterError, match=r"rows_from.*one per generator"):
        pq_mesh(A, B, rows_from=["c1"] * 40)
    with pytest.raises(ParameterError, match=r"rows_from\[40\]"):
        pq_mesh(A, B, rows_from=["c1"] * 40 + ["c3"])


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), rows_from=st.sampled_from(["c1", "c2", "both", "none", "mixed"]),
       m=st.integers(12, 61),
       rows=st.integers(4, 40), option=st.integers(0, 1))
def test_rows_through_the_end_points_keep_the_invariants(seed, rows_from, m, rows, option):
    """Random skew surfaces between two smooth curves: every face planar, convex and with
    area, every vertex on its generator inside the patch, with the rows through either
    curve's end points, without rows (or, per generator, from either, the primary or none)."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1.0, m)[:, None]
    k1, k2 = rng.normal(size=(2, 3)), rng.normal(size=(2, 3))
    c1 = np.c_[10 * s, np.zeros_like(s), np.zeros_like(s)] + np.sin(3 * s) * k1[0] + s ** 2 * k1[1]
    c2 = np.c_[10 * s, 2 + 0 * s, 4 + 0 * s] + np.cos(2 * s) * k2[0] + s ** 3 * k2[1]
    if rows_from == "mixed":     # per generator, at random, and the checkerboard too
        rows_from = rng.choice(["primary", "c1", "c2", "both", "none"], size=m).tolist()
        option = rng.integers(0, 2, size=m).tolist()
    mesh = pq_mesh(c1, c2, rows=rows, rows_from=rows_from, option=option)
    check_mesh(mesh)
    g, t = mesh.vertex_data["generator"], mesh.vertex_data["t"]
    assert np.abs(mesh.vertices - (c1[g] + t[:, None] * (c2 - c1)[g])).max() <= 1e-12 * 12
    assert ((t >= -1e-12) & (t <= 1 + 1e-12)).all()
