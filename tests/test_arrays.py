"""ruledmesh._arrays against numpy: unique values, cross products, norms, percentiles and medians,
bit for bit; corner angles against the C library's atan2, to two ulps."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from ruledmesh._arrays import corner_angle, cross, median, member, norm, percentile, ranks, unique


def _same(x: np.ndarray, y: np.ndarray) -> bool:
    if x.dtype.kind == "f":
        return x.shape == y.shape and bool(np.all((x == y) | (np.isnan(x) & np.isnan(y))))
    return x.dtype == y.dtype and np.array_equal(x, y)


@settings(max_examples=200, deadline=None)
@given(hnp.arrays(st.sampled_from([np.int64, np.int32, np.uint8]), hnp.array_shapes(min_dims=1, max_dims=2, min_side=0),
                  elements=st.integers(0, 50)))
def test_integers(a):
    got = unique(a)
    assert got.dtype == a.dtype and np.array_equal(got, np.unique(a))


@settings(max_examples=200, deadline=None)
@given(hnp.arrays(np.float64, st.integers(0, 60),
                  elements=st.sampled_from([0.0, -0.0, 1.0, -2.5, np.nan, np.inf, -np.inf, 1e-300])))
def test_floats(a):
    assert _same(unique(a), np.unique(a))


def test_large_keys_sorted():
    rng = np.random.default_rng(3)
    keys = rng.integers(0, 10**12, 200_000)
    keys = np.concatenate([keys, keys[:50_000]])
    got = unique(keys)
    assert np.array_equal(got, np.unique(keys)) and np.all(np.diff(got) > 0)


def _bits(x: np.ndarray, y: np.ndarray) -> bool:
    """Same shape, dtype and bytes (zeros' signs and NaN payloads included)."""
    return x.shape == y.shape and x.dtype == y.dtype and x.tobytes() == y.tobytes()


_FLOATS = st.floats(-1e6, 1e6, allow_subnormal=True) | st.sampled_from([0.0, -0.0, 1e-300, np.inf, np.nan])


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 400), st.integers(0, 3), st.data())
def test_cross_is_np_cross(n, extra, data):
    """Bit for bit np.cross, on both sides of the size where the gathering form stops."""
    shape = (n,) + (2,) * extra + (3,)
    x = data.draw(hnp.arrays(np.float64, shape, elements=_FLOATS))
    y = data.draw(hnp.arrays(np.float64, shape, elements=_FLOATS))
    with np.errstate(invalid="ignore", over="ignore"):
        assert _bits(cross(x, y), np.cross(x, y))


def test_cross_broadcasts_like_np_cross():
    rng = np.random.default_rng(5)
    x, y = rng.standard_normal((4, 1, 3)), rng.standard_normal((1, 6, 3))
    assert _bits(cross(x, y), np.cross(x, y))


@settings(max_examples=200, deadline=None)
@given(hnp.arrays(np.float64, hnp.array_shapes(min_dims=1, max_dims=3, min_side=0), elements=_FLOATS))
def test_norm_is_linalg_norm(x):
    with np.errstate(invalid="ignore", over="ignore"):
        assert _bits(norm(x), np.linalg.norm(x, axis=-1))


@settings(max_examples=300, deadline=None)
@given(hnp.arrays(np.int64, st.tuples(st.integers(1, 40), st.integers(1, 4)),
                  elements=st.sampled_from([-(2**62), -3, -1, 0, 1, 2, 7, 2**62])))
def test_first_of_equal_rows_is_unique_rows(key):
    """The grouping the mesher merges end points by: np.unique's over rows."""
    from ruledmesh.skew.pq.assemble import _first_of_equal_rows

    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    assert np.array_equal(_first_of_equal_rows(key), first[inverse.reshape(-1)])


@given(st.lists(st.integers(0, 6), max_size=30))
def test_ranks_are_the_aranges_of_the_counts(counts):
    got = ranks(np.asarray(counts, dtype=np.int64))
    want = np.concatenate([np.arange(c) for c in counts]) if counts else np.zeros(0)
    assert got.shape == want.shape and np.array_equal(got, want)


