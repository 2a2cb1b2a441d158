"""Generators from director curves: each distribution's defining property."""

import math

import numpy as np
import pytest
from scipy.integrate import dblquad

from ruledmesh.curves import Arc, BSpline, Line, Polyline
from ruledmesh.design.rulings import from_csv, rulings_from_spec
from ruledmesh.errors import DesignError, GeometryError, ParameterError
from ruledmesh.rulings import (
    Distribution,
    Rulings,
    between,
    conoid,
    from_lines,
    three_directrices,
)

C1 = BSpline([[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]], 3)
C2 = BSpline([[0, 0, 4], [4, 2, 5], [7, -1, 3], [10, 1, 4]], 3)
D = np.array([[5.0, -3.0, 2.0], [5.0, 6.0, 2.0]])


def _on_curve(curve, points, params):
    return np.abs(curve.evaluate(params) - points).max()


def _surface_matches_generators(r, tol=1e-12):
    assert np.abs(r.surface.point(r.u, 0.0) - r.a).max() <= tol
    assert np.abs(r.surface.point(r.u, 1.0) - r.b).max() <= tol


# --- the four distributions -------------------------------------------------

def test_arc_length_distribution_divides_both_curves_evenly():
    r = between(C1, C2, 11, "arc-length")
    for curve, key in ((C1, "c1_params"), (C2, "c2_params")):
        s = curve.arclength(r.info[key])
        assert np.allclose(np.diff(s), curve.length() / 10, rtol=1e-10)
    assert _on_curve(C1, r.a, r.info["c1_params"]) == 0.0
    assert np.allclose(r.u, np.linspace(0, 1, 11))
    _surface_matches_generators(r)


def test_parameter_distribution_uses_curve_parameters():
    r = between(C1, C2, 7, Distribution.PARAMETER)
    u = np.linspace(0, 1, 7)
    assert np.array_equal(r.a, C1.evaluate(u)) and np.array_equal(r.b, C2.evaluate(u))
    assert np.allclose(r.directions, r.b - r.a)


def test_director_plane_generators_lie_in_the_planes():
    n = np.array([1.0, 0.2, 0.0])
    r = between(C1, C2, 21, "director-plane", director_plane=n)
    na, nb = r.a @ n, r.b @ n
    assert np.allclose(na, nb, atol=1e-12 * 10)
    # the planes are evenly spaced over the common range, in c1's direction
    assert np.allclose(np.diff(na), np.diff(na)[0], rtol=1e-9)
    assert _on_curve(C1, r.a, r.info["c1_params"]) < 1e-14
    assert _on_curve(C2, r.b, r.info["c2_params"]) < 1e-14
    # the smooth surface's generators stay parallel to the director plane
    _su, st = r.surface.partials(np.linspace(0, 1, 101), 0.3)
    assert np.abs(st @ n).max() < 1e-6
    _surface_matches_generators(r)


def test_linear_directrix_generators_are_coplanar_with_d():
    r = between(C1, C2, 15, "linear-directrix", directrix=D)
    e = D[1] - D[0]
    triple = np.cross(r.a - D[0], r.b - D[0]) @ e
    scale = np.linalg.norm(r.a - D[0], axis=1) * np.linalg.norm(r.b - D[0], axis=1) * np.linalg.norm(e)
    assert np.all(np.abs(triple) <= 1e-12 * scale)
    s = C1.arclength(r.info["c1_params"])
    assert np.allclose(np.diff(s), C1.length() / 14, rtol=1e-10)
    assert _on_curve(C2, r.b, r.info["c2_params"]) < 1e-14
    _surface_matches_generators(r)


def test_moving_the_linear_directrix_changes_the_generators():
    above = np.array([[5.0, -3.0, 8.0], [5.0, 6.0, 8.0]])  # planes through it fan down
    r1 = between(C1, C2, 9, "linear-directrix", directrix=above)
    r2 = between(C1, C2, 9, "linear-directrix", directrix=above + [1.0, 0, 0])
    assert np.array_equal(r1.a, r2.a)
    assert np.abs(r1.b - r2.b).max() > 0.1


# --- three directrices -----------------------------------------------------

