"""Property-based fuzzing over random designs of every kind (docs/robustness.md).

Properties, for every random input:

* nothing but ruledmesh's documented errors (:class:`RuledMeshError`) escapes;
* no NaN or infinity in any output (vertices, ``t``, the analysis figures);
* every face is planar to 1e-12 (relative; the constructions promise it, so
  no face may need flagging);
* a trimmed §4.3 mesh lies inside the patch: every vertex is on its
  generator segment (``0 <= t <= 1``, at ``a_g + t (b_g - a_g)``).

Example counts: the base counts below sum to more than 10,000 under the
default ``ci`` profile (tests/conftest.py); ``HYPOTHESIS_PROFILE=local``
multiplies them by ten.
"""

from __future__ import annotations

import contextvars
import functools
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from ruledmesh.analysis import planarity
from ruledmesh.design import build_design, parse_design
from ruledmesh.errors import RuledMeshError
from ruledmesh.pq import pq_mesh
from ruledmesh.skew.hybrid import hybrid_mesh
from ruledmesh.web.toml_writer import dumps

SCALE = 10 if os.environ.get("HYPOTHESIS_PROFILE") == "local" else 1


def fuzz(n: int):
    """``n`` examples under the ci profile (times ten under ``local``)."""
    return settings(max_examples=n * SCALE, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much,
                                           HealthCheck.data_too_large])


# Outcomes of the examples of the running test: a fuzz test whose inputs were all refused
# would check nothing, so each test states the share of its examples that must build.
_OUTCOMES: contextvars.ContextVar[list[int]] = contextvars.ContextVar("fuzz_outcomes")


def count_outcome(ok: bool) -> bool:
    """Count one example as built (``ok``) or refused with a documented error."""
    counts = _OUTCOMES.get(None)
    if counts is not None:
        counts[0 if ok else 1] += 1
    return ok


def min_built(share: float):
    """Fail the test unless at least ``share`` of its examples built (see :func:`count_outcome`).

    The shares asked below are about 60 % of what the ci profile measures (PQ 78 %, hybrid
    75 %, ruled designs 41 %, line designs 72 %, catalogue 48 %, transforms 38 %), so random
    seeds under the local profile pass too.
    """
    def deco(test):
        @functools.wraps(test)
        def run(*args, **kwargs):
            counts = [0, 0]
            token = _OUTCOMES.set(counts)
            try:
                test(*args, **kwargs)
            finally:
                _OUTCOMES.reset(token)
            total = counts[0] + counts[1]
            print(f"{test.__name__}: {counts[0]} of {total} examples built")
            assert total and counts[0] >= share * total, (
                f"only {counts[0]} of {total} examples built (at least {share:.0%} expected): "
                "the strategy no longer reaches the mesher")
        return run
    return deco


# ------------------------------------------------------------------ checks
def check_mesh(mesh, *, planar: float = 1e-12, generators=None, stages=None) -> None:
    assert np.all(np.isfinite(mesh.vertices))
    for values in mesh.vertex_data.values():
        arr = np.asarray(values)
        if arr.dtype.kind == "f":
            assert np.all(np.isfinite(arr))
    if mesh.n_faces:
        assert mesh.face_indices.min() >= 0 and mesh.face_indices.max() < mesh.n_vertices
        p = planarity(mesh)
        assert np.all(np.isfinite(p))
        bad = np.flatnonzero(p > planar)
        if bad.size:
            check_flagged_rounding(mesh, p, bad, generators, stages, planar)


def _extrapolation_error(mesh, f: int, generators) -> float:
    """How far rounding can move face ``f``'s vertices at t far outside [0, 1] of their generator.

    A vertex ``a + t (b - a)`` carries the rounding of ``b - a`` (eps times the end points'
    size, in the frame the mesher works in) multiplied by ``|t|``: far out on a generator
    much shorter than the patch (a fan towards a point) that exceeds eps * |x|.
    """
    if generators is None or "t" not in mesh.vertex_data:
        return 0.0
    a, b = (np.asarray(x, float) for x in generators)
    ids = mesh.face(f)
    t = np.abs(np.asarray(mesh.vertex_data["t"])[ids])
    g = np.asarray(mesh.vertex_data["generator"])[ids]
    pts = np.concatenate([a, b])
    size = np.linalg.norm(pts.max(0) - pts.min(0)) + np.maximum(
        np.linalg.norm(a[g], axis=1), np.linalg.norm(b[g], axis=1))
    return float((t * size).max())


