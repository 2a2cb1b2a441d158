"""Director curves: exact lengths, plane roots, sweeps, specs, properties."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from ruledmesh.curves import Arc, BSpline, Helix, Line, Polyline
from ruledmesh.design.curves import curve_from_spec
from ruledmesh.errors import DesignError, GeometryError, ParameterError

SPLINE = BSpline([[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]], 3)
ARC = Arc.through([1, 0, 0], [0, 1, 0], [-1, 0, 0])

CURVES = [
    Line([0, 0, 0], [3, 4, 12]),
    Polyline([[0, 0, 0], [1, 0, 0], [1, 2, 0], [3, 2, 1]]),
    ARC,
    Arc.from_center([1, 2, 3], 2.5, [1, 1, 1], 30, 250),
    SPLINE,
    BSpline.interpolate([[0, 0, 0], [1, 2, 0], [3, 3, 1], [4, 1, 2], [6, 0, 2]], 3),
    BSpline([[0, 0, 0], [1, 1, 0], [2, 0, 1], [3, 1, 1], [4, 0, 0]], 2,
            [0, 0, 0, 1, 1, 3, 3, 3]),
    Helix([0, 0, 0], [0, 0, 1], 2.0, 1.5, 2.25, start_angle=20),
]
IDS = ["line", "polyline", "arc3", "arc-center", "bspline", "interp", "bspline-knots", "helix"]


def _numeric_length(c, a=0.0, b=1.0):
    breaks = np.unique(np.concatenate([c.breaks(), [a, b]]))
    breaks = breaks[(breaks >= a) & (breaks <= b)]
    return sum(quad(lambda x: np.linalg.norm(c.derivative(x)), lo, hi, epsabs=0, epsrel=1e-13,
                    limit=200)[0] for lo, hi in itertools.pairwise(breaks))


# --- exact values ----------------------------------------------------------

def test_exact_lengths():
    assert Line([0, 0, 0], [3, 4, 12]).length() == pytest.approx(13.0, rel=1e-15)
    assert ARC.length() == pytest.approx(math.pi, rel=1e-14)
    assert Arc.from_center([0, 0, 0], 2.0, [0, 0, 1], 0, 90).length() == pytest.approx(math.pi,
                                                                                          rel=1e-14)
    h = Helix([0, 0, 0], [0, 0, 1], 1.0, 2.0, 3.0)
    assert h.length() == pytest.approx(3 * math.hypot(2 * math.pi, 2.0), rel=1e-14)
    assert Polyline([[0, 0, 0], [1, 0, 0], [1, 2, 0]]).length() == pytest.approx(3.0, rel=1e-15)


def test_arc_through_passes_through_its_points():
    p = np.array([[2.0, 1.0, 0.5], [0.0, 3.0, 1.0], [-1.0, 0.5, 2.0]])
    arc = Arc.through(*p)
    assert np.allclose(arc.evaluate([0.0, 1.0]), p[[0, 2]], atol=1e-13)
    assert np.min(np.linalg.norm(arc.sample(20001) - p[1], axis=1)) < 1e-3
    assert np.allclose(np.linalg.norm(arc.sample(50) - arc.center, axis=1), arc.radius)


def test_helix_rises_pitch_per_turn():
    h = Helix([1, 2, 3], [0, 0, 2], 1.5, 0.75, 4.0)
    u = np.arange(5) / 4.0  # one full turn per quarter of u
    pts = h.evaluate(u)
    assert np.allclose(pts[:, :2], pts[0, :2], atol=1e-13)
    assert np.allclose(np.diff(pts[:, 2]), 0.75)


@pytest.mark.parametrize("curve", CURVES, ids=IDS)
def test_arclength_matches_adaptive_quadrature(curve):
    u = np.array([0.0, 0.13, 0.5, 0.77, 1.0])
    expected = [_numeric_length(curve, 0.0, x) for x in u]
    assert np.allclose(curve.arclength(u), expected, rtol=1e-11, atol=1e-12 * curve.length())


@pytest.mark.parametrize("curve", CURVES, ids=IDS)
def test_equal_arc_length_spacing(curve):
    u = curve.arclength_params(9)
    assert u[0] == 0.0 and u[-1] == 1.0 and np.all(np.diff(u) > 0)
    pieces = np.diff(curve.arclength(u))
    assert np.allclose(pieces, curve.length() / 8, rtol=1e-11)


@pytest.mark.parametrize("curve", CURVES, ids=IDS)
def test_derivatives_match_finite_differences(curve):
    u = np.array([0.11, 0.37, 0.62, 0.91])
    h = 1e-6
    d1 = (curve.evaluate(u + h) - curve.evaluate(u - h)) / (2 * h)
    d2 = (curve.evaluate(u + h) - 2 * curve.evaluate(u) + curve.evaluate(u - h)) / h**2
    scale = np.abs(curve.derivative(u)).max()
    assert np.allclose(curve.derivative(u), d1, atol=1e-7 * scale)
    if not isinstance(curve, (Polyline,)):
        assert np.allclose(curve.derivative(u, 2), d2, atol=1e-3 * max(scale, 1.0))


@pytest.mark.parametrize("curve", CURVES, ids=IDS)
def test_vectorised_shapes(curve):
    u = np.linspace(0, 1, 12).reshape(3, 4)
    assert curve.evaluate(u).shape == (3, 4, 3)
    assert curve.derivative(u, 2).shape == (3, 4, 3)
    assert curve.arclength(u).shape == (3, 4)
    assert curve.evaluate(0.5).shape == (3,)
    assert np.allclose(curve.evaluate(u)[1, 2], curve.evaluate(u[1, 2]))


@pytest.mark.parametrize("curve", CURVES, ids=IDS)
def test_unchecked_kernels_compute_what_the_checked_methods_do(curve):
    u = np.linspace(0.0, 1.0, 37)
    assert np.array_equal(curve.point_at(u), curve.evaluate(u))
    assert np.array_equal(curve.tangent_at(u), curve.derivative(u))
    assert np.array_equal(curve.speed_at(u), np.linalg.norm(curve.derivative(u), axis=-1))
    assert np.array_equal(curve.param_at_fraction(u), curve.param_at_length(u * curve.length()))
    b = curve.breaks()
    assert b[0] == 0.0 and b[-1] == 1.0 and np.all(np.diff(b) > 0)
    assert curve.size > 0
    # the height function's roots are the plane intersections
    n = np.array([0.0, 0.0, 1.0])
    level = curve.height_function(n)
    mid = float(curve.evaluate(0.5)[2])
    if curve.bounding_box()[1, 2] - curve.bounding_box()[0, 2] > 1e-6:
        np.testing.assert_array_equal(level.roots(mid), curve.intersect_plane(n, mid))
    # a NaN iterate gives NaN, not an error: the kernels are for Newton loops
    assert np.isnan(curve.point_at(np.array([np.nan]))).all()


@pytest.mark.parametrize("curve", CURVES, ids=IDS)
def test_spec_round_trip(curve):
    spec = curve.to_spec()
    again = curve_from_spec(spec, "curves.c")
    assert again == curve
    assert hash(again) == hash(curve)
    assert np.array_equal(again.sample(7), curve.sample(7))


@pytest.mark.parametrize("curve", CURVES, ids=IDS)
def test_bounding_box_holds_dense_samples_tightly(curve):
    box = curve.bounding_box()
    pts = curve.sample(20001)
    assert np.all(pts >= box[0] - 1e-12) and np.all(pts <= box[1] + 1e-12)
    assert np.allclose(pts.min(axis=0), box[0], atol=1e-6 * curve.length())
    assert np.allclose(pts.max(axis=0), box[1], atol=1e-6 * curve.length())


# --- plane intersections -------------------------------------------------

def test_arc_plane_roots_exact():
    roots = ARC.intersect_plane([0, 1, 0], 0.5)
    assert np.allclose(roots, [1 / 6, 5 / 6], atol=1e-14)
    assert np.allclose(ARC.intersect_plane([0, 1, 0], 1.0), [0.5], atol=1e-7)  # touch
    assert len(ARC.intersect_plane([0, 1, 0], 1.01)) == 0
    assert np.allclose(ARC.intersect_plane([0, 2, 0], 1.0), [1 / 6, 5 / 6])  # unnormalised


def test_helix_meets_a_plane_through_its_axis_twice_per_turn():
    h = Helix([0, 0, 0], [0, 0, 1], 1.0, 1.0, 3.0, start_angle=10)
    roots = h.intersect_plane([1, 0, 0], 0.0)
    assert len(roots) == 6
    assert np.allclose(h.evaluate(roots)[:, 0], 0.0, atol=1e-12)


def test_spline_touching_a_plane_counts_once():
    # the cubic Bezier's y has a single maximum 0.25 at u = 1/3 (tangential touch)
    c = BSpline([[0, 0, 0], [1, 0.5, 0], [2, 0, 0], [3, 0, 0]], 3)
    ymax = c.bounding_box()[1, 1]
    roots = c.intersect_plane([0, 1, 0], ymax)
    assert len(roots) == 1
    assert c.evaluate(roots[0])[1] == pytest.approx(ymax, abs=1e-12)


def test_curve_in_the_plane_is_refused():
    with pytest.raises(GeometryError, match="lies in the plane"):
        ARC.intersect_plane([0, 0, 1], 0.0)
    with pytest.raises(GeometryError, match="lies in the plane"):
        Line([0, 0, 1], [1, 1, 1]).intersect_plane([0, 0, 3], 3.0)


def test_polyline_segment_in_plane_and_crossing():
    p = Polyline([[0, 0, 0], [1, 0, 0], [1, 1, 0], [2, 1, 0]])
    assert np.allclose(p.intersect_plane([1, 0, 0], 0.5), [1 / 6])
    assert len(p.intersect_plane([1, 0, 0], 1.0)) == 1  # a whole segment: one root
    assert len(p.intersect_plane([1, 0, 0], 3.0)) == 0


# --- sweeps ---------------------------------------------------------------

def test_sweep_follows_one_branch_and_stops_where_it_turns_back():
    offsets = np.linspace(0.0, 1.5, 7)
    u, ok = ARC.plane_sweep([0, 1, 0], offsets)
    assert ok.tolist() == [True] * 5 + [False] * 2
    assert np.allclose(ARC.evaluate(u[:5])[:, 1], offsets[:5], atol=1e-12)
    assert np.all(np.diff(u[:5]) > 0) and u[0] == 0.0 and u[4] == pytest.approx(0.5)
    assert np.all(np.isfinite(u)) and np.all(u[5:] == u[4])


def test_sweep_start_u_picks_the_other_branch():
    u, ok = ARC.plane_sweep([0, 1, 0], np.linspace(0.5, 0.9, 5), start_u=0.9)
    assert ok.all() and np.all(np.diff(u) < 0) and u[0] == pytest.approx(5 / 6)


def test_sweep_stops_at_the_end_of_the_curve():
    u, ok = SPLINE.plane_sweep([1, 0, 0], [2.0, 6.0, 10.0, 11.0])
    assert ok.tolist() == [True, True, True, False]
    assert u[2] == pytest.approx(1.0)


def test_sweep_of_a_missed_plane_is_all_false_not_nan():
    u, ok = ARC.plane_sweep([0, 1, 0], [2.0, 3.0])
    assert not ok.any() and np.all(np.isfinite(u))


def test_sweep_refuses_non_monotone_offsets():
    with pytest.raises(ParameterError, match="offsets: expected a monotone"):
        ARC.plane_sweep([0, 1, 0], [0.1, 0.5, 0.2])


# --- Hypothesis over random B-splines ------------------------------------

@st.composite
def splines(draw):
    degree = draw(st.integers(1, 5))
    n = draw(st.integers(degree + 1, degree + 5))
    coords = draw(st.lists(st.floats(-10, 10, allow_nan=False), min_size=3 * n, max_size=3 * n))
    pts = np.array(coords).reshape(n, 3)
    # keep control polygons away from degenerate (zero-speed) configurations
    pts = pts + np.arange(n)[:, None] * np.array([1.0, 0.3, 0.1])
    return BSpline(pts, degree)


FAST = settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@FAST
@given(splines(), st.lists(st.floats(0, 1), min_size=1, max_size=8))
def test_param_at_length_inverts_arclength(c, fractions):
    s = np.array(fractions) * c.length()
    u = c.param_at_length(s)
    assert np.allclose(c.arclength(u), s, rtol=0, atol=1e-11 * c.length())
    order = np.argsort(s)
    assert np.all(np.diff(u[order]) >= -1e-15)


@FAST
@given(splines(), st.floats(0.05, 0.95), st.tuples(st.floats(-1, 1), st.floats(-1, 1),
                                                    st.floats(-1, 1)))
def test_plane_roots_satisfy_the_plane_equation(c, frac, normal):
    n = np.array(normal)
    if np.linalg.norm(n) < 0.1:
        n = np.array([1.0, 0.0, 0.0])
    g = c.sample(400) @ n
    offset = g.min() + frac * (g.max() - g.min())
    roots = c.intersect_plane(n, offset)
    assert np.all((roots >= 0) & (roots <= 1)) and np.all(np.diff(roots) > 0)
    assert np.allclose(c.evaluate(roots) @ n, offset, atol=1e-9 * c._size * np.linalg.norm(n))
    # every sign change of the dense sampling is near a reported root
    samples = np.linspace(0, 1, 400)
    changes = np.nonzero(np.sign(g[:-1] - offset) * np.sign(g[1:] - offset) < 0)[0]
    for i in changes:
        assert np.any((roots >= samples[i] - 1e-12) & (roots <= samples[i + 1] + 1e-12))


@FAST
@given(splines(), st.floats(0.02, 0.98))
def test_spline_derivative_matches_finite_differences(c, u):
    h = 1e-6
    if c.degree == 1:  # the derivative jumps at the knots (a polyline)
        assume(np.all(np.abs(c.breaks() - u) > 2 * h))
    fd = (c.evaluate(u + h) - c.evaluate(u - h)) / (2 * h)
    d = c.derivative(u)
    assert np.allclose(d, fd, atol=1e-6 * max(np.abs(d).max(), 1.0))


@FAST
@given(splines())
def test_spline_spec_round_trip(c):
    assert curve_from_spec(c.to_spec(), "curves.s") == c


# --- construction errors ---------------------------------------------------

def test_collinear_arc_is_refused():
    with pytest.raises(ParameterError, match="collinear"):
        Arc.through([0, 0, 0], [1, 1, 1], [2, 2, 2])


def test_zero_radius_is_refused():
    with pytest.raises(ParameterError, match="radius: expected a number > 0, got 0"):
        Arc.from_center([0, 0, 0], 0.0, [0, 0, 1], 0, 90)


def test_bspline_needs_enough_control_points():
    with pytest.raises(ParameterError, match="at least 4 control points, got 3"):
        BSpline([[0, 0, 0], [1, 0, 0], [2, 1, 0]], 3)


# --- design specs -----------------------------------------------------------

def test_spec_bspline_example():
    c = curve_from_spec({"type": "bspline", "degree": 3,
                         "points": [[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]]}, "curves.c1")
    assert c == SPLINE


def test_spec_interpolating_bspline_passes_through_points():
    pts = [[0, 0, 0], [1, 2, 0], [3, 3, 1], [4, 1, 2], [6, 0, 2]]
    c = curve_from_spec({"type": "bspline", "interpolate": True, "points": pts}, "curves.c1")
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    u = np.concatenate([[0], np.cumsum(seg)]) / seg.sum()
    assert np.allclose(c.evaluate(u), pts, atol=1e-12)


def test_spec_arc_forms_agree():
    a = curve_from_spec({"type": "arc", "points": [[1, 0, 0], [0, 1, 0], [-1, 0, 0]]}, "c")
    b = curve_from_spec({"type": "arc", "center": [0, 0, 0], "radius": 1, "normal": [0, 0, 1],
                         "start_angle": 0, "end_angle": 180, "x_axis": [1, 0, 0]}, "c")
    assert np.allclose(a.sample(9), b.sample(9), atol=1e-14)


@pytest.mark.parametrize("spec, message", [
    ({"type": "bspline", "degree": 7, "points": [[0, 0, 0]] * 9},
     "curves.c1.degree: expected an integer >= 1 and <= 5, got 7"),
    ({"type": "bspline", "degre": 3, "points": [[0, 0, 0], [1, 0, 0]]},
     'curves.c1.degre: unknown key (did you mean "degree"?)'),
    ({"type": "bsplin", "points": []}, 'curves.c1.type: expected one of "line" | "polyline"'),
    ({"points": [[0, 0, 0], [1, 0, 0]]}, "curves.c1.type: missing"),
    ({"type": "line", "points": [[0, 0, 0]]}, "curves.c1.points: expected 2 points, got 1"),
    ({"type": "line", "points": [[0, 0, 0], [0, 0, 0]]}, "curves.c1.points: p0 and p1 coincide"),
    ({"type": "arc", "points": [[0, 0, 0], [1, 1, 1], [2, 2, 2]]}, "curves.c1.points: the three "
     "points are collinear"),
    ({"type": "arc", "center": [0, 0, 0], "radius": 0, "normal": [0, 0, 1], "start_angle": 0,
      "end_angle": 90}, "curves.c1.radius: expected a number > 0, got 0"),
    ({"type": "arc", "center": [0, 0, 0], "radius": 1, "start_angle": 0, "end_angle": 90},
     "curves.c1.normal: missing"),
    ({"type": "bspline", "degree": 3, "points": [[0, 0, 0], [1, 0, 0], [2, 1, 0]]},
     "curves.c1.points: a degree-3 B-spline needs at least 4 points, got 3"),
    ({"type": "bspline", "degree": 1, "points": [[0, 0, 0], [1, 0, 0]], "knots": [0, 1, 1]},
     "curves.c1.knots: expected 4 knots"),
    ({"type": "polyline", "points": [[0, 0, "x"]]}, "curves.c1.points: expected numbers"),
    ({"type": "helix", "center": [0, 0, 0], "axis": [0, 0, 0], "radius": 1, "pitch": 1,
      "turns": 2}, "curves.c1.axis: expected a non-zero vector"),
    ({"type": "helix", "center": [0, 0, 0], "axis": [0, 0, 1], "radius": 1, "pitch": 1,
      "turns": -2}, "curves.c1.turns: expected a number > 0, got -2"),
])
def test_spec_errors_name_the_field(spec, message):
    with pytest.raises(DesignError) as err:
        curve_from_spec(spec, "curves.c1")
    assert str(err.value).startswith(message), str(err.value)


# --- numpy B-spline evaluation, the Hermite helper and the fast arc-length inverse -------
def _random_bspline(rng, degree):
    n = int(rng.integers(degree + 1, degree + 9))
    inner = np.sort(rng.uniform(0, 1, n - degree - 1))
    if degree > 1 and len(inner) > 1 and rng.uniform() < 0.3:
        inner[1] = inner[0]  # a double knot
    knots = np.r_[np.zeros(degree + 1), inner, np.ones(degree + 1)]
    return rng.normal(size=(n, 3)), knots


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_de_boor_matches_scipy_bspline(degree):
    from scipy.interpolate import BSpline as SciBSpline

    rng = np.random.default_rng(degree)
    for _ in range(10):
        cp, knots = _random_bspline(rng, degree)
        curve = BSpline(cp, degree, knots)
        ref = SciBSpline(knots, cp, degree, extrapolate=True)
        u = np.r_[np.linspace(0, 1, 301), -0.01, 1.01]
        np.testing.assert_allclose(curve.evaluate(u[:-2]), ref(u[:-2]), rtol=0, atol=5e-14)
        want = ref(u)  # with the end polynomials continued
        np.testing.assert_allclose(curve.point_at(u), want, rtol=0, atol=5e-14 * np.abs(want).max())
        for order in range(1, degree + 1):
            got, want = curve.derivative(u[:-2], order), ref(u[:-2], nu=order)
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-13 * max(np.abs(want).max(), 1))


def test_cubic_hermite_matches_scipy():
    from scipy.interpolate import CubicHermiteSpline

    from ruledmesh.curves import CubicHermite

    rng = np.random.default_rng(7)
    x = np.sort(rng.uniform(0, 5, 12))
    for y, m in [(rng.normal(size=12), rng.normal(size=12)),
                 (rng.normal(size=(12, 3)), rng.normal(size=(12, 3)))]:
        q = np.linspace(x[0], x[-1], 400).reshape(20, 20)
        ref = CubicHermiteSpline(x, y, m)
        np.testing.assert_allclose(CubicHermite(x, y, m)(q), ref(q), rtol=0, atol=1e-13)
        np.testing.assert_allclose(CubicHermite(x, y, m)(q, 1), ref(q, 1), rtol=0, atol=1e-12)


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_tabulated_inverse_is_the_exact_inverse(degree):
    """param_at_length from the table + Newton equals a bisection of the exact arc length
    to 1e-14 in u (the tolerance stated in docs/benchmarks.md)."""
    rng = np.random.default_rng(10 + degree)
    for _ in range(8):
        cp, knots = _random_bspline(rng, degree)
        curve = BSpline(cp, degree, knots)
        s = np.linspace(0, curve.length(), 257)
        u = curve.param_at_length(s)
        lo, hi = np.zeros_like(s), np.ones_like(s)
        for _ in range(60):  # bisection: slow, sure
            mid = 0.5 * (lo + hi)
            below = curve.arclength(mid) < s
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        np.testing.assert_allclose(u, 0.5 * (lo + hi), rtol=0, atol=1e-14)
        np.testing.assert_allclose(curve.arclength(u), s, rtol=0, atol=4e-14 * curve.length())


def test_brentq_is_scipys():
    import math

    from scipy.optimize import brentq as scipy_brentq

    from ruledmesh.roots import brentq

    rng = np.random.default_rng(3)
    checked = 0
    for i in range(600):
        c = rng.normal(size=5)

        def f(x, c=c):
            return float(np.polyval(c, x) + 0.3 * math.sin(5 * x))

        a, b = sorted(rng.uniform(-3, 3, 2))
        if f(a) * f(b) >= 0:
            continue
        xtol = [2e-12, 1e-16][i % 2]
        assert brentq(f, a, b, xtol=xtol, rtol=8.9e-16) == scipy_brentq(f, a, b, xtol=xtol,
                                                                        rtol=8.9e-16)
        checked += 1
    assert checked > 100
    with pytest.raises(ValueError, match="sign change"):
        brentq(lambda x: x * x + 1.0, -1.0, 1.0)


def test_no_module_outside_curves_calls_private_curve_methods():
    # The generators and meshers use Curve's public kernels (point_at, tangent_at, ...); the
    # private ones are the subclasses' protocol and may change with them.
    import ast
    from pathlib import Path

    from ruledmesh.curves import Curve

    src = Path(__file__).resolve().parents[1] / "src" / "ruledmesh"
    private = {name for cls in Curve.__subclasses__() + [Curve] for name in vars(cls)
               if name.startswith("_") and not name.startswith("__")}
    used = []
    for path in sorted(src.rglob("*.py")):
        if path.name == "curves.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Attribute) and node.attr in private
                    and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
                used.append(f"{path.relative_to(src)}:{node.lineno} .{node.attr}")
    assert not used, used


@pytest.mark.parametrize("degree", [1, 2, 3, 5])
def test_speed_series_padded_for_newton_gives_the_same_numbers(degree):
    """The inverse evaluates the arc-length and speed series in one Clenshaw pass, the speed
    padded with a zero top coefficient: the values must be those of the speed series alone
    (bit for bit), so the Newton iterates, and the generators, are the unpadded ones."""
    from ruledmesh.curves import _clenshaw

    rng = np.random.default_rng(40 + degree)
    for _ in range(6):
        cp, knots = _random_bspline(rng, degree)
        curve = BSpline(cp, degree, knots)
        _, _, speed, length = curve._length_series
        both = curve._newton_series
        k = rng.integers(0, len(speed), 500)
        xi = rng.uniform(-1.0, 1.0, 500)
        assert np.array_equal(_clenshaw(both[:, 1, k], xi), _clenshaw(speed.T[:, k], xi))
        assert np.array_equal(_clenshaw(both[:, 0, k], xi), _clenshaw(length.T[:, k], xi))


@pytest.mark.parametrize("degree", [1, 2, 3, 5])
def test_many_points_by_columns_are_the_few_points_numbers(degree):
    """From _BY_COLUMNS points on, B-splines and polylines are evaluated one coordinate at a
    time; points and derivatives must be those of the same parameters in small batches."""
    from ruledmesh.curves import _BY_COLUMNS

    rng = np.random.default_rng(60 + degree)
    for _ in range(4):
        cp, knots = _random_bspline(rng, degree)
        u = rng.uniform(-0.05, 1.05, (3, _BY_COLUMNS))  # outside [0, 1] too: the end spans continue
        for curve in (BSpline(cp, degree, knots), BSpline(cp, degree), Polyline(cp)):
            for order in (0, 1, 2):
                many = curve._eval(u) if order == 0 else curve._deriv(u, order)
                few = np.stack([curve._eval(row[i:i + 16]) if order == 0 else curve._deriv(row[i:i + 16], order)
                                for row in u for i in range(0, len(row), 16)])
                assert many.shape == u.shape + (3,)
                assert np.array_equal(many.reshape(-1, 3), few.reshape(-1, 3))