def _hyperboloid_directrices():
    # x^2 + y^2 - z^2 = 1: its generators (cos p, sin p, 0) + s (-sin p, cos p, 1)
    # meet the circles z = -1, 0, 1; the arcs keep only one regulus
    r2 = math.sqrt(2)
    c1 = Arc.from_center([0, 0, -1], r2, [0, 0, 1], -45, 45, x_axis=[1, 0, 0])
    c2 = Arc.from_center([0, 0, 1], r2, [0, 0, 1], 40, 140, x_axis=[1, 0, 0])
    c3 = Arc.from_center([0, 0, 0], 1, [0, 0, 1], -5, 95, x_axis=[1, 0, 0])
    return c1, c2, c3


def test_three_directrices_lines_meet_all_three_curves():
    c1, c2, c3 = _hyperboloid_directrices()
    r = three_directrices(c1, c2, c3, 13)
    hit = r.a + r.info["c3_t"][:, None] * (r.b - r.a)
    assert np.abs(hit - c3.evaluate(r.info["c3_params"])).max() < 1e-9
    assert _on_curve(c1, r.a, r.info["c1_params"]) < 1e-12
    assert _on_curve(c2, r.b, r.info["c2_params"]) < 1e-12
    # and they are the hyperboloid's generators
    mid = 0.5 * (r.a + r.b)
    assert np.allclose(mid[:, 0] ** 2 + mid[:, 1] ** 2 - mid[:, 2] ** 2, 1.0, atol=1e-12)


def test_three_directrices_area_is_a_quarter_hyperboloid():
    c1, c2, c3 = _hyperboloid_directrices()
    r = three_directrices(c1, c2, c3, 9)
    # surface of revolution of rho(z) = sqrt(1 + z^2), z in [-1, 1], a quarter of it
    z = np.polynomial.legendre.leggauss(60)
    zz = z[0]
    exact = 0.25 * 2 * math.pi * np.sum(z[1] * np.sqrt(1 + zz**2) * np.sqrt(1 + zz**2 / (1 + zz**2)))
    assert r.surface.area() == pytest.approx(exact, rel=1e-8)


def test_three_directrices_reports_where_the_family_ends():
    c1, _c2, c3 = _hyperboloid_directrices()
    short = Arc.from_center([0, 0, 1], math.sqrt(2), [0, 0, 1], 40, 100, x_axis=[1, 0, 0])
    with pytest.raises(GeometryError, match=r"family of lines ends near u = .* runs off the end "
                                            r"of c2"):
        three_directrices(c1, short, c3, 9)


# --- conoid ------------------------------------------------------------------

ARC = Arc.through([0, 1, 3], [2, 2.5, 3], [4, 1, 3])
LINE_D = np.array([[0.0, 0.0, 0.0], [4.0, 0.0, 0.0]])


def test_conoid_generators_meet_d_and_are_parallel_to_the_director_plane():
    n = np.array([1.0, 0.0, 0.0])
    r = conoid(ARC, LINE_D, n, 17)
    e = LINE_D[1] - LINE_D[0]
    # b_i on d: (b_i - d0) parallel to e
    assert np.abs(np.cross(r.b - LINE_D[0], e)).max() < 1e-12
    assert np.abs(r.directions @ n).max() < 1e-12
    assert np.allclose(np.diff(ARC.arclength(r.info["c1_params"])), ARC.length() / 16)
    _surface_matches_generators(r)