def _rounding_floor(mesh, f: int, areas: np.ndarray, generators=None) -> float:
    """The planarity face ``f`` of ``mesh`` can have from the rounding of its coordinates."""
    v = mesh.vertices[mesh.face(f)]
    edges = np.linalg.norm(v - np.roll(v, 1, axis=0), axis=1)
    # the face's thinnest extent: its shortest edge or its width across
    # the longest edge (a sliver in angle, not in length)
    thin = min(edges.min(), 2 * areas[f] / max(edges.max(), 1e-300))
    size = max(np.abs(v).max(), _extrapolation_error(mesh, f, generators))
    return 1e3 * np.finfo(float).eps * size / max(thin, 1e-300)


def check_flagged_rounding(mesh, p: np.ndarray, bad: np.ndarray, generators=None,
                           stages=None, planar: float = 1e-12) -> None:
    """Faces above 1e-12 must be flagged by the analysis, and be rounding only.

    A face much smaller than its distance from the origin (a sliver of a
    rotation by 1e-10 degrees, a mesh scaled by 1e-7 about a far centre)
    cannot be planar to 1e-12 *relative to its size* in float64: its
    coordinates carry errors of eps * |x|.  Such faces are allowed when the
    report flags them and their planarity is within that rounding floor.  With the
    ``generators`` (a, b) of a mesher's input, the floor includes the rounding of
    vertices far out on short generators (:func:`_extrapolation_error`).  ``stages``
    (a callable) gives the meshes a chain of transforms went through, the same faces
    in the same order: each stage's rounding is carried on by the maps after it (an
    inversion that shrinks a torus to a thousandth of its size 5 units from the origin,
    and one that blows it up again), so the floor is the largest of theirs.
    """
    from ruledmesh.analysis.live import face_measures, unit_copy
    from ruledmesh.analysis.report import analyze

    report = analyze(mesh)
    # The analysis measures in a centred unit frame, where mostly less of the coordinates'
    # rounding is left (but not always: a face a hundredth of the prism's length across
    # read 1.5e-13 as given, above 1e-12 there); it warns of what it finds, and every face
    # above the tolerance in either frame must be rounding.
    framed = face_measures(unit_copy(mesh)[0]).planarity
    flagged = report["planarity"]["above_tolerance"]
    assert flagged <= int(np.count_nonzero(framed > planar))
    bad = np.flatnonzero(np.maximum(p, framed) > planar)
    p = np.maximum(p, framed)
    if flagged:
        assert any("not planar" in w for w in report["warnings"]), report["warnings"]
    from ruledmesh.analysis import face_areas

    meshes = [mesh] + ([] if stages is None else list(stages()))
    assert all(m.n_faces == mesh.n_faces for m in meshes)
    areas = [face_areas(m) for m in meshes]
    for f in bad.tolist():
        floor = max(_rounding_floor(m, f, a, generators) for m, a in zip(meshes, areas))
        assert p[f] <= floor, f"face {f}: planarity {p[f]:.3g} above the rounding floor {floor:.3g}"


def check_inside_patch(mesh, a: np.ndarray, b: np.ndarray) -> None:
    """Every vertex of a trimmed mesh lies on its generator segment."""
    t = np.asarray(mesh.vertex_data["t"])
    g = np.asarray(mesh.vertex_data["generator"])
    size = float(np.linalg.norm(np.ptp(np.concatenate([a, b]), axis=0)))
    on = g >= 0
    assert np.all(on), "vertex without a generator"
    assert t.min() >= -1e-9 and t.max() <= 1 + 1e-9, (t.min(), t.max())
    expected = a[g] + t[:, None] * (b[g] - a[g])
    assert np.abs(mesh.vertices - expected).max() <= 1e-9 * size


# ------------------------------------------------------------- strategies
coord = st.floats(-10, 10, allow_nan=False, width=64)
point = st.tuples(coord, coord, coord)
scales = st.sampled_from([1e-6, 1e-3, 1.0, 1e3, 1e6])


