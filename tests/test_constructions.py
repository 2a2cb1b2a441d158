"""Catalogue constructions (paper §2-§3): each kind's invariant, over its parameters.

Invariants: every face planar to 1e-12; vertices on the
analytic surface to 1e-10 relative (checked with the test's own implicit
equation, not the library's reference); circular kinds circular to 1e-10;
translational kinds parallelograms.  The predicates come from
``_catalogue_checks`` (independent computations).
"""

from __future__ import annotations

import _catalogue_checks as chk  # a helper module of tests/ (see conftest.py)
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ruledmesh import constructions as C
from ruledmesh.errors import GeometryError, ParameterError

PLANAR = 1e-12
ON_SURFACE = 1e-10
CIRCULAR = 1e-10
FAST = settings(max_examples=20, deadline=None)

pos = st.floats(0.3, 4.0)


def faces(mesh):
    return mesh.face_list()


def assert_planar(mesh):
    q = chk.quads_of(mesh.vertices, faces(mesh))
    if len(q):
        assert chk.planarity(q).max() <= PLANAR
    for p in chk.polygons_of(mesh.vertices, faces(mesh)):
        assert chk.polygon_planarity(p) <= PLANAR
    assert np.all(mesh.valences >= 3)


def assert_circular(mesh):
    q = chk.quads_of(mesh.vertices, faces(mesh))
    assert len(q)
    assert chk.circularity(q).max() <= CIRCULAR


def assert_parallelograms(mesh):
    q = chk.quads_of(mesh.vertices, faces(mesh))
    assert len(q)
    assert chk.parallelogram(q).max() <= PLANAR


def assert_on(mesh, value, gradient):
    d = chk.sampson(value, gradient, mesh.vertices, chk.diagonal(mesh.vertices))
    assert d.max() <= ON_SURFACE


# ------------------------------------------------------------------ strips
@FAST
@given(st.lists(st.floats(0.5, 1.5), min_size=1, max_size=4), st.integers(3, 7),
       st.randoms(use_true_random=False))
def test_similar_strips_are_trapezoids(scales, n, rnd):
    rng = np.random.default_rng(rnd.randint(0, 2 ** 31))
    poly = rng.normal(size=(n, 3))
    trans = rng.normal(size=(len(scales), 3))
    mesh = C.similar_strips(poly, scales, trans, closed=True)
    assert mesh.n_faces == len(scales) * n
    assert_planar(mesh)
    # Consecutive polygons have pairwise parallel edges.
    v = mesh.vertices.reshape(len(scales) + 1, n, 3)
    e0, e1 = np.diff(v[:-1], axis=1), np.diff(v[1:], axis=1)
    cross = np.linalg.norm(np.cross(e0, e1), axis=2)
    assert cross.max() <= 1e-12 * (np.linalg.norm(e0, axis=2) * np.linalg.norm(e1, axis=2)).max()


@FAST
@given(st.integers(3, 6), st.integers(1, 4), st.randoms(use_true_random=False))
def test_parallel_edge_strips_planar(n, k, rnd):
    rng = np.random.default_rng(rnd.randint(0, 2 ** 31))
    mesh = C.parallel_edge_strips(rng.normal(size=(n, 3)), rng.normal(size=(k, 3)),
                                  rng.uniform(0.5, 1.5, size=(k, n - 1)))
    assert mesh.n_faces == k * (n - 1)
    assert_planar(mesh)