def test_right_conoid_is_not_the_bilinear_ruled_surface():
    """§5.1: a NURBS ruled surface between the segment and the arc is a different surface."""
    count = 17
    r = conoid(ARC, LINE_D, [1, 0, 0], count)
    u = ARC.arclength_params(count)  # the arc divided uniformly (its parameter is arc length)
    bilinear_b = LINE_D[0] + u[:, None] * (LINE_D[1] - LINE_D[0])
    assert np.allclose(r.a, ARC.evaluate(u), atol=1e-14)  # same points on the arc ...
    diff = np.linalg.norm(r.b - bilinear_b, axis=1)
    assert diff.max() > 0.1  # ... but other generators
    assert diff[0] < 1e-12 and diff[-1] < 1e-12 and diff[count // 2] < 1e-12  # symmetric arc
    tilt = np.abs((bilinear_b - r.a) @ [1, 0, 0])
    assert tilt.max() > 0.1  # the bilinear rulings are not parallel to the director plane


def test_conoid_directrix_parallel_to_director_plane_is_refused():
    with pytest.raises(GeometryError, match="parallel to the director plane"):
        conoid(ARC, LINE_D, [0, 0, 1], 9)


# --- explicit lines and the reference surface -----------------------------

def test_from_lines_and_area_of_a_hyperbolic_paraboloid():
    # S(u, t) = (u, t, u t) is z = x y over the unit square
    u = np.linspace(0, 1, 9)
    lines = np.stack([np.column_stack([u, 0 * u, 0 * u]), np.column_stack([u, 1 + 0 * u, u])], 1)
    r = from_lines(lines)
    exact, _ = dblquad(lambda y, x: math.sqrt(1 + x * x + y * y), 0, 1, 0, 1, epsabs=1e-13,
                       epsrel=1e-13)
    assert r.surface.area() == pytest.approx(exact, rel=1e-10)
    assert np.allclose(r.u, u)  # even lines -> even chord parameters
    _surface_matches_generators(r, 1e-14)


def test_curve_surface_area_of_a_plane_rectangle():
    r = between(Line([0, 0, 0], [2, 0, 0]), Line([0, 3, 0], [2, 3, 0]), 5)
    assert r.surface.area() == pytest.approx(6.0, rel=1e-13)


def test_surface_partials_match_finite_differences():
    r = between(C1, C2, 11, "director-plane", director_plane=[1, 0, 0])
    u, t, h = np.array([0.21, 0.5, 0.83]), np.array([0.1, 0.5, 0.9]), 1e-6
    su, st = r.surface.partials(u, t)
    fu = (r.surface.point(u + h, t) - r.surface.point(u - h, t)) / (2 * h)
    ft = (r.surface.point(u, t + h) - r.surface.point(u, t - h)) / (2 * h)
    assert np.allclose(su, fu, atol=1e-5) and np.allclose(st, ft, atol=1e-7)
    assert r.surface.point(u[:, None], t[None, :]).shape == (3, 3, 3)


def test_zero_length_generator_is_refused():
    lines = [[[0, 0, 0], [0, 0, 1]], [[1, 0, 0], [1, 0, 0]], [[2, 0, 0], [2, 0, 1]]]
    with pytest.raises(GeometryError, match="generator 1 has zero length"):
        from_lines(lines)


def test_from_csv_reads_rows_and_names_bad_lines(tmp_path):
    good = tmp_path / "lines.csv"
    good.write_text("x0,y0,z0,x1,y1,z1\n0,0,0,0,1,0\n1,0,0,1,1,0.5\n\n2,0,0,2,1,1\n")
    r = from_csv(good)
    assert len(r) == 3 and np.allclose(r.b[2], [2, 1, 1])
    bad = tmp_path / "bad.csv"
    bad.write_text("0,0,0,0,1,0\n1,0,0,1,1\n")
    with pytest.raises(DesignError, match=r"bad.csv: line 2: expected 6 numbers"):
        from_csv(bad)
    with pytest.raises(DesignError, match=r"missing\.csv: cannot read"):
        from_csv(tmp_path / "missing.csv")


# --- impossible distributions ------------------------------------------------

def test_curve_parallel_to_director_plane_is_refused():
    flat = Line([0, 0, 0], [0, 5, 0])
    with pytest.raises(GeometryError, match="c1 lies in a plane parallel to the director plane"):
        between(flat, C2, 9, "director-plane", director_plane=[1, 0, 0])


def test_director_plane_branch_turning_back_names_the_generator():
    zigzag = Polyline([[0, 0, 4], [8, 1, 4], [3, 2, 4], [12, 3, 4]])  # x: 0 -> 8 -> 3 -> 12
    with pytest.raises(GeometryError, match=r"director-plane: the branch on c2 turns back at "
                                            r"u = 0.36289\d* between generators 6 and 7 of 9"):
        between(C1, zigzag, 9, "director-plane", director_plane=[1, 0, 0])


def test_curves_without_common_planes_are_refused():
    far = Line([20, 0, 0], [30, 0, 1])
    with pytest.raises(GeometryError, match=r"no plane n \. x = s meets both curves"):
        between(C1, far, 9, "director-plane", director_plane=[1, 0, 0])


def test_directrix_through_a_generator_point_is_refused():
    a3 = C1.evaluate(C1.arclength_params(9)[3])
    d = np.array([a3, a3 + [0, 0, 1.0]])
    with pytest.raises(GeometryError, match=r"passes through a_3 \(generator 3\)"):
        between(C1, C2, 9, "linear-directrix", directrix=d)


def test_directrix_meeting_c2_is_refused():
    p = C2.evaluate(0.4)
    with pytest.raises(GeometryError, match="c2 meets the directrix d"):
        between(C1, C2, 9, "linear-directrix", directrix=[p, p + [0, 1.0, 0]])


def test_wrong_options_for_a_distribution():
    with pytest.raises(ParameterError, match="director_plane: required"):
        between(C1, C2, 9, "director-plane")
    with pytest.raises(ParameterError, match='directrix: only used with distribution "linear'):
        between(C1, C2, 9, "arc-length", directrix=D)
    with pytest.raises(ParameterError, match=r'distribution: expected one of .*did you mean '
                                             '"arc-length"'):
        between(C1, C2, 9, "arclength")


def test_rulings_validates_its_arrays():
    with pytest.raises(ParameterError, match="u: expected strictly increasing"):
        Rulings(np.zeros((3, 3)), np.ones((3, 3)), [0, 0.5, 0.4], None, {})


# --- design specs --------------------------------------------------------------

CURVES = {"c1": C1, "c2": C2}


def test_spec_between_matches_the_api():
    spec = {"between": ["c1", "c2"], "distribution": "linear-directrix",
            "directrix": D.tolist(), "count": 9}
    r = rulings_from_spec(spec, CURVES)
    expected = between(C1, C2, 9, "linear-directrix", directrix=D)
    assert np.array_equal(r.a, expected.a) and np.array_equal(r.b, expected.b)


def test_spec_lines_file_and_conoid(tmp_path):
    (tmp_path / "g.csv").write_text("0,0,0,0,1,0\n1,0,0,1,1,1\n2,0,0,2,1,0\n")
    r = rulings_from_spec({"file": "g.csv"}, {}, base_dir=tmp_path)
    assert len(r) == 3
    r = rulings_from_spec({"lines": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1]]]}, {})
    assert len(r) == 2
    r = rulings_from_spec({"conoid": {"curve": "arc", "directrix": LINE_D.tolist(),
                                      "director_plane": [1, 0, 0]}, "count": 5}, {"arc": ARC})
    assert np.abs(r.directions[:, 0]).max() < 1e-12