@st.composite
def generator_sets(draw, min_m=3, max_m=9):
    """Random generators: free, near a smooth family, or with degeneracies mixed in."""
    m = draw(st.integers(min_m, max_m))
    style = draw(st.sampled_from(["random", "smooth", "degenerate"]))
    if style == "random":
        a = np.array(draw(st.lists(point, min_size=m, max_size=m)))
        b = np.array(draw(st.lists(point, min_size=m, max_size=m)))
    else:
        # samples of a smooth ruled surface: a(u), b(u) quadratic in u
        c = np.array(draw(st.lists(point, min_size=6, max_size=6)))
        u = np.linspace(0, 1, m)[:, None]
        a = c[0] + u * c[1] + u * u * c[2] * 0.3
        b = c[3] + u * c[4] + u * u * c[5] * 0.3
        if style == "degenerate":
            kind = draw(st.sampled_from(["parallel", "cone", "crossing", "repeat", "flat"]))
            i = draw(st.integers(0, m - 2))
            if kind == "parallel":          # cylinder piece: generator i+1 parallel to i
                b[i + 1] = a[i + 1] + (b[i] - a[i])
            elif kind == "cone":            # all through one point
                b[:] = b[0]
            elif kind == "crossing":        # torsal pair meeting at a point
                mid = 0.5 * (a[i] + b[i])
                b[i + 1] = mid + (mid - a[i + 1])
            elif kind == "repeat":
                a[i + 1], b[i + 1] = a[i], b[i]
            else:                           # everything in one plane
                a[:, 2] = 0.0
                b[:, 2] = 0.0
    s = draw(scales)
    return a * s, b * s


ALLOWED = (RuledMeshError,)


# ------------------------------------------------------------ §4.3 PQ mesh
# (A generator repeated two places later next to a torsal one used to warn 0/0 in
# pq._normalise; fixed, regression test in test_robustness_geometry.py.)
@min_built(0.5)
@fuzz(2500)
@given(gens=generator_sets(), rows=st.integers(1, 8), option=st.integers(0, 1),
       trim=st.booleans(), primary=st.one_of(st.just("middle"), st.integers(-3, 2)),
       extend=st.one_of(st.just("auto"), st.floats(0, 3)))
# Found at 10x examples: untrimmed, generator 0 is a millionth of the patch and carries a
# vertex 4e5 of its lengths out; rounding of its direction puts that quad at 4e-12 (the
# same generators scaled by 1e6 give 2.7e-13), which the floor now allows for.
@example(gens=(np.array([[0.0, 2e-6, 0.0], [1e-6 / 3, 2e-6, 6e-7 / 9], [2e-6 / 3, 2e-6, 2.4e-6 / 9],
                         [1e-6, 2e-6, 6e-7]]),
               np.array([[0.0, 2e-6, 1e-12], [0.0, 7e-6 / 3, 1e-12], [0.0, 8e-6 / 3, 1e-12],
                         [0.0, 3e-6, 1e-12]])),
         rows=1, option=0, trim=False, primary="middle", extend="auto")
def test_fuzz_pq_random_generators(gens, rows, option, trim, primary, extend):
    a, b = gens
    try:
        mesh = pq_mesh(a, b, rows=rows, primary=primary, option=option, trim=trim,
                       extend=extend)
    except ALLOWED:
        count_outcome(False)
        return
    count_outcome(True)
    check_mesh(mesh, generators=(a, b))
    if trim:
        check_inside_patch(mesh, a, b)


# ------------------------------------------------------- hybrid (§4.1) mesh
@min_built(0.5)
@fuzz(1500)
@given(gens=generator_sets(max_m=7), midpoints=st.integers(0, 3), divisions=st.integers(1, 6),
       flip=st.booleans())
def test_fuzz_hybrid_random_generators(gens, midpoints, divisions, flip):
    a, b = gens
    try:
        mesh = hybrid_mesh(a, b, midpoints=midpoints, divisions=divisions, flip=flip)
    except ALLOWED:
        count_outcome(False)
        return
    count_outcome(True)
    check_mesh(mesh)


# --------------------------------------------- ruled designs from curves
# The strategies are built once, here: built inside the composite, every draw made new
# strategy objects, which Hypothesis validates and analyses on first use (about a third of
# the test's time went to that). The same strategies draw the same designs.
# Without subnormal coordinates: the design layer refuses them in points (one line, tested by
# test_fuzz_malformed_values_in_examples and the command-line campaign), and newer Hypothesis
# versions draw so many that a fifth of the designs never reached the mesher.
xyz = st.lists(st.floats(-10, 10, allow_nan=False, width=64, allow_subnormal=False), min_size=3, max_size=3)
CURVE_SPECS = st.one_of(
    st.fixed_dictionaries({"type": st.just("line"), "points": st.lists(xyz, min_size=2, max_size=2)}),
    st.fixed_dictionaries({"type": st.just("polyline"), "points": st.lists(xyz, min_size=2, max_size=6)}),
    st.fixed_dictionaries({"type": st.just("bspline"), "points": st.lists(xyz, min_size=2, max_size=6),
                           "degree": st.integers(1, 3)}),
    st.fixed_dictionaries({"type": st.just("arc"), "points": st.lists(xyz, min_size=3, max_size=3)}),
    st.fixed_dictionaries({"type": st.just("helix"), "center": xyz, "axis": xyz,
                           "radius": st.floats(0.1, 5), "pitch": st.floats(-3, 3),
                           "turns": st.floats(0.1, 2)}),
)
DISTRIBUTIONS = st.sampled_from(["arc-length", "parameter", "director-plane", "linear-directrix",
                                 None])