# -------------------------------------------------------------- developables
@FAST
@given(st.integers(3, 8), st.integers(1, 5), st.randoms(use_true_random=False))
def test_prism_pyramid_torsal_planar_with_members_on_lines(n, layers, rnd):
    rng = np.random.default_rng(rnd.randint(0, 2 ** 31))
    poly = rng.normal(size=(n, 3))
    prism = C.prism(poly, rng.normal(size=3) + [0, 0, 3], layers)
    assert_parallelograms(prism)
    pyr = C.pyramid(poly, [0.1, 0.2, 5.0], layers, closed=True, to_apex=True)
    assert_planar(pyr)
    assert pyr.count_kinds()["polygon"] == n  # triangles at the apex
    ang = np.linspace(0, 2.5, n + 2)
    helix = np.stack([np.cos(ang), np.sin(ang), 0.3 * ang], axis=1)
    tors = C.torsal_polyhedron(helix, (0.1, 1.0), layers)
    assert_planar(tors)
    for mesh in (prism, pyr, tors):
        # All member segments of one line are collinear.
        for line in np.unique(mesh.member_id):
            seg = mesh.vertices[mesh.members[mesh.member_id == line]]
            d = seg[:, 1] - seg[:, 0]
            scale = np.linalg.norm(d[0]) * np.linalg.norm(d, axis=1).max()
            assert np.linalg.norm(np.cross(d, d[0]), axis=1).max() <= 1e-12 * scale


def test_torsal_polyhedron_refuses_straight_polygon():
    with pytest.raises(GeometryError, match="parallel"):
        C.torsal_polyhedron([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 1, 0]])


# ------------------------------------------------------------ translational
@FAST
@given(st.integers(2, 9), st.integers(2, 9), st.randoms(use_true_random=False))
def test_translational_parallelograms(m, n, rnd):
    rng = np.random.default_rng(rnd.randint(0, 2 ** 31))
    p = np.cumsum(rng.normal(size=(m, 3)), axis=0)
    q = np.cumsum(rng.normal(size=(n, 3)), axis=0)
    mesh = C.translational_mesh(p, q)
    assert mesh.n_faces == (m - 1) * (n - 1)
    assert_parallelograms(mesh)
    assert_planar(mesh)


# --------------------------------------------------------------- rotational
meridians = st.lists(st.tuples(st.one_of(st.just(0.0), st.floats(0.1, 3.0)),
                               st.integers(-30, 30)),
                     min_size=2, max_size=8, unique_by=lambda t: t[1]).filter(
    lambda m: sum(r > 0 for r, _ in m) >= 1)


@FAST
@given(st.integers(3, 30), meridians, st.floats(10, 360))
def test_rotational_circular_on_surface(steps, merid, angle):
    # Heights on a 0.1 grid: distinct meridian points, no faces below rounding.
    rz = np.array(sorted(merid, key=lambda t: t[1]), dtype=float) * [1.0, 0.1]
    axis = np.array([0.2, -0.3, 1.0])
    origin = np.array([1.0, 2.0, -1.0])
    # Lay the meridian in a plane through the tilted axis.
    a = axis / np.linalg.norm(axis)
    e = np.cross(a, [1.0, 0, 0])
    e /= np.linalg.norm(e)
    pts = origin + rz[:, :1] * e + rz[:, 1:] * a
    if angle == 360 and steps < 3:
        steps = 3
    mesh = C.rotational_mesh(pts, steps, origin=origin, axis=axis, angle=angle)
    assert_planar(mesh)
    q = chk.quads_of(mesh.vertices, faces(mesh))
    if len(q):
        assert chk.circularity(q).max() <= CIRCULAR
    # On the surface: each vertex has a meridian point's (distance, height).
    rel = mesh.vertices - origin
    h = rel @ a
    r = np.linalg.norm(rel - h[:, None] * a, axis=1)
    d = np.abs(r[:, None] - rz[None, :, 0]) + np.abs(h[:, None] - rz[None, :, 1])
    assert d.min(axis=1).max() <= ON_SURFACE * chk.diagonal(mesh.vertices)


def test_rotational_skew_meridian_is_laid_into_a_plane():
    # A skew line turned about z is a hyperboloid; the mesh uses its meridian curve.
    mesh = C.rotational_mesh([[1, -1, -1], [1, 0, 0], [1, 1, 1]], 12)
    assert_circular(mesh)
    x, y, z = mesh.vertices.T
    assert np.abs(x * x + y * y - z * z - 1).max() <= 1e-12