@settings(max_examples=300, deadline=None)
@given(hnp.arrays(np.float64, hnp.array_shapes(min_dims=1, max_dims=2, min_side=0),
                  elements=st.sampled_from([0.0, -0.0, 1.5, 2.0, -3.25, np.inf, np.nan])),
       hnp.arrays(np.float64, st.integers(0, 80),
                  elements=st.sampled_from([0.0, 1.5, 2.0, 7.0, -np.inf, np.nan])))
def test_member_is_isin(values, among):
    """Large ``among`` too: np.isin's sorting path (the one that imports numpy.ma)."""
    got = member(values, among)
    assert got.shape == values.shape
    assert np.array_equal(got, np.isin(values, among))


def test_member_of_integer_keys():
    rng = np.random.default_rng(3)
    values, among = rng.integers(0, 5000, 3000), rng.integers(0, 5000, 2000)
    assert np.array_equal(member(values, among), np.isin(values, among))
    assert not member(values, np.zeros(0, np.int64)).any()


_ORDER_VALUES = st.one_of(st.floats(-1e6, 1e6), st.sampled_from([0.0, -0.0, 1.0, 3.0, 1e-300, 89.99]))


@settings(max_examples=300, deadline=None)
@given(hnp.arrays(np.float64, st.integers(1, 80), elements=_ORDER_VALUES),
       st.one_of(st.sampled_from([0.0, 1.0, 5.0, 50.0, 95.0, 100.0]), st.floats(0.0, 100.0)))
def test_percentile_is_numpys(a, q):
    assert percentile(a, q) == float(np.percentile(a, q))


@settings(max_examples=300, deadline=None)
@given(hnp.arrays(np.float64, st.integers(1, 80), elements=_ORDER_VALUES))
def test_median_is_numpys(a):
    assert median(a) == float(np.median(a))


@pytest.mark.parametrize("fn", [lambda a: percentile(a, 5), median])
def test_order_statistics_of_nan_are_nan(fn):
    assert np.isnan(fn(np.array([1.0, np.nan, 2.0])))


def test_order_statistics_import_no_masked_arrays():
    """The reason they exist: numpy's own import numpy.ma (see the module docstring)."""
    code = ("import sys, numpy as np\nfrom ruledmesh._arrays import median, percentile\n"
            "x = np.random.default_rng(0).random(101)\npercentile(x, 5), median(x)\n"
            "assert 'numpy.ma' not in sys.modules\nnp.median(x)\nassert 'numpy.ma' in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)


def _ulps(got: np.ndarray, want: np.ndarray) -> np.ndarray:
    return np.abs(got - want) / np.spacing(np.maximum(np.abs(want), np.finfo(float).tiny))


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 500), st.floats(-300, 300), st.floats(0, 30))
def test_corner_angle_is_atan2(seed, n, scale, spread):
    """Within two ulps of math.atan2 in degrees, from 0 to 180 and at any scale."""
    import math

    rng = np.random.default_rng(seed)
    s = np.abs(rng.standard_normal(n)) * 10.0 ** scale
    c = rng.standard_normal(n) * 10.0 ** scale * np.exp(rng.uniform(-spread, spread, n))
    want = np.array([math.degrees(math.atan2(y, x)) for y, x in zip(s.tolist(), c.tolist())])
    assert _ulps(corner_angle(s, c), want).max() <= 2.0


def test_corner_angle_edges_of_its_domain():
    """Zero edges (0 or 180 by the zero's sign, as atan2), right angles, NaN through, no warning."""
    s = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 2.0, np.nan, 1.0, 1e-310])
    c = np.array([0.0, -0.0, -3.0, 0.0, -0.0, 2.0, 1.0, np.nan, 1.0])
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        got = corner_angle(s, c)
    assert got[:6].tolist() == [0.0, 180.0, 180.0, 90.0, 90.0, 45.0]
    assert np.isnan(got[6:8]).all() and 0.0 < got[8] < 1e-300
    # Each reduction interval of the atan, and its ends.
    x = np.r_[np.linspace(0.0, 1.0, 20001), 0.4375, 0.6875, np.nextafter(0.4375, 0), np.nextafter(0.6875, 0)]
    assert _ulps(corner_angle(x, np.ones_like(x)), np.degrees(np.arctan(x))).max() <= 2.0