DIRECTRIX = st.lists(xyz, min_size=2, max_size=2)


@st.composite
def ruled_designs(draw):
    c1, c2 = draw(CURVE_SPECS), draw(CURVE_SPECS)
    rulings = {"between": ["c1", "c2"], "count": draw(st.integers(3, 12))}
    dist = draw(DISTRIBUTIONS)
    if dist is not None:
        rulings["distribution"] = dist
    if dist == "director-plane":
        rulings["director_plane"] = draw(xyz)
    if dist == "linear-directrix":
        rulings["directrix"] = draw(DIRECTRIX)
    if draw(st.booleans()):
        mesh = {"method": "pq", "rows": draw(st.integers(1, 6)),
                "option": draw(st.integers(0, 1)), "trim": True, "refine": draw(st.booleans())}
    else:
        mesh = {"method": "hybrid", "midpoints": draw(st.integers(0, 2)),
                "divisions": draw(st.integers(1, 4))}
    return {"curves": {"c1": c1, "c2": c2}, "rulings": rulings, "mesh": mesh}


def _build(data):
    """Build a design dict through the TOML text path; None if refused with a documented error."""
    text = dumps(data)
    try:
        out = build_design(parse_design(text, "fuzz.toml"))
    except ALLOWED as exc:
        message = str(exc)
        assert "\n" not in message.strip(), message
        assert message.startswith("fuzz.toml: "), message
        count_outcome(False)
        return None
    count_outcome(True)
    return out


@min_built(0.25)
@fuzz(1000)
@given(data=ruled_designs())
def test_fuzz_ruled_designs(data):
    built = _build(data)
    if built is None:
        return
    check_mesh(built.mesh)
    if data["mesh"]["method"] == "pq":
        check_inside_patch(built.mesh, np.asarray(built.rulings.a), np.asarray(built.rulings.b))


@min_built(0.5)
@fuzz(800)
@given(gens=generator_sets(), rows=st.integers(1, 6), hybrid=st.booleans(), refine=st.booleans())
def test_fuzz_line_designs(gens, rows, hybrid, refine):
    a, b = gens
    lines = np.stack([a, b], axis=1).tolist()
    mesh = {"method": "hybrid"} if hybrid else {"rows": rows, "refine": refine}
    built = _build({"rulings": {"lines": lines}, "mesh": mesh})
    if built is not None:
        check_mesh(built.mesh)
        if not hybrid:
            check_inside_patch(built.mesh, np.asarray(built.rulings.a),
                               np.asarray(built.rulings.b))