# -------------------------------------------------------- moulding and pipe
@FAST
@given(st.integers(1, 6), st.randoms(use_true_random=False))
def test_moulding_circular_any_axes_in_profile_plane(k, rnd):
    rng = np.random.default_rng(rnd.randint(0, 2 ** 31))
    prof = np.c_[rng.uniform(1, 2, 5), np.zeros(5), np.linspace(0, 2, 5)]
    o = np.c_[rng.uniform(-0.5, 0.5, k), np.zeros(k), rng.uniform(-1, 1, k)]
    d = np.c_[rng.uniform(-0.3, 0.3, k), np.zeros(k), np.ones(k)]
    mesh = C.moulding_mesh(prof, o, d, rng.uniform(5, 30, k))
    assert mesh.n_faces == 4 * k
    assert_circular(mesh)
    assert_planar(mesh)


def test_moulding_refuses_axis_off_the_profile_plane():
    with pytest.raises(GeometryError, match="plane"):
        C.moulding_mesh([[1, 0, 0], [1, 0, 1], [2, 0, 2]], [[0, 0, 0]], [[0, 1, 1]], [10])


@FAST
@given(st.floats(0.1, 0.8), st.floats(0.5, 3), st.integers(3, 20), st.integers(4, 30))
def test_pipe_circular_and_torus_exact_on_circle_spine(radius, pitch, segments, n):
    s = np.linspace(0, 2.0, n)
    helix = np.stack([2 * np.cos(s), 2 * np.sin(s), pitch * s], axis=1)
    mesh = C.pipe_mesh(helix, radius, segments)
    assert_circular(mesh)
    ring = mesh.vertices.reshape(n, segments, 3)
    assert np.abs(np.linalg.norm(ring - helix[:, None], axis=2) - radius).max() <= 1e-12 * 4
    # A circular spine gives the exact torus.
    circle = np.stack([3 * np.cos(s), 3 * np.sin(s), 0 * s], axis=1)
    tor = C.pipe_mesh(circle, radius, segments)
    x, y, z = tor.vertices.T
    assert np.abs(np.hypot(np.hypot(x, y) - 3, z) - radius).max() <= ON_SURFACE * 6


# ------------------------------------------------------- canal, torus, cyclide
@FAST
@given(st.floats(0.4, 0.6), st.floats(0.6, 1.2), st.integers(3, 24), st.integers(20, 40),
       st.floats(0.0, 0.3))
def test_canal_circular_on_spheres(r0, r1, segments, n, lift):
    t = np.linspace(0, np.pi, n)
    spine = np.stack([3 * np.cos(t), 3 * np.sin(t), lift * t ** 2], axis=1)
    radii = np.linspace(r0, r1, n)
    mesh = C.canal_mesh(spine, radii, segments)
    assert_circular(mesh)
    ring = mesh.vertices.reshape(n - 1, segments, 3)
    for off in (0, 1):
        dev = np.abs(np.linalg.norm(ring - spine[off:n - 1 + off, None], axis=2)
                     - radii[off:n - 1 + off, None])
        assert dev.max() <= 1e-12 * 10


def test_canal_refuses_spheres_that_do_not_meet():
    with pytest.raises(GeometryError, match="do not meet"):
        C.canal_mesh([[0, 0, 0], [5, 0, 0], [10, 0, 0]], 1.0, 8)


def torus_f(R, r):
    def value(p):
        rho = np.hypot(p[:, 0], p[:, 1])
        return (rho - R) ** 2 + p[:, 2] ** 2 - r * r

    def gradient(p):
        rho = np.hypot(p[:, 0], p[:, 1])
        k = 2 * (rho - R) / rho
        return np.stack([k * p[:, 0], k * p[:, 1], 2 * p[:, 2]], axis=1)

    return value, gradient


@FAST
@given(st.floats(1.5, 5), st.floats(0.1, 0.9), st.integers(3, 40), st.integers(3, 40))
def test_torus_circular_on_surface(R, frac, u, v):
    r = frac * R
    mesh = C.torus_mesh(R, r, u, v)
    assert mesh.n_faces == u * v and mesh.euler_characteristic() == 0
    assert_circular(mesh)
    assert_on(mesh, *torus_f(R, r))