@pytest.mark.parametrize("spec, message", [
    ({"between": ["c1", "c2"], "count": "forty"}, 'rulings.count: expected an integer >= 3, '
                                                  'got "forty"'),
    ({"between": ["c1", "c3"], "count": 9}, 'rulings.between: no curve named "c3" (defined: '
                                            'c1, c2)'),
    ({"between": ["c1", "c2"], "cont": 9}, 'rulings.cont: unknown key (did you mean "count"?)'),
    ({"between": ["c1", "c2"], "lines": [], "count": 9}, "rulings.lines: give only one of"),
    ({"count": 9}, "rulings: expected one of between, lines, file or conoid"),
    ({"between": ["c1", "c2"]}, "rulings.count: missing"),
    ({"between": ["c1", "c2"], "count": 2}, "rulings.count: expected an integer >= 3, got 2"),
    ({"between": "c1", "count": 9}, 'rulings.between: expected two or three curve names'),
    ({"between": ["c1", "c2"], "count": 9, "distribution": "director-plane"},
     "rulings.director_plane: missing"),
    ({"between": ["c1", "c2"], "count": 9, "distribution": "linear-directrix",
      "directrix": [[0, 0, 0]]}, "rulings.directrix: expected 2 points of the line, got 1"),
    ({"between": ["c1", "c2"], "count": 9, "director_plane": [1, 0, 0]},
     'rulings.director_plane: not used with distribution "arc-length"'),
    ({"between": ["c1", "c2", "c1"], "count": 9, "distribution": "parameter"},
     "rulings.distribution: not used with three directrices"),
    ({"lines": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1]]], "count": 9},
     "rulings.count: not used with lines"),
    ({"lines": [[0, 0, 0]]}, "rulings.lines: expected at least 2 lines"),
    ({"file": "nope.csv"}, 'rulings.file: no such file "nope.csv"'),
    ({"conoid": {"curve": "c1", "directrix": [[0, 0, 0], [1, 0, 0]]}, "count": 9},
     "rulings.conoid.director_plane: missing"),
    ({"conoid": {"curve": "c9", "directrix": [[0, 0, 0], [1, 0, 0]], "director_plane": [1, 0, 0]},
      "count": 9}, 'rulings.conoid.curve: no curve named "c9"'),
    ({"conoid": {"curve": "c1", "directrix": [[0, 0, 0], [1, 0, 0]], "director_plan": [1, 0, 0]},
      "count": 9}, 'rulings.conoid.director_plan: unknown key (did you mean "director_plane"?)'),
])
def test_spec_errors_name_the_field(spec, message):
    with pytest.raises(DesignError) as err:
        rulings_from_spec(spec, CURVES)
    assert str(err.value).startswith(message), str(err.value)