# --------------------------------------------------- catalogue kinds (§2-§3)
pos = st.floats(0.05, 20)
small = st.integers(1, 12)
pt3 = st.lists(st.floats(-5, 5), min_size=3, max_size=3)
polygon = st.lists(pt3, min_size=2, max_size=7)
plane = st.sampled_from(["xy", "xz", "yz"])
profile = st.one_of(
    polygon,
    st.fixed_dictionaries({"type": st.just("arc"), "center": pt3, "radius": pos,
                           "start": st.floats(-360, 360), "end": st.floats(-360, 360),
                           "plane": plane}),
    st.fixed_dictionaries({"type": st.just("parabola"), "vertex": pt3, "k": st.floats(-2, 2),
                           "range": st.lists(st.floats(-3, 3), min_size=2, max_size=2),
                           "plane": plane}),
    st.fixed_dictionaries({"type": st.just("helix"), "center": pt3, "radius": pos,
                           "pitch": st.floats(-3, 3), "turns": st.floats(0.1, 2),
                           "start": st.floats(-180, 180)}),
)
KINDS = {
    "strips": st.fixed_dictionaries({"polygon": polygon, "closed": st.booleans(),
                                     "scales": st.lists(st.floats(-2, 2), min_size=1, max_size=4),
                                     "translations": st.lists(pt3, min_size=1, max_size=4)}),
    "prism": st.fixed_dictionaries({"polygon": polygon, "direction": pt3, "closed": st.booleans()}),
    "pyramid": st.fixed_dictionaries({"polygon": polygon, "apex": pt3, "closed": st.booleans(),
                                      "to_apex": st.booleans()}),
    "torsal-polyhedron": st.fixed_dictionaries({"polygon": polygon,
                                                "lengths": st.lists(st.floats(-1, 3), min_size=2,
                                                                    max_size=2)}),
    "translational": st.fixed_dictionaries({"p": profile, "q": profile}),
    "rotational": st.fixed_dictionaries({"meridian": profile,
                                         "axis": st.fixed_dictionaries({"point": pt3,
                                                                        "direction": pt3}),
                                         "angle": st.floats(-360, 360)}),
    "moulding": st.fixed_dictionaries({"profile": profile, "closed": st.booleans(),
                                       "axes": st.lists(st.fixed_dictionaries(
                                           {"point": pt3, "direction": pt3,
                                            "angle": st.floats(-90, 90)}), min_size=1,
                                           max_size=3)}),
    "pipe": st.fixed_dictionaries({"spine": profile, "radius": pos}),
    "canal": st.fixed_dictionaries({"spine": profile, "radius": pos}),
    "torus": st.fixed_dictionaries({"R": pos, "r": pos}),
    "dupin-cyclide": st.fixed_dictionaries({"R": pos, "r": pos, "center": pt3, "radius": pos}),
    "ellipsoid": st.fixed_dictionaries({"axes": st.lists(pos, min_size=3, max_size=3)}),
    "hyperboloid-two-sheets": st.fixed_dictionaries({"a": pos, "b": pos, "c": pos,
                                                     "height": pos}),
    "elliptic-paraboloid": st.fixed_dictionaries({"a": pos, "b": pos, "height": pos}),
    "hyperboloid": st.fixed_dictionaries({"a": pos, "b": pos, "c": pos, "height": pos,
                                          "style": st.sampled_from(["circular", "generators"])}),
    "hyperbolic-paraboloid": st.fixed_dictionaries({"a": pos, "b": pos, "size": pos,
                                                    "style": st.sampled_from(["parabolas",
                                                                              "generators"])}),
    "helicoid": st.fixed_dictionaries({"radius": pos, "pitch": st.floats(-5, 5),
                                       "turns": st.floats(0.05, 2)}),
}
ONE_DIRECTION = {"strips": (None, None), "prism": ("u", None), "pyramid": ("u", None),
                 "torsal-polyhedron": ("u", None)}

CATALOGUE_KINDS = tuple(sorted(KINDS))


@st.composite
def catalogue_designs(draw, kinds=CATALOGUE_KINDS):
    kind = draw(st.sampled_from(kinds))
    surface = {"kind": kind, **draw(KINDS[kind])}
    keys = ONE_DIRECTION.get(kind, ("u", "v"))
    mesh = {k: draw(small) for k in keys if k}
    return {"surface": surface, "mesh": mesh}


@min_built(0.3)
@fuzz(2500)
@given(data=catalogue_designs())
def test_fuzz_catalogue_kinds(data):
    built = _build(data)
    if built is not None:
        check_mesh(built.mesh)


# --------------------------------------------------------------- transforms
transform = st.one_of(
    st.fixed_dictionaries({"type": st.just("translate"), "vector": pt3}),
    st.fixed_dictionaries({"type": st.just("rotate"), "axis": pt3, "angle": st.floats(-720, 720),
                           "center": pt3}),
    st.fixed_dictionaries({"type": st.just("scale"),
                           "factor": st.one_of(st.floats(-1e3, 1e3),
                                               st.lists(st.floats(-10, 10), min_size=3,
                                                        max_size=3)),
                           "center": pt3}),
    st.fixed_dictionaries({"type": st.just("shear"), "xy": st.floats(-3, 3),
                           "zx": st.floats(-3, 3)}),
    st.fixed_dictionaries({"type": st.just("affine"),
                           "matrix": st.lists(st.lists(st.floats(-3, 3), min_size=3, max_size=3),
                                              min_size=3, max_size=3), "offset": pt3}),
    st.fixed_dictionaries({"type": st.just("projective"),
                           "matrix": st.lists(st.lists(st.floats(-3, 3), min_size=4, max_size=4),
                                              min_size=4, max_size=4)}),
    st.fixed_dictionaries({"type": st.just("inversion"), "center": pt3, "radius": pos}),
)