@FAST
@given(st.floats(2, 4), st.floats(0.3, 1.0),
       st.tuples(st.floats(-3, 3), st.floats(-3, 3), st.floats(2.5, 6)), st.floats(1, 8))
def test_dupin_cyclide_circular_and_inverse_on_torus(R, r, center, radius):
    mesh = C.dupin_cyclide(R, r, 24, 12, center, radius)
    assert_circular(mesh)
    assert_planar(mesh)
    # Inverting back lands on the torus.
    c = np.asarray(center)
    rel = mesh.vertices - c
    back = c + radius ** 2 * rel / np.einsum("ij,ij->i", rel, rel)[:, None]
    value, gradient = torus_f(R, r)
    assert (chk.sampson(value, gradient, back, chk.diagonal(back))).max() <= ON_SURFACE


# ------------------------------------------------------------------ quadrics
@FAST
@given(pos, pos, pos, st.integers(3, 30), st.integers(2, 20))
def test_ellipsoid_trapezoids_on_surface(a, b, c, u, v):
    mesh = C.ellipsoid_mesh(a, b, c, u, v)
    assert_planar(mesh)
    w = np.array([1 / a ** 2, 1 / b ** 2, 1 / c ** 2])
    assert_on(mesh, lambda p: (p * p) @ w - 1, lambda p: 2 * p * w)
    assert mesh.count_kinds()["polygon"] == 2 * u  # pole triangles
    if a == b and v >= 3:
        assert_circular(mesh)


def test_ellipsoid_of_revolution_is_circular():
    assert_circular(C.ellipsoid_mesh(2.0, 2.0, 1.0, 16, 8))


@FAST
@given(pos, pos, pos, st.floats(1.2, 4), st.integers(3, 30), st.integers(1, 12))
def test_two_sheet_hyperboloid_and_elliptic_paraboloid(a, b, c, hf, u, v):
    m1 = C.two_sheet_hyperboloid_mesh(a, b, c, hf * c, u, v)
    assert_planar(m1)
    w = np.array([-1 / a ** 2, -1 / b ** 2, 1 / c ** 2])
    assert_on(m1, lambda p: (p * p) @ w - 1, lambda p: 2 * p * w)
    m2 = C.elliptic_paraboloid_mesh(a, b, hf, u, v)
    assert_planar(m2)
    assert_on(m2, lambda p: p[:, 0] ** 2 / a ** 2 + p[:, 1] ** 2 / b ** 2 - p[:, 2],
              lambda p: np.stack([2 * p[:, 0] / a ** 2, 2 * p[:, 1] / b ** 2, -np.ones(len(p))], 1))


def hyperboloid_f(a, b, c):
    w = np.array([1 / a ** 2, 1 / b ** 2, -1 / c ** 2])
    return (lambda p: (p * p) @ w - 1), (lambda p: 2 * p * w)


@FAST
@given(pos, pos, st.floats(0.2, 4), st.integers(3, 40), st.integers(1, 20))
def test_hyperboloid_circular_style(a, c, height, u, v):
    mesh = C.hyperboloid_mesh(a, c, height, u, v, style="circular")
    assert_circular(mesh)
    assert_on(mesh, *hyperboloid_f(a, a, c))
    assert np.abs(mesh.vertices[:, 2]).max() == pytest.approx(height)


@FAST
@given(pos, pos, st.floats(1.0, 4), st.integers(4, 48))
def test_hyperboloid_generator_style(a, c, hc, u):
    height = hc * c
    try:
        mesh = C.hyperboloid_mesh(a, c, height, u, style="generators")
    except GeometryError:
        assert c * np.tan(2 * np.pi / u) > height
        return
    assert_circular(mesh)
    assert_on(mesh, *hyperboloid_f(a, a, c))
    assert np.abs(mesh.vertices[:, 2]).max() <= height * (1 + 1e-12)
    # Every face diagonal is a member, and each member lies on the hyperboloid.
    seg = mesh.vertices[mesh.members]
    mids = seg.mean(axis=1)
    value, gradient = hyperboloid_f(a, a, c)
    assert chk.sampson(value, gradient, mids, chk.diagonal(mesh.vertices)).max() <= ON_SURFACE
    assert len(mesh.members) == 2 * mesh.n_faces
    # Members with one id are collinear (one generator each).
    for line in np.unique(mesh.member_id)[:6]:
        s = seg[mesh.member_id == line]
        d = s[:, 1] - s[:, 0]
        assert np.linalg.norm(np.cross(d, d[0]), axis=1).max() <= 1e-10 * (d[0] @ d[0])


