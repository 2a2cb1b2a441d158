"""ruledmesh._arrays.unique against np.unique: the same values, NaNs collapsed alike."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from ruledmesh._arrays import unique


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