@pytest.mark.parametrize("dist, kw", [
    ("director-plane", {"director_plane": [1, 0, 0]}),
    ("linear-directrix", {"directrix": [[5, -3, 8], [5, 6, 8]]}),
    ("arc-length", {}),
])
def test_reference_surface_does_not_depend_on_the_generator_count(dist, kw):
    areas = [between(C1, C2, count, dist, **kw).surface.area() for count in (3, 17, 60)]
    assert np.ptp(areas) <= 1e-10 * areas[0]


@pytest.mark.parametrize("make", [
    lambda: between(C1, C2, 11, "arc-length"),
    lambda: between(C1, Polyline([[0, 2, 4], [3, 4, 5], [6, 3, 3], [10, 3, 4]]), 9, "director-plane",
                    director_plane=[1, 0, 0]),
    lambda: conoid(ARC, LINE_D, np.array([1.0, 0.0, 0.0]), 7),
    lambda: from_lines(np.stack([np.column_stack([np.linspace(0, 1, 9), np.zeros(9), np.zeros(9)]),
                                 np.column_stack([np.linspace(0, 1, 9), np.ones(9), np.linspace(0, 1, 9) ** 2])], 1)),
])
def test_point_partials_is_point_and_partials(make):
    """The closest-point steps' combined evaluation is bit for bit the two separate ones."""
    s = make().surface
    u, t = np.linspace(0, 1, 23), np.linspace(0, 1, 23)[::-1]
    p, su, st = s.point_partials(u, t)
    qu, qt = s.partials(u, t)
    assert np.array_equal(p, s.point(u, t)) and np.array_equal(su, qu) and np.array_equal(st, qt)


# --- three skew lines (closed form) -----------------------------------------

def _regulus_line(a: float, b: float, c: float, phi: float, s: float) -> Line:
    """The segment of x^2/a^2 + y^2/b^2 - z^2/c^2 = 1's regulus line at angle phi, half-length s."""
    p = np.array([a * math.cos(phi), b * math.sin(phi), 0.0])
    d = np.array([-a * math.sin(phi), b * math.cos(phi), c])
    return Line(p - s * d, p + s * d)


def _off_quadric(x: np.ndarray, a: float, b: float, c: float) -> float:
    return float(np.abs(x[:, 0] ** 2 / a**2 + x[:, 1] ** 2 / b**2 - x[:, 2] ** 2 / c**2 - 1).max())


def test_three_lines_meet_the_third_beyond_its_points_and_at_infinity():
    """c3 only chooses the regulus: the lines may meet it beyond its two points, or run
    parallel to it, and the surface between c1 and c2 is still there.  (The numeric search
    refused this design: 'the line runs off the end of c3'.)"""
    a, b, c = 4.0, 3.0, 2.0
    c1, c2, c3 = (_regulus_line(a, b, c, phi, s) for phi, s in ((0.0, 1.0), (0.5, 2.0), (2.21, 1.0)))
    r = three_directrices(c1, c2, c3, 41)
    assert not r.info["warnings"]
    assert _on_curve(c1, r.a, r.info["c1_params"]) < 1e-12
    assert _on_curve(c2, r.b, r.info["c2_params"]) < 1e-12
    assert r.info["c1_params"][[0, -1]].tolist() == [0.0, 1.0]
    # Every generator lies on the quadric (the other regulus), and meets c3's line.
    for t in (0.0, 0.37, 1.0):
        assert _off_quadric(r.a + t * (r.b - r.a), a, b, c) < 1e-12
    w, lam = r.info["c3_params"], r.info["c3_t"]
    seen = np.isfinite(w)
    assert (~seen).sum() <= 1 and ((w[seen] < 0) | (w[seen] > 1)).any()
    hit = r.a[seen] + lam[seen, None] * (r.b - r.a)[seen]
    assert np.abs(hit - c3.evaluate(w[seen])).max() < 1e-9
    # The closed form agrees with the numeric search (the same lines as polylines) where the
    # search can follow the family: within the segments of c2 and c3.
    c3 = _regulus_line(a, b, c, 0.8, 4.0)
    closed = three_directrices(c1, c2, c3, 9)
    numeric = three_directrices(c1, *(Polyline(np.array([l.p0, l.p1])) for l in (c2, c3)), 9)
    assert np.array_equal(closed.a, numeric.a) and np.abs(closed.b - numeric.b).max() < 1e-12