def hp_f(a, b):
    return (lambda p: p[:, 0] ** 2 / a ** 2 - p[:, 1] ** 2 / b ** 2 - p[:, 2],
            lambda p: np.stack([2 * p[:, 0] / a ** 2, -2 * p[:, 1] / b ** 2, -np.ones(len(p))], 1))


@FAST
@given(pos, pos, st.floats(0.2, 5), st.integers(1, 20), st.integers(1, 20))
def test_hp_parabolas(a, b, size, u, v):
    mesh = C.hyperbolic_paraboloid_mesh(a, b, size, u, v, "parabolas")
    assert mesh.n_faces == u * v
    assert_parallelograms(mesh)
    assert_on(mesh, *hp_f(a, b))
    assert np.abs(mesh.vertices[:, :2]).max() == pytest.approx(size)


@FAST
@given(pos, pos, st.floats(0.2, 5), st.integers(2, 16), st.integers(2, 16), st.booleans())
def test_hp_generators(a, b, size, u, v, fill):
    try:
        mesh = C.hyperbolic_paraboloid_mesh(a, b, size, u, v, "generators", fill=fill)
    except GeometryError:
        assert u == v == 2 and not fill  # the only grid without a face
        return
    if u + v > 4:
        assert_parallelograms(mesh)
    assert_planar(mesh)
    assert_on(mesh, *hp_f(a, b))
    assert np.abs(mesh.vertices[:, 0]).max() <= size * (1 + 1e-12)
    assert np.abs(mesh.vertices[:, 1]).max() <= size * (1 + 1e-12)
    # The members are generators: their midpoints lie on the surface too.
    mids = mesh.vertices[mesh.members].mean(axis=1)
    assert chk.sampson(*hp_f(a, b), mids, chk.diagonal(mesh.vertices)).max() <= ON_SURFACE


def helicoid_f(pitch):
    k = pitch / (2 * np.pi)
    return (lambda p: p[:, 0] * np.sin(p[:, 2] / k) - p[:, 1] * np.cos(p[:, 2] / k),
            lambda p: np.stack([np.sin(p[:, 2] / k), -np.cos(p[:, 2] / k),
                                (p[:, 0] * np.cos(p[:, 2] / k) + p[:, 1] * np.sin(p[:, 2] / k)) / k], 1))


@FAST
@given(st.floats(0.3, 4), st.floats(-5, 5).filter(lambda x: abs(x) > 0.2), st.floats(0.25, 2),
       st.integers(8, 60), st.integers(8, 60))
def test_helicoid_parallelograms_on_surface(radius, pitch, turns, u, v):
    mesh = C.helicoid_mesh(radius, pitch, turns, u, v)
    assert_parallelograms(mesh)
    assert_on(mesh, *helicoid_f(pitch))
    assert np.hypot(mesh.vertices[:, 0], mesh.vertices[:, 1]).max() <= radius * (1 + 1e-12)
    z = np.sign(pitch) * mesh.vertices[:, 2]
    assert z.min() >= -1e-12 * abs(pitch) and z.max() <= abs(pitch) * turns * (1 + 1e-12)


@pytest.mark.parametrize("call, match", [
    (lambda: C.torus_mesh(1.0, 2.0, 8, 8), "r < R"),
    (lambda: C.ellipsoid_mesh(1, -1, 1, 8, 8), "b"),
    (lambda: C.hyperboloid_mesh(1, 1, 1, 8, style="twisted"), "circular"),
    (lambda: C.rotational_mesh([[1, 0, 0]], 8), "meridian"),
])
def test_bad_parameters_name_the_parameter(call, match):
    with pytest.raises(ParameterError, match=match):
        call()