@min_built(0.2)
@fuzz(1200)
@given(data=catalogue_designs(kinds=("torus", "hyperboloid", "rotational", "prism",
                                     "hyperbolic-paraboloid", "ellipsoid")),
       chain=st.lists(transform, min_size=1, max_size=3))
# Drawn in a normal run: the torus shrunk about a point 5 units out by an inversion of radius
# 1/16 keeps coordinates ~5 for faces ~1e-4 across (1.2e-12 once the second blows it up).
@example(data={"surface": {"kind": "torus", "R": 2.0, "r": 0.875}, "mesh": {"u": 5, "v": 3}},
         chain=[{"type": "inversion", "center": [5.0, 0.0, 1.0], "radius": 0.0625},
                {"type": "inversion", "center": [5.0, 0.0, 1.0], "radius": 1.0}])
@example(data={"surface": {"kind": "prism", "polygon": [[0.0, 0.0, 1.4114334467728957],
                                                        [2.5, 2.0, -4.928932751854671],
                                                        [0.0, 1e-05, 0.0]],
                           "direction": [2.5, 2.0, -4.928932751854671], "closed": False},
               "mesh": {"u": 4}},
         chain=[{"type": "translate", "vector": [0.0, 0.0, 0.0]}])
def test_fuzz_transforms(data, chain):
    data["transform"] = chain
    built = _build(data)
    if built is not None:
        # a projective map or an inversion may squeeze faces: planarity is
        # measured relative to each face, so the bound holds the same
        def stages():
            for k in range(len(chain)):
                yield build_design(parse_design(dumps({**data, "transform": chain[:k]}), "fuzz.toml")).mesh

        check_mesh(built.mesh, stages=stages)


# ------------------------------------------- malformed values in real designs
EXAMPLES = sorted((os.path.dirname(__file__) + "/../examples/" + n)
                  for n in os.listdir(os.path.join(os.path.dirname(__file__), "..", "examples"))
                  if n.endswith(".toml") and n not in ("lines-file.toml",))
JUNK = st.one_of(st.text(max_size=5), st.booleans(), st.integers(-10, 500),
                 st.floats(allow_nan=True, allow_infinity=True), st.just([]),
                 st.lists(st.integers(-3, 3), max_size=4), st.just({"x": 1}),
                 st.lists(st.lists(st.floats(-1e300, 1e300), max_size=4), max_size=3))


def _leaves(data, path=()):
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _leaves(v, path + (k,))
    elif isinstance(data, list) and data and isinstance(data[0], dict):
        for i, v in enumerate(data):
            yield from _leaves(v, path + (i,))
    else:
        yield path


@fuzz(400)
@given(example=st.sampled_from(EXAMPLES), pick=st.integers(0, 10 ** 6), junk=JUNK)
def test_fuzz_malformed_values_in_examples(example, pick, junk):
    import tomllib

    with open(example, "rb") as fh:
        data = tomllib.load(fh)
    # keep the example small so the fuzzing stays fast
    for table, key, cap in (("rulings", "count", 12), ("mesh", "rows", 8), ("mesh", "u", 10),
                            ("mesh", "v", 10), ("mesh", "divisions", 4)):
        if isinstance(data.get(table), dict) and isinstance(data[table].get(key), int):
            data[table][key] = min(data[table][key], cap)
    # ... and unrefined: the refinement rebuilds a design up to a dozen times, and what this
    # test checks is the handling of the values (test_fuzz_ruled_designs fuzzes the refinement)
    mesh = data.get("mesh", {})
    if "rulings" in data and isinstance(mesh, dict) and mesh.get("method", "pq") == "pq":
        data["mesh"] = {**mesh, "refine": False}
    leaves = list(_leaves(data))
    path = leaves[pick % len(leaves)]
    node = data
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = junk
    try:
        dumps(data)
    except Exception:  # noqa: BLE001 -                     # values TOML cannot hold (e.g. None)
        assume(False)
    built = _build(data)
    if built is not None:
        check_mesh(built.mesh)


def test_min_built_fails_when_every_example_is_refused():
    @min_built(0.5)
    @settings(max_examples=5, database=None)
    @given(st.integers())
    def refused(x):
        count_outcome(False)

    with pytest.raises(AssertionError, match="only 0 of"):
        refused()