def test_three_lines_span_the_part_of_c1_whose_lines_reach_c2():
    a, b, c = 4.0, 3.0, 2.0
    c1, c3 = _regulus_line(a, b, c, 0.3, 1.5), _regulus_line(a, b, c, 2.6, 1.5)
    c2 = _regulus_line(a, b, c, 1.4, 0.5)          # too short for every line through c1
    r = three_directrices(c1, c2, c3, 21)
    [said] = r.info["warnings"]
    assert "reach the segment c2 only from arc-length fraction" in said and "lengthen c2" in said
    v, u1 = r.info["c2_params"], r.info["c1_params"]
    assert (v >= 0).all() and (v <= 1).all()
    # c1 is cut where its lines leave the segment c2: there a generator ends at an end of c2.
    assert u1[0] > 0.1 and min(v[0], 1 - v[0]) < 1e-9
    assert u1[-1] < 1.0 or min(v[-1], 1 - v[-1]) > 1e-3
    assert _off_quadric(0.5 * (r.a + r.b), a, b, c) < 1e-12
    # No line through c1 reaches a far-away c2 at all.
    whole = _regulus_line(a, b, c, 1.4, 0.5)
    far = Line(whole.p0 + 5 * (whole.p1 - whole.p0), whole.p0 + 6 * (whole.p1 - whole.p0))
    with pytest.raises(GeometryError, match="no line through a point of c1 that meets the line c3 "
                                            "meets the segment c2"):
        three_directrices(c1, far, c3, 9)


def test_a_design_of_three_lines_says_which_part_its_generators_span():
    from ruledmesh.design import build_design, parse_design

    a, b, c = 4.0, 3.0, 2.0
    lines = [_regulus_line(a, b, c, phi, s) for phi, s in ((0.3, 1.5), (1.4, 0.5), (2.6, 1.5))]
    text = "".join(f"[curves.c{i + 1}]\ntype = \"line\"\npoints = [{l.p0.tolist()}, {l.p1.tolist()}]\n\n"
                   for i, l in enumerate(lines))
    text += "[rulings]\nbetween = [\"c1\", \"c2\", \"c3\"]\ncount = 25\n\n[mesh]\nrows = 12\n"
    built = build_design(parse_design(text, "three.toml"))
    assert built.mesh.info["warnings"][0].startswith("three directrices: the lines through c1")
    assert _off_quadric(built.mesh.vertices, a, b, c) < 1e-12


def test_a_line_c3_is_the_linear_directrix_taken_as_the_whole_line():
    """c3 a line, c2 a curve: the family is that of the linear directrix c3 (§5.2 (d)), so a
    short c3 segment, which the numeric search refused ('no line through c1(0) meets both c2
    and c3'), gives the same generators as the long one."""
    c1 = Line(np.array([-4.0, 0.0, 0.0]), np.array([4.0, 0.0, 0.0]))
    c2 = BSpline([[-2, 4, -1], [0, 4, 3], [2, 4, -1]], 2)
    long_c3 = Line(np.array([0.0, 8.0, -6.0]), np.array([0.0, 8.0, 6.0]))
    short_c3 = Line(np.array([0.0, 8.0, -1.0]), np.array([0.0, 8.0, 1.0]))
    long_r, short_r = (three_directrices(c1, c2, c3, 31) for c3 in (long_c3, short_c3))
    assert np.abs(long_r.b - short_r.b).max() < 1e-12
    assert short_r.info["distribution"] == "three-directrices"
    w, lam = short_r.info["c3_params"], short_r.info["c3_t"]
    assert ((w < 0) | (w > 1)).any()
    hit = short_r.a + lam[:, None] * (short_r.b - short_r.a)
    assert np.abs(hit - short_c3.evaluate(w)).max() < 1e-9
    # Every generator meets the three: c1 and c2 at its ends, the line c3 where reported.
    assert _on_curve(c2, short_r.b, short_r.info["c2_params"]) < 1e-12
    away = Line(np.array([0.0, 8.0, 50.0]), np.array([1.0, 8.0, 50.0]))
    with pytest.raises(GeometryError, match=r"^three directrices, the line c3 as linear directrix d: "):
        three_directrices(c1, c2, away, 9)
